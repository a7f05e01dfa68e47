//! Object perturbation between readings (Sec. V-B4): "the object pose is perturbed by a small amount
//! (up to 10 degrees in orientation and 10% of the object width in translation) each time a sensor
//! reading is taken".
//!
//! A perturbation is a rotation by `angle <= R` about a uniformly random axis through the object's
//! bounding-box centre, then a horizontal translation of length `<= T * width` (uniform over the
//! disc), after which the object is lowered or raised to rest on the table again (its lowest vertex at
//! z = 0), so it never floats or sinks into the table. The applied perturbation is recorded.

use glam::{DQuat, DVec3};
use rand::RngExt;
use serde::{Deserialize, Serialize};

use crate::bodies::FreeBody;
use crate::pose::Pose;
use crate::rng::Rng;
use crate::sim::SimError;
use crate::sim::scene::Scene;
use crate::valid::RangeError;

/// How a perturbation moves the object.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PerturbationAct {
    /// The paper's (Sec. V-B4): the object is put at the drawn pose, resting on the table (a free
    /// object then settles under gravity).
    #[default]
    Teleport,
    /// Beyond the paper: a free object is pushed, and friction stops it about where the draw
    /// would have put it ([`Scene::push_object`](crate::sim::Scene::push_object)). A plan names it
    /// `steadied_push`, the hand that holds the object upright as it pushes, so that no dataset
    /// cached under the earlier hand's `push` (which let rounded objects rock and tip) is taken
    /// for this one's; a plan that says `push` still reads.
    #[serde(rename = "steadied_push", alias = "push")]
    Push,
}

impl PerturbationAct {
    pub const ALL: [PerturbationAct; 2] = [Self::Teleport, Self::Push];

    /// Every act's name, as the edges spell them, in [`ALL`](Self::ALL)'s order.
    pub const NAMES: [&'static str; 2] = ["teleport", "push"];

    /// The name `--perturb-by` and Python's `perturb_by` take.
    pub fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }

    /// Parses [`name`](Self::name).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|a| a.name() == name)
    }

    /// The paper's act, which plans and headers leave unsaid.
    pub fn is_teleport(&self) -> bool {
        *self == Self::Teleport
    }
}

/// Bounds of a perturbation, and its act; construct with [`PerturbationBounds::new`], which checks
/// them.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PerturbationBounds {
    max_rotation_rad: f64,
    max_translation_fraction: f64,
    /// Left out of the JSON when the paper's, so every plan made before pushes keeps its key.
    #[serde(default, skip_serializing_if = "PerturbationAct::is_teleport")]
    act: PerturbationAct,
}

impl PerturbationBounds {
    /// No perturbation.
    pub const NONE: Self = Self {
        max_rotation_rad: 0.0,
        max_translation_fraction: 0.0,
        act: PerturbationAct::Teleport,
    };

    /// The paper's bounds (Sec. V-B4): up to 10 degrees of rotation and 10% of the object's width
    /// of translation, what [`PerturbationBounds::new`]`(10.0, 0.1)` gives.
    pub const PAPER: Self = Self {
        max_rotation_rad: 10.0_f64.to_radians(),
        max_translation_fraction: 0.1,
        act: PerturbationAct::Teleport,
    };

    /// Rotation at most `max_rotation_deg` (0..=180) and translation at most
    /// `max_translation_fraction` (0..=1) of the object's bounding width.
    pub fn new(max_rotation_deg: f64, max_translation_fraction: f64) -> Result<Self, SimError> {
        if !(0.0..=180.0).contains(&max_rotation_deg) {
            return Err(SimError::BadConfiguration {
                message: format!("perturbation rotation {max_rotation_deg} deg is outside [0, 180]"),
            });
        }
        if !(0.0..=1.0).contains(&max_translation_fraction) {
            return Err(SimError::BadConfiguration {
                message: format!(
                    "perturbation translation {max_translation_fraction} is outside [0, 1] of the object width"
                ),
            });
        }
        Ok(Self {
            max_rotation_rad: max_rotation_deg.to_radians(),
            max_translation_fraction,
            act: PerturbationAct::Teleport,
        })
    }

    /// The same bounds, the object moved by `act`.
    pub fn by(self, act: PerturbationAct) -> Self {
        Self { act, ..self }
    }

    pub fn act(&self) -> PerturbationAct {
        self.act
    }

    /// Whether this perturbation can move an object held as `free_object` says (a mocap object
    /// when `None`); if not, the error of field `perturbation` of `config`: a push (beyond the
    /// paper) moves a free object that friction stops, and a mocap object has no dynamics while a
    /// frictionless one would slide on.
    pub fn check_act_on(
        &self,
        free_object: Option<FreeBody>,
        config: &'static str,
    ) -> Result<(), RangeError> {
        if self.act != PerturbationAct::Push || self.is_none() {
            return Ok(());
        }
        let allowed = match free_object {
            None => "teleport for a mocap object (a push needs a free object's dynamics)",
            Some(body) if body.friction() <= 0.0 => {
                "teleport for a frictionless object (nothing would stop a pushed one)"
            }
            Some(_) => return Ok(()),
        };
        Err(RangeError {
            config,
            field: "perturbation",
            value: self.act.name().into(),
            allowed,
        })
    }

    pub fn max_rotation_rad(&self) -> f64 {
        self.max_rotation_rad
    }

    pub fn max_translation_fraction(&self) -> f64 {
        self.max_translation_fraction
    }

    pub fn is_none(&self) -> bool {
        self.max_rotation_rad == 0.0 && self.max_translation_fraction == 0.0
    }

    /// Draws one perturbation for an object `width_m` wide.
    pub fn draw(&self, width_m: f64, rng: &mut Rng) -> Perturbation {
        let z: f64 = rng.random_range(-1.0..=1.0);
        let phi: f64 = rng.random_range(0.0..std::f64::consts::TAU);
        let s = (1.0 - z * z).max(0.0).sqrt();
        let axis = DVec3::new(s * phi.cos(), s * phi.sin(), z);
        let angle_rad = rng.random_range(0.0..=1.0) * self.max_rotation_rad;
        let radius = self.max_translation_fraction * width_m * rng.random_range(0.0..=1.0f64).sqrt();
        let theta: f64 = rng.random_range(0.0..std::f64::consts::TAU);
        Perturbation {
            axis,
            angle_rad,
            translation_m: DVec3::new(radius * theta.cos(), radius * theta.sin(), 0.0),
        }
    }
}

/// One applied perturbation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Perturbation {
    /// Unit rotation axis (world frame, through the object's bounding-box centre).
    pub axis: DVec3,
    pub angle_rad: f64,
    /// Horizontal translation, metres (before re-resting on the table).
    pub translation_m: DVec3,
}

impl Scene {
    /// Applies `p` to the object and rests it on the table; returns the new object pose.
    pub fn perturb_object(&mut self, p: &Perturbation) -> Result<Pose, SimError> {
        let pose = self.object_pose().ok_or(SimError::NoObject)?;
        let center = self.object_center().ok_or(SimError::NoObject)?;
        let rot = DQuat::from_axis_angle(p.axis, p.angle_rad);
        let rotated = Pose::new(
            rot * (pose.position_m - center) + center + p.translation_m,
            rot * pose.rotation,
        );
        let lowest = self.object_lowest_z(&rotated).ok_or(SimError::NoObject)?;
        let rested = Pose::new(rotated.position_m - DVec3::Z * lowest, rotated.rotation);
        self.set_object_pose(rested)?;
        Ok(rested)
    }

    /// Width of the object: the larger horizontal side of its bounding box at rest.
    pub fn object_width_m(&self) -> Option<f64> {
        let (lo, hi) = self.object()?.mesh.bounds()?;
        Some((hi.x - lo.x).max(hi.y - lo.y))
    }
}
