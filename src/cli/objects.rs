//! `taction objects list|fetch|letters|overlap|export`: the object sets the arm explores.

use std::path::{Path, PathBuf};

use crate::cli::common::ObjectSizeArg;
use clap::{Args, Subcommand};
use taction::mesh::BUILTIN_SETS;
use taction::mesh::Font;
use taction::mesh::LetterStyle;
use taction::mesh::letter_pairs;
use taction::mesh::{BuildOptions, MeshError, ObjectSet, ObjectSource, write_obj};
use taction::mesh::{CGAL_MESHES, ObjectCache};

#[derive(Debug, Args)]
pub struct ObjectsArgs {
    #[command(subcommand)]
    pub command: ObjectsCommand,
    /// Cache of fetched meshes [default: $TACTION_CACHE/objects, else $XDG_CACHE_HOME/taction/objects,
    /// else ~/.cache/taction/objects].
    #[arg(long, global = true, value_name = "DIR")]
    pub cache: Option<PathBuf>,
}

#[derive(Debug, Subcommand)]
pub enum ObjectsCommand {
    /// List the built-in sets (name, version, id) and their objects.
    List {
        /// Font of the letters set [default: OpenDyslexic, capital I of DejaVu Sans Mono, built in].
        #[arg(long, value_name = "FILE.ttf")]
        font: Option<PathBuf>,
    },
    /// Fetch the ten CGAL meshes of the `shapes` set (Debian's libcgal-demo 5.5.1-2) into the cache.
    Fetch {
        /// Use this already downloaded libcgal-demo_5.5.1-2_all.deb instead of apt-get download.
        #[arg(long, value_name = "FILE.deb")]
        deb: Option<PathBuf>,
    },
    /// Write the 52 raised letters as OBJ (metres): upper_A.obj ... lower_z.obj, plus manifest.json.
    Letters {
        /// TrueType/OpenType font [default: the built-in letters: OpenDyslexic, capital I of DejaVu Sans Mono].
        #[arg(long, value_name = "FILE.ttf")]
        font: Option<PathBuf>,
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
    },
    /// How alike the letters are under rotation: every pair's best-rotation IoU, most alike first.
    /// Touch cannot tell which way a letter lies, so a pair near 1 can never be told apart.
    Overlap {
        /// TrueType/OpenType font of every letter [default: the built-in letters].
        #[arg(long, value_name = "FILE.ttf")]
        font: Option<PathBuf>,
        /// How many of the most alike pairs to print.
        #[arg(long, default_value_t = 10, value_name = "N")]
        top: usize,
    },
    /// Write every object of a set as OBJ (metres, normalised as the set says), plus manifest.json.
    Export {
        /// A built-in set (shapes, chess, letters), a manifest .json, a folder of meshes, or mesh files.
        #[arg(required = true, value_name = "SET")]
        set: Vec<PathBuf>,
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
        /// Font of the letters set [default: OpenDyslexic, capital I of DejaVu Sans Mono, built in].
        #[arg(long, value_name = "FILE.ttf")]
        font: Option<PathBuf>,
        #[command(flatten)]
        object_size: ObjectSizeArg,
        /// Fetch the CGAL meshes first if the cache lacks them.
        #[arg(long)]
        fetch: bool,
    },
}

pub fn run(args: &ObjectsArgs) -> Result<(), Box<dyn std::error::Error>> {
    let cache = args
        .cache
        .clone()
        .map(ObjectCache::new)
        .unwrap_or_else(ObjectCache::from_env);
    match &args.command {
        ObjectsCommand::List { font } => list(&cache, font.as_deref()),
        ObjectsCommand::Fetch { deb } => {
            let fresh = deb.is_some() || cache.verify().is_err();
            if fresh {
                cache.fetch(deb.as_deref())?;
            }
            let verb = if fresh { "fetched" } else { "already present" };
            println!(
                "{} CGAL meshes {verb} in {} (checksums verified)",
                CGAL_MESHES.len(),
                cache.mesh_dir().display()
            );
            Ok(())
        }
        ObjectsCommand::Letters { font, out } => {
            let set = match font {
                Some(path) => ObjectSet::letters(&Font::load(path)?, LetterStyle::default()),
                None => ObjectSet::default_letters(LetterStyle::default())?,
            };
            export(&set, &BuildOptions { cache, fetch: false }, out)
        }
        ObjectsCommand::Overlap { font, top } => {
            let set = ObjectSet::builtin("letters", font.as_deref())?;
            println!("first,second,iou");
            for pair in letter_pairs(&set)?.iter().take(*top) {
                println!("{},{},{:.3}", pair.first, pair.second, pair.iou);
            }
            Ok(())
        }
        ObjectsCommand::Export {
            set,
            out,
            font,
            object_size,
            fetch,
        } => {
            let set = ObjectSet::resolve(set, font.as_deref(), object_size.m)?;
            export(&set, &BuildOptions { cache, fetch: *fetch }, out)
        }
    }
}

/// Sets with more objects than this are listed by their first and last object.
const LIST_IN_FULL: usize = 20;

fn list(cache: &ObjectCache, font: Option<&Path>) -> Result<(), Box<dyn std::error::Error>> {
    let cached = cache.verify();
    for name in BUILTIN_SETS {
        let set = match ObjectSet::builtin(name, font) {
            Ok(set) => set,
            Err(e) => {
                println!("{name}: unavailable: {e}\n");
                continue;
            }
        };
        let size = set
            .diagonal_m
            .map(|d| format!(", {} diagonal", taction::units::length(d)))
            .unwrap_or_default();
        println!(
            "{} v{} (id {}): {} objects{size}",
            set.name,
            set.version,
            set.id(),
            set.objects.len()
        );
        if let Some(first) = set.objects.first().filter(|_| set.objects.len() > LIST_IN_FULL) {
            let summary = match &first.source {
                ObjectSource::Letter { font, style, .. } => format!(
                    "raised letters in {} (capitals {} tall, raised {} on a {} plate)",
                    font.path.display(),
                    taction::units::length(style.cap_height_m),
                    taction::units::length(style.raise_m),
                    taction::units::length(style.plate_thickness_m)
                ),
                other => other.to_string(),
            };
            println!(
                "  {} ... {}: {summary}",
                first.name,
                set.objects[set.objects.len() - 1].name
            );
        } else {
            for object in &set.objects {
                let note = match (&object.source, &cached) {
                    (ObjectSource::Cgal { .. }, Err(MeshError::NotFetched { .. })) => "  [not fetched]",
                    (ObjectSource::Cgal { .. }, Err(_)) => "  [cache damaged: fetch again]",
                    _ => "",
                };
                println!("  {:14} {}{note}", object.name, object.source);
            }
        }
        println!();
    }
    if let Err(e) = cached {
        println!("{e}");
    }
    Ok(())
}

/// Writes every object of `set` into `out`; on failure removes what it wrote (the folder too when
/// it made it), so that a failed export leaves nothing that looks like a set.
fn export(set: &ObjectSet, options: &BuildOptions, out: &Path) -> Result<(), Box<dyn std::error::Error>> {
    let objects = set.build(options)?;
    let made_folder = !out.exists();
    std::fs::create_dir_all(out).map_err(|source| MeshError::Write {
        path: out.to_path_buf(),
        source,
    })?;
    let mut written = Vec::new();
    let result = write_export(set, objects, out, &mut written);
    if result.is_err() {
        for path in &written {
            let _ = std::fs::remove_file(path);
        }
        if made_folder {
            let _ = std::fs::remove_dir(out);
        }
    }
    result
}

fn write_export(
    set: &ObjectSet,
    objects: Vec<taction::mesh::Object>,
    out: &Path,
    written: &mut Vec<PathBuf>,
) -> Result<(), Box<dyn std::error::Error>> {
    let id = set.id();
    for object in objects {
        let path = out.join(format!("{}.obj", object.name));
        let comment = format!(
            "taction object '{}' of set {} v{} (id {id})",
            object.name, set.name, set.version
        );
        write_obj(&object.mesh, &path, &comment)?;
        written.push(path.clone());
        let flipped = if object.flipped {
            ", flipped to face outward"
        } else {
            ""
        };
        println!(
            "{} ({} triangles; {}{flipped})",
            path.display(),
            object.mesh.triangles.len(),
            object.warnings
        );
    }
    let manifest = out.join("manifest.json");
    set.save_manifest(&manifest)?;
    written.push(manifest);
    println!(
        "{} v{} (id {id}): {} objects in {}",
        set.name,
        set.version,
        set.objects.len(),
        out.display()
    );
    Ok(())
}
