//! The free-floating pad as a [`PadCarrier`]: the pad site on a mocap body with no arm, moved by
//! writing the mocap pose (the training sampler of Sec. V-A3, and `taction touch`).
//!
//! Nothing but Press's own terminations stops it (Sec. III-B: the mean pressure reached, or a
//! taxel close to saturation), as nothing else stops the arm's pad on the object
//! (`control::arm_pad`): started over the same patch from the same direction, both settle to the
//! same image (`tests/carrier_parity.rs`).

use mujoco_rs::prelude::*;

use crate::control::arm_pad::pad_pose_of_site;
use crate::control::carrier::{ControlError, PadCarrier, PadMotion};
use crate::pose::Pose;
use crate::sim::arm::{PAD_SITE, site_pose};
use crate::sim::{Scene, SimError};
use crate::tactile::free_floating::pad_rotation;
use crate::tactile::{PadPose, SensorConfig, TactileImage};

/// A pad on a mocap body, read by `reader`.
pub struct FreePad<'s, R> {
    scene: &'s mut Scene,
    site: usize,
    mocap: usize,
    /// The site's pose in its body's frame.
    site_in_body: Pose,
    sensor: SensorConfig,
    reader: R,
}

impl<'s, R> FreePad<'s, R>
where
    R: FnMut(&mut Scene) -> Result<TactileImage, ControlError>,
{
    /// Finds the site `pad` and the mocap body carrying it.
    pub fn new(scene: &'s mut Scene, sensor: SensorConfig, reader: R) -> Result<Self, ControlError> {
        let missing = |message: &str| SimError::Mjcf {
            origin: "free-floating pad".into(),
            message: message.into(),
        };
        let model = scene.model();
        let site = model
            .name_to_id(MjtObjBase::mjOBJ_SITE, PAD_SITE)
            .ok_or_else(|| missing("no site 'pad'"))?;
        let body = model.site_bodyid()[site] as usize;
        let mocap = model.body_mocapid()[body];
        if mocap < 0 {
            return Err(missing("the body carrying site 'pad' is not a mocap body").into());
        }
        let site_in_body = Pose::from_mujoco(model.site_pos()[site], model.site_quat()[site]);
        Ok(Self {
            scene,
            site,
            mocap: mocap as usize,
            site_in_body,
            sensor,
            reader,
        })
    }

    pub fn scene(&mut self) -> &mut Scene {
        self.scene
    }

    /// Places the pad at `pose` (no motion in between: the free-floating pad teleports).
    pub fn place(&mut self, pose: &PadPose) {
        let site_world = Pose::new(pose.center_m, pad_rotation(pose));
        let body = site_world.compose(&self.site_in_body.inverse());
        let data = self.scene.data_mut();
        data.mocap_pos_mut()[self.mocap] = body.position_m.to_array();
        data.mocap_quat_mut()[self.mocap] = body.mujoco_quat();
        data.kinematics();
    }
}

impl<R> PadCarrier for FreePad<'_, R>
where
    R: FnMut(&mut Scene) -> Result<TactileImage, ControlError>,
{
    fn sensor(&self) -> &SensorConfig {
        &self.sensor
    }

    fn pad_pose(&self) -> PadPose {
        pad_pose_of_site(&site_pose(self.scene.data(), self.site))
    }

    fn read(&mut self) -> Result<TactileImage, ControlError> {
        let pose = self.pad_pose();
        Ok((self.reader)(self.scene)?.with_pose(pose))
    }

    fn move_pad(&mut self, target: &PadPose) -> Result<PadMotion, ControlError> {
        if !(target.center_m.is_finite() && target.normal.is_finite() && target.up.is_finite()) {
            return Ok(PadMotion::Unreachable);
        }
        self.place(target);
        Ok(PadMotion::Moved)
    }
}
