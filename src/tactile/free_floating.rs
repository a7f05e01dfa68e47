//! The free-floating sensor (Sec. V-A3): the same covering pad on a mocap body with no arm, for the
//! training sampler and `taction sense`. Placing it is writing the mocap pose; reading it is one
//! `mj_forward` (which runs the plugin at the sensor stage) and a copy out of `sensordata`.

use glam::{DMat3, DQuat};

use crate::sim::mjcf::{Section, numbers};
use crate::sim::{ObjectSpec, Scene, SceneBuilder, SimError};
use crate::tactile::config::SensorConfig;
use crate::tactile::image::{PadPose, TactileImage};
use crate::tactile::sensor::{CoveringSensor, TactileError, add_sensor};

/// The mocap body carrying the free-floating pad.
pub const FREE_PAD_BODY: &str = "free_pad";
/// The pad site (the same name as the arm's, so controllers find either).
pub const FREE_PAD_SITE: &str = crate::sim::arm::PAD_SITE;
/// The sensor element's name.
pub const FREE_PAD_SENSOR: &str = "covering";

/// The world rotation of the pad site for a pad pose: site y = up, site z = normal, and site
/// x = up x normal (a rotation needs a right-handed frame), which is `-pose.right()`: the image's
/// columns run along `PadPose::right() = normal x up`, the viewer's right looking along the
/// normal from behind the pad.
pub fn pad_rotation(pose: &PadPose) -> DQuat {
    DQuat::from_mat3(&DMat3::from_cols(
        pose.up.cross(pose.normal),
        pose.up,
        pose.normal,
    ))
    .normalize()
}

/// The MJCF body of the free-floating pad: a mocap body whose frame is the pad frame, with the
/// pad site and a thin plate drawn behind the pad that takes part in no contact (`contype` and
/// `conaffinity` 0), so the object never collides with it; the covering itself is not a geom.
pub fn free_pad_body_xml(config: &SensorConfig) -> String {
    let plate = numbers([0.5 * config.pad_width_m, 0.5 * config.pad_height_m, 0.0005]);
    format!(
        "<body name=\"{FREE_PAD_BODY}\" mocap=\"true\" pos=\"0 0 0.5\">\n\
         <site name=\"{FREE_PAD_SITE}\" size=\"0.001\" rgba=\"0.9 0.8 0.2 1\"/>\n\
         <geom name=\"free_pad_plate\" type=\"box\" size=\"{plate}\" pos=\"0 0 -0.0005\" contype=\"0\" \
         conaffinity=\"0\" rgba=\"0.55 0.25 0.65 0.6\"/>\n\
         </body>"
    )
}

/// The scene builder of a free-floating sensor looking at `object` (no arm, no table unless the
/// caller adds one), with the covering sensor registered and configured.
pub fn free_floating_builder(
    object: ObjectSpec,
    config: &SensorConfig,
) -> Result<SceneBuilder, TactileError> {
    let builder = SceneBuilder::new()
        .table(false)
        .object(object)
        .add(Section::Worldbody, free_pad_body_xml(config));
    Ok(add_sensor(builder, config, FREE_PAD_SENSOR, FREE_PAD_SITE)?)
}

/// A compiled free-floating sensor scene.
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
/// use taction::mesh::TriMesh;
/// use taction::sim::ObjectSpec;
/// use taction::tactile::{FreeFloatingSensor, PadPose, SensorConfig};
///
/// let config = SensorConfig::default();
/// let top_m = 0.02;
/// let object = ObjectSpec::new("box", TriMesh::cuboid(DVec3::new(0.03, 0.03, top_m)));
/// let mut sensor = FreeFloatingSensor::new(object, &config)?;
/// let pressed = PadPose {
///     center_m: DVec3::new(0.0, 0.0, top_m + 0.5 * config.thickness_m),
///     normal: -DVec3::Z,
///     up: DVec3::Y,
/// };
/// let image = sensor.read_at(&pressed)?;
/// assert_eq!((image.rows(), image.cols()), (6, 6));
/// assert!(image.values().iter().all(|v| (v - 0.5).abs() < 1e-6), "{:?}", image.values());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub struct FreeFloatingSensor {
    scene: Scene,
    sensor: CoveringSensor,
    mocap: usize,
}

impl FreeFloatingSensor {
    /// Compiles the scene of [`free_floating_builder`] (or any scene with a mocap body carrying a
    /// covering sensor's site).
    pub fn new(object: ObjectSpec, config: &SensorConfig) -> Result<Self, TactileError> {
        Self::from_scene(free_floating_builder(object, config)?.build()?)
    }

    /// Wraps a compiled scene whose covering sensor sits on a mocap body.
    pub fn from_scene(scene: Scene) -> Result<Self, TactileError> {
        let sensor = CoveringSensor::on_site(scene.model(), FREE_PAD_SITE)?;
        let body = scene.model().site_bodyid()[sensor.site_id()] as usize;
        let mocap = scene.model().body_mocapid()[body];
        if mocap < 0 {
            return Err(SimError::Mjcf {
                origin: "free-floating sensor".into(),
                message: format!("the body carrying site '{FREE_PAD_SITE}' is not a mocap body"),
            }
            .into());
        }
        Ok(Self {
            scene,
            sensor,
            mocap: mocap as usize,
        })
    }

    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    pub fn scene_mut(&mut self) -> &mut Scene {
        &mut self.scene
    }

    pub fn sensor(&self) -> &CoveringSensor {
        &self.sensor
    }

    /// Puts the pad at `pose` (teleports; nothing else moves). The site is the mocap body's frame.
    pub fn place(&mut self, pose: &PadPose) {
        let data = self.scene.data_mut();
        data.mocap_pos_mut()[self.mocap] = pose.center_m.to_array();
        let q = pad_rotation(pose);
        data.mocap_quat_mut()[self.mocap] = [q.w, q.x, q.y, q.z];
    }

    /// Runs `mj_forward` and returns the reading at the current pad pose.
    pub fn read(&mut self) -> Result<TactileImage, TactileError> {
        self.scene.forward();
        self.sensor.read(self.scene.data())
    }

    /// Places the pad and reads: one raw reading (what `taction sense` prints).
    pub fn read_at(&mut self, pose: &PadPose) -> Result<TactileImage, TactileError> {
        self.place(pose);
        self.read()
    }

    pub fn into_scene(self) -> Scene {
        self.scene
    }
}
