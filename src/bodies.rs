//! The names of the MJCF world's bodies (`mjcf/arm.xml` and the object slot).
//!
//! Two modules speak of them: `sim`, which builds the world and looks bodies up by name, and
//! `dataset`, whose `touched_bodies` column records who touched whom (`sensor/object`,
//! `link4/world`) and must classify those names into the `cause` column's names (`pad_on_object`,
//! `arm_on_table`) when a dataset is read back, with no MuJoCo at hand. Both take the
//! names from here, so a renamed body cannot make old datasets misclassified in silence.

/// The body the arm is mounted on, fixed to the world.
pub const ARM_BASE: &str = "base";
/// The body carrying the pad (its rigid back and holder).
pub const PAD_BODY: &str = "sensor";
/// The arm's bodies, base to pad: what a collision's body names are checked against.
pub const ARM_BODIES: [&str; 5] = [ARM_BASE, "link2", "link3", "link4", PAD_BODY];
/// The object's body in the object slot.
pub const OBJECT_BODY: &str = "object";
