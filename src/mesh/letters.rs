//! Raised letters (Sec. V-D): each of the 52 upper- and lower-case letters as a closed solid, the
//! glyph extruded by a raise height on top of a rectangular base plate, explored from above.
//!
//! Geometry, with plate thickness t_p and raise h (z up, plate bottom on z = 0):
//! - the plate: the glyph's bounding box grown by a margin, from z = 0 to z = t_p;
//! - the letter: the glyph's filled region, from z = t_p to z = t_p + h.
//!
//! They form one closed, consistently oriented 2-manifold: the plate's top face is the rectangle
//! minus the glyph (plus the glyph's counters at plate level, e.g. the inside of 'o'), the letter's
//! walls stand on the glyph contours, and its top face is the glyph with its holes. Every contour
//! vertex is shared by the faces that meet there, so the mesh is watertight; it is a topological
//! sphere (Euler characteristic 2), and its top face at z = t_p + h has one boundary loop per
//! contour: its holes are the glyph's counters ('B' two, 'o' one, 'x' none). [`raised_letter`]
//! checks the finished mesh and names the glyph when it is not so, whatever the font.

use glam::{DVec2, DVec3};
use serde::{Deserialize, Serialize};

use super::TriMesh;
use super::error::MeshError;
use super::glyph::{Font, GlyphOutline};
use super::topology::EdgeTopology;
use super::triangulate::{ring_area2, triangulate_with_holes};

/// The size and shape parameters of the raised letters.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LetterStyle {
    /// Height of the capital letters: the paper's letters were "approximately 2.5 cm per side".
    /// All letters share one font scale, so lower case is smaller, as in a real alphabet set.
    pub cap_height_m: f64,
    /// How far the letter stands above the plate.
    pub raise_m: f64,
    /// Thickness of the base plate.
    pub plate_thickness_m: f64,
    /// Plate border around the glyph's bounding box.
    pub margin_m: f64,
    /// Largest distance between a glyph curve and its flattened polyline.
    pub flatten_tolerance_m: f64,
}

impl Default for LetterStyle {
    fn default() -> Self {
        Self {
            cap_height_m: 0.025,
            raise_m: 0.003,
            plate_thickness_m: 0.002,
            margin_m: 0.002,
            flatten_tolerance_m: 5e-5,
        }
    }
}

impl LetterStyle {
    fn check(&self) -> Result<(), MeshError> {
        for (field, value) in [
            ("cap_height_m", self.cap_height_m),
            ("raise_m", self.raise_m),
            ("plate_thickness_m", self.plate_thickness_m),
            ("flatten_tolerance_m", self.flatten_tolerance_m),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(MeshError::InvalidParameter {
                    field,
                    what: format!("{value} is not a positive length"),
                });
            }
        }
        if !(self.margin_m.is_finite() && self.margin_m >= 0.0) {
            return Err(MeshError::InvalidParameter {
                field: "margin_m",
                what: format!("{} is not a length >= 0", self.margin_m),
            });
        }
        Ok(())
    }
}

/// The 52 letters in order: 'A'..='Z' then 'a'..='z'.
pub fn alphabet() -> impl Iterator<Item = char> {
    ('A'..='Z').chain('a'..='z')
}

/// The object name of a letter: `upper_A` or `lower_a` (file systems that ignore case keep both).
pub fn letter_name(ch: char) -> String {
    if ch.is_uppercase() {
        format!("upper_{ch}")
    } else {
        format!("lower_{ch}")
    }
}

/// The letter named by [`letter_name`], if `name` is one of the 52.
pub fn letter_from_name(name: &str) -> Option<char> {
    let (case, rest) = name.split_once('_')?;
    let mut chars = rest.chars();
    let ch = chars.next().filter(|_| chars.next().is_none())?;
    match case {
        "upper" if ch.is_ascii_uppercase() => Some(ch),
        "lower" if ch.is_ascii_lowercase() => Some(ch),
        _ => None,
    }
}

/// Contours sorted into filled regions by nesting: a contour inside an even number of others bounds
/// ink from outside, one inside an odd number bounds a counter (a hole).
struct Nesting {
    /// Contours oriented so the ink is on their left: outer boundaries counter-clockwise, holes
    /// clockwise.
    contours: Vec<Vec<DVec2>>,
    depth: Vec<usize>,
    /// The innermost contour containing each one.
    parent: Vec<Option<usize>>,
}

/// Even-odd point in polygon (crossing number).
fn contains(ring: &[DVec2], p: DVec2) -> bool {
    let mut inside = false;
    for i in 0..ring.len() {
        let (a, b) = (ring[i], ring[(i + 1) % ring.len()]);
        if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y) {
            inside = !inside;
        }
    }
    inside
}

impl Nesting {
    fn new(outline: &GlyphOutline) -> Self {
        let n = outline.contours.len();
        let inside: Vec<Vec<usize>> = (0..n)
            .map(|i| {
                (0..n)
                    .filter(|&j| j != i && contains(&outline.contours[j], outline.contours[i][0]))
                    .collect()
            })
            .collect();
        let depth: Vec<usize> = inside.iter().map(Vec::len).collect();
        let parent = (0..n)
            .map(|i| inside[i].iter().copied().max_by_key(|&j| depth[j]))
            .collect();
        let contours = outline
            .contours
            .iter()
            .zip(&depth)
            .map(|(c, &d)| {
                let ccw = ring_area2(c) > 0.0;
                let mut c = c.clone();
                if ccw != (d % 2 == 0) {
                    c.reverse();
                }
                c
            })
            .collect();
        Self {
            contours,
            depth,
            parent,
        }
    }

    fn children(&self, i: usize) -> impl Iterator<Item = usize> + '_ {
        (0..self.contours.len()).filter(move |&j| self.parent[j] == Some(i))
    }
}

/// Vertex ids of the letter mesh under construction.
struct Builder {
    vertices: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
}

impl Builder {
    fn ring(&mut self, points: &[DVec2], z: f64) -> Vec<u32> {
        let first = self.vertices.len() as u32;
        self.vertices
            .extend(points.iter().map(|p| DVec3::new(p.x, p.y, z)));
        (first..first + points.len() as u32).collect()
    }

    /// Upward-facing triangles filling the region bounded by `rings` (outer first).
    fn cap(&mut self, rings: &[(&[DVec2], &[u32])], what: &str) -> Result<(), MeshError> {
        let points: Vec<Vec<DVec2>> = rings.iter().map(|(p, _)| p.to_vec()).collect();
        let ids: Vec<u32> = rings.iter().flat_map(|(_, ids)| ids.iter().copied()).collect();
        for [a, b, c] in triangulate_with_holes(&points, what)? {
            self.triangles.push([ids[a], ids[b], ids[c]]);
        }
        Ok(())
    }

    /// Vertical walls between two rings of the same contour, facing right of the contour's direction.
    fn walls(&mut self, bottom: &[u32], top: &[u32]) {
        let n = bottom.len();
        for i in 0..n {
            let j = (i + 1) % n;
            self.triangles.push([bottom[i], bottom[j], top[j]]);
            self.triangles.push([bottom[i], top[j], top[i]]);
        }
    }
}

/// The outline of letter `ch` in `font` at `style`'s size (capitals `cap_height_m` tall), metres.
pub fn letter_outline(font: &Font, ch: char, style: &LetterStyle) -> Result<GlyphOutline, MeshError> {
    style.check()?;
    let metres_per_unit = style.cap_height_m / font.cap_height_units()?;
    font.outline(ch, metres_per_unit, style.flatten_tolerance_m)
}

/// The raised letter `ch` in `font`: closed, outward-oriented, plate centred on x = y = 0 with its
/// bottom on z = 0 and the letter on top (+z).
pub fn raised_letter(font: &Font, ch: char, style: &LetterStyle) -> Result<TriMesh, MeshError> {
    let outline = letter_outline(font, ch, style)?;
    let nesting = Nesting::new(&outline);
    let (contours, lo, hi) = centred_on_plate(&outline, &nesting, style.margin_m);
    let (z_plate, z_top) = (style.plate_thickness_m, style.plate_thickness_m + style.raise_m);

    let mut b = Builder {
        vertices: Vec::new(),
        triangles: Vec::new(),
    };
    let rect = [lo, DVec2::new(hi.x, lo.y), hi, DVec2::new(lo.x, hi.y)];
    let plate_top = b.plate(&rect, z_plate);
    let low: Vec<Vec<u32>> = contours.iter().map(|c| b.ring(c, z_plate)).collect();
    let high: Vec<Vec<u32>> = contours.iter().map(|c| b.ring(c, z_top)).collect();
    for i in 0..contours.len() {
        b.walls(&low[i], &high[i]);
    }
    let rings = LetterRings {
        contours,
        low,
        high,
        nesting,
    };
    b.caps(&rings, (&rect, &plate_top), ch)?;
    let mesh = TriMesh {
        vertices: b.vertices,
        triangles: b.triangles,
    };
    closed_sphere(&mesh).map_err(|what| MeshError::Glyph {
        font: font.path().to_path_buf(),
        glyph: ch,
        what,
    })?;
    Ok(mesh)
}

/// The outline's contours moved so that the plate (their bounds grown by `margin_m`) is centred on
/// the origin, and the plate's corners.
fn centred_on_plate(
    outline: &GlyphOutline,
    nesting: &Nesting,
    margin_m: f64,
) -> (Vec<Vec<DVec2>>, DVec2, DVec2) {
    let all = || outline.contours.iter().flatten();
    let lo = all().fold(DVec2::splat(f64::INFINITY), |m, &p| m.min(p)) - DVec2::splat(margin_m);
    let hi = all().fold(DVec2::splat(f64::NEG_INFINITY), |m, &p| m.max(p)) + DVec2::splat(margin_m);
    let centre = 0.5 * (lo + hi);
    let contours: Vec<Vec<DVec2>> = nesting
        .contours
        .iter()
        .map(|c| c.iter().map(|&p| p - centre).collect())
        .collect();
    (contours, lo - centre, hi - centre)
}

/// The letter's contours and their rings of vertex ids at plate level and at the top.
struct LetterRings {
    contours: Vec<Vec<DVec2>>,
    low: Vec<Vec<u32>>,
    high: Vec<Vec<u32>>,
    nesting: Nesting,
}

impl Builder {
    /// The plate under the letter: its bottom and walls; returns the ids of its top ring.
    fn plate(&mut self, rect: &[DVec2; 4], z_plate: f64) -> Vec<u32> {
        let plate_bottom = self.ring(rect, 0.0);
        let plate_top = self.ring(rect, z_plate);
        self.triangles
            .push([plate_bottom[0], plate_bottom[2], plate_bottom[1]]);
        self.triangles
            .push([plate_bottom[0], plate_bottom[3], plate_bottom[2]]);
        self.walls(&plate_bottom, &plate_top);
        plate_top
    }

    /// Plate level: the rectangle minus the outermost ink contours, then each counter minus the
    /// ink nested in it. Letter level: each ink contour minus its counters.
    fn caps(
        &mut self,
        letter: &LetterRings,
        (rect, plate_top): (&[DVec2; 4], &[u32]),
        ch: char,
    ) -> Result<(), MeshError> {
        let (contours, nesting) = (&letter.contours, &letter.nesting);
        let what = |part: &str| format!("glyph '{ch}' {part}");
        let reversed: Vec<(Vec<DVec2>, Vec<u32>)> = contours
            .iter()
            .zip(&letter.low)
            .map(|(c, ids)| {
                (
                    c.iter().rev().copied().collect(),
                    ids.iter().rev().copied().collect(),
                )
            })
            .collect();
        let top_level: Vec<usize> = (0..contours.len()).filter(|&i| nesting.depth[i] == 0).collect();
        let mut rings: Vec<(&[DVec2], &[u32])> = vec![(rect.as_slice(), plate_top)];
        rings.extend(
            top_level
                .iter()
                .map(|&i| (reversed[i].0.as_slice(), reversed[i].1.as_slice())),
        );
        self.cap(&rings, &what("plate"))?;
        for i in 0..contours.len() {
            let children: Vec<usize> = nesting.children(i).collect();
            if nesting.depth[i] % 2 == 1 {
                let mut rings: Vec<(&[DVec2], &[u32])> = vec![(&reversed[i].0, &reversed[i].1)];
                rings.extend(
                    children
                        .iter()
                        .map(|&j| (reversed[j].0.as_slice(), reversed[j].1.as_slice())),
                );
                self.cap(&rings, &what("counter at plate level"))?;
            } else {
                let mut rings: Vec<(&[DVec2], &[u32])> = vec![(&contours[i], &letter.high[i])];
                let counters: Vec<Vec<DVec2>> = children.iter().map(|&j| contours[j].clone()).collect();
                rings.extend(
                    children
                        .iter()
                        .zip(&counters)
                        .map(|(&j, c)| (c.as_slice(), letter.high[j].as_slice())),
                );
                self.cap(&rings, &what("top"))?;
            }
        }
        Ok(())
    }
}

/// Whether `mesh` is what the module docs promise: one closed, consistently oriented shell of
/// Euler characteristic 2. A glyph whose contours the construction misreads (contours that cross or
/// touch) fails here rather than leaving an open or tangled mesh to the simulation.
fn closed_sphere(mesh: &TriMesh) -> Result<(), String> {
    let topology = EdgeTopology::new(mesh);
    let open = topology.boundary_edges().count();
    if open > 0 {
        return Err(format!(
            "the raised letter is not closed: {open} open boundary edge(s) in {} loop(s)",
            topology.boundary_loop_count()
        ));
    }
    let (non_manifold, misoriented) = (
        topology.non_manifold_edge_count(),
        topology.misoriented_edge_count(),
    );
    if non_manifold + misoriented > 0 {
        return Err(format!(
            "the raised letter is not one oriented surface: {non_manifold} non-manifold and \
             {misoriented} misoriented edge(s)"
        ));
    }
    let chi = topology.euler_characteristic(mesh);
    if chi != 2 {
        return Err(format!(
            "the raised letter has Euler characteristic {chi}, not 2 (one solid without tunnels)"
        ));
    }
    Ok(())
}
