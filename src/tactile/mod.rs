//! The covering sensor (Sec. V-A2): an orthographic depth camera looking through a
//! soft covering of thickness t, blurred by a point-spread, averaged to taxels, with optional noise.
//! It is a MuJoCo sensor plugin (`taction.covering`), so any MuJoCo user reads it from `sensordata`.
//!
//! ```text
//! config      SensorConfig: the <config> keys, their ranges, the PSF law
//! plugin      registration with MuJoCo and the C callbacks
//! covering    one instance's state: sensed geoms, BVHs, the per-reading pass
//! mesh_bvh    one obvhs BVH per mesh, queried with the pad's slab
//! shared_bvh  the BVHs of meshes already read, found by their mesh for the next instance
//! raster      parallel rays as an orthographic z-buffer, and the inside test
//! primitive   planes, spheres, capsules, ellipsoids, cylinders, boxes cut analytically
//! grid        where the (supersampled) rays pierce the pad
//! formation   penetration -> PSF -> taxels -> [0, 1] -> noise
//! press_back  the same penetration as a force on the object and the pad (a free object's scene)
//! sensor      the Rust handle (read an image from sensordata) and the MJCF helpers
//! free_floating  the scene of the pad on a mocap body, no arm (Sec. V-A3; `control::FreePad`)
//! image       TactileImage (and PadPose, from `pose`)
//! ```

pub(crate) mod back_contact;
pub(crate) mod config;
pub(crate) mod covering;
pub(crate) mod formation;
pub(crate) mod free_floating;
pub(crate) mod grid;
pub(crate) mod image;
pub(crate) mod mesh_bvh;
pub(crate) mod model_view;
pub(crate) mod plugin;
pub(crate) mod press_back;
pub(crate) mod primitive;
pub(crate) mod raster;
pub(crate) mod sensor;
pub(crate) mod shared_bvh;

// The sensor: its configuration, its image, and the handle that reads it from `sensordata`.
pub use config::{ConfigError, ConfigKey, SensorConfig, psf_sigma_for_thickness};
pub use image::{ImageError, TactileImage, write_contact_sheet};
pub use sensor::{
    CoveringSensor, SENSOR_NAME, TactileError, add_sensor, arm_with_sensor, extension_xml, sensor_xml,
};

// The pad on a mocap body, no arm (Sec. V-A3).
pub use free_floating::{free_floating_builder, free_pad_body_xml};

// The MuJoCo plugin: registration, and the taxel colours of the viewer.
pub use plugin::{PLUGIN_NAME, ensure_registered, register, taxel_rgba, taxel_tiles};

// The covering's force on what it touches, where the object is free to move.
pub use press_back::{
    BodyPress, CoveringModulus, CoveringModulusError, RELAXATION_S, column_pressure_pa, total_force_n,
};

// One instance's state and the model it reads.
pub use covering::{Covering, CoveringError, CoveringStats, query_region};
pub use model_view::{ModelView, PoseView};

/// The stages of one reading one by one, for code that runs or times them on their own (the
/// benchmarks): where the rays pierce the pad, the mesh BVH, the depth buffer, and the image
/// formation from penetration to taxels. [`CoveringSensor`] runs them all.
pub mod pipeline {
    pub use super::formation::ImageFormation;
    pub use super::grid::SampleGrid;
    pub use super::mesh_bvh::MeshBvh;
    pub use super::raster::{DepthBuffer, rasterise_triangle};
}
