//! Approach (Fig. 3c): a guarded move along the pad normal that ends as soon as any taxel rises
//! significantly above zero.

use crate::control::carrier::{ControlError, PadCarrier, PadMotion};
use crate::control::config::ControlConfig;
use crate::control::trace::{Command, Trace};
use crate::tactile::TactileImage;

/// How an Approach ended.
#[derive(Debug, Clone, PartialEq)]
pub enum ApproachOutcome {
    /// A taxel exceeded the contact threshold; the image at that pose.
    Contact(TactileImage),
    /// The whole approach distance was travelled without contact.
    NoContact,
    /// The carrier could not move on.
    Blocked(PadMotion),
}

/// Steps the pad along its normal in steps of `approach_step_thickness * t` until contact, at most
/// `approach_max_distance_m`.
pub fn approach<C: PadCarrier + ?Sized>(
    carrier: &mut C,
    config: &ControlConfig,
    trace: &mut Trace,
) -> Result<ApproachOutcome, ControlError> {
    let threshold = config.effective_contact_threshold();
    let image = carrier.read()?;
    if image.max() > threshold {
        return Ok(ApproachOutcome::Contact(image));
    }
    let step_m = config.approach_step_thickness * carrier.sensor().thickness_m;
    let mut travelled_m = 0.0;
    while travelled_m < config.approach_max_distance_m {
        let step_m = step_m.min(config.approach_max_distance_m - travelled_m);
        travelled_m += step_m;
        let mut pose = carrier.pad_pose();
        pose.center_m += pose.normal * step_m;
        trace.push(Command::Approach, pose);
        match carrier.move_pad(&pose)? {
            PadMotion::Moved => {}
            PadMotion::RigidContact => return Ok(ApproachOutcome::Contact(carrier.read()?)),
            blocked => return Ok(ApproachOutcome::Blocked(blocked)),
        }
        let image = carrier.read()?;
        if image.max() > threshold {
            return Ok(ApproachOutcome::Contact(image));
        }
    }
    Ok(ApproachOutcome::NoContact)
}
