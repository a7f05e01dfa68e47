//! What every touch of one collection run shares, whichever procedure makes the touches.

use serde::{Deserialize, Serialize};

use crate::control::{ControlConfig, ControlError};
use crate::rng::Rng;
use crate::sim::{ObjectMotion, PerturbationAct, PerturbationBounds, Scene, SimError};
use crate::tactile::SensorConfig;
use crate::valid::Valid;

/// The sensor that reads, the surface contact controllers that settle each touch (Sec. III-B),
/// and how far the object is moved after each reading: the same for the training sampler
/// (Sec. V-A3) and the exploration planner (Sec. III-A).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TouchSetup {
    pub sensor: SensorConfig,
    pub control: Valid<ControlConfig>,
    pub perturbation: PerturbationBounds,
}

impl TouchSetup {
    /// Moves the object in `scene` by a random draw within [`perturbation`](Self::perturbation)
    /// (nothing, drawing nothing, when it allows no motion): after every reading, so that the
    /// next one sees the object where it now lies (Sec. V-B4). Teleported, a free object is put
    /// there and then comes to rest under gravity ([`Scene::settle_object`]); pushed, it is
    /// pushed toward there ([`Scene::push_object`]). The same draws either way. Returns how the
    /// object moved; `None` when nothing was drawn.
    pub(crate) fn perturb(
        &self,
        scene: &mut Scene,
        rng: &mut Rng,
    ) -> Result<Option<ObjectMotion>, ControlError> {
        if self.perturbation.is_none() {
            return Ok(None);
        }
        let width = scene.object_width_m().ok_or(SimError::NoObject)?;
        let start = scene.object_pose().ok_or(SimError::NoObject)?;
        let p = self.perturbation.draw(width, rng);
        let motion = match self.perturbation.act() {
            PerturbationAct::Teleport => {
                scene.perturb_object(&p)?;
                scene.settle_object()?;
                scene.object_motion_from(&start)?
            }
            PerturbationAct::Push => scene.push_object(&p)?,
        };
        Ok(Some(motion))
    }
}
