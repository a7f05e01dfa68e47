//! `taction touch`: one run of the surface contact controllers (Sec. III-B, Fig. 3a: Approach ->
//! Press <-> Orient) from a given pad pose, printed as one JSON object.
//!
//! The mesh and pad flags are those of `taction sense`: the pad starts at `--pad-center`, looking
//! along `--pad-normal`, and approaches along that normal. By default the pad is the free-floating
//! one of the training sampler (Sec. V-A3), teleported by pose commands. With `--arm` the same
//! controllers drive the arm of Sec. V-A1: the mesh is placed in the MuJoCo world with its origin at
//! the world origin, on the table top (z = 0), the arm is put at an inverse-kinematics solution for
//! the start pose, and every command goes through the IK and is executed by MuJoCo stepping.
//!
//! The output's `pad_center` is metres in the world, `pad_normal` a unit vector, `mean_pressure` and
//! the `image` values fractions of the sensing range (row 0 the pad's up edge, as in `sense`). With
//! `--arm` it adds `arm_joints` (the arm's joint names, chain order) and `arm_q_rad`, the joint
//! angles the touch ended at: the `qpos` of the scene `taction scene export --object` writes for the
//! same mesh (the object there is a mocap body, so the arm's joints are all of `qpos`), so the touch
//! replays in MuJoCo's own tools.

use clap::Args;
use serde::Serialize;
use taction::control::{
    ArmPad, ContactOutcome, ContactReport, ControlConfig, FreePad, sensor_reader, settle,
};
use taction::explore::precise_motion;
use taction::pose::PadPose;
use taction::sim::{ARM_JOINTS, PAD_SITE};
use taction::sim::{IkError, InverseKinematics, ObjectSpec, PadTarget};
use taction::tactile::{CoveringSensor, SensorConfig, arm_with_sensor};
use taction::valid::Valid;

use crate::cli::common::{ControlArg, ControlFileError, SeedArg};
use crate::cli::plausible::Carrier;
use crate::cli::sensor_args::{PadArgs, PadFrameError, SensorArgs, SensorFlagError};

#[derive(Debug, Args)]
pub struct TouchArgs {
    #[command(flatten)]
    pub pad: PadArgs,
    #[command(flatten)]
    pub sensor: SensorArgs,
    #[command(flatten)]
    pub seed: SeedArg,
    /// Drive the arm in the MuJoCo world (object on the table at its origin) instead of the
    /// free-floating pad. The arm's IK leaves the pad's rotation about its normal free, so
    /// `--pad-up` has no effect.
    #[arg(long)]
    pub arm: bool,
    /// Press target: the mean taxel value, a fraction of the sensing range in (0, 1)
    /// [default: the controller config's, 0.3].
    #[arg(long, allow_hyphen_values = true)]
    pub target_pressure: Option<f64>,
    #[command(flatten)]
    pub control: ControlArg,
}

/// What can go wrong; each names the flag or file at fault.
#[derive(Debug, thiserror::Error)]
pub enum TouchError {
    #[error(transparent)]
    Flag(#[from] SensorFlagError),
    #[error(transparent)]
    PadFrame(#[from] PadFrameError),
    #[error("--target-pressure: {0} is out of range: want a fraction of the range in (0, 1)")]
    TargetPressure(f64),
    #[error(transparent)]
    ControlFile(#[from] ControlFileError),
    #[error(
        "--pad-center / --pad-normal: the arm cannot reach the start pose ({0}); with --arm the object stands on the table at the world origin, the arm's base at x = -0.35 m"
    )]
    Unreachable(IkError),
    #[error(
        "--pad-center / --pad-normal: at the start pose the arm touches something ({a} with {b}); start further from the object"
    )]
    StartsInCollision { a: String, b: String },
    #[error(transparent)]
    Mesh(#[from] taction::mesh::MeshError),
    #[error(transparent)]
    Tactile(#[from] taction::tactile::TactileError),
    #[error(transparent)]
    Config(#[from] taction::tactile::ConfigError),
    #[error(transparent)]
    Sim(#[from] taction::sim::SimError),
    #[error(transparent)]
    Control(#[from] taction::control::ControlError),
    #[error("cannot write the JSON: {0}")]
    Json(#[from] serde_json::Error),
}

impl TouchArgs {
    /// The controller configuration the flags describe, validated. The controllers expect the
    /// sensor's own noise: their contact threshold and tolerances widen with it.
    pub fn control_config(&self, sensor: &SensorConfig) -> Result<Valid<ControlConfig>, TouchError> {
        let mut config = self.control.config(sensor.noise_fraction)?;
        if let Some(target) = self.target_pressure {
            if !(target > 0.0 && target < 1.0) {
                return Err(TouchError::TargetPressure(target));
            }
            config.target_mean_pressure = target;
        }
        Valid::new(config).map_err(|e| match (e.field, self.target_pressure) {
            ("target_mean_pressure", Some(t)) => TouchError::TargetPressure(t),
            _ => self.control.error(e).into(),
        })
    }
}

/// The controllers on the free-floating pad, from `start`.
fn touch_free(
    object: ObjectSpec,
    sensor: &Valid<SensorConfig>,
    control: &Valid<ControlConfig>,
    start: &PadPose,
) -> Result<ContactOutcome, TouchError> {
    let mut pad = FreePad::new(object, sensor)?;
    pad.place(start);
    Ok(settle(&mut pad, control)?)
}

/// A touch of the arm: the controllers' outcome and the state they left the world in.
pub struct ArmTouch {
    pub outcome: ContactOutcome,
    /// The arm's joint angles at the end, radians, in [`ARM_JOINTS`] order.
    pub q_rad: Vec<f64>,
    /// The whole `qpos` at the end (the arm's joints, then a free object's pose if it had one).
    pub qpos: Vec<f64>,
}

/// The controllers on the arm, the object placed as `object` says (mocap at the world origin for a
/// mesh given in world metres), from the arm configuration that puts the pad at `start`.
pub fn touch_arm(
    object: ObjectSpec,
    sensor: &Valid<SensorConfig>,
    control: &Valid<ControlConfig>,
    start: &PadPose,
) -> Result<ArmTouch, TouchError> {
    let mut scene = arm_with_sensor(object, sensor).build()?;
    let arm = scene.arm().cloned().ok_or(taction::sim::SimError::NoArm)?;
    let reader = sensor_reader(CoveringSensor::on_site(scene.model(), PAD_SITE)?);
    let (ik_options, motion) = precise_motion();
    let mut ik = InverseKinematics::for_scene(&scene, ik_options)?;
    let home = arm.q(scene.data());
    let q = ik
        .solve(
            &PadTarget {
                center_m: start.center_m,
                normal: start.normal,
            },
            &home,
        )
        .map_err(TouchError::Unreachable)?;
    arm.teleport(&mut scene, &q);
    if let Some(c) = arm.collision(&scene) {
        return Err(TouchError::StartsInCollision {
            a: c.body_a,
            b: c.body_b,
        });
    }
    let mut pad = ArmPad::new(&mut scene, &mut ik, **sensor, reader, motion)?;
    let outcome = settle(&mut pad, control)?;
    Ok(ArmTouch {
        outcome,
        q_rad: arm.q(scene.data()),
        qpos: scene.data().qpos().to_vec(),
    })
}

/// What `touch` prints: the controllers' outcome and, with `--arm`, where the arm ended.
#[derive(Serialize)]
struct TouchReport {
    #[serde(flatten)]
    contact: ContactReport,
    #[serde(skip_serializing_if = "Option::is_none")]
    arm_joints: Option<[&'static str; ARM_JOINTS.len()]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    arm_q_rad: Option<Vec<f64>>,
}

/// Runs the controllers once and prints the outcome as one JSON object.
pub fn run(args: &TouchArgs) -> Result<(), Box<dyn std::error::Error>> {
    let sensor = args.sensor.config(args.seed.seed).map_err(TouchError::from)?;
    let start = args.pad.pad_pose().map_err(TouchError::from)?;
    let control = args.control_config(&sensor)?;
    if args.arm && args.pad.pad_up.is_some() {
        eprintln!(
            "taction touch: note: --pad-up has no effect with --arm (the IK leaves the pad's roll free)"
        );
    }
    let carrier = if args.arm { Carrier::Arm } else { Carrier::FreePad };
    let object = args.pad.load_object("touch", carrier)?;
    let report = if args.arm {
        let touch = touch_arm(object, &sensor, &control, &start)?;
        TouchReport {
            contact: ContactReport::from(&touch.outcome),
            arm_joints: Some(ARM_JOINTS),
            arm_q_rad: Some(touch.q_rad),
        }
    } else {
        TouchReport {
            contact: ContactReport::from(&touch_free(object, &sensor, &control, &start)?),
            arm_joints: None,
            arm_q_rad: None,
        }
    };
    let json = serde_json::to_string(&report).map_err(TouchError::from)?;
    println!("{json}");
    Ok(())
}
