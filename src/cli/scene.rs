//! `taction scene export`: the simulated world as a self-contained MJCF for MuJoCo's own tools.
//!
//! The scene is the one the arm explores (`SceneBuilder`: the arm of Sec. V-A1, the table, the object
//! with its collision shell in geom group 3) with the `taction.covering` sensor on the pad site,
//! configured by the sensor flags. The object's mesh goes beside the MJCF as an OBJ file the mesh
//! asset refers to. The object is a mocap body at the world origin, resting on the table, or with
//! `--free-object` a body on a free joint there, its mass its mesh's, the covering pushing it.
//!
//! Like `mjcf/scene.xml`, the scene carries a keyframe `touch`: the arm where `taction touch --arm`
//! leaves it after pressing the pad onto the object from above, so that MuJoCo's own tools open it
//! with the pad on the object (`mj_resetDataKeyframe`, or "Load key" in the viewer).

use std::path::{Path, PathBuf};

use clap::{Args, Subcommand};
use glam::DVec3;
use taction::control::ControlConfig;
use taction::dataset::ContactStatus;
use taction::mesh::BUILTIN_SETS;
use taction::mesh::{BuildOptions, MeshError, Object, ObjectSet, write_obj};
use taction::pose::PadPose;
use taction::sim::{ObjectMount, ObjectSpec, SceneBuilder};
use taction::sim::{Section, comment, numbers};
use taction::tactile::{SensorConfig, arm_with_sensor};
use taction::valid::Valid;

use crate::cli::common::{FreeObjectArgs, ObjectSizeArg, SeedArg, check_output_folder};
use crate::cli::plausible::{Carrier, check_mesh};
use crate::cli::plugin_path::PLUGIN_LIBRARY;
use crate::cli::sensor_args::SensorArgs;
use crate::cli::touch::{ArmTouch, TouchError, touch_arm};

#[derive(Debug, Args)]
pub struct SceneArgs {
    #[command(subcommand)]
    pub command: SceneCommand,
}

#[derive(Debug, Subcommand)]
pub enum SceneCommand {
    /// Write DIR/scene.xml (arm, table, object, the covering sensor on the pad) and the object's mesh
    /// as DIR/<object>.obj; it opens in MuJoCo's viewer once the plugin library is loaded
    /// (`taction plugin-path`).
    Export(ExportArgs),
}

#[derive(Debug, Args)]
pub struct ExportArgs {
    /// The object: a name from a built-in set (`taction objects list`: bunny, pawn, upper_A, ...;
    /// CGAL meshes are fetched on first use) or an OBJ/OFF/STL file, coordinates in metres.
    #[arg(long, value_name = "NAME|FILE")]
    pub object: String,
    /// Output folder (created if missing); scene.xml and the mesh file are overwritten.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    #[command(flatten)]
    pub object_size: ObjectSizeArg,
    #[command(flatten)]
    pub sensor: SensorArgs,
    #[command(flatten)]
    pub seed: SeedArg,
    /// The object on a free joint (`--free-object`, with `--object-density` and
    /// `--object-friction`): its mass and inertia its mesh's, the covering pushing it.
    #[command(flatten)]
    pub free: FreeObjectArgs,
}

/// What can go wrong; each names the flag or file at fault.
#[derive(Debug, thiserror::Error)]
pub enum SceneExportError {
    #[error("--object: '{0}' is neither an existing mesh file nor an object of the built-in sets ({sets}); `taction objects list` lists them", sets = BUILTIN_SETS.join(", "))]
    UnknownObject(String),
    #[error("--object: {0}")]
    Mesh(#[from] MeshError),
    #[error("--out: {path}: {source}")]
    Write { path: PathBuf, source: std::io::Error },
}

/// The object `--object` names, built as `collect` builds it (resting on z = 0, centred).
fn resolve_object(object: &str, object_size_m: Option<f64>) -> Result<Object, SceneExportError> {
    let options = BuildOptions {
        fetch: true,
        ..BuildOptions::default()
    };
    let path = Path::new(object);
    if path.is_file() {
        return Ok(match object_size_m {
            Some(size_m) => Object::from_file_with_size(path, size_m)?,
            None => Object::from_file(path)?,
        });
    }
    for set_name in BUILTIN_SETS {
        // A set that cannot be listed here (the letters without their font) cannot hold the object.
        let Ok(set) = ObjectSet::builtin(set_name, None) else {
            continue;
        };
        if set.object_names().contains(&object) {
            return Ok(set.build_object(object, &options)?);
        }
    }
    Err(SceneExportError::UnknownObject(object.into()))
}

/// How far above the object's top the touch of the `touch` keyframe starts, metres.
const TOUCH_START_ABOVE_M: f64 = 0.005;

/// The arm's touch of `object` from above with the default controllers (told to expect `sensor`'s
/// noise), as `taction touch --arm` runs them: started looking straight down over the centre of the
/// object's bounding box, then over its highest vertex (a ring has nothing under its centre); the
/// first that converges, else the first that ends in contact, else `None`.
fn touch_from_above(
    object: &ObjectSpec,
    sensor: &Valid<SensorConfig>,
) -> Result<Option<ArmTouch>, TouchError> {
    let Some((lo, hi)) = object.mesh.bounds() else {
        return Ok(None);
    };
    let highest = object
        .mesh
        .vertices
        .iter()
        .copied()
        .reduce(|a, b| if b.z > a.z { b } else { a })
        .unwrap_or(hi);
    let control = Valid::new(ControlConfig {
        expected_noise_fraction: sensor.noise_fraction,
        ..ControlConfig::default()
    })
    .map_err(|e| {
        TouchError::Sim(taction::sim::SimError::BadConfiguration {
            message: e.to_string(),
        })
    })?;
    let mut in_contact = None;
    for (x, y) in [((lo.x + hi.x) * 0.5, (lo.y + hi.y) * 0.5), (highest.x, highest.y)] {
        let start = PadPose {
            center_m: DVec3::new(x, y, hi.z + TOUCH_START_ABOVE_M),
            normal: DVec3::NEG_Z,
            up: DVec3::X,
        };
        let touch = match touch_arm(object.clone(), sensor, &control, &start) {
            Ok(touch) => touch,
            Err(TouchError::Unreachable(_) | TouchError::StartsInCollision { .. }) => continue,
            Err(e) => return Err(e),
        };
        if touch.outcome.status == ContactStatus::Converged {
            return Ok(Some(touch));
        }
        if in_contact.is_none() && touch.outcome.image.max() > control.effective_contact_threshold() {
            in_contact = Some(touch);
        }
    }
    Ok(in_contact)
}

/// What the header says of a free object: its mass, material and the covering's push; nothing
/// for a mocap one.
fn free_sentence(object: &ObjectSpec) -> String {
    if object.mount != ObjectMount::Free {
        return String::new();
    }
    let body = object.free_body;
    let mass_kg = object.solid_mass_kg().unwrap_or(0.0);
    format!(
        "\n  The object stands on a free joint: {} g, a solid of {} kg/m3, friction {}; the covering pushes it\n  \
         (the sensor's modulus_pa), so stepping the scene presses it as taction collect does with its free-object flag.",
        taction::units::significant(mass_kg * 1e3),
        body.density_kg_m3(),
        body.friction()
    )
}

/// `builder` with the keyframe "touch" where the arm, pressing from above, settled on `spec`
/// (none, with a warning, when it could not), and the sentence the scene's header gives it. A free
/// object's joint stands in the keyframe where the object was built, at rest.
fn with_touch_keyframe(
    mut builder: SceneBuilder,
    spec: &ObjectSpec,
    config: &Valid<SensorConfig>,
    object: &str,
    mount: ObjectMount,
) -> Result<(SceneBuilder, String), Box<dyn std::error::Error>> {
    let keyframe = match touch_from_above(spec, config)? {
        Some(touch) => {
            let object_qpos = match mount {
                ObjectMount::Free => {
                    let [w, x, y, z] = spec.pose.mujoco_quat();
                    let p = spec.pose.position_m;
                    vec![p.x, p.y, p.z, w, x, y, z]
                }
                ObjectMount::Mocap => Vec::new(),
            };
            builder = builder.add(
                Section::Keyframe,
                format!(
                    "<key name=\"touch\" qpos=\"{}\" ctrl=\"{}\"/>",
                    numbers(touch.qpos.iter().copied().chain(object_qpos)),
                    numbers(touch.q_rad.iter().copied())
                ),
            );
            format!(
                "The keyframe \"touch\" (qpos: the arm's 8 joints, radians; the same angles as the servos' ctrl, so\n  \
                 stepping holds the pose) is where taction touch with the arm leaves it after pressing the pad onto\n  \
                 the object from above ({}, mean pressure {:.2} of the range).",
                touch.outcome.status.name(),
                touch.outcome.image.mean()
            )
        }
        None => {
            eprintln!(
                "taction scene export: warning: {}: the arm could not press the pad onto the object from above; the scene has no keyframe \"touch\"",
                object
            );
            "No keyframe: the arm could not press the pad onto the object from above.".to_string()
        }
    };
    Ok((builder, keyframe))
}

/// Writes the scene and its mesh; returns the scene file's path.
pub fn export(args: &ExportArgs) -> Result<PathBuf, Box<dyn std::error::Error>> {
    check_output_folder(&args.out, "out")?;
    let config = args.sensor.config(args.seed.seed)?;
    let free_body = args.free.body()?;
    let built = resolve_object(&args.object, args.object_size.m)?;
    check_mesh(&format!("--object: {}", args.object), &built.mesh, Carrier::Arm)?;
    if !built.warnings.is_clean() {
        eprintln!(
            "taction scene export: warning: {}: {}",
            args.object, built.warnings
        );
    }
    // Named as `taction objects export` names its files.
    let mesh_file = format!("{}.obj", built.name);
    let spec = ObjectSpec::from(built);
    let mounted = spec.mounted(free_body);
    let builder = arm_with_sensor(mounted.clone(), &config).object_mesh_file(mesh_file.clone());
    let (builder, keyframe) = with_touch_keyframe(builder, &spec, &config, &args.object, mounted.mount)?;
    let xml = builder.to_xml()?;
    let header = comment(&format!(
        "  Written by taction scene export for the object {}: the arm, the table, the object (mesh in {mesh_file},\n  \
         metres) and the taction.covering sensor on the pad site. Load the plugin library first:\n  \
         mujoco.mj_loadPluginLibrary(path) with the path `taction plugin-path` prints ({PLUGIN_LIBRARY}),\n  \
         or copy the library into the plugin/ folder of the mujoco Python package.\n  {keyframe}{}",
        args.object,
        free_sentence(&mounted)
    )) + "\n";
    let write = |path: PathBuf, text: &str| {
        taction::atomic::write_atomic(&path, text.as_bytes()).map_err(|e| SceneExportError::Write {
            path: e.path,
            source: e.source,
        })
    };
    std::fs::create_dir_all(&args.out).map_err(|source| SceneExportError::Write {
        path: args.out.clone(),
        source,
    })?;
    write_obj(
        &spec.mesh,
        &args.out.join(&mesh_file),
        &format!("{}: exported by taction scene export", spec.name),
    )?;
    let scene = args.out.join("scene.xml");
    write(scene.clone(), &format!("{header}{xml}"))?;
    Ok(scene)
}

pub fn run(args: &SceneArgs) -> Result<(), Box<dyn std::error::Error>> {
    match &args.command {
        SceneCommand::Export(export_args) => {
            let scene = export(export_args)?;
            println!("{}", scene.display());
            Ok(())
        }
    }
}
