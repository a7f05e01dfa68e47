//! Object sets: named, versioned manifests of the objects an experiment explores. Datasets and
//! trained models record the set's name, version and id ([`ObjectSetRef`]), so a model is never
//! applied to objects other than those it was trained on.
//!
//! A manifest lists each object's source (a pinned CGAL mesh, a generated chess piece, a letter of a
//! pinned font, or a user's mesh file with its checksum) and the common size objects are scaled to.
//! Its id is the SHA-256 of the manifest's canonical JSON with local paths reduced to file names, so
//! the same set has the same id on every machine, and any change of content (a file, the font, the
//! scale, the letter style) changes it.

use std::collections::BTreeMap;
use std::fmt;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::pose::MaxHeading;

use super::cgal::{CGAL_MESHES, ObjectCache};
use super::checksum::{sha256_file, sha256_hex};
use super::chess::ChessPiece;
use super::error::MeshError;
use super::glyph::Font;
use super::letters::{LetterStyle, alphabet, letter_name, raised_letter};
use super::load::{LoadedMesh, MeshFormat, parse};
use super::normalise::{UpAxis, rotate_up_to_z};
use super::object::{Object, name_of_file};
use super::validate::ValidationReport;

/// The common size of the 3D objects: a 12 cm bounding-box diagonal, table-top objects an arm can
/// walk a 12 mm pad over.
pub const SHAPES_DIAGONAL_M: f64 = 0.12;

/// Names of the built-in sets.
pub const BUILTIN_SETS: [&str; 3] = ["shapes", "chess", "letters"];

/// Whether a command line's `entry` names a set that sizes its own objects, a built-in set or a
/// manifest (`.json`), which [`ObjectSet::resolve`] reads as such and a diagonal does not rescale.
pub fn sizes_its_own_objects(entry: &Path) -> bool {
    BUILTIN_SETS.contains(&entry.to_string_lossy().as_ref()) || entry.extension().is_some_and(|e| e == "json")
}

/// A pinned font: where it was found and what it contained.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FontRef {
    pub path: PathBuf,
    pub sha256: String,
}

impl FontRef {
    /// The font this reference pins, read once into `fonts` (keyed by path) and checked against the
    /// recorded checksum: a set's letters are only rebuilt from the font they were made with.
    pub fn load_into<'a>(&self, fonts: &'a mut BTreeMap<PathBuf, Font>) -> Result<&'a Font, MeshError> {
        if !fonts.contains_key(&self.path) {
            fonts.insert(self.path.clone(), Font::load(&self.path)?);
        }
        let loaded = &fonts[&self.path];
        if loaded.sha256() != self.sha256 {
            return Err(MeshError::Checksum {
                path: self.path.clone(),
                expected: self.sha256.clone(),
                actual: loaded.sha256().into(),
                hint: "the font changed since the set was made; use the same font file".into(),
            });
        }
        Ok(loaded)
    }
}

/// Where an object's mesh comes from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum ObjectSource {
    /// A mesh of Debian's libcgal-demo, from the object cache.
    Cgal {
        file: String,
        sha256: String,
        up: UpAxis,
    },
    /// A chess piece generated as a surface of revolution.
    Chess { piece: ChessPiece },
    /// A raised letter of a font.
    Letter {
        glyph: char,
        font: FontRef,
        style: LetterStyle,
    },
    /// A user's OBJ/OFF/STL file (coordinates in metres unless the set rescales them).
    File { path: PathBuf, sha256: String },
}

impl fmt::Display for ObjectSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ObjectSource::Cgal { file, .. } => match CGAL_MESHES.iter().find(|m| m.file == file) {
                Some(m) => write!(f, "libcgal-demo {file}: {}", m.description),
                None => write!(f, "libcgal-demo {file}"),
            },
            ObjectSource::Chess { piece } => write!(f, "generated {} (surface of revolution)", piece.name()),
            ObjectSource::Letter { glyph, font, .. } => {
                let name = font
                    .path
                    .file_name()
                    .map(|n| n.to_string_lossy())
                    .unwrap_or_default();
                write!(f, "raised '{glyph}' in {name}")
            }
            ObjectSource::File { path, .. } => write!(f, "file {}", path.display()),
        }
    }
}

/// One object of a set.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NamedObject {
    pub name: String,
    pub source: ObjectSource,
}

/// A named, versioned list of objects.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ObjectSet {
    pub name: String,
    pub version: u32,
    /// Bounding-box diagonal every object is scaled to (then centred on x = y = 0, resting on z = 0);
    /// `None` keeps each object's own size (letters are made to size; user meshes in metres).
    pub diagonal_m: Option<f64>,
    pub objects: Vec<NamedObject>,
}

/// What a dataset or model records about the set it was made from.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct ObjectSetRef {
    pub name: String,
    pub version: u32,
    pub id: String,
}

/// Where building a set finds what it needs.
#[derive(Debug, Clone)]
pub struct BuildOptions {
    pub cache: ObjectCache,
    /// Fetch missing CGAL meshes (otherwise a missing cache is an error saying how to fetch it).
    pub fetch: bool,
}

impl Default for BuildOptions {
    fn default() -> Self {
        Self {
            cache: ObjectCache::from_env(),
            fetch: false,
        }
    }
}

fn set_error(what: impl Into<String>) -> MeshError {
    MeshError::ObjectSet { what: what.into() }
}

impl ObjectSet {
    /// The 3D set (version 1): the ten CGAL meshes and the two chess pieces, each scaled to a 12 cm
    /// diagonal, standing in for the paper's ten Princeton models (Sec. V-B, Fig. 5).
    pub fn shapes() -> Self {
        let mut objects: Vec<NamedObject> = CGAL_MESHES
            .iter()
            .map(|m| NamedObject {
                name: m.name.into(),
                source: ObjectSource::Cgal {
                    file: m.file.into(),
                    sha256: m.sha256.into(),
                    up: m.up,
                },
            })
            .collect();
        objects.extend(Self::chess().objects);
        Self {
            name: "shapes".into(),
            version: 1,
            diagonal_m: Some(SHAPES_DIAGONAL_M),
            objects,
        }
    }

    /// The two generated chess pieces (version 1), 12 cm diagonal: needs no download.
    pub fn chess() -> Self {
        let objects = ChessPiece::ALL
            .iter()
            .map(|&piece| NamedObject {
                name: piece.name().into(),
                source: ObjectSource::Chess { piece },
            })
            .collect();
        Self {
            name: "chess".into(),
            version: 1,
            diagonal_m: Some(SHAPES_DIAGONAL_M),
            objects,
        }
    }

    /// The 52 raised letters (version 1) of `font` in `style` (Sec. V-D), named `upper_A` ...
    /// `lower_z`, the capital 'I' from `capital_i` (the paper's letters take it from a second font
    /// for its cross-bars).
    pub fn letters_with(font: &Font, capital_i: &Font, style: LetterStyle) -> Self {
        let font_ref = |font: &Font| FontRef {
            path: font.path().to_path_buf(),
            sha256: font.sha256().into(),
        };
        let objects = alphabet()
            .map(|glyph| NamedObject {
                name: letter_name(glyph),
                source: ObjectSource::Letter {
                    glyph,
                    font: font_ref(if glyph == 'I' { capital_i } else { font }),
                    style,
                },
            })
            .collect();
        Self {
            name: "letters".into(),
            version: 1,
            diagonal_m: None,
            objects,
        }
    }

    /// The 52 raised letters, all of `font`.
    pub fn letters(font: &Font, style: LetterStyle) -> Self {
        Self::letters_with(font, font, style)
    }

    /// The built-in letters: [`DEFAULT_FONT`](super::glyph::DEFAULT_FONT) with the capital 'I' of
    /// [`CAPITAL_I_FONT`](super::glyph::CAPITAL_I_FONT).
    pub fn default_letters(style: LetterStyle) -> Result<Self, MeshError> {
        Ok(Self::letters_with(
            &Font::load_default()?,
            &Font::load_capital_i()?,
            style,
        ))
    }

    /// A built-in set by name; `font`, when given, draws every letter of `letters` (default:
    /// [`ObjectSet::default_letters`]).
    pub fn builtin(name: &str, font: Option<&Path>) -> Result<Self, MeshError> {
        match name {
            "shapes" => Ok(Self::shapes()),
            "chess" => Ok(Self::chess()),
            "letters" => match font {
                Some(path) => Ok(Self::letters(&Font::load(path)?, LetterStyle::default())),
                None => Self::default_letters(LetterStyle::default()),
            },
            other => Err(set_error(format!(
                "no built-in set '{other}' (the built-in sets are {})",
                BUILTIN_SETS.join(", ")
            ))),
        }
    }

    /// A user set from mesh files, each named by its file stem, optionally rescaled to a diagonal.
    pub fn from_files(name: &str, paths: &[PathBuf], diagonal_m: Option<f64>) -> Result<Self, MeshError> {
        if paths.is_empty() {
            return Err(set_error(format!("set '{name}' has no mesh files")));
        }
        if let Some(d) = diagonal_m.filter(|d| !(d.is_finite() && *d > 0.0)) {
            return Err(MeshError::InvalidParameter {
                field: "diagonal_m",
                what: format!("{d} is not a positive length"),
            });
        }
        let mut seen: BTreeMap<String, PathBuf> = BTreeMap::new();
        let mut objects = Vec::with_capacity(paths.len());
        for path in paths {
            MeshFormat::from_path(path)?;
            let stem = name_of_file(path)?;
            if let Some(other) = seen.insert(stem.clone(), path.clone()) {
                return Err(set_error(format!(
                    "{} and {} would both be named '{stem}'",
                    other.display(),
                    path.display()
                )));
            }
            let sha256 = sha256_file(path)?;
            let path = std::fs::canonicalize(path).map_err(|source| MeshError::Io {
                path: path.clone(),
                source,
            })?;
            objects.push(NamedObject {
                name: stem,
                source: ObjectSource::File { path, sha256 },
            });
        }
        Ok(Self {
            name: name.into(),
            version: 1,
            diagonal_m,
            objects,
        })
    }

    /// A user set from every .obj, .off and .stl file in `dir` (not recursive), in name order; the
    /// set is named after the folder.
    pub fn from_dir(dir: &Path, diagonal_m: Option<f64>) -> Result<Self, MeshError> {
        let entries = std::fs::read_dir(dir).map_err(|source| MeshError::Io {
            path: dir.to_path_buf(),
            source,
        })?;
        let mut paths = Vec::new();
        for entry in entries {
            let path = entry
                .map_err(|source| MeshError::Io {
                    path: dir.to_path_buf(),
                    source,
                })?
                .path();
            if path.is_file() && MeshFormat::from_path(&path).is_ok() {
                paths.push(path);
            }
        }
        paths.sort();
        if paths.is_empty() {
            return Err(set_error(format!(
                "{} holds no .obj, .off or .stl files",
                dir.display()
            )));
        }
        let name = std::fs::canonicalize(dir)
            .ok()
            .and_then(|d| d.file_name().map(|n| n.to_string_lossy().into_owned()))
            .unwrap_or_else(|| "custom".into());
        Self::from_files(&name, &paths, diagonal_m)
    }

    /// The set a command line names: a built-in set, a manifest (`.json`), a folder of meshes, or
    /// one or more mesh files.
    pub fn resolve(
        spec: &[PathBuf],
        font: Option<&Path>,
        diagonal_m: Option<f64>,
    ) -> Result<Self, MeshError> {
        match spec {
            [] => Err(set_error("no object set given")),
            [one] => {
                let text = one.to_string_lossy();
                if BUILTIN_SETS.contains(&text.as_ref()) {
                    Self::builtin(&text, font)
                } else if one.is_dir() {
                    Self::from_dir(one, diagonal_m)
                } else if one.extension().is_some_and(|e| e == "json") {
                    Self::load_manifest(one)
                } else if one.exists() {
                    Self::from_files("custom", spec, diagonal_m)
                } else {
                    Err(set_error(format!(
                        "'{text}' is neither a built-in set ({}) nor an existing folder or file",
                        BUILTIN_SETS.join(", ")
                    )))
                }
            }
            many => {
                // Several entries are mesh files; a set among them would be read as a file of an
                // unknown format.
                if let Some(set) = many.iter().find(|p| sizes_its_own_objects(p) || p.is_dir()) {
                    return Err(set_error(format!(
                        "'{}' is a set: give one set (a built-in set, a folder or a manifest) or several mesh files",
                        set.display()
                    )));
                }
                Self::from_files("custom", many, diagonal_m)
            }
        }
    }

    /// The stable id: the first 16 hex digits of the SHA-256 of the canonical manifest.
    pub fn id(&self) -> String {
        let mut canonical = self.clone();
        let file_name = |p: &Path| PathBuf::from(p.file_name().unwrap_or_default());
        for object in &mut canonical.objects {
            match &mut object.source {
                ObjectSource::File { path, .. } => *path = file_name(path),
                ObjectSource::Letter { font, .. } => font.path = file_name(&font.path),
                ObjectSource::Cgal { .. } | ObjectSource::Chess { .. } => {}
            }
        }
        let json = serde_json::to_string(&canonical).unwrap_or_default();
        sha256_hex(json.as_bytes())[..16].to_string()
    }

    pub fn reference(&self) -> ObjectSetRef {
        ObjectSetRef {
            name: self.name.clone(),
            version: self.version,
            id: self.id(),
        }
    }

    /// How far a random start (`pose::StartPose::Random`) may turn this set's objects about the
    /// vertical: [`MaxHeading::LETTERS`] when any of them is a raised letter, whose heading is part
    /// of its identity ('b' turned half round is 'q'), else [`MaxHeading::ANY`].
    pub fn start_heading(&self) -> MaxHeading {
        let letters = self
            .objects
            .iter()
            .any(|o| matches!(o.source, ObjectSource::Letter { .. }));
        if letters {
            MaxHeading::LETTERS
        } else {
            MaxHeading::ANY
        }
    }

    pub fn object_names(&self) -> Vec<&str> {
        self.objects.iter().map(|o| o.name.as_str()).collect()
    }

    /// Builds every object (see [`ObjectSet::build_object`]).
    pub fn build(&self, options: &BuildOptions) -> Result<Vec<Object>, MeshError> {
        let mut fonts: BTreeMap<PathBuf, Font> = BTreeMap::new();
        self.objects
            .iter()
            .map(|o| self.build_with(o, options, &mut fonts))
            .collect()
    }

    /// Builds the object named `name`: its mesh from its source (checksums checked), facing out,
    /// scaled to the set's diagonal, centred and resting on z = 0.
    pub fn build_object(&self, name: &str, options: &BuildOptions) -> Result<Object, MeshError> {
        let object = self.objects.iter().find(|o| o.name == name).ok_or_else(|| {
            set_error(format!(
                "set '{}' has no object '{name}' (it has {})",
                self.name,
                self.object_names().join(", ")
            ))
        })?;
        self.build_with(object, options, &mut BTreeMap::new())
    }

    fn build_with(
        &self,
        object: &NamedObject,
        options: &BuildOptions,
        fonts: &mut BTreeMap<PathBuf, Font>,
    ) -> Result<Object, MeshError> {
        let (mesh, warnings) = match &object.source {
            ObjectSource::Cgal { file, sha256, up } => {
                let cgal = CGAL_MESHES
                    .iter()
                    .find(|m| m.file == file && m.sha256 == sha256)
                    .ok_or_else(|| {
                        set_error(format!(
                            "'{}': {file} is not one of the pinned CGAL meshes",
                            object.name
                        ))
                    })?;
                if options.fetch {
                    options.cache.ensure_fetched()?;
                }
                let loaded = options.cache.load(cgal)?;
                (rotate_up_to_z(&loaded.mesh, *up), loaded.warnings)
            }
            ObjectSource::Chess { piece } => {
                let mesh = piece.mesh()?;
                let warnings = ValidationReport::of(&mesh);
                (mesh, warnings)
            }
            ObjectSource::Letter { glyph, font, style } => {
                let mesh = raised_letter(font.load_into(fonts)?, *glyph, style)?;
                let warnings = ValidationReport::of(&mesh);
                (mesh, warnings)
            }
            ObjectSource::File { path, sha256 } => {
                let loaded = load_checked(path, sha256)?;
                (loaded.mesh, loaded.warnings)
            }
        };
        Object::checked(
            object.name.clone(),
            &object.source,
            mesh,
            warnings,
            self.diagonal_m,
        )
    }

    /// The manifest as pretty JSON.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).unwrap_or_default()
    }

    pub fn save_manifest(&self, path: &Path) -> Result<(), MeshError> {
        Ok(crate::atomic::write_atomic(path, self.to_json().as_bytes())?)
    }

    /// Reads a manifest written by [`ObjectSet::save_manifest`]; object names must be unique.
    pub fn load_manifest(path: &Path) -> Result<Self, MeshError> {
        let text = std::fs::read_to_string(path).map_err(|source| MeshError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let set: ObjectSet = serde_json::from_str(&text)
            .map_err(|e| set_error(format!("{}: line {}: {e}", path.display(), e.line())))?;
        let mut names = std::collections::BTreeSet::new();
        if let Some(dup) = set.objects.iter().find(|o| !names.insert(o.name.as_str())) {
            return Err(set_error(format!(
                "{}: object '{}' appears twice",
                path.display(),
                dup.name
            )));
        }
        if set.objects.is_empty() {
            return Err(set_error(format!("{}: the set has no objects", path.display())));
        }
        Ok(set)
    }
}

/// The mesh file at `path`, read once: its checksum must be `sha256` (the file unchanged since its
/// set was made), and it is parsed from the same bytes while the checksum is computed beside it (a
/// 1.3M-triangle scan is 72 MB of text: reading it twice and hashing before parsing took a fifth of
/// the time to its first reading, issue 39). A changed file is reported before any parse error.
fn load_checked(path: &Path, sha256: &str) -> Result<LoadedMesh, MeshError> {
    let format = MeshFormat::from_path(path)?;
    let bytes = std::fs::read(path).map_err(|source| MeshError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let (actual, parsed) = std::thread::scope(|scope| {
        let digest = scope.spawn(|| sha256_hex(&bytes));
        let parsed = parse(&bytes, format, path);
        // The digest cannot panic; were its thread lost, it is computed here.
        (digest.join().unwrap_or_else(|_| sha256_hex(&bytes)), parsed)
    });
    if actual != sha256 {
        return Err(MeshError::Checksum {
            path: path.to_path_buf(),
            expected: sha256.to_string(),
            actual,
            hint: "the file changed since the set was made; make the set again".into(),
        });
    }
    parsed
}
