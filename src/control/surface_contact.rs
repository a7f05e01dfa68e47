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
use crate::sim::Collision;
use crate::tactile::{PadPose, TactileImage};
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

/// Runs the controllers on `carrier` from its current pose, approaching along the pad normal.
pub fn settle<C: PadCarrier + ?Sized>(
    carrier: &mut C,
    config: &Valid<ControlConfig>,
) -> Result<ContactOutcome, ControlError> {
    let config: &ControlConfig = config;
    let mut trace = Trace::default();
    let finish = |carrier: &mut C, status, image: TactileImage, iterations, trace, collision| {
        let pose = carrier.pad_pose();
        Ok(ContactOutcome {
            status,
            image: image.with_pose(pose),
            pose,
            iterations,
            trace,
            collision,
        })
    };
    let blocked_status = |motion: &PadMotion| match motion {
        PadMotion::Collided(c) => (ContactStatus::Collision, Some(c.clone())),
        PadMotion::RigidContact => (ContactStatus::Saturated, None),
        PadMotion::Unreachable | PadMotion::Moved => (ContactStatus::Unreachable, None),
    };

    let mut image = match approach(carrier, config, &mut trace)? {
        ApproachOutcome::Contact(image) => image,
        ApproachOutcome::NoContact => {
            let image = carrier.read()?;
            return finish(carrier, ContactStatus::NoContact, image, 0, trace, None);
        }
        ApproachOutcome::Blocked(motion) => {
            let (status, collision) = blocked_status(&motion);
            let image = carrier.read()?;
            return finish(carrier, status, image, 0, trace, collision);
        }
    };

    for iteration in 1..=config.max_iterations as u32 {
        let pressed = match press(carrier, config, &mut trace)? {
            PressOutcome::Done {
                image: pressed_image,
                commanded,
            } => {
                image = pressed_image;
                commanded
            }
            PressOutcome::Blocked(motion) => {
                let (status, collision) = blocked_status(&motion);
                let image = carrier.read()?;
                return finish(carrier, status, image, iteration, trace, collision);
            }
        };
        let pose = carrier.pad_pose();
        let oriented = match orient_command(&image, &pose, carrier.sensor(), config) {
            None => false,
            Some(command) => {
                let target = command.apply(&pose);
                trace.push(Command::Orient, target);
                match carrier.move_pad(&target)? {
                    PadMotion::Moved => {}
                    PadMotion::RigidContact => {}
                    motion => {
                        let (status, collision) = blocked_status(&motion);
                        let image = carrier.read()?;
                        return finish(carrier, status, image, iteration, trace, collision);
                    }
                }
                image = carrier.read()?;
                true
            }
        };
        if touches_nothing(&image, config) {
            // Orient lifted the pad off a narrow feature: nothing is touched any more.
            return finish(carrier, ContactStatus::NoContact, image, iteration, trace, None);
        }
        if !pressed && !oriented {
            let status = if is_clipped(&image, config) {
                ContactStatus::Saturated
            } else {
                ContactStatus::Converged
            };
            return finish(carrier, status, image, iteration, trace, None);
        }
    }
    finish(
        carrier,
        ContactStatus::MaxIterations,
        image,
        config.max_iterations as u32,
        trace,
        None,
    )
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
