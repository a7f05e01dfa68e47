//! The scene of the free-floating sensor (Sec. V-A3): the same covering pad on a mocap body with no
//! arm, for the training sampler, `taction sense` and `taction touch`. The pad itself, placed and
//! read, is `control::FreePad`.

use crate::sim::mjcf::{Section, numbers};
use crate::sim::{ObjectSpec, SceneBuilder};
use crate::tactile::config::SensorConfig;
use crate::tactile::sensor::add_sensor;
use crate::valid::Valid;

/// The mocap body carrying the free-floating pad.
pub const FREE_PAD_BODY: &str = "free_pad";
/// The pad site (the same name as the arm's, so controllers find either).
pub const FREE_PAD_SITE: &str = crate::sim::arm::PAD_SITE;

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
/// caller adds one), with the covering sensor registered and configured. Nothing in it collides
/// with the object, so the object has no collision shell.
pub fn free_floating_builder(object: ObjectSpec, config: &Valid<SensorConfig>) -> SceneBuilder {
    let builder = SceneBuilder::new()
        .table(false)
        .object(object)
        .without_collision_shell()
        .add(Section::Worldbody, free_pad_body_xml(config));
    add_sensor(builder, config, FREE_PAD_SITE)
}
