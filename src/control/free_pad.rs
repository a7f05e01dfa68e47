//! The free-floating pad (Sec. V-A3): the covering pad on a mocap body with no arm, for the training
//! sampler, `taction sense` and `taction touch`. Placing it is writing the mocap pose (it
//! teleports; nothing else moves); reading it computes the position-stage sensors, where the
//! plugin runs ([`sensor_reader`]), and copies the image out of `sensordata`.
//!
//! As a [`PadCarrier`], nothing but Press's own terminations stops it (Sec. III-B: the mean
//! pressure reached, or a taxel close to saturation), as nothing else stops the arm's pad on the
//! object (`control::arm_pad`): started over the same patch from the same direction, both settle to
//! the same image (`tests/carrier_parity.rs`).

use crate::control::carrier::{ControlError, PadCarrier, PadMotion, ReadTactile, sensor_reader};
use crate::pose::{PadPose, Pose};
use crate::sim::arm::site_pose;
use crate::sim::{ObjectSpec, Scene, SimError};
use crate::tactile::free_floating::{FREE_PAD_SITE, free_floating_builder};
use crate::tactile::{CoveringSensor, SensorConfig, TactileError, TactileImage};
use crate::valid::Valid;

/// The free-floating pad: its own scene (the object and a mocap body carrying the covering
/// sensor's site), the sensor, and how it is read.
///
/// # Example
///
/// The pad (the paper's 6x6 taxels, 12 mm, 1.2 mm covering) pressed half the covering's
/// thickness into the flat top of a box: the penetration is t/2 under every taxel, so every taxel
/// reads 0.5, the penetration as a fraction of t (Sec. V-A2), to within MuJoCo's single-precision
/// mesh vertices (the box's top at 0.02 m is stored 4.5e-10 m lower: 4e-7 of t).
///
/// ```
/// use glam::DVec3;
/// use taction::control::FreePad;
/// use taction::mesh::TriMesh;
/// use taction::sim::ObjectSpec;
/// use taction::pose::PadPose;
/// use taction::tactile::SensorConfig;
/// use taction::valid::Valid;
///
/// let sensor = Valid::new(SensorConfig::paper())?;
/// let top_m = 0.02;
/// let object = ObjectSpec::new("box", TriMesh::cuboid(DVec3::new(0.03, 0.03, top_m)));
/// let mut pad = FreePad::new(object, &sensor)?;
/// let pressed = PadPose {
///     center_m: DVec3::new(0.0, 0.0, top_m + 0.5 * sensor.thickness_m),
///     normal: -DVec3::Z,
///     up: DVec3::Y,
/// };
/// let image = pad.read_at(&pressed)?;
/// assert_eq!((image.rows(), image.cols()), (6, 6));
/// assert!(image.values().iter().all(|v| (v - 0.5).abs() < 1e-6), "{:?}", image.values());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub struct FreePad {
    scene: Scene,
    sensor: CoveringSensor,
    mocap: usize,
    /// The site's pose in its body's frame.
    site_in_body: Pose,
    reader: Box<dyn ReadTactile + Send>,
}

impl FreePad {
    /// The free pad looking at `object` ([`free_floating_builder`]: no arm, no table).
    pub fn new(object: ObjectSpec, sensor: &Valid<SensorConfig>) -> Result<Self, ControlError> {
        Self::from_scene(free_floating_builder(object, sensor).build()?)
    }

    /// The free pad of a compiled scene whose covering sensor sits on site `pad` of a mocap body.
    pub fn from_scene(scene: Scene) -> Result<Self, ControlError> {
        let sensor = CoveringSensor::on_site(scene.model(), FREE_PAD_SITE)?;
        let model = scene.model();
        let site = sensor.site_id();
        let mocap = model.body_mocapid()[model.site_bodyid()[site] as usize];
        if mocap < 0 {
            return Err(TactileError::from(SimError::Mjcf {
                origin: "free-floating pad".into(),
                message: format!("the body carrying site '{FREE_PAD_SITE}' is not a mocap body"),
            })
            .into());
        }
        let site_in_body = Pose::from_mujoco(model.site_pos()[site], model.site_quat()[site]);
        let reader = Box::new(sensor_reader(sensor.clone()));
        Ok(Self {
            scene,
            sensor,
            mocap: mocap as usize,
            site_in_body,
            reader,
        })
    }

    /// The same pad read by `reader` instead of the covering sensor alone: a reader that wraps
    /// [`sensor_reader`] to count reads, or to corrupt the world before one (the tests of physics
    /// faults).
    pub fn with_reader(self, reader: impl ReadTactile + Send + 'static) -> Self {
        Self {
            reader: Box::new(reader),
            ..self
        }
    }

    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    pub fn scene_mut(&mut self) -> &mut Scene {
        &mut self.scene
    }

    /// The covering sensor the pad carries.
    pub fn covering(&self) -> &CoveringSensor {
        &self.sensor
    }

    /// Puts the pad site at `pose` (it teleports; nothing else moves): the mocap body goes where
    /// the site, at its offset in the body, lands at `pose`'s site pose ([`PadPose::site_pose`]).
    pub fn place(&mut self, pose: &PadPose) {
        let body = pose.site_pose().compose(&self.site_in_body.inverse());
        let data = self.scene.data_mut();
        data.mocap_pos_mut()[self.mocap] = body.position_m.to_array();
        data.mocap_quat_mut()[self.mocap] = body.mujoco_quat();
        data.kinematics();
    }

    /// The reading at the current pad pose, tagged with that pose.
    pub fn read(&mut self) -> Result<TactileImage, ControlError> {
        let pose = self.pad_pose();
        Ok((self.reader)(&mut self.scene)?.with_pose(pose))
    }

    /// Places the pad and reads: one raw reading (what `taction sense` prints).
    pub fn read_at(&mut self, pose: &PadPose) -> Result<TactileImage, ControlError> {
        self.place(pose);
        self.read()
    }
}

impl PadCarrier for FreePad {
    fn sensor(&self) -> &SensorConfig {
        self.sensor.config()
    }

    fn pad_pose(&self) -> PadPose {
        PadPose::of_site(&site_pose(self.scene.data(), self.sensor.site_id()))
    }

    fn read(&mut self) -> Result<TactileImage, ControlError> {
        FreePad::read(self)
    }

    fn move_pad(&mut self, target: &PadPose) -> Result<PadMotion, ControlError> {
        if !(target.center_m.is_finite() && target.normal.is_finite() && target.up.is_finite()) {
            return Ok(PadMotion::Unreachable);
        }
        self.place(target);
        Ok(PadMotion::Moved)
    }
}

#[cfg(test)]
mod tests {
    use glam::{DQuat, DVec3};

    use super::*;
    use crate::mesh::TriMesh;
    use crate::sim::SceneBuilder;
    use crate::sim::mjcf::Section;
    use crate::tactile::add_sensor;

    /// The free pad's body with the site at an offset (turned and shifted in the body).
    fn offset_pad(config: &Valid<SensorConfig>) -> FreePad {
        let body = format!(
            "<body name=\"free_pad\" mocap=\"true\" pos=\"0 0 0.5\">\n\
             <site name=\"{FREE_PAD_SITE}\" size=\"0.001\" pos=\"0.01 -0.02 0.03\" euler=\"0.3 -0.2 0.5\"/>\n\
             </body>"
        );
        let object = ObjectSpec::new("box", TriMesh::cuboid(DVec3::new(0.03, 0.03, 0.02)));
        let builder = SceneBuilder::new()
            .table(false)
            .object(object)
            .add(Section::Worldbody, body);
        let scene = add_sensor(builder, config, FREE_PAD_SITE).build().unwrap();
        FreePad::from_scene(scene).unwrap()
    }

    #[test]
    fn placing_the_pad_puts_the_sensor_site_exactly_there() {
        let config = Valid::default();
        let poses = [
            PadPose::new(DVec3::new(0.0, 0.0, 0.05), -DVec3::Z, DVec3::Y).unwrap(),
            PadPose::new(
                DVec3::new(0.02, -0.01, 0.04),
                DQuat::from_rotation_x(0.7) * -DVec3::Z,
                DVec3::new(0.3, 1.0, 0.1),
            )
            .unwrap(),
        ];
        let mut plain = FreePad::new(
            ObjectSpec::new("box", TriMesh::cuboid(DVec3::new(0.03, 0.03, 0.02))),
            &config,
        )
        .unwrap();
        let mut offset = offset_pad(&config);
        assert_ne!(offset.site_in_body, Pose::IDENTITY);
        for pad in [&mut plain, &mut offset] {
            for pose in &poses {
                pad.place(pose);
                let back = pad.pad_pose();
                assert!(
                    (back.center_m - pose.center_m).length() < 1e-12,
                    "{back:?} vs {pose:?}"
                );
                assert!(
                    (back.normal - pose.normal).length() < 1e-12,
                    "{back:?} vs {pose:?}"
                );
                assert!((back.up - pose.up).length() < 1e-12, "{back:?} vs {pose:?}");
                // The sensor's own reading of its site agrees, and tags the image with it.
                let image = pad.read().unwrap();
                let tagged = image.pose().unwrap();
                assert!((tagged.center_m - pose.center_m).length() < 1e-12);
                let seen = pad.covering().pad_pose(pad.scene().data()).unwrap();
                assert!((seen.normal - pose.normal).length() < 1e-12 && (seen.up - pose.up).length() < 1e-12);
            }
        }
        // The offset in the body changes nothing the pad reads.
        let pressed = PadPose::new(DVec3::new(0.0, 0.0, 0.0206), -DVec3::Z, DVec3::Y).unwrap();
        let (a, b) = (
            plain.read_at(&pressed).unwrap(),
            offset.read_at(&pressed).unwrap(),
        );
        for (x, y) in a.values().iter().zip(b.values()) {
            assert!((x - y).abs() < 1e-9, "{x} vs {y}");
        }
        assert!(a.mean() > 0.1);
    }
}
