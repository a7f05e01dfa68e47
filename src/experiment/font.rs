//! The font for PNG plot text. The SVG names the generic family `sans-serif` and leaves the font
//! to the viewer; the PNG is that SVG rendered by `resvg`, which needs an actual font file. One
//! system TrueType font is loaded (not every installed font, so the PNG does not change when other
//! fonts are installed) and made the `sans-serif` family. DejaVu Sans renders every character the
//! plots use, minus signs included.
//!
//! (plotters' own `ab_glyph` text feature is deliberately not used: cargo's feature unification
//! would switch it on for criterion's plotters too, whose report plots then fail for want of a
//! registered font.)

use std::path::PathBuf;
use std::sync::{Arc, OnceLock};

use super::error::ExperimentError;

/// The font family name the plots ask for.
pub const FAMILY: &str = "sans-serif";

/// Environment variable naming a `.ttf` file to use instead of the system fonts below.
pub const FONT_ENV: &str = "TACTION_FONT";

const CANDIDATES: [&str; 5] = [
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/TTF/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu-sans-fonts/DejaVuSans.ttf",
    "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
];

static FONT: OnceLock<Result<Arc<resvg::usvg::fontdb::Database>, Vec<PathBuf>>> = OnceLock::new();

/// A font database holding the plot font as `sans-serif`, loaded once per process; the error lists
/// every path tried.
pub fn plot_fonts() -> Result<Arc<resvg::usvg::fontdb::Database>, ExperimentError> {
    FONT.get_or_init(load)
        .clone()
        .map_err(|tried| ExperimentError::NoFont { tried })
}

fn load() -> Result<Arc<resvg::usvg::fontdb::Database>, Vec<PathBuf>> {
    let mut tried = Vec::new();
    let env = std::env::var_os(FONT_ENV).map(PathBuf::from);
    for path in env.into_iter().chain(CANDIDATES.iter().map(PathBuf::from)) {
        if let Ok(bytes) = std::fs::read(&path) {
            let mut db = resvg::usvg::fontdb::Database::new();
            db.load_font_data(bytes);
            let family = db
                .faces()
                .next()
                .and_then(|face| face.families.first())
                .map(|(name, _)| name.clone());
            if let Some(family) = family {
                db.set_sans_serif_family(family);
                return Ok(Arc::new(db));
            }
        }
        tried.push(path);
    }
    Err(tried)
}
