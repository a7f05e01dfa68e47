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

/// Fonts compiled into the binary, named by a path with this prefix (`taction:OpenDyslexic-Regular.otf`).
/// The files and their licences are in the repository's `fonts/` folder.
pub const BUILTIN_FONT_PREFIX: &str = "taction:";

const BUILTIN_FONTS: [(&str, &[u8]); 2] = [
    (
        "OpenDyslexic-Regular.otf",
        include_bytes!("../../fonts/OpenDyslexic-Regular.otf"),
    ),
    (
        "DejaVuSansMono.ttf",
        include_bytes!("../../fonts/DejaVuSansMono.ttf"),
    ),
];

/// The default letter font: OpenDyslexic, a rounded sans serif drawn so that no letter is another
/// one turned round (its 'b' is not a turned 'q': the bowls are weighted to the bottom). The
/// descriptors cannot see which way a letter lies (Sec. IV), so in a font where 'q' is a turned 'b'
/// the two can never be told apart by touch; `meshes/README.md` measures every pair.
pub const DEFAULT_FONT: &str = "taction:OpenDyslexic-Regular.otf";

/// The font of the default capital 'I': DejaVu Sans Mono, whose 'I' has cross-bars. The paper took
/// its capital 'I' from a second font for the same reason: the physical letter has cross-bars,
/// which tell it from 'l' (Sec. V-D, footnote 1).
pub const CAPITAL_I_FONT: &str = "taction:DejaVuSansMono.ttf";

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
    /// Reads and checks a font file, or a built-in font named with [`BUILTIN_FONT_PREFIX`] (it must
    /// parse and map characters to glyphs).
    pub fn load(path: &Path) -> Result<Self, MeshError> {
        let builtin = path.to_str().and_then(|p| p.strip_prefix(BUILTIN_FONT_PREFIX));
        let data = match builtin {
            Some(name) => BUILTIN_FONTS
                .iter()
                .find(|(file, _)| *file == name)
                .map(|(_, data)| data.to_vec())
                .ok_or_else(|| MeshError::Font {
                    path: path.to_path_buf(),
                    what: format!(
                        "no built-in font '{name}' (the built-in fonts are {})",
                        BUILTIN_FONTS.map(|(file, _)| file).join(", ")
                    ),
                })?,
            None => std::fs::read(path).map_err(|e| MeshError::Font {
                path: path.to_path_buf(),
                what: e.to_string(),
            })?,
        };
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

    /// Reads [`CAPITAL_I_FONT`].
    pub fn load_capital_i() -> Result<Self, MeshError> {
        Self::load(Path::new(CAPITAL_I_FONT))
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

    /// The height of the capital letters in font units: the top of 'H' as drawn, else the OS/2 cap
    /// height. The drawn height comes first because some fonts' OS/2 value is not their letters'
    /// (OpenDyslexic's would make its capitals 18 mm tall instead of 25).
    pub fn cap_height_units(&self) -> Result<f64, MeshError> {
        let face = self.face()?;
        let drawn = face
            .glyph_index('H')
            .and_then(|g| face.glyph_bounding_box(g))
            .map(|r| r.y_max as f64)
            .filter(|&h| h > 0.0);
        let declared = face.capital_height().filter(|&h| h > 0).map(f64::from);
        drawn.or(declared).ok_or_else(|| MeshError::Font {
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
