//! Area-weighted random points on a mesh surface (Sec. V-A3): "a triangle is selected from the
//! triangular mesh with probability proportional to its area. A point p is then sampled uniformly at
//! random inside the selected triangle".
//!
//! Triangle choice inverts the cumulative area by binary search. A uniform point in triangle (a, b, c)
//! is `(1 - √r1) a + √r1 (1 - r2) b + √r1 r2 c` for r1, r2 ~ U(0, 1) (Osada et al. 2002, Eq. 1),
//! whose density is constant over the triangle.

use glam::DVec3;
use rand::RngExt;

use crate::mesh::TriMesh;
use crate::rng::Rng;

/// A point on the surface and the outward unit normal of its triangle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfacePoint {
    pub triangle: usize,
    pub point_m: DVec3,
    pub normal: DVec3,
}

/// Precomputed cumulative areas of the eligible triangles of a mesh.
#[derive(Debug, Clone)]
pub struct SurfaceSampler {
    triangles: Vec<usize>,
    cumulative_area: Vec<f64>,
}

impl SurfaceSampler {
    /// Every triangle with non-zero area is eligible when `eligible` says so (e.g. only faces seen from
    /// above for the raised letters, Sec. V-D); `None` when no eligible area remains.
    pub fn new(mesh: &TriMesh, eligible: impl Fn(DVec3) -> bool) -> Option<Self> {
        let mut triangles = Vec::new();
        let mut cumulative_area = Vec::new();
        let mut total = 0.0;
        for t in 0..mesh.triangles.len() {
            let area = mesh.triangle_area(t);
            let Some(normal) = triangle_normal(mesh, t) else {
                continue;
            };
            if area > 0.0 && area.is_finite() && eligible(normal) {
                total += area;
                triangles.push(t);
                cumulative_area.push(total);
            }
        }
        (total > 0.0).then_some(Self {
            triangles,
            cumulative_area,
        })
    }

    /// Total eligible area, square metres.
    pub fn total_area(&self) -> f64 {
        self.cumulative_area.last().copied().unwrap_or(0.0)
    }

    /// One area-weighted random surface point.
    pub fn sample(&self, mesh: &TriMesh, rng: &mut Rng) -> SurfacePoint {
        let u = rng.random_range(0.0..self.total_area());
        let i = self
            .cumulative_area
            .partition_point(|&c| c <= u)
            .min(self.triangles.len() - 1);
        let triangle = self.triangles[i];
        let [a, b, c] = mesh.corners(triangle);
        let (r1, r2): (f64, f64) = (rng.random_range(0.0..=1.0), rng.random_range(0.0..=1.0));
        let s = r1.sqrt();
        let point_m = a * (1.0 - s) + b * (s * (1.0 - r2)) + c * (s * r2);
        let normal = triangle_normal(mesh, triangle).unwrap_or(DVec3::Z);
        SurfacePoint {
            triangle,
            point_m,
            normal,
        }
    }
}

/// Outward unit normal of triangle `t` (counter-clockwise seen from outside); `None` if degenerate.
pub fn triangle_normal(mesh: &TriMesh, t: usize) -> Option<DVec3> {
    let [a, b, c] = mesh.corners(t);
    (b - a).cross(c - a).try_normalize()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng;

    /// Two triangles of areas 1 and 3: chosen 1:3 (binomial test, 5 sigma), points inside their triangle.
    #[test]
    fn triangle_choice_is_proportional_to_area() {
        let mesh = TriMesh {
            vertices: vec![
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(2.0, 0.0, 0.0),
                DVec3::new(0.0, 1.0, 0.0),
                DVec3::new(10.0, 0.0, 0.0),
                DVec3::new(12.0, 0.0, 0.0),
                DVec3::new(10.0, 3.0, 0.0),
            ],
            triangles: vec![[0, 1, 2], [3, 4, 5]],
        };
        let sampler = SurfaceSampler::new(&mesh, |_| true).unwrap();
        assert!((sampler.total_area() - 4.0).abs() < 1e-12);
        let mut r = rng::rng(11);
        let n = 20_000;
        let mut second = 0;
        for _ in 0..n {
            let p = sampler.sample(&mesh, &mut r);
            if p.triangle == 1 {
                second += 1;
                assert!(
                    p.point_m.x >= 10.0
                        && p.point_m.y >= 0.0
                        && p.point_m.y <= 3.0 * (1.0 - (p.point_m.x - 10.0) / 2.0) + 1e-12
                );
            } else {
                assert!(p.point_m.x >= 0.0 && p.point_m.x <= 2.0 * (1.0 - p.point_m.y) + 1e-12);
            }
            assert_eq!(p.normal, DVec3::Z);
        }
        let expected = 0.75 * n as f64;
        let sigma = (n as f64 * 0.75 * 0.25).sqrt();
        assert!(
            (second as f64 - expected).abs() < 5.0 * sigma,
            "{second} vs {expected}"
        );
    }

    /// Points are uniform inside a triangle: the fraction in the sub-triangle of the midpoints (a quarter
    /// of the area) is a quarter.
    #[test]
    fn points_are_uniform_within_a_triangle() {
        let mesh = TriMesh {
            vertices: vec![DVec3::ZERO, DVec3::new(1.0, 0.0, 0.0), DVec3::new(0.0, 1.0, 0.0)],
            triangles: vec![[0, 1, 2]],
        };
        let sampler = SurfaceSampler::new(&mesh, |_| true).unwrap();
        let mut r = rng::rng(3);
        let n = 20_000;
        let inside_corner = (0..n)
            .map(|_| sampler.sample(&mesh, &mut r).point_m)
            .filter(|p| p.x + p.y <= 0.5)
            .count();
        let sigma = (n as f64 * 0.25 * 0.75).sqrt();
        assert!(
            (inside_corner as f64 - 0.25 * n as f64).abs() < 5.0 * sigma,
            "{inside_corner}"
        );
    }

    #[test]
    fn ineligible_faces_are_never_chosen() {
        let mesh = TriMesh {
            vertices: vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
            triangles: vec![[0, 1, 2], [0, 2, 1], [0, 3, 1]],
        };
        let sampler = SurfaceSampler::new(&mesh, |n| n.z > 0.5).unwrap();
        let mut r = rng::rng(1);
        assert!((0..500).all(|_| sampler.sample(&mesh, &mut r).triangle == 0));
        assert!(SurfaceSampler::new(&mesh, |n| n.x > 2.0).is_none());
    }
}
