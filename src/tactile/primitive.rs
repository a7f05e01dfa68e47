//! MuJoCo's primitive geoms as solids, cut by the pad's rays analytically.
//!
//! Every primitive is convex, so a line `o + s d` (geom frame, `|d| = 1`) meets it in one interval
//! `[s_in, s_out]` of the line parameter, possibly unbounded (a plane). With the line starting on
//! the pad plane and `d` the pad normal, `s` is the pad-frame depth: `s_in > 0` is the nearest
//! surface in front of the pad, and `s_in <= 0 <= s_out` means the pad point is inside the solid.
//!
//! Sizes follow MuJoCo's `geom_size`: sphere `r`; capsule and cylinder `r`, half-length along the
//! local z; ellipsoid the three semi-axes; box the three half-sizes. A plane is the half-space
//! `z <= 0` of its frame, unbounded as in MuJoCo's collisions (its size only sets how it is drawn).

use glam::DVec3;
use mujoco_rs::mujoco_c::mjtGeom;

/// Directions closer than this (squared sine) to parallel count as parallel.
const PARALLEL_EPS: f64 = 1e-30;

/// A primitive solid in its geom frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Solid {
    HalfSpace,
    Sphere { radius_m: f64 },
    Capsule { radius_m: f64, half_length_m: f64 },
    Ellipsoid { radii_m: DVec3 },
    Cylinder { radius_m: f64, half_length_m: f64 },
    Box { half_m: DVec3 },
}

/// What a MuJoCo geom type is to the covering's rays.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GeomShape {
    /// A primitive, cut analytically.
    Solid(Solid),
    /// A mesh, rasterised from its BVH (`mesh_bvh`).
    Mesh,
    /// A geom the covering cannot sense, by kind (a height field, a signed distance field).
    Unsupported(&'static str),
}

impl GeomShape {
    /// The shape of a geom of MuJoCo type `geom_type` (`mjtGeom`) and `geom_size` `size` (three
    /// values, read as the module docs say).
    pub fn of_geom(geom_type: i32, size: &[f64]) -> Self {
        let is = |t: mjtGeom| geom_type == t as i32;
        if is(mjtGeom::mjGEOM_PLANE) {
            Self::Solid(Solid::HalfSpace)
        } else if is(mjtGeom::mjGEOM_SPHERE) {
            Self::Solid(Solid::Sphere { radius_m: size[0] })
        } else if is(mjtGeom::mjGEOM_CAPSULE) {
            Self::Solid(Solid::Capsule {
                radius_m: size[0],
                half_length_m: size[1],
            })
        } else if is(mjtGeom::mjGEOM_ELLIPSOID) {
            Self::Solid(Solid::Ellipsoid {
                radii_m: DVec3::from_slice(size),
            })
        } else if is(mjtGeom::mjGEOM_CYLINDER) {
            Self::Solid(Solid::Cylinder {
                radius_m: size[0],
                half_length_m: size[1],
            })
        } else if is(mjtGeom::mjGEOM_BOX) {
            Self::Solid(Solid::Box {
                half_m: DVec3::from_slice(size),
            })
        } else if is(mjtGeom::mjGEOM_MESH) {
            Self::Mesh
        } else if is(mjtGeom::mjGEOM_HFIELD) {
            Self::Unsupported("height field")
        } else {
            Self::Unsupported("signed distance field")
        }
    }
}

/// A parameter interval `[s_in, s_out]` of a line inside a solid.
pub type Interval = (f64, f64);

impl Solid {
    /// The interval of the line `o + s d` inside the solid, if any (`d` a unit vector).
    pub fn line_interval(&self, o: DVec3, d: DVec3) -> Option<Interval> {
        match *self {
            Solid::HalfSpace => half_space(o.z, d.z),
            Solid::Sphere { radius_m } => quadric(
                d.length_squared(),
                o.dot(d),
                o.length_squared() - radius_m * radius_m,
            ),
            Solid::Ellipsoid { radii_m } => {
                let (o, d) = (o / radii_m, d / radii_m);
                quadric(d.length_squared(), o.dot(d), o.length_squared() - 1.0)
            }
            Solid::Cylinder {
                radius_m,
                half_length_m,
            } => cylinder(o, d, radius_m, half_length_m),
            Solid::Capsule {
                radius_m,
                half_length_m,
            } => {
                let axis = DVec3::Z * half_length_m;
                let r2 = radius_m * radius_m;
                [
                    cylinder(o, d, radius_m, half_length_m),
                    quadric(1.0, (o - axis).dot(d), (o - axis).length_squared() - r2),
                    quadric(1.0, (o + axis).dot(d), (o + axis).length_squared() - r2),
                ]
                .into_iter()
                .flatten()
                .reduce(|(a0, a1), (b0, b1)| (a0.min(b0), a1.max(b1)))
            }
            Solid::Box { half_m } => {
                let mut lo = f64::NEG_INFINITY;
                let mut hi = f64::INFINITY;
                for k in 0..3 {
                    let (ok, dk, hk) = (o[k], d[k], half_m[k]);
                    let (s0, s1) = slab(ok, dk, hk)?;
                    lo = lo.max(s0);
                    hi = hi.min(s1);
                }
                (lo <= hi).then_some((lo, hi))
            }
        }
    }
}

/// `{ s : o + s d  with  |o_k + s d_k| <= h }` for one axis.
fn slab(o: f64, d: f64, h: f64) -> Option<Interval> {
    if d * d < PARALLEL_EPS {
        return (o.abs() <= h).then_some((f64::NEG_INFINITY, f64::INFINITY));
    }
    let (a, b) = ((-h - o) / d, (h - o) / d);
    Some((a.min(b), a.max(b)))
}

/// `{ s : oz + s dz <= 0 }`.
fn half_space(oz: f64, dz: f64) -> Option<Interval> {
    if dz * dz < PARALLEL_EPS {
        return (oz <= 0.0).then_some((f64::NEG_INFINITY, f64::INFINITY));
    }
    let s = -oz / dz;
    Some(if dz > 0.0 {
        (f64::NEG_INFINITY, s)
    } else {
        (s, f64::INFINITY)
    })
}

/// `{ s : a s^2 + 2 b s + c <= 0 }` for `a > 0`.
fn quadric(a: f64, b: f64, c: f64) -> Option<Interval> {
    let disc = b * b - a * c;
    if disc < 0.0 || a <= 0.0 {
        return None;
    }
    // Stable roots: q = -(b + sign(b) sqrt(disc)); roots q / a and c / q.
    let sq = disc.sqrt();
    let q = -(b + sq.copysign(b));
    if q == 0.0 {
        return Some((0.0, 0.0));
    }
    let (r0, r1) = (q / a, c / q);
    Some((r0.min(r1), r0.max(r1)))
}

/// Finite cylinder about the local z axis.
fn cylinder(o: DVec3, d: DVec3, radius_m: f64, half_length_m: f64) -> Option<Interval> {
    let a = d.x * d.x + d.y * d.y;
    let c = o.x * o.x + o.y * o.y - radius_m * radius_m;
    let radial = if a < PARALLEL_EPS {
        (c <= 0.0).then_some((f64::NEG_INFINITY, f64::INFINITY))?
    } else {
        quadric(a, o.x * d.x + o.y * d.y, c)?
    };
    let axial = slab(o.z, d.z, half_length_m)?;
    let (lo, hi) = (radial.0.max(axial.0), radial.1.min(axial.1));
    (lo <= hi).then_some((lo, hi))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Option<Interval>, b: Interval) -> bool {
        let near = |u: f64, v: f64| u == v || (u - v).abs() < 1e-12;
        a.is_some_and(|(x, y)| near(x, b.0) && near(y, b.1))
    }

    #[test]
    fn sphere_and_ellipsoid_chords() {
        let s = Solid::Sphere { radius_m: 2.0 };
        assert!(close(
            s.line_interval(DVec3::new(0.0, 0.0, -5.0), DVec3::Z),
            (3.0, 7.0)
        ));
        assert!(close(
            s.line_interval(DVec3::new(0.0, 0.0, 1.0), DVec3::Z),
            (-3.0, 1.0)
        ));
        assert!(s.line_interval(DVec3::new(2.1, 0.0, -5.0), DVec3::Z).is_none());
        let e = Solid::Ellipsoid {
            radii_m: DVec3::new(1.0, 2.0, 3.0),
        };
        assert!(close(
            e.line_interval(DVec3::new(0.0, 0.0, -5.0), DVec3::Z),
            (2.0, 8.0)
        ));
        assert!(close(
            e.line_interval(DVec3::new(0.0, -5.0, 0.0), DVec3::Y),
            (3.0, 7.0)
        ));
    }

    #[test]
    fn half_space_from_either_side() {
        let h = Solid::HalfSpace;
        assert!(close(
            h.line_interval(DVec3::new(0.0, 0.0, 1.0), -DVec3::Z),
            (1.0, f64::INFINITY)
        ));
        let (lo, hi) = h.line_interval(DVec3::new(0.0, 0.0, -1.0), DVec3::Z).unwrap();
        assert!(lo == f64::NEG_INFINITY && (hi - 1.0).abs() < 1e-15);
        assert!(h.line_interval(DVec3::new(0.0, 0.0, 1.0), DVec3::X).is_none());
        assert!(h.line_interval(DVec3::new(0.0, 0.0, -1.0), DVec3::X).is_some());
    }

    #[test]
    fn box_cylinder_capsule() {
        let b = Solid::Box {
            half_m: DVec3::new(1.0, 2.0, 3.0),
        };
        assert!(close(
            b.line_interval(DVec3::new(0.5, 0.5, -10.0), DVec3::Z),
            (7.0, 13.0)
        ));
        assert!(b.line_interval(DVec3::new(1.5, 0.5, -10.0), DVec3::Z).is_none());
        let d = DVec3::new(1.0, 1.0, 0.0).normalize();
        let (lo, hi) = b.line_interval(DVec3::new(-5.0, -5.0, 0.0), d).unwrap();
        assert!((lo - 4.0 * 2f64.sqrt()).abs() < 1e-12 && (hi - 6.0 * 2f64.sqrt()).abs() < 1e-12);

        let c = Solid::Cylinder {
            radius_m: 1.0,
            half_length_m: 2.0,
        };
        assert!(close(
            c.line_interval(DVec3::new(0.0, 0.0, -5.0), DVec3::Z),
            (3.0, 7.0)
        ));
        assert!(close(
            c.line_interval(DVec3::new(-5.0, 0.0, 1.0), DVec3::X),
            (4.0, 6.0)
        ));
        assert!(c.line_interval(DVec3::new(-5.0, 0.0, 2.5), DVec3::X).is_none());

        let k = Solid::Capsule {
            radius_m: 1.0,
            half_length_m: 2.0,
        };
        assert!(close(
            k.line_interval(DVec3::new(0.0, 0.0, -5.0), DVec3::Z),
            (2.0, 8.0)
        ));
        assert!(close(
            k.line_interval(DVec3::new(-5.0, 0.0, 2.5), DVec3::X),
            (5.0 - 0.75f64.sqrt(), 5.0 + 0.75f64.sqrt())
        ));
    }
}
