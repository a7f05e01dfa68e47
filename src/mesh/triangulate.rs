//! Triangulating a planar polygon with holes without adding or dropping vertices, so that the
//! triangulation shares every ring edge exactly with the walls built on the same rings (the raised
//! letters need this to be watertight).
//!
//! Ear clipping with hole bridging is done by the `earcut` crate. Earcut silently drops ring
//! vertices that are exactly collinear with their neighbours (also ones that become collinear after
//! a hole is bridged). A dropped vertex lies on an edge of the triangulation; so may a vertex earcut
//! kept, when a bridge runs along collinear ring edges (DejaVu Serif's 'B' and 'D': the counters'
//! bottom edges continue the top edge of the serif, and one triangle edge spans both, passing
//! through the bridge's ends). Either way the edge along the ring is not the ring's own, and the
//! wall built on the ring would meet it in a T-junction. So every triangle with a ring vertex inside
//! one of its edges is split there: (a, b, c) with v on ab becomes (a, v, c) and (v, b, c). The
//! result is checked: every vertex used, every triangle counter-clockwise, and the triangle areas
//! summing to the polygon's area, A = |A_outer| - sum |A_hole|.

use glam::DVec2;

use super::error::MeshError;

/// Twice the signed area of a closed ring (shoelace): positive when counter-clockwise.
pub fn ring_area2(ring: &[DVec2]) -> f64 {
    (0..ring.len())
        .map(|i| ring[i].perp_dot(ring[(i + 1) % ring.len()]))
        .sum()
}

/// Twice the signed area of triangle (a, b, c): (b - a) x (c - a).
fn area2(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    (b - a).perp_dot(c - a)
}

/// Triangulates the polygon whose outer ring is `rings[0]` and whose holes are `rings[1..]`
/// (any orientation; rings closed implicitly, no repeated end point). Returns counter-clockwise
/// triangles as indices into the rings concatenated in order. `what` names the polygon in errors.
pub fn triangulate_with_holes(rings: &[Vec<DVec2>], what: &str) -> Result<Vec<[usize; 3]>, MeshError> {
    let fail = |why: String| MeshError::Triangulation {
        what: format!("{what}: {why}"),
    };
    if rings.is_empty() || rings.iter().any(|r| r.len() < 3) {
        return Err(fail("every ring needs at least 3 points".into()));
    }
    let points: Vec<DVec2> = rings.iter().flatten().copied().collect();
    let mut triangles = earcut_counter_clockwise(rings, &points);
    let scale = rings[0]
        .iter()
        .fold(0.0f64, |m, p| m.max(p.abs().max_element()))
        .max(f64::MIN_POSITIVE);
    split_at_ring_vertices(&points, &mut triangles, scale);
    check_every_point_used(&points, &triangles).map_err(fail)?;
    check_area(rings, &points, &triangles, scale).map_err(fail)?;
    Ok(triangles)
}

/// Earcut's triangles of the rings (holes bridged), each turned counter-clockwise.
fn earcut_counter_clockwise(rings: &[Vec<DVec2>], points: &[DVec2]) -> Vec<[usize; 3]> {
    let mut hole_starts = Vec::with_capacity(rings.len() - 1);
    let mut start = rings[0].len();
    for ring in &rings[1..] {
        hole_starts.push(start as u32);
        start += ring.len();
    }
    let mut flat: Vec<u32> = Vec::new();
    earcut::Earcut::new().earcut(points.iter().map(|p| [p.x, p.y]), &hole_starts, &mut flat);
    flat.chunks_exact(3)
        .map(|t| {
            let [a, b, c] = [t[0] as usize, t[1] as usize, t[2] as usize];
            if area2(points[a], points[b], points[c]) < 0.0 {
                [a, c, b]
            } else {
                [a, b, c]
            }
        })
        .collect()
}

/// Splits every triangle with a ring vertex inside one of its edges there (see the module's
/// doc); `scale` is the polygon's extent, for the collinearity tolerance.
fn split_at_ring_vertices(points: &[DVec2], triangles: &mut Vec<[usize; 3]>, scale: f64) {
    // Whether `v` lies strictly inside the segment from `a` to `b`.
    let on_edge = |v: usize, a: usize, b: usize| {
        let (p, pa, pb) = (points[v], points[a], points[b]);
        let d = pb - pa;
        let t = (p - pa).dot(d) / d.length_squared();
        t > 0.0 && t < 1.0 && area2(pa, pb, p).abs() <= 1e-12 * scale * d.length()
    };
    for v in 0..points.len() {
        // Split every triangle with `v` inside one of its edges: after this no edge passes through
        // a ring vertex, so the edges along each ring are exactly the ring's own.
        while let Some((k, (a, b, c))) = triangles.iter().enumerate().find_map(|(k, &[a, b, c])| {
            [(a, b, c), (b, c, a), (c, a, b)]
                .into_iter()
                .find(|&(x, y, z)| z != v && on_edge(v, x, y))
                .map(|e| (k, e))
        }) {
            triangles[k] = [a, v, c];
            triangles.push([v, b, c]);
        }
    }
}

/// Every ring point is a corner of some triangle.
fn check_every_point_used(points: &[DVec2], triangles: &[[usize; 3]]) -> Result<(), String> {
    let mut used = vec![false; points.len()];
    for t in triangles {
        for &i in t {
            used[i] = true;
        }
    }
    if let Some(v) = (0..points.len()).find(|&v| !used[v]) {
        let p = points[v];
        return Err(format!(
            "point {v} at ({}, {}) is not on the triangulation",
            p.x, p.y
        ));
    }
    Ok(())
}

/// The triangles cover the polygon's area: the outer ring's less the holes'.
fn check_area(
    rings: &[Vec<DVec2>],
    points: &[DVec2],
    triangles: &[[usize; 3]],
    scale: f64,
) -> Result<(), String> {
    let expected = ring_area2(&rings[0]).abs() - rings[1..].iter().map(|r| ring_area2(r).abs()).sum::<f64>();
    let got: f64 = triangles
        .iter()
        .map(|&[a, b, c]| area2(points[a], points[b], points[c]))
        .sum();
    if (got - expected).abs() > 1e-9 * expected.abs().max(scale * scale) {
        return Err(format!(
            "triangles cover area {} instead of {}",
            got / 2.0,
            expected / 2.0
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64) -> DVec2 {
        DVec2::new(x, y)
    }

    #[test]
    fn square_with_square_hole_and_collinear_points_keeps_every_vertex() {
        // Outer square with an extra collinear point on each side (earcut drops those); hole inside.
        let outer = vec![
            v(0.0, 0.0),
            v(2.0, 0.0),
            v(4.0, 0.0),
            v(4.0, 4.0),
            v(2.0, 4.0),
            v(0.0, 4.0),
        ];
        let hole = vec![v(1.0, 1.0), v(1.0, 3.0), v(3.0, 3.0), v(3.0, 1.0)];
        let tris = triangulate_with_holes(&[outer.clone(), hole.clone()], "test").unwrap();
        let pts: Vec<DVec2> = outer.iter().chain(&hole).copied().collect();
        let mut used = [false; 10];
        let mut area = 0.0;
        for &[a, b, c] in &tris {
            let a2 = area2(pts[a], pts[b], pts[c]);
            assert!(a2 > 0.0);
            area += a2 / 2.0;
            used[a] = true;
            used[b] = true;
            used[c] = true;
        }
        assert!(used.iter().all(|&u| u));
        assert!((area - 12.0).abs() < 1e-12);
        // A triangulation of a polygon with h holes and n vertices has n + 2h - 2 triangles.
        assert_eq!(tris.len(), 10 + 2 - 2);
    }

    #[test]
    fn a_hole_whose_edge_continues_an_outer_edge_leaves_no_t_junction() {
        // DejaVu Serif's 'D' in font units / 100: the serif's top edge (y = 1.77, x 1.89 to 5.07)
        // and the counter's bottom edge (x 8.47 to 11.59) lie on one line.
        let outer = vec![
            v(1.89, 0.0),
            v(11.84, 0.0),
            v(25.52, 12.53),
            v(11.84, 25.0),
            v(1.89, 25.0),
            v(1.89, 23.21),
            v(5.07, 23.21),
            v(5.07, 1.77),
            v(1.89, 1.77),
        ];
        let hole = vec![
            v(8.47, 1.77),
            v(8.47, 23.21),
            v(11.59, 23.21),
            v(21.67, 12.53),
            v(11.59, 1.77),
        ];
        let tris = triangulate_with_holes(&[outer.clone(), hole.clone()], "D").unwrap();
        let pts: Vec<DVec2> = outer.iter().chain(&hole).copied().collect();
        for &[a, b, c] in &tris {
            for (x, y) in [(a, b), (b, c), (c, a)] {
                for (k, &p) in pts.iter().enumerate() {
                    let d = pts[y] - pts[x];
                    let t = (p - pts[x]).dot(d) / d.length_squared();
                    let inside = t > 0.0 && t < 1.0 && area2(pts[x], pts[y], p) == 0.0;
                    assert!(!inside, "vertex {k} lies inside edge {x}-{y}");
                }
            }
        }
    }

    #[test]
    fn degenerate_rings_are_errors() {
        assert!(triangulate_with_holes(&[vec![v(0.0, 0.0), v(1.0, 0.0)]], "two points").is_err());
        assert!(triangulate_with_holes(&[], "nothing").is_err());
    }
}
