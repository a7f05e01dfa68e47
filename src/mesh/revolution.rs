//! Surfaces of revolution: a profile curve in the (r, z) half-plane, from a point on the axis to
//! another point on the axis, swept once around the z axis. Closed and consistently oriented by
//! construction: the two axis end points become single pole vertices and every other profile point a
//! ring of vertices.
//!
//! The profile is made of line segments and circular arcs, so its enclosed volume is known in closed
//! form (disc integration, equivalently Pappus' centroid theorem):
//! V = pi * integral over the profile of r(s)^2 dz(s),
//! which counts the parts where the profile runs downwards (a cup) negatively. A line from (r1, z1) to
//! (r2, z2) contributes pi (z2 - z1) (r1^2 + r1 r2 + r2^2) / 3 (a frustum); an arc of centre (c_r, c_z)
//! and radius R from angle a to b contributes pi R [c_r^2 sin t + 2 c_r R (t/2 + sin 2t / 4)
//! + R^2 (sin t - sin^3 t / 3)] evaluated from t = a to t = b.

use std::f64::consts::{PI, TAU};

use glam::{DVec2, DVec3};

use super::TriMesh;
use super::error::MeshError;

/// One piece of a profile, continuing from where the previous one ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ProfileSegment {
    /// A straight line to `end` = (r, z), metres.
    Line { end: DVec2 },
    /// A circular arc about `center` = (r, z) from angle `start_rad` to `end_rad` (counter-clockwise
    /// in the (r, z) plane when `end_rad > start_rad`); its radius is the distance from the centre to
    /// the current point.
    Arc {
        center: DVec2,
        radius_m: f64,
        start_rad: f64,
        end_rad: f64,
    },
}

impl ProfileSegment {
    fn end(&self) -> DVec2 {
        match *self {
            ProfileSegment::Line { end } => end,
            ProfileSegment::Arc {
                center,
                radius_m,
                end_rad,
                ..
            } => center + radius_m * DVec2::new(end_rad.cos(), end_rad.sin()),
        }
    }
}

/// A profile curve in the (r, z) half-plane, from the axis back to the axis, r > 0 in between.
#[derive(Debug, Clone, PartialEq)]
pub struct Profile {
    start: DVec2,
    segments: Vec<ProfileSegment>,
}

/// Tolerance on the continuity of segments and on points lying on the axis, metres.
const JOIN_TOLERANCE_M: f64 = 1e-9;

impl Profile {
    /// Starts a profile at height `z_m` on the axis.
    pub fn builder(z_m: f64) -> ProfileBuilder {
        ProfileBuilder {
            start: DVec2::new(0.0, z_m),
            current: DVec2::new(0.0, z_m),
            segments: Vec::new(),
        }
    }

    pub fn segments(&self) -> &[ProfileSegment] {
        &self.segments
    }

    /// The exact volume of the solid the profile sweeps out (see the module docs).
    pub fn analytic_volume_m3(&self) -> f64 {
        let mut current = self.start;
        let mut volume = 0.0;
        for segment in &self.segments {
            volume += match *segment {
                ProfileSegment::Line { end } => {
                    let (r1, r2) = (current.x, end.x);
                    PI * (end.y - current.y) * (r1 * r1 + r1 * r2 + r2 * r2) / 3.0
                }
                ProfileSegment::Arc {
                    center,
                    radius_m: r,
                    start_rad,
                    end_rad,
                } => {
                    let c = center.x;
                    let primitive = |t: f64| {
                        let s = t.sin();
                        c * c * s
                            + 2.0 * c * r * (t / 2.0 + (2.0 * t).sin() / 4.0)
                            + r * r * (s - s * s * s / 3.0)
                    };
                    PI * r * (primitive(end_rad) - primitive(start_rad))
                }
            };
            current = segment.end();
        }
        volume
    }

    /// The profile as points: lines by their end points, arcs split into pieces of at most
    /// `max_arc_step_rad`. The first and last points are on the axis.
    pub fn points(&self, max_arc_step_rad: f64) -> Vec<DVec2> {
        let mut points = vec![self.start];
        for segment in &self.segments {
            match *segment {
                ProfileSegment::Line { end } => points.push(end),
                ProfileSegment::Arc {
                    center,
                    radius_m,
                    start_rad,
                    end_rad,
                } => {
                    let n = ((end_rad - start_rad).abs() / max_arc_step_rad).ceil().max(1.0) as usize;
                    points.extend((1..=n).map(|k| {
                        let t = start_rad + (end_rad - start_rad) * k as f64 / n as f64;
                        center + radius_m * DVec2::new(t.cos(), t.sin())
                    }));
                }
            }
        }
        points
    }

    /// Sweeps the profile around the z axis in `segments` steps. Each profile point off the axis
    /// becomes a ring of `segments` vertices at angles 2 pi j / segments; the end points are poles.
    /// Triangles are wound so their normals point away from the solid (positive signed volume for a
    /// profile that runs upward on its outer side).
    ///
    /// The mesh inscribes the smooth surface: each ring is a regular polygon, so the mesh volume is
    /// the analytic volume times n sin(2 pi / n) / (2 pi) plus the arc-flattening error.
    pub fn revolve(&self, segments: usize, max_arc_step_rad: f64) -> Result<TriMesh, MeshError> {
        if segments < 3 {
            return Err(MeshError::InvalidParameter {
                field: "segments",
                what: format!("a surface of revolution needs at least 3 segments, got {segments}"),
            });
        }
        if !(max_arc_step_rad > 0.0 && max_arc_step_rad.is_finite()) {
            return Err(MeshError::InvalidParameter {
                field: "max_arc_step_rad",
                what: format!("{max_arc_step_rad} is not a positive angle"),
            });
        }
        let points = self.points(max_arc_step_rad);
        let rings = &points[1..points.len() - 1];
        let n = segments as u32;
        let mut vertices = Vec::with_capacity(rings.len() * segments + 2);
        vertices.push(DVec3::new(0.0, 0.0, points[0].y));
        for p in rings {
            vertices.extend((0..segments).map(|j| {
                let a = TAU * j as f64 / segments as f64;
                DVec3::new(p.x * a.cos(), p.x * a.sin(), p.y)
            }));
        }
        let top = vertices.len() as u32;
        vertices.push(DVec3::new(0.0, 0.0, points[points.len() - 1].y));

        let ring = |i: usize, j: u32| 1 + i as u32 * n + j % n;
        let mut triangles = Vec::with_capacity(2 * segments * (rings.len() + 1));
        for j in 0..n {
            triangles.push([0, ring(0, j + 1), ring(0, j)]);
        }
        for i in 0..rings.len() - 1 {
            for j in 0..n {
                triangles.push([ring(i, j), ring(i, j + 1), ring(i + 1, j)]);
                triangles.push([ring(i, j + 1), ring(i + 1, j + 1), ring(i + 1, j)]);
            }
        }
        let last = rings.len() - 1;
        for j in 0..n {
            triangles.push([ring(last, j), ring(last, j + 1), top]);
        }
        Ok(TriMesh { vertices, triangles })
    }
}

/// Builds a [`Profile`] segment by segment; `finish` checks it.
#[derive(Debug, Clone)]
pub struct ProfileBuilder {
    start: DVec2,
    current: DVec2,
    segments: Vec<ProfileSegment>,
}

impl ProfileBuilder {
    /// A straight line from the current point to (r_m, z_m).
    pub fn line_to(mut self, r_m: f64, z_m: f64) -> Self {
        let end = DVec2::new(r_m, z_m);
        self.segments.push(ProfileSegment::Line { end });
        self.current = end;
        self
    }

    /// A circular arc about (center_r_m, center_z_m) from the current point to the angle `end_rad`
    /// (measured from the +r axis toward +z); counter-clockwise when `end_rad` exceeds the current
    /// point's angle.
    pub fn arc_to(mut self, center_r_m: f64, center_z_m: f64, end_rad: f64) -> Self {
        let center = DVec2::new(center_r_m, center_z_m);
        let offset = self.current - center;
        let segment = ProfileSegment::Arc {
            center,
            radius_m: offset.length(),
            start_rad: offset.y.atan2(offset.x),
            end_rad,
        };
        self.current = segment.end();
        self.segments.push(segment);
        self
    }

    /// The profile, checked: it must end on the axis, have at least one point off the axis, keep
    /// r > 0 between its ends, and use finite numbers only.
    pub fn finish(self) -> Result<Profile, MeshError> {
        let profile = Profile {
            start: self.start,
            segments: self.segments,
        };
        let points = profile.points(TAU / 4096.0);
        let bad = |what: String| Err(MeshError::Profile { what });
        if points.iter().any(|p| !p.is_finite()) {
            return bad("a coordinate is not finite".into());
        }
        if points.len() < 3 {
            return bad("a profile needs at least one point off the axis".into());
        }
        let end = points[points.len() - 1];
        if end.x.abs() > JOIN_TOLERANCE_M {
            return bad(format!(
                "the profile must end on the axis (r = 0), it ends at r = {}",
                end.x
            ));
        }
        if let Some(p) = points[1..points.len() - 1]
            .iter()
            .find(|p| p.x <= JOIN_TOLERANCE_M)
        {
            return bad(format!(
                "the profile touches or crosses the axis between its ends, at z = {}",
                p.y
            ));
        }
        Ok(profile)
    }
}
