//! How alike two letters are to a touch sensor that cannot tell which way round a letter lies.
//!
//! The descriptors of Sec. IV are invariant to in-plane rotation, and the letters are explored from
//! above at any orientation (Sec. V-D), so two glyphs that coincide after a turn (in many sans-serif
//! fonts 'b' turned half round is 'q', 'n' is 'u') cannot be told apart by any amount of touching.
//! Mirror images are not confused: a raised letter is never turned over.
//!
//! The measure is the best-rotation intersection over union of the filled glyphs,
//!
//! `IoU(A, B) = max_θ |A ∩ R_θ B| / |A ∪ R_θ B|`,
//!
//! with both glyphs at their true size (lower case is smaller than upper case, as on the plate) and
//! their area centroids at the origin, which is the best translation for near-congruent shapes. The
//! areas are counted on a square pixel grid of pitch [`OVERLAP_PIXEL_M`] and θ runs over
//! [`OVERLAP_ANGLES`] equal steps of the full turn.

use std::collections::BTreeMap;
use std::path::PathBuf;

use glam::DVec2;

use super::error::MeshError;
use super::glyph::{Font, GlyphOutline};
use super::letters::letter_outline;
use super::object_set::{ObjectSet, ObjectSource};

/// Pixel pitch of the overlap grid: 0.2 mm, a tenth of a stroke of a 25 mm letter.
pub const OVERLAP_PIXEL_M: f64 = 2e-4;
/// Number of equally spaced turns tried (2 degree steps).
pub const OVERLAP_ANGLES: usize = 180;

/// A filled glyph on the overlap grid, as a bit set of pixels (row-major, `side` x `side`).
#[derive(Debug, Clone, PartialEq)]
struct Mask {
    bits: Vec<u64>,
    count: u32,
}

impl Mask {
    /// `outline` turned by `angle_rad` about `centre`, moved to the grid centre, filled with the
    /// non-zero winding rule (TrueType and CFF outlines are drawn for it). Each pixel is in when its
    /// centre is.
    fn fill(outline: &GlyphOutline, centre: DVec2, angle_rad: f64, side: usize) -> Self {
        let (sin, cos) = angle_rad.sin_cos();
        let half = side as f64 * 0.5;
        let to_grid = |p: DVec2| {
            let d = p - centre;
            DVec2::new(cos * d.x - sin * d.y, sin * d.x + cos * d.y) / OVERLAP_PIXEL_M + DVec2::splat(half)
        };
        let edges: Vec<(DVec2, DVec2)> = outline
            .contours
            .iter()
            .flat_map(|ring| {
                let points: Vec<DVec2> = ring.iter().map(|&p| to_grid(p)).collect();
                (0..points.len()).map(move |i| (points[i], points[(i + 1) % points.len()]))
            })
            .collect();
        let mut bits = vec![0u64; (side * side).div_ceil(64)];
        let mut count = 0;
        let mut crossings: Vec<(f64, i32)> = Vec::new();
        for row in 0..side {
            let y = row as f64 + 0.5;
            crossings.clear();
            for &(a, b) in &edges {
                let upward = a.y <= y && b.y > y;
                let downward = b.y <= y && a.y > y;
                if upward || downward {
                    let x = a.x + (y - a.y) / (b.y - a.y) * (b.x - a.x);
                    crossings.push((x, if upward { 1 } else { -1 }));
                }
            }
            crossings.sort_by(|p, q| p.0.total_cmp(&q.0));
            let mut winding = 0;
            for pair in crossings.windows(2) {
                winding += pair[0].1;
                if winding == 0 {
                    continue;
                }
                let first = (pair[0].0 - 0.5).ceil().max(0.0) as usize;
                let end = ((pair[1].0 - 0.5).ceil().max(0.0) as usize).min(side);
                for col in first..end {
                    let index = row * side + col;
                    bits[index / 64] |= 1 << (index % 64);
                    count += 1;
                }
            }
        }
        Self { bits, count }
    }

    fn intersection(&self, other: &Self) -> u32 {
        self.bits
            .iter()
            .zip(&other.bits)
            .map(|(a, b)| (a & b).count_ones())
            .sum()
    }
}

/// Area centroid of a non-zero-filled outline (signed shoelace sums; holes wind the other way and
/// subtract; contours that overlap count their overlap twice, which moves both copies of a glyph
/// alike) and the largest distance of an outline point from it.
fn centroid_and_radius(outline: &GlyphOutline) -> (DVec2, f64) {
    let (mut area2, mut moment) = (0.0, DVec2::ZERO);
    for ring in &outline.contours {
        for i in 0..ring.len() {
            let (a, b) = (ring[i], ring[(i + 1) % ring.len()]);
            let cross = a.perp_dot(b);
            area2 += cross;
            moment += (a + b) * cross;
        }
    }
    let centre = if area2.abs() > 0.0 {
        moment / (3.0 * area2)
    } else {
        DVec2::ZERO
    };
    let radius = outline
        .contours
        .iter()
        .flatten()
        .map(|p| p.distance(centre))
        .fold(0.0, f64::max);
    (centre, radius)
}

/// The glyphs of a font prepared for pairwise comparison: each one upright, and turned through
/// every one of the [`OVERLAP_ANGLES`] steps.
pub struct GlyphOverlaps {
    upright: Vec<Mask>,
    turned: Vec<Vec<Mask>>,
}

impl GlyphOverlaps {
    /// Prepares `outlines` on one common grid, large enough for the largest glyph at any turn.
    pub fn new(outlines: &[GlyphOutline]) -> Self {
        let placed: Vec<(DVec2, f64)> = outlines.iter().map(centroid_and_radius).collect();
        let radius_m = placed.iter().map(|&(_, r)| r).fold(0.0, f64::max);
        let side = 2 * (radius_m / OVERLAP_PIXEL_M).ceil() as usize + 2;
        let upright = outlines
            .iter()
            .zip(&placed)
            .map(|(outline, &(centre, _))| Mask::fill(outline, centre, 0.0, side))
            .collect();
        let turned = outlines
            .iter()
            .zip(&placed)
            .map(|(outline, &(centre, _))| {
                (0..OVERLAP_ANGLES)
                    .map(|k| {
                        let angle = std::f64::consts::TAU * k as f64 / OVERLAP_ANGLES as f64;
                        Mask::fill(outline, centre, angle, side)
                    })
                    .collect()
            })
            .collect();
        Self { upright, turned }
    }

    /// The best-rotation IoU of glyphs `a` and `b` (indices into the outlines given to [`Self::new`])
    /// and the turn of `b` that achieves it, radians.
    pub fn best_rotation_iou(&self, a: usize, b: usize) -> (f64, f64) {
        let fixed = &self.upright[a];
        let mut best = (0.0, 0.0);
        for (k, turned) in self.turned[b].iter().enumerate() {
            let intersection = turned.intersection(fixed);
            let union = fixed.count + turned.count - intersection;
            let iou = if union == 0 {
                0.0
            } else {
                intersection as f64 / union as f64
            };
            if iou > best.0 {
                best = (iou, std::f64::consts::TAU * k as f64 / OVERLAP_ANGLES as f64);
            }
        }
        best
    }

    /// Every unordered pair (i < j) with its best-rotation IoU, most alike first.
    pub fn all_pairs(&self) -> Vec<(usize, usize, f64)> {
        let n = self.upright.len();
        let mut pairs: Vec<(usize, usize, f64)> = (0..n)
            .flat_map(|i| (i + 1..n).map(move |j| (i, j)))
            .map(|(i, j)| (i, j, self.best_rotation_iou(i, j).0))
            .collect();
        pairs.sort_by(|p, q| q.2.total_cmp(&p.2).then((p.0, p.1).cmp(&(q.0, q.1))));
        pairs
    }
}

/// Two letters of a set and how alike they are.
#[derive(Debug, Clone, PartialEq)]
pub struct LetterPair {
    pub first: String,
    pub second: String,
    /// Best-rotation IoU (module docs), in [0, 1].
    pub iou: f64,
}

/// Every pair of the generated letters of `set` (each in its own font and style, the font checked
/// against the set's checksum), most alike first.
/// Objects of other kinds are left out.
pub fn letter_pairs(set: &ObjectSet) -> Result<Vec<LetterPair>, MeshError> {
    let mut fonts: BTreeMap<PathBuf, Font> = BTreeMap::new();
    let mut names = Vec::new();
    let mut outlines = Vec::new();
    for object in &set.objects {
        if let ObjectSource::Letter { glyph, font, style } = &object.source {
            outlines.push(letter_outline(font.load_into(&mut fonts)?, *glyph, style)?);
            names.push(object.name.clone());
        }
    }
    Ok(GlyphOverlaps::new(&outlines)
        .all_pairs()
        .into_iter()
        .map(|(i, j, iou)| LetterPair {
            first: names[i].clone(),
            second: names[j].clone(),
            iou,
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rectangle(w: f64, h: f64, at: DVec2) -> Vec<DVec2> {
        vec![
            at,
            at + DVec2::new(w, 0.0),
            at + DVec2::new(w, h),
            at + DVec2::new(0.0, h),
        ]
    }

    fn outline(contours: Vec<Vec<DVec2>>) -> GlyphOutline {
        GlyphOutline { contours }
    }

    #[test]
    fn a_shape_and_its_turned_copy_coincide() {
        // An 'L' (two rectangles, one contour each, overlapping: non-zero fill) and the same 'L'
        // turned 90 degrees and moved. Its strokes are 30 pixels wide, so pixels cut by the outline
        // (up to one along each edge) cost at most a few percent.
        let l = outline(vec![
            rectangle(0.006, 0.03, DVec2::ZERO),
            rectangle(0.018, 0.006, DVec2::ZERO),
        ]);
        let turn = |p: DVec2| DVec2::new(-p.y, p.x) + DVec2::new(0.03, -0.01);
        let turned = outline(
            l.contours
                .iter()
                .map(|r| r.iter().map(|&p| turn(p)).collect())
                .collect(),
        );
        let overlaps = GlyphOverlaps::new(&[l, turned]);
        let (iou, angle) = overlaps.best_rotation_iou(0, 1);
        assert!(iou > 0.97, "iou {iou}");
        assert!((angle - 1.5 * std::f64::consts::PI).abs() < 0.05, "angle {angle}");
    }

    #[test]
    fn known_overlap_of_two_squares_and_holes_are_empty() {
        // A 4 mm square against a 4x2 mm bar: the bar fits inside, IoU = 8 / 16 at the best turn.
        let square = outline(vec![rectangle(0.004, 0.004, DVec2::ZERO)]);
        let bar = outline(vec![rectangle(0.004, 0.002, DVec2::ZERO)]);
        // A 4 mm square with a 2 mm square hole (wound the other way): area 12.
        let mut hole = rectangle(0.002, 0.002, DVec2::splat(0.001));
        hole.reverse();
        let ring = outline(vec![rectangle(0.004, 0.004, DVec2::ZERO), hole]);
        let overlaps = GlyphOverlaps::new(&[square, bar, ring]);
        let (iou, _) = overlaps.best_rotation_iou(0, 1);
        assert!((iou - 0.5).abs() < 0.02, "iou {iou}");
        let (iou, _) = overlaps.best_rotation_iou(0, 2);
        assert!((iou - 0.75).abs() < 0.02, "iou {iou}");
        assert_eq!(overlaps.all_pairs()[0].0, 0);
    }
}
