//! An object's known surface, as the geometric recogniser matches contacts against it: points
//! spread evenly over the mesh with their outward normals, in the object's own frame (the mesh
//! frame, resting on the table at the canonical pose), and a grid of cells for the nearest point.
//!
//! Points rather than triangles: a model file carries them as plain numbers, a point-to-plane
//! residual against the nearest point and its normal is the surface's distance to within the
//! spacing's curvature error (well under a millimetre at 1.5 mm), and the nearest point is found
//! by scanning the 27 cells around the query, so a query costs the same on a 1,000- and a
//! 1,000,000-triangle mesh.

use glam::DVec3;
use serde::{Deserialize, Serialize};

use crate::mesh::TriMesh;

/// Spacing of the surface points, metres: finer than the contact noise (1.7 mm RMS).
pub const SURFACE_SPACING_M: f64 = 0.0015;

/// Side of the nearest-point grid's cells, metres: the nearest point is exact within this
/// distance of a query; beyond it a query may find none ([`ObjectSurface::nearest`]), which the
/// robust likelihood reads as a contact the pose does not explain.
const CELL_M: f64 = 0.005;

/// Spacing of the sparse points [`ObjectSurface::nearest_anywhere`] scans beyond the grid's reach,
/// metres: a few thousand points on a 12 cm object, a millimetre or two of error in a prediction
/// that looks centimetres away (`locate::predict`).
const SPARSE_SPACING_M: f64 = 0.004;

/// One object's surface points and normals (object frame), with what the likelihood needs of it.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(try_from = "SurfaceFile", into = "SurfaceFile")]
pub struct ObjectSurface {
    points: Vec<DVec3>,
    normals: Vec<DVec3>,
    /// Total area, square metres: the density of where on the surface a touch lands.
    area_m2: f64,
    /// Centre of the points' bounding box: the point turns are taken about (as
    /// `sim::Scene::perturb_object` turns the object about its bounding box's centre).
    center_m: DVec3,
    /// The larger horizontal side of the bounding box, metres.
    width_m: f64,
    grid: CellGrid,
    /// Indices of points about [`SPARSE_SPACING_M`] apart.
    sparse: Vec<u32>,
}

impl PartialEq for ObjectSurface {
    fn eq(&self, other: &Self) -> bool {
        self.points == other.points && self.normals == other.normals && self.area_m2 == other.area_m2
    }
}

/// The nearest surface point to a query and its signed distance along that point's normal.
#[derive(Debug, Clone, Copy)]
pub struct Nearest {
    pub index: usize,
    /// `(query - point) . normal`: positive outside the surface.
    pub signed_distance_m: f64,
}

impl ObjectSurface {
    /// Points over `mesh` (object frame, metres) about [`SURFACE_SPACING_M`] apart: every triangle
    /// cut into `m x m` similar triangles (`m` its longest edge over the spacing, at least 1), one
    /// point at each one's centroid, then at most one point per cube of the spacing kept (the
    /// first, in triangle order), so a finely tessellated mesh is not sampled finer than a coarse
    /// one. No randomness: the same mesh gives the same points. Coordinates are rounded to a
    /// micrometre (normals to 1e-6), what the model file keeps, so that a model read back is the
    /// model written, bit for bit.
    pub fn of_mesh(mesh: &TriMesh) -> Option<Self> {
        let mut points = Vec::new();
        let mut normals = Vec::new();
        for t in 0..mesh.triangles.len() {
            let [a, b, c] = mesh.corners(t);
            let Some(normal) = (b - a).cross(c - a).try_normalize() else {
                continue;
            };
            let longest = (b - a).length().max((c - b).length()).max((a - c).length());
            let m = ((longest / SURFACE_SPACING_M).ceil() as usize).max(1);
            let (u, v) = ((b - a) / m as f64, (c - a) / m as f64);
            for i in 0..m {
                for j in 0..m - i {
                    points.push(a + u * (i as f64 + 1.0 / 3.0) + v * (j as f64 + 1.0 / 3.0));
                    normals.push(normal);
                    if i + j + 1 < m {
                        points.push(a + u * (i as f64 + 2.0 / 3.0) + v * (j as f64 + 2.0 / 3.0));
                        normals.push(normal);
                    }
                }
            }
        }
        let (points, normals) = thin(points, normals, SURFACE_SPACING_M);
        Self::new(points, normals, mesh.total_area())
    }

    /// A surface of given points and unit normals, both rounded to 1e-6 (a rounding that leaves
    /// rounded values as they are, so a surface read back from its file is the surface written,
    /// bit for bit; normalising again after the rounding would move the last digit); `None` when
    /// there are none, a count differs, a value is not finite or a normal is not of unit length.
    pub fn new(points: Vec<DVec3>, normals: Vec<DVec3>, area_m2: f64) -> Option<Self> {
        let micrometre = |v: DVec3| (v * 1e6).round() / 1e6;
        let points: Vec<DVec3> = points.into_iter().map(micrometre).collect();
        let normals: Vec<DVec3> = normals.into_iter().map(micrometre).collect();
        let finite = points.iter().chain(&normals).all(|p| p.is_finite());
        let unit = normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-5);
        if points.is_empty()
            || points.len() != normals.len()
            || !finite
            || !unit
            || area_m2.is_nan()
            || area_m2 <= 0.0
        {
            return None;
        }
        let (lo, hi) = points
            .iter()
            .fold((DVec3::MAX, DVec3::MIN), |(lo, hi), &p| (lo.min(p), hi.max(p)));

        let sparse = thinned_indices(&points, SPARSE_SPACING_M);
        Some(Self {
            grid: CellGrid::new(&points, lo, hi),
            sparse,
            points,
            normals,
            area_m2,
            center_m: (lo + hi) * 0.5,
            width_m: (hi.x - lo.x).max(hi.y - lo.y),
        })
    }

    pub fn points(&self) -> &[DVec3] {
        &self.points
    }

    pub fn normals(&self) -> &[DVec3] {
        &self.normals
    }

    pub fn area_m2(&self) -> f64 {
        self.area_m2
    }

    pub fn center_m(&self) -> DVec3 {
        self.center_m
    }

    pub fn width_m(&self) -> f64 {
        self.width_m
    }

    /// The surface point nearest `query` (object frame) if one lies within the grid's reach (at
    /// least one cell side), with the query's distance along that point's normal.
    pub fn nearest(&self, query: DVec3) -> Option<Nearest> {
        let index = self.grid.nearest(&self.points, query)?;
        Some(Nearest {
            index,
            signed_distance_m: (query - self.points[index]).dot(self.normals[index]),
        })
    }

    /// The index of the surface point nearest `query` (object frame) however far it lies: the
    /// exact one within the grid's reach ([`nearest`](Self::nearest)), else the nearest of the
    /// sparse points, 4 mm apart (so within 4 mm of the exact one), the first of equals.
    pub fn nearest_anywhere(&self, query: DVec3) -> usize {
        if let Some(near) = self.nearest(query) {
            return near.index;
        }
        let mut best = (f64::INFINITY, 0);
        for &i in &self.sparse {
            let d = self.points[i as usize].distance_squared(query);
            if d < best.0 {
                best = (d, i as usize);
            }
        }
        best.1
    }
}

/// The index of the first point of each cube of side `cell_m`, in order.
fn thinned_indices(points: &[DVec3], cell_m: f64) -> Vec<u32> {
    let mut seen = std::collections::HashSet::new();
    (0..points.len() as u32)
        .filter(|&i| {
            let key = (points[i as usize] / cell_m).floor();
            seen.insert((key.x as i64, key.y as i64, key.z as i64))
        })
        .collect()
}

/// Keeps the first point of each cube of side `cell_m`.
fn thin(points: Vec<DVec3>, normals: Vec<DVec3>, cell_m: f64) -> (Vec<DVec3>, Vec<DVec3>) {
    thinned_indices(&points, cell_m)
        .into_iter()
        .map(|i| (points[i as usize], normals[i as usize]))
        .unzip()
}

/// Points binned into cubes of [`CELL_M`] over their bounding box (one cell of margin), stored
/// cell after cell: the nearest point to a query is among the 27 cells around it, exactly so
/// within one cell side.
#[derive(Debug, Clone)]
struct CellGrid {
    origin_m: DVec3,
    dims: [usize; 3],
    /// `starts[c]..starts[c + 1]` index `order` for cell `c`.
    starts: Vec<u32>,
    order: Vec<u32>,
}

impl CellGrid {
    fn new(points: &[DVec3], lo: DVec3, hi: DVec3) -> Self {
        let origin_m = lo - DVec3::splat(CELL_M);
        let extent = (hi - origin_m) / CELL_M;
        let dims = [extent.x, extent.y, extent.z].map(|e| e.floor() as usize + 2);
        let mut grid = Self {
            origin_m,
            dims,
            starts: Vec::new(),
            order: Vec::new(),
        };
        let cells: Vec<usize> = points
            .iter()
            .map(|&p| grid.cell_of(p).map_or(0, |c| grid.index(c)))
            .collect();
        let mut counts = vec![0u32; dims[0] * dims[1] * dims[2] + 1];
        for &c in &cells {
            counts[c + 1] += 1;
        }
        for i in 1..counts.len() {
            counts[i] += counts[i - 1];
        }
        let mut fill = counts.clone();
        let mut order = vec![0u32; points.len()];
        for (i, &c) in cells.iter().enumerate() {
            order[fill[c] as usize] = i as u32;
            fill[c] += 1;
        }
        grid.starts = counts;
        grid.order = order;
        grid
    }

    fn cell_of(&self, p: DVec3) -> Option<[usize; 3]> {
        let c = ((p - self.origin_m) / CELL_M).floor();
        let c = [c.x, c.y, c.z];
        (0..3)
            .all(|k| c[k] >= 0.0 && (c[k] as usize) < self.dims[k])
            .then(|| c.map(|x| x as usize))
    }

    fn index(&self, [x, y, z]: [usize; 3]) -> usize {
        (z * self.dims[1] + y) * self.dims[0] + x
    }

    fn nearest(&self, points: &[DVec3], query: DVec3) -> Option<usize> {
        let c = self.cell_of(query)?;
        let mut best: Option<(f64, usize)> = None;
        let range = |k: usize| c[k].saturating_sub(1)..=(c[k] + 1).min(self.dims[k] - 1);
        for z in range(2) {
            for y in range(1) {
                let row = self.index([0, y, z]);
                let (x0, x1) = (c[0].saturating_sub(1), (c[0] + 1).min(self.dims[0] - 1));
                let (from, to) = (self.starts[row + x0] as usize, self.starts[row + x1 + 1] as usize);
                for &i in &self.order[from..to] {
                    let d = (points[i as usize] - query).length_squared();
                    if best.is_none_or(|(b, _)| d < b) {
                        best = Some((d, i as usize));
                    }
                }
            }
        }
        best.map(|(_, i)| i)
    }
}

/// The file form of a surface: points and normals as `[x, y, z, nx, ny, nz]` rows, the area.
#[derive(Serialize, Deserialize)]
struct SurfaceFile {
    area_m2: f64,
    points: Vec<[f64; 6]>,
}

impl From<ObjectSurface> for SurfaceFile {
    fn from(s: ObjectSurface) -> Self {
        Self {
            area_m2: s.area_m2,
            points: s
                .points
                .iter()
                .zip(&s.normals)
                .map(|(p, n)| [p.x, p.y, p.z, n.x, n.y, n.z])
                .collect(),
        }
    }
}

impl TryFrom<SurfaceFile> for ObjectSurface {
    type Error = String;

    fn try_from(f: SurfaceFile) -> Result<Self, String> {
        let (points, normals) = f
            .points
            .iter()
            .map(|r| (DVec3::new(r[0], r[1], r[2]), DVec3::new(r[3], r[4], r[5])))
            .unzip();
        Self::new(points, normals, f.area_m2).ok_or_else(|| {
            "a surface needs at least one point, finite values, unit normals and a positive area".to_string()
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube() -> ObjectSurface {
        ObjectSurface::of_mesh(&TriMesh::cuboid(DVec3::splat(0.02))).expect("a cube")
    }

    #[test]
    fn points_cover_the_surface_evenly() {
        let s = cube();
        // 6 faces of 4 cm: one point per 1.5 mm cube, about 96 cm^2 / (1.5 mm)^2.
        assert!((3_000..6_000).contains(&s.points().len()), "{}", s.points().len());
        assert!((s.area_m2() - 6.0 * 0.04 * 0.04).abs() < 1e-12);
        for (p, n) in s.points().iter().zip(s.normals()) {
            // On a face, its normal the face's: the coordinate along it at the half-size.
            assert!((p.dot(*n) - 0.02).abs() < 2e-6, "{p} {n}");
        }
    }

    #[test]
    fn the_nearest_point_is_the_nearest_of_all_within_a_cell() {
        let s = cube();
        let mut r = crate::rng::rng(7);
        use rand::RngExt;
        for _ in 0..200 {
            let q = DVec3::new(
                r.random_range(-0.024..0.024),
                r.random_range(-0.024..0.024),
                r.random_range(-0.024..0.024),
            );
            let brute = s
                .points()
                .iter()
                .map(|p| (*p - q).length())
                .fold(f64::INFINITY, f64::min);
            match s.nearest(q) {
                Some(n) if brute <= CELL_M => assert_eq!((s.points()[n.index] - q).length(), brute),
                Some(n) => assert!((s.points()[n.index] - q).length() >= brute),
                None => assert!(brute > CELL_M, "missed a point {brute} m away"),
            }
        }
    }

    #[test]
    fn a_point_above_a_face_is_its_height_outside() {
        let s = cube();
        let n = s.nearest(DVec3::new(0.001, 0.002, 0.023)).expect("near the top");
        assert!((n.signed_distance_m - 0.003).abs() < 2e-6);
        let inside = s.nearest(DVec3::new(0.0, 0.0, 0.018)).expect("under the top");
        assert!((inside.signed_distance_m + 0.002).abs() < 2e-6);
    }

    #[test]
    fn a_surface_read_back_is_the_surface_written_bit_for_bit() {
        // A tetrahedron: its slanted face's normal has no exact decimal form.
        let mesh = TriMesh {
            vertices: vec![
                DVec3::ZERO,
                DVec3::new(0.03, 0.0, 0.0),
                DVec3::new(0.0, 0.02, 0.0),
                DVec3::new(0.0, 0.0, 0.025),
            ],
            triangles: vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        };
        let written = ObjectSurface::of_mesh(&mesh).expect("a tetrahedron");
        let json = serde_json::to_string(&written).expect("encodes");
        let read: ObjectSurface = serde_json::from_str(&json).expect("decodes");
        assert_eq!(read.points(), written.points());
        assert_eq!(read.normals(), written.normals());
        assert_eq!(serde_json::to_string(&read).expect("encodes"), json);
        // A normal that is not of unit length is refused, not silently normalised.
        let mut value: serde_json::Value = serde_json::from_str(&json).expect("JSON");
        value["points"][0][3] = serde_json::json!(2.0);
        assert!(serde_json::from_value::<ObjectSurface>(value).is_err());
    }

    #[test]
    fn a_surface_file_without_points_is_refused() {
        let e = serde_json::from_str::<ObjectSurface>(r#"{"area_m2": 1.0, "points": []}"#);
        assert!(e.is_err());
    }
}
