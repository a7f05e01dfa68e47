//! The surface contact control loop (Fig. 3a): Approach, then Press, then Press and Orient in turn
//! until both issue no command in a row (Orient issues none once the normals agree within its
//! threshold), or the iteration budget runs out.

use serde::{Deserialize, Serialize};

use crate::control::approach::{ApproachOutcome, approach};
use crate::control::carrier::{ControlError, PadCarrier, PadMotion};
use crate::control::config::ControlConfig;
use crate::control::orient::orient_command;
use crate::control::press::{PressOutcome, is_clipped, press, pressed_peak};
use crate::control::trace::{Command, Trace};
use crate::dataset::ContactStatus;
use crate::pose::PadPose;
use crate::sim::Collision;
use crate::tactile::TactileImage;
use crate::valid::Valid;

/// The result of one settling run.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactOutcome {
    pub status: ContactStatus,
    /// The last image read (the reading, when `status` is `Converged`), tagged with its pad pose.
    pub image: TactileImage,
    /// Where the pad ended.
    pub pose: PadPose,
    /// Press/Orient alternations run.
    pub iterations: u32,
    /// Every command issued, in order.
    pub trace: Trace,
    /// The collision, when `status` is `Collision`.
    pub collision: Option<Collision>,
}

/// Runs the controllers on `carrier` from its current pose, approaching along the pad normal
/// (Algorithm 1): Approach until contact, then Press and Orient in turn until neither issues a
/// command, contact is lost, a motion is blocked, or the iteration budget runs out.
///
/// ```
/// use glam::DVec3;
/// use taction::control::{ControlConfig, FreePad, settle};
/// use taction::dataset::ContactStatus;
/// use taction::mesh::TriMesh;
/// use taction::sim::ObjectSpec;
/// use taction::pose::PadPose;
/// use taction::tactile::SensorConfig;
/// use taction::valid::Valid;
///
/// let object = ObjectSpec::new("box", TriMesh::cuboid(DVec3::new(0.03, 0.03, 0.02)));
/// let mut pad = FreePad::new(object, &Valid::new(SensorConfig::paper())?)?;
/// pad.place(&PadPose::new(DVec3::new(0.0, 0.0, 0.025), -DVec3::Z, DVec3::Y).unwrap());
/// let control = Valid::new(ControlConfig::default())?;
/// let touch = settle(&mut pad, &control)?;
/// assert_eq!(touch.status, ContactStatus::Converged);
/// assert!((touch.image.mean() - control.target_mean_pressure).abs() <= control.pressure_tolerance);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn settle<C: PadCarrier + ?Sized>(
    carrier: &mut C,
    config: &Valid<ControlConfig>,
) -> Result<ContactOutcome, ControlError> {
    let config: &ControlConfig = config;
    let mut run = Settling {
        carrier,
        config,
        trace: Trace::default(),
    };
    let mut image = match run.approach()? {
        Step::On(image) => image,
        Step::Ended(outcome) => return Ok(*outcome),
    };
    for iteration in 1..=config.max_iterations as u32 {
        let pressed = match run.press(iteration, &mut image)? {
            Step::On(commanded) => commanded,
            Step::Ended(outcome) => return Ok(*outcome),
        };
        let oriented = match run.orient(iteration, &mut image)? {
            Step::On(commanded) => commanded,
            Step::Ended(outcome) => return Ok(*outcome),
        };
        if let Some(status) = settled(&image, pressed, oriented, config) {
            return run.finish(status, image, iteration, None);
        }
    }
    run.finish(
        ContactStatus::MaxIterations,
        image,
        config.max_iterations as u32,
        None,
    )
}

/// Where one step of the loop leaves a run: going on (with what the step gives), or ended (boxed:
/// an outcome is large, and a step goes on far more often than it ends).
enum Step<T> {
    On(T),
    Ended(Box<ContactOutcome>),
}

/// One run of the controllers: the carrier, the configuration and the commands issued so far.
struct Settling<'c, C: ?Sized> {
    carrier: &'c mut C,
    config: &'c ControlConfig,
    trace: Trace,
}

impl<C: PadCarrier + ?Sized> Settling<'_, C> {
    /// Approach (Fig. 3c): along the pad normal until a taxel feels contact; the image then.
    fn approach(&mut self) -> Result<Step<TactileImage>, ControlError> {
        Ok(match approach(self.carrier, self.config, &mut self.trace)? {
            ApproachOutcome::Contact(image) => Step::On(image),
            ApproachOutcome::NoContact => {
                let image = self.carrier.read()?;
                Step::Ended(Box::new(self.finish(ContactStatus::NoContact, image, 0, None)?))
            }
            ApproachOutcome::Blocked(motion) => Step::Ended(Box::new(self.blocked(&motion, 0)?)),
        })
    }

    /// Press (Fig. 3b): toward the target mean pressure; whether it commanded a motion, and the
    /// image it ended on in `image`.
    fn press(&mut self, iteration: u32, image: &mut TactileImage) -> Result<Step<bool>, ControlError> {
        Ok(match press(self.carrier, self.config, &mut self.trace)? {
            PressOutcome::Done {
                image: pressed,
                commanded,
            } => {
                *image = pressed;
                Step::On(commanded)
            }
            PressOutcome::Blocked(motion) => Step::Ended(Box::new(self.blocked(&motion, iteration)?)),
        })
    }

    /// Orient (Fig. 3d, Algorithm 1, line 11): turns the pad toward the surface normal fitted to
    /// `image`; whether it commanded a turn, and the image after it in `image`. A turn whose rigid
    /// back would meet a surface was backed off by the carrier, and Press closes the gap.
    fn orient(&mut self, iteration: u32, image: &mut TactileImage) -> Result<Step<bool>, ControlError> {
        let pose = self.carrier.pad_pose();
        let Some(command) = orient_command(image, &pose, self.carrier.sensor(), self.config) else {
            return Ok(Step::On(false));
        };
        let target = command.apply(&pose);
        self.trace.push(Command::Orient, target);
        match self.carrier.move_pad(&target)? {
            PadMotion::Moved | PadMotion::RigidContact => {}
            PadMotion::TurnOutOfReach => return Ok(Step::On(false)),
            motion => return Ok(Step::Ended(Box::new(self.blocked(&motion, iteration)?))),
        }
        *image = self.carrier.read()?;
        Ok(Step::On(true))
    }

    /// The end of a run whose motion was blocked: a collision, a rigid contact (the covering
    /// cannot be pressed further: saturated), or a pose out of reach.
    fn blocked(&mut self, motion: &PadMotion, iteration: u32) -> Result<ContactOutcome, ControlError> {
        let (status, collision) = match motion {
            PadMotion::Collided(c) => (ContactStatus::Collision, Some(c.clone())),
            PadMotion::RigidContact => (ContactStatus::Saturated, None),
            PadMotion::Unreachable | PadMotion::Moved | PadMotion::TurnOutOfReach => {
                (ContactStatus::Unreachable, None)
            }
        };
        let image = self.carrier.read()?;
        self.finish(status, image, iteration, collision)
    }

    /// The outcome: `image` tagged with where the pad ended, and the commands issued.
    fn finish(
        &mut self,
        status: ContactStatus,
        image: TactileImage,
        iterations: u32,
        collision: Option<Collision>,
    ) -> Result<ContactOutcome, ControlError> {
        let pose = self.carrier.pad_pose();
        Ok(ContactOutcome {
            status,
            image: image.with_pose(pose),
            pose,
            iterations,
            trace: std::mem::take(&mut self.trace),
            collision,
        })
    }
}

/// How a Press and Orient round ended the run, if it did: no contact when Orient lifted the pad
/// off a narrow feature, else, when neither issued a command, converged (saturated when a taxel
/// is clipped).
fn settled(
    image: &TactileImage,
    pressed: bool,
    oriented: bool,
    config: &ControlConfig,
) -> Option<ContactStatus> {
    if touches_nothing(image, config) {
        return Some(ContactStatus::NoContact);
    }
    if pressed || oriented {
        return None;
    }
    Some(if is_clipped(image, config) {
        ContactStatus::Saturated
    } else {
        ContactStatus::Converged
    })
}

/// Whether the pad has lost contact. Without noise: no taxel above the contact threshold. With noise
/// the test on single taxels (above `contact_threshold + a`, the most noise alone gives) misses a
/// small contact patch pressed to the target as often as not (at 100% noise a taxel at 0.3 exceeds
/// 0.55 a quarter of the time), so the noise-free estimate of the most pressed neighbourhood
/// ([`pressed_peak`]) is compared with the noise-free threshold. Should the estimate wrongly see
/// contact, Press simply pushes on toward the surface.
fn touches_nothing(image: &TactileImage, config: &ControlConfig) -> bool {
    if config.expected_noise_fraction > 0.0 {
        pressed_peak(image, config) <= config.contact_threshold
    } else {
        image.max() <= config.effective_contact_threshold()
    }
}

/// A controller outcome as one JSON-friendly record (for `taction touch`).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ContactReport {
    pub status: ContactStatus,
    pub iterations: u32,
    pub pad_center: [f64; 3],
    pub pad_normal: [f64; 3],
    pub mean_pressure: f64,
    pub image: Vec<Vec<f64>>,
}

impl From<&ContactOutcome> for ContactReport {
    fn from(o: &ContactOutcome) -> Self {
        Self {
            status: o.status,
            iterations: o.iterations,
            pad_center: o.pose.center_m.to_array(),
            pad_normal: o.pose.normal.to_array(),
            mean_pressure: o.image.mean(),
            image: o
                .image
                .values()
                .chunks(o.image.cols())
                .map(<[f64]>::to_vec)
                .collect(),
        }
    }
}
