//! Letter outlines from a TrueType/OpenType font: the shapes of the raised letters (Sec. V-D,
//! "simulated letters were generated using a font").
//!
//! Outlines are read with `ttf-parser`; quadratic (TrueType) and cubic (CFF) curves are flattened
//! into polylines whose distance from the curve is at most a tolerance. A Bezier curve B(t) cut
//! into n equal parameter steps h = 1/n deviates from its chords by at most max|B''| h^2 / 8; for a
//! quadratic |B''| = 2 |p0 - 2 p1 + p2|, for a cubic |B''| <= 6 max(|p0 - 2 p1 + p2|, |p1 - 2 p2 + p3|),
//! so n = ceil(sqrt(max|B''| / (8 tol))).

use std::path::{Path, PathBuf};

use glam::DVec2;

use super::checksum::sha256_hex;
use super::error::MeshError;

/// The default font: DejaVu Sans, a clean sans serif close to the rounded letters of a child's
/// magnetic alphabet.
pub const DEFAULT_FONT: &str = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
/// The Debian package that installs [`DEFAULT_FONT`].
pub const DEFAULT_FONT_PACKAGE: &str = "fonts-dejavu-core";

/// A font file in memory, with its checksum (object-set manifests pin the font by it).
#[derive(Debug, Clone)]
pub struct Font {
    path: PathBuf,
    data: Vec<u8>,
    sha256: String,
}

/// A glyph outline: closed contours in metres (no repeated end point), as the font draws them.
#[derive(Debug, Clone, PartialEq)]
pub struct GlyphOutline {
    pub contours: Vec<Vec<DVec2>>,
}

impl Font {
    /// Reads and checks a font file (it must parse and map characters to glyphs).
    pub fn load(path: &Path) -> Result<Self, MeshError> {
        let data = std::fs::read(path).map_err(|e| {
            let mut what = e.to_string();
            if path == Path::new(DEFAULT_FONT) {
                what = format!(
                    "{what}; the default font comes from the Debian package {DEFAULT_FONT_PACKAGE} \
                     (apt-get install {DEFAULT_FONT_PACKAGE}), or pass another font with --font FILE.ttf"
                );
            }
            MeshError::Font {
                path: path.to_path_buf(),
                what,
            }
        })?;
        ttf_parser::Face::parse(&data, 0).map_err(|e| MeshError::Font {
            path: path.to_path_buf(),
            what: format!("not a usable font: {e}"),
        })?;
        let sha256 = sha256_hex(&data);
        Ok(Self {
            path: path.to_path_buf(),
            data,
            sha256,
        })
    }

    /// Reads [`DEFAULT_FONT`].
    pub fn load_default() -> Result<Self, MeshError> {
        Self::load(Path::new(DEFAULT_FONT))
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    pub fn sha256(&self) -> &str {
        &self.sha256
    }

    fn face(&self) -> Result<ttf_parser::Face<'_>, MeshError> {
        ttf_parser::Face::parse(&self.data, 0).map_err(|e| MeshError::Font {
            path: self.path.clone(),
            what: format!("not a usable font: {e}"),
        })
    }

    /// The height of the capital letters in font units: the OS/2 cap height, or the top of 'H'.
    pub fn cap_height_units(&self) -> Result<f64, MeshError> {
        let face = self.face()?;
        if let Some(h) = face.capital_height().filter(|&h| h > 0) {
            return Ok(h as f64);
        }
        face.glyph_index('H')
            .and_then(|g| face.glyph_bounding_box(g))
            .map(|r| r.y_max as f64)
            .filter(|&h| h > 0.0)
            .ok_or_else(|| MeshError::Font {
                path: self.path.clone(),
                what: "the font gives no cap height and has no 'H' to measure it".into(),
            })
    }

    /// The outline of `ch` scaled by `metres_per_unit`, curves flattened to within `tolerance_m`.
    pub fn outline(
        &self,
        ch: char,
        metres_per_unit: f64,
        tolerance_m: f64,
    ) -> Result<GlyphOutline, MeshError> {
        let glyph_error = |what: &str| MeshError::Glyph {
            font: self.path.clone(),
            glyph: ch,
            what: what.into(),
        };
        let face = self.face()?;
        let id = face
            .glyph_index(ch)
            .ok_or_else(|| glyph_error("the font has no glyph for it"))?;
        let mut flattener = Flattener {
            tolerance: tolerance_m / metres_per_unit,
            contours: Vec::new(),
            current: Vec::new(),
        };
        face.outline_glyph(id, &mut flattener)
            .ok_or_else(|| glyph_error("the glyph has no outline"))?;
        ttf_parser::OutlineBuilder::close(&mut flattener);
        let contours: Vec<Vec<DVec2>> = flattener
            .contours
            .into_iter()
            .map(|c| clean_ring(c.into_iter().map(|p| p * metres_per_unit).collect()))
            .filter(|c| c.len() >= 3)
            .collect();
        if contours.is_empty() {
            return Err(glyph_error("the glyph outline is empty"));
        }
        Ok(GlyphOutline { contours })
    }
}

/// Removes repeated points (including a closing point equal to the first) and points exactly
/// collinear with their neighbours, which carry no shape.
fn clean_ring(mut ring: Vec<DVec2>) -> Vec<DVec2> {
    ring.dedup();
    while ring.len() > 1 && ring.first() == ring.last() {
        ring.pop();
    }
    let mut changed = true;
    while changed && ring.len() >= 3 {
        changed = false;
        let n = ring.len();
        if let Some(i) = (0..n).find(|&i| {
            let (a, b, c) = (ring[(i + n - 1) % n], ring[i], ring[(i + 1) % n]);
            (b - a).perp_dot(c - b) == 0.0
        }) {
            ring.remove(i);
            changed = true;
        }
    }
    ring
}

struct Flattener {
    /// Largest chord deviation, font units.
    tolerance: f64,
    contours: Vec<Vec<DVec2>>,
    current: Vec<DVec2>,
}

impl Flattener {
    fn last(&self) -> DVec2 {
        self.current.last().copied().unwrap_or(DVec2::ZERO)
    }

    fn steps(&self, second_derivative_bound: f64) -> usize {
        ((second_derivative_bound / (8.0 * self.tolerance)).sqrt().ceil() as usize).clamp(1, 256)
    }
}

impl ttf_parser::OutlineBuilder for Flattener {
    fn move_to(&mut self, x: f32, y: f32) {
        self.close();
        self.current.push(DVec2::new(x as f64, y as f64));
    }

    fn line_to(&mut self, x: f32, y: f32) {
        self.current.push(DVec2::new(x as f64, y as f64));
    }

    fn quad_to(&mut self, x1: f32, y1: f32, x: f32, y: f32) {
        let (p0, p1, p2) = (
            self.last(),
            DVec2::new(x1 as f64, y1 as f64),
            DVec2::new(x as f64, y as f64),
        );
        let n = self.steps(2.0 * (p0 - 2.0 * p1 + p2).length());
        for k in 1..=n {
            let t = k as f64 / n as f64;
            let u = 1.0 - t;
            self.current.push(u * u * p0 + 2.0 * u * t * p1 + t * t * p2);
        }
    }

    fn curve_to(&mut self, x1: f32, y1: f32, x2: f32, y2: f32, x: f32, y: f32) {
        let p0 = self.last();
        let (p1, p2) = (DVec2::new(x1 as f64, y1 as f64), DVec2::new(x2 as f64, y2 as f64));
        let p3 = DVec2::new(x as f64, y as f64);
        let bound = 6.0 * (p0 - 2.0 * p1 + p2).length().max((p1 - 2.0 * p2 + p3).length());
        let n = self.steps(bound);
        for k in 1..=n {
            let t = k as f64 / n as f64;
            let u = 1.0 - t;
            self.current
                .push(u * u * u * p0 + 3.0 * u * u * t * p1 + 3.0 * u * t * t * p2 + t * t * t * p3);
        }
    }

    fn close(&mut self) {
        if !self.current.is_empty() {
            self.contours.push(std::mem::take(&mut self.current));
        }
    }
}
