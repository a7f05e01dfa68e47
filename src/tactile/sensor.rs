//! The Rust side of a `taction.covering` sensor in a compiled model: find it, read its image from
//! `sensordata` together with the pad pose, and write the MJCF that inserts it into a scene.

use mujoco_rs::mujoco_c::mjtObj;
use mujoco_rs::prelude::*;
use mujoco_rs::wrappers::mj_model::traits::ModelType;

use crate::pose::PadPose;
use crate::sim::arm::PAD_SITE;
use crate::sim::mjcf::{Section, escape_attr};
use crate::sim::{ObjectMount, ObjectSpec, SceneBuilder};
use crate::tactile::config::{ConfigError, ConfigKey, SensorConfig};
use crate::tactile::covering::CoveringStats;
use crate::tactile::image::{ImageError, TactileImage};
use crate::tactile::model_view::ModelView;
use crate::tactile::plugin::{
    MODULUS_CONFIG_KEY, PLUGIN_NAME, ensure_registered, instance_config, instance_sensors, instance_state,
    is_covering_instance,
};
use crate::tactile::press_back::{BodyPress, CoveringModulus};
use crate::valid::Valid;

/// Errors of the tactile module; each names the sensor, site or key concerned.
#[derive(Debug, thiserror::Error)]
pub enum TactileError {
    #[error(transparent)]
    Config(#[from] ConfigError),
    #[error("no taction.covering sensor is attached to site '{site}'")]
    NoSensorOnSite { site: String },
    #[error("the model has no taction.covering sensor")]
    NoSensor,
    #[error("sensor '{sensor}': {source}")]
    Image { sensor: String, source: ImageError },
    #[error("sensor '{sensor}': the pad frame of site '{site}' is degenerate (mj_forward not run?)")]
    BadPadFrame { sensor: String, site: String },
    #[error(transparent)]
    Sim(#[from] crate::sim::SimError),
}

/// One covering sensor of a compiled model.
#[derive(Debug, Clone, PartialEq)]
pub struct CoveringSensor {
    name: String,
    sensor: usize,
    instance: usize,
    site: usize,
    site_name: String,
    adr: usize,
    config: Valid<SensorConfig>,
}

impl CoveringSensor {
    /// Every covering sensor of `model`, in sensor order.
    pub fn all(model: &MjModel) -> Result<Vec<Self>, TactileError> {
        let raw = model.ffi();
        // SAFETY: a compiled model has all its arrays.
        let view = unsafe { ModelView::new(raw) };
        let mut found = Vec::new();
        for instance in 0..raw.nplugin.max(0) as usize {
            if !is_covering_instance(raw, instance) {
                continue;
            }
            let config = instance_config(raw, instance)?;
            for sensor in instance_sensors(&view, instance) {
                let site = view.sensor_objid[sensor].max(0) as usize;
                found.push(Self {
                    name: view.name(mjtObj::mjOBJ_SENSOR, sensor),
                    sensor,
                    instance,
                    site,
                    site_name: view.name(mjtObj::mjOBJ_SITE, site),
                    adr: view.sensor_adr[sensor] as usize,
                    config,
                });
            }
        }
        Ok(found)
    }

    /// The covering sensor attached to site `site`.
    pub fn on_site(model: &MjModel, site: &str) -> Result<Self, TactileError> {
        Self::all(model)?
            .into_iter()
            .find(|s| s.site_name == site)
            .ok_or_else(|| TactileError::NoSensorOnSite {
                site: site.to_string(),
            })
    }

    /// The model's only (or first) covering sensor.
    pub fn first(model: &MjModel) -> Result<Self, TactileError> {
        Self::all(model)?.into_iter().next().ok_or(TactileError::NoSensor)
    }

    pub fn name(&self) -> &str {
        &self.name
    }

    /// The sensor's configuration, as the plugin parsed (and checked) it from the model.
    pub fn config(&self) -> &Valid<SensorConfig> {
        &self.config
    }

    /// The sensor's index among the model's sensors.
    pub fn sensor_id(&self) -> usize {
        self.sensor
    }

    /// The pad site's index.
    pub fn site_id(&self) -> usize {
        self.site
    }

    /// The pad frame of the site, from `site_xpos` / `site_xmat` (valid after kinematics).
    pub fn pad_pose<M: ModelType>(&self, data: &MjData<M>) -> Result<PadPose, TactileError> {
        PadPose::of_site_xmat(data.site_xpos()[self.site], &data.site_xmat()[self.site]).ok_or_else(|| {
            TactileError::BadPadFrame {
                sensor: self.name.clone(),
                site: self.site_name.clone(),
            }
        })
    }

    /// The image in `sensordata` (as of the last `mj_forward`/`mj_step`), tagged with the pad pose.
    pub fn read<M: ModelType>(&self, data: &MjData<M>) -> Result<TactileImage, TactileError> {
        let n = self.config.taxel_count();
        let values = data.sensordata()[self.adr..self.adr + n].to_vec();
        let image = TactileImage::new(self.config.rows, self.config.cols, values).map_err(|source| {
            TactileError::Image {
                sensor: self.name.clone(),
                source,
            }
        })?;
        Ok(image.with_pose(self.pad_pose(data)?))
    }

    /// Whether the object reached the pad's rigid back at the last computed reading: some sample
    /// of the covering fully compressed ([`CoveringStats::last_full_samples`]), or a mesh triangle
    /// at the back between the samples ([`CoveringStats::last_back_touched`]). The arm's guard
    /// against pressing its rigid back into the object: exact on the object's triangles, where
    /// MuJoCo's contacts would see its convex pieces.
    pub fn back_reached<M: ModelType>(&self, model: &MjModel, data: &MjData<M>) -> bool {
        self.stats(model, data)
            .is_some_and(|s| s.last_full_samples > 0 || s.last_back_touched)
    }

    /// What the covering pushed in `data`'s last passive stage (`press_back.rs`): per body it
    /// touched, the force on it and the moment about the pad's origin; empty when the covering
    /// has no modulus. `None` when this copy of the plugin's code does not own the instance.
    pub fn last_press<M: ModelType>(&self, model: &MjModel, data: &MjData<M>) -> Option<Vec<BodyPress>> {
        // SAFETY: `data` was made by MuJoCo for `model` (mujoco-rs ties them together).
        unsafe { instance_state(model.ffi(), data.ffi(), self.instance).map(|c| c.last_press().to_vec()) }
    }

    /// The instance's counters (BVHs built, readings computed) in `data`.
    pub fn stats<M: ModelType>(&self, model: &MjModel, data: &MjData<M>) -> Option<CoveringStats> {
        // SAFETY: `data` was made by MuJoCo for `model` (mujoco-rs ties them together).
        unsafe { instance_state(model.ffi(), data.ffi(), self.instance).map(|c| c.stats()) }
    }
}

/// The `<extension>` content that declares the plugin (once per model).
pub fn extension_xml() -> String {
    format!("<plugin plugin=\"{PLUGIN_NAME}\"/>")
}

/// The `<sensor>` content of a covering sensor named `name` on site `site` with every config key,
/// and the covering's `modulus` when it pushes back (`press_back.rs`; none writes no key, so the
/// paper's scenes are unchanged).
pub fn sensor_xml(config: &Valid<SensorConfig>, name: &str, site: &str, modulus: CoveringModulus) -> String {
    let mut xml = format!(
        "<plugin name=\"{}\" plugin=\"{PLUGIN_NAME}\" objtype=\"site\" objname=\"{}\">\n",
        escape_attr(name),
        escape_attr(site)
    );
    for key in ConfigKey::ALL {
        xml.push_str(&format!(
            "  <config key=\"{key}\" value=\"{}\"/>\n",
            config.value_text(key)
        ));
    }
    if !modulus.is_none() {
        xml.push_str(&format!(
            "  <config key=\"{MODULUS_CONFIG_KEY}\" value=\"{modulus}\"/>\n"
        ));
    }
    xml.push_str("</plugin>");
    xml
}

/// The name of the covering sensor's element in every scene the library builds, the arm's and the
/// free pad's: users read it as `m.sensor("tactile")` (the README, `examples/python`).
pub const SENSOR_NAME: &str = "tactile";

/// Adds the plugin declaration and the covering sensor ([`SENSOR_NAME`]) on site `site` to a
/// scene, and registers the plugin so the scene compiles. Where the scene's object is free
/// ([`ObjectMount::Free`]) the covering pushes it back, a [`CoveringModulus::SOFT_GEL`]: a free
/// object would otherwise feel no press at all, the pad's rigid back not touching it.
pub fn add_sensor(builder: SceneBuilder, config: &Valid<SensorConfig>, site: &str) -> SceneBuilder {
    let modulus = match builder.object_mount() {
        Some(ObjectMount::Free) => CoveringModulus::SOFT_GEL,
        Some(ObjectMount::Mocap) | None => CoveringModulus::NONE,
    };
    ensure_registered();
    builder
        .add(Section::Extension, extension_xml())
        .add(Section::Sensor, sensor_xml(config, SENSOR_NAME, site, modulus))
}

/// The arm on its table with `object` and the covering sensor on the pad site: the world of every
/// arm touch (collection, `touch`, `scene export`, the demo, Python's `scene`).
pub fn arm_with_sensor(object: ObjectSpec, config: &Valid<SensorConfig>) -> SceneBuilder {
    add_sensor(
        SceneBuilder::with_arm_and_table().object(object),
        config,
        PAD_SITE,
    )
}
