//! The object's start on the table: the pose it was built in, or one drawn at random that the
//! explorer is not told ([`StartPose`], plain data in the `pose` leaf, where the dataset header
//! that records it can name it too).
//!
//! A recogniser trained and tested on objects that always start at the pose they were built in
//! can tell them apart by where they are rather than by what they feel like: "a model that uses
//! contact positions could learn the canonical pose instead of the object". A random start is the
//! demo's placement of its unknown object, made the library's so that `collect`, the experiments
//! and the step-by-step episode can start every object that way.

use std::f64::consts::TAU;

use glam::DVec3;
use rand::RngExt;

use crate::pose::{Pose, StartPose};
use crate::rng::Rng;
use crate::sim::SimError;
use crate::sim::perturb::{Perturbation, PerturbationBounds};
use crate::sim::scene::Scene;

impl Scene {
    /// Puts the object at `start` and returns its pose: nothing for [`StartPose::Canonical`] (the
    /// object stays where it was built, no draw taken from `rng`); for [`StartPose::Random`], a
    /// heading about the vertical through the object's bounding-box centre (uniform over the full
    /// turn for [`MaxHeading::ANY`](crate::pose::MaxHeading::ANY), else uniform within
    /// +-`max_heading`), then one perturbation of Sec. V-B4 ([`PerturbationBounds::PAPER`]: a tilt
    /// of up to 10 degrees about a random axis, a shift of up to 10% of the width), the object
    /// resting on the table after each (its lowest vertex at z = 0).
    ///
    /// The tilt keeps a raised letter face up. The object's centre moves by at most a tenth of its
    /// width sideways and, resting again after the tilt, by at most sin(10 deg) of its horizontal
    /// half-extent (plus 1 - cos(10 deg) of its half-height) up or down: under 2 cm for the
    /// 12 cm objects of the built-in sets, within the 3 cm margin by which the planner's workspace
    /// (`explore::PlannerConfig::fitted_to`) exceeds each object's bounding sphere, which the
    /// heading, a turn about the centre, does not leave.
    ///
    /// [`StartPose::Turned`] is the same draw at one fixed heading: its tilt and shift, nothing
    /// drawn for the heading.
    ///
    /// A free object then comes to rest under gravity ([`Scene::settle_object`]): it starts where
    /// it settled, which the pose returned is.
    pub fn place_at_start(&mut self, start: &StartPose, rng: &mut Rng) -> Result<Pose, SimError> {
        let put = self.put_at_start(start, rng)?;
        match self.settle_object()? {
            Some(_) => self.object_pose().ok_or(SimError::NoObject),
            None => Ok(put),
        }
    }

    /// [`place_at_start`](Self::place_at_start) but for the settling.
    fn put_at_start(&mut self, start: &StartPose, rng: &mut Rng) -> Result<Pose, SimError> {
        let angle_rad = match start {
            StartPose::Canonical => return self.object_pose().ok_or(SimError::NoObject),
            StartPose::Turned { heading } => heading.rad(),
            // The full turn is drawn as the demo always drew it, so that its runs stay as they were.
            StartPose::Random { max_heading } if max_heading.is_any() => rng.random_range(0.0..TAU),
            StartPose::Random { max_heading } => rng.random_range(-max_heading.rad()..=max_heading.rad()),
        };
        let width = self.object_width_m().ok_or(SimError::NoObject)?;
        self.turn_object(angle_rad)?;
        self.perturb_object(&PerturbationBounds::PAPER.draw(width, rng))
    }

    /// Turns the object by `angle_rad` about the vertical through its bounding-box centre.
    fn turn_object(&mut self, angle_rad: f64) -> Result<Pose, SimError> {
        self.perturb_object(&Perturbation {
            axis: DVec3::Z,
            angle_rad,
            translation_m: DVec3::ZERO,
        })
    }
}
