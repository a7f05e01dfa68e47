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

/// What a free object is made of (`sim::ObjectMount::Free`, issue 74): its density and its
/// friction on the table and the arm. A dataset's header records it, so it lives here, beside
/// the names both `sim` and `dataset` use.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(try_from = "FreeBodyFields", into = "FreeBodyFields")]
pub struct FreeBody {
    density_kg_m3: f64,
    friction: f64,
}

/// [`FreeBody`]'s fields as a file holds them, checked on the way in.
#[derive(serde::Serialize, serde::Deserialize)]
struct FreeBodyFields {
    density_kg_m3: f64,
    friction: f64,
}

impl TryFrom<FreeBodyFields> for FreeBody {
    type Error = FreeBodyError;
    fn try_from(fields: FreeBodyFields) -> Result<Self, FreeBodyError> {
        Self::new(fields.density_kg_m3, fields.friction)
    }
}

impl From<FreeBody> for FreeBodyFields {
    fn from(body: FreeBody) -> Self {
        Self {
            density_kg_m3: body.density_kg_m3,
            friction: body.friction,
        }
    }
}

/// A density or friction out of range, named with its value and the range.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct FreeBodyError(String);

/// The densities a free object may have, kg/m3: foam to tungsten.
pub const DENSITY_RANGE_KG_M3: std::ops::RangeInclusive<f64> = 10.0..=20_000.0;
/// The sliding frictions a free object may have.
pub const FRICTION_RANGE: std::ops::RangeInclusive<f64> = 0.0..=2.0;

impl FreeBody {
    /// A solid of plastic or wood, 1000 kg/m3, on a table with friction 0.8 (the table's own,
    /// `mjcf/table.xml`): a 12 cm object of the shapes weighs 28-125 g, and Press's target press
    /// on the default covering (`tactile::CoveringModulus::SOFT_GEL`, 13 mN) is a sixteenth of
    /// the friction that holds the lightest.
    pub const DEFAULT: Self = Self {
        density_kg_m3: 1000.0,
        friction: 0.8,
    };

    /// A body of `density_kg_m3` (in [`DENSITY_RANGE_KG_M3`]) and sliding friction `friction`
    /// (in [`FRICTION_RANGE`]) on everything it touches.
    pub fn new(density_kg_m3: f64, friction: f64) -> Result<Self, FreeBodyError> {
        if !(density_kg_m3.is_finite() && DENSITY_RANGE_KG_M3.contains(&density_kg_m3)) {
            return Err(FreeBodyError(format!(
                "object density {density_kg_m3} kg/m3 is outside [10, 20000]"
            )));
        }
        if !(friction.is_finite() && FRICTION_RANGE.contains(&friction)) {
            return Err(FreeBodyError(format!(
                "object friction {friction} is outside [0, 2]"
            )));
        }
        Ok(Self {
            density_kg_m3,
            friction,
        })
    }

    pub fn density_kg_m3(&self) -> f64 {
        self.density_kg_m3
    }

    pub fn friction(&self) -> f64 {
        self.friction
    }
}

impl Default for FreeBody {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// A free object's material as an edge asks for it (`taction collect --free-object
/// --object-density --object-friction`, Python's `collect(free_object=, object_density=,
/// object_friction=)`) refused, naming the field as both edges spell it but for their dashes.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FreeBodyRequestError {
    #[error("{field}: only with free_object")]
    WithoutFreeObject { field: &'static str },
    #[error("{field} {value}: {error}")]
    OutOfRange {
        field: &'static str,
        value: f64,
        error: FreeBodyError,
    },
}

impl FreeBody {
    /// The material an edge asked for: `None` when `free_object` is not asked (a density or a
    /// friction given without it is refused: it would be ignored), else the given `density_kg_m3`
    /// and `friction`, or [`DEFAULT`](Self::DEFAULT)'s.
    pub fn requested(
        free_object: bool,
        density_kg_m3: Option<f64>,
        friction: Option<f64>,
    ) -> Result<Option<Self>, FreeBodyRequestError> {
        let given = [("object_density", density_kg_m3), ("object_friction", friction)];
        if !free_object {
            return match given.iter().find(|(_, value)| value.is_some()) {
                Some(&(field, _)) => Err(FreeBodyRequestError::WithoutFreeObject { field }),
                None => Ok(None),
            };
        }
        let density = density_kg_m3.unwrap_or(Self::DEFAULT.density_kg_m3);
        let friction = friction.unwrap_or(Self::DEFAULT.friction);
        Self::new(density, friction).map(Some).map_err(|error| {
            let (field, value) = match DENSITY_RANGE_KG_M3.contains(&density) {
                true => ("object_friction", friction),
                false => ("object_density", density),
            };
            FreeBodyRequestError::OutOfRange { field, value, error }
        })
    }
}
