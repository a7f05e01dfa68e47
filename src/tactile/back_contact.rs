//! Whether the object reaches the pad's rigid back, exactly: a triangle of the object inside the
//! slab just behind the pad plane, within the pad's rectangle.
//!
//! The covering's samples see full compression only where a sample lies (2x2 per taxel, about
//! 1 mm apart on the default pad), so a blade or a tip thinner than their spacing could reach the
//! back between them unseen. The triangles the covering rasterises are tested against the slab
//! instead, with the separating-axis test of a triangle and an axis-aligned box (Akenine-Moller,
//! "Fast 3D triangle-box overlap testing", 2001): the two are disjoint iff their projections are
//! disjoint on one of the box's three axes, the triangle's normal, or the nine cross products of a
//! box axis with a triangle edge.

use glam::DVec3;

/// Whether triangle `[a, b, c]` and the axis-aligned box of centre `center` and half-sizes `half`
/// share a point (touching counts).
pub fn triangle_overlaps_box([a, b, c]: [DVec3; 3], center: DVec3, half: DVec3) -> bool {
    let v = [a - center, b - center, c - center];
    // The projections of the triangle and of the box on `axis` are disjoint.
    let separated = |axis: DVec3| {
        let p = v.map(|x| axis.dot(x));
        let radius = half.dot(axis.abs());
        p[0].min(p[1]).min(p[2]) > radius || p[0].max(p[1]).max(p[2]) < -radius
    };
    let edges = [v[1] - v[0], v[2] - v[1], v[0] - v[2]];
    let box_axes = [DVec3::X, DVec3::Y, DVec3::Z];
    if box_axes.into_iter().any(separated) || separated(edges[0].cross(edges[1])) {
        return false;
    }
    !edges
        .iter()
        .flat_map(|e| box_axes.map(|axis| axis.cross(*e)))
        .any(|axis| axis.length_squared() > 0.0 && separated(axis))
}

#[cfg(test)]
mod tests {
    use super::*;

    const HALF: DVec3 = DVec3::new(0.006, 0.006, 0.0006);
    const CENTER: DVec3 = DVec3::new(0.0, 0.0, -0.0006);

    fn overlaps(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> bool {
        triangle_overlaps_box([DVec3::from(a), DVec3::from(b), DVec3::from(c)], CENTER, HALF)
    }

    #[test]
    fn a_thin_blade_between_samples_reaches_the_slab() {
        // A vertical sliver 0.1 mm wide poking 0.3 mm behind the pad plane, far from any corner
        // of the box: the overlap of the projections on z alone decides.
        assert!(overlaps(
            [0.0003, 0.0, -0.0003],
            [0.0004, 0.0, 0.002],
            [0.0002, 0.0, 0.002]
        ));
        // The same sliver stopping 0.1 mm in front of the pad plane does not.
        assert!(!overlaps(
            [0.0003, 0.0, 0.0001],
            [0.0004, 0.0, 0.002],
            [0.0002, 0.0, 0.002]
        ));
    }

    #[test]
    fn agrees_with_dense_sampling_of_random_triangles() {
        use rand::RngExt;
        // Triangles around the box: where a dense grid of points on the triangle has a point in
        // the box, the test must say they overlap; where it says they overlap, some grid point
        // must lie within the grid's spacing of the box.
        let mut rng = crate::rng::rng(5);
        let (mut overlapping, mut apart) = (0, 0);
        for _ in 0..2000 {
            let corner = |rng: &mut crate::rng::Rng| {
                DVec3::new(
                    rng.random_range(-0.009..0.009),
                    rng.random_range(-0.009..0.009),
                    rng.random_range(-0.003..0.002),
                )
            };
            let tri = [corner(&mut rng), corner(&mut rng), corner(&mut rng)];
            let n = 120;
            let longest = (tri[1] - tri[0]).length().max((tri[2] - tri[0]).length());
            let spacing = longest / n as f64;
            let (mut inside, mut nearest) = (false, f64::INFINITY);
            for i in 0..=n {
                for j in 0..=n - i {
                    let p = tri[0]
                        + (tri[1] - tri[0]) * (i as f64 / n as f64)
                        + (tri[2] - tri[0]) * (j as f64 / n as f64);
                    let outside = ((p - CENTER).abs() - HALF).max(DVec3::ZERO);
                    inside |= outside == DVec3::ZERO;
                    nearest = nearest.min(outside.length());
                }
            }
            let sat = triangle_overlaps_box(tri, CENTER, HALF);
            if inside {
                assert!(sat, "{tri:?}");
            }
            if sat {
                assert!(nearest <= 2.0 * spacing, "{tri:?}: nearest {nearest}");
                overlapping += 1;
            } else {
                apart += 1;
            }
        }
        assert!(overlapping > 100 && apart > 100, "{overlapping} / {apart}");
    }

    #[test]
    fn a_large_triangle_around_the_box_overlaps_and_one_beside_it_does_not() {
        assert!(overlaps(
            [-1.0, -1.0, -0.0003],
            [1.0, -1.0, -0.0003],
            [0.0, 1.0, -0.0003]
        ));
        assert!(!overlaps(
            [-1.0, -1.0, 0.0003],
            [1.0, -1.0, 0.0003],
            [0.0, 1.0, 0.0003]
        ));
        assert!(!overlaps(
            [0.007, 0.0, -0.0003],
            [0.008, 0.0, -0.0003],
            [0.007, 0.001, -0.0003]
        ));
    }
}
