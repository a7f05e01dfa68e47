//! What a recognition experiment varies besides the descriptor: its factors, one CSV column each,
//! named in the paper's words, each cell one level (`0.5`, `perturbed`, `6x6`), never a pair.

use std::fmt;

use serde::ser::{SerializeMap, SerializeStruct};
use serde::{Serialize, Serializer};

/// A factor of the recognition experiments, named as its column.
///
/// | column | levels | experiments |
/// |---|---|---|
/// | `data` | the test readings: `validation` (the sampler's validation readings the model was chosen on) or `exploration` (the planner's, L = 0.5) (Fig. 9) | `validation` |
/// | `resolution` | taxels of the sensor on the 12 mm pad: `6x6`, `14x14`, `26x26` (Fig. 12) | `validation`, `resolution` |
/// | `local_probability` | L, the probability that the planner takes its local strategy (Sec. III-A), in [0, 1] | `strategy`, `active`, `end-to-end` |
/// | `object_motion` | `fixed`, or `perturbed` after every reading by up to 10 degrees and 10% of its width (Sec. V-B4) | `perturbation`, `active`, `end-to-end` |
/// | `thickness_fraction` | covering thickness as a fraction of the pad side (0.1 = 1.2 mm; Fig. 11) | `thickness` |
/// | `noise_fraction` | width of the uniform additive noise, fraction of the sensing range, in training and test (Sec. V-B7) | `noise` |
/// | `training_readings` | training readings per object at scale 1 (`--scale` scales them) | `training-size` |
/// | `training` | `paper` (sampler readings from every direction) or `reachable` (ours: three times as many, from the starts the arm can reach) | `end-to-end` |
/// | `strategy` | `blind` (the planner's random local or global moves) or `active` (its candidates scored by expected information gain) | `active`, `fusion` |
/// | `evidence` | what the recogniser weighs: `appearance` (the tactile images' bag of features), `contacts` (where each touch landed, against each object's surface at a pose it is not told) or `fused` (both) | `fusion`, `free-object` |
/// | `mount` | how the object is held: `mocap` (the paper's: where it is put, no touch moves it) or `free_d<kg/m3>_mu<friction>` (on a free joint, a solid of that density and sliding friction, pressed by the covering) | `free-object` |
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Factor {
    Data,
    Resolution,
    LocalProbability,
    ObjectMotion,
    ThicknessFraction,
    NoiseFraction,
    TrainingReadings,
    Training,
    Strategy,
    Evidence,
    Mount,
}

impl Factor {
    pub const ALL: [Factor; 11] = [
        Self::Data,
        Self::Resolution,
        Self::LocalProbability,
        Self::ObjectMotion,
        Self::ThicknessFraction,
        Self::NoiseFraction,
        Self::TrainingReadings,
        Self::Training,
        Self::Strategy,
        Self::Evidence,
        Self::Mount,
    ];

    /// The column's name.
    pub fn column(self) -> &'static str {
        match self {
            Self::Data => "data",
            Self::Resolution => "resolution",
            Self::LocalProbability => "local_probability",
            Self::ObjectMotion => "object_motion",
            Self::ThicknessFraction => "thickness_fraction",
            Self::NoiseFraction => "noise_fraction",
            Self::TrainingReadings => "training_readings",
            Self::Training => "training",
            Self::Strategy => "strategy",
            Self::Evidence => "evidence",
            Self::Mount => "mount",
        }
    }

    /// The factor whose column is `name`.
    pub fn from_column(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|f| f.column() == name)
    }
}

impl fmt::Display for Factor {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.column())
    }
}

impl Serialize for Factor {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(self.column())
    }
}

/// Why a list of levels cannot be an experiment's factor columns.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum FactorError {
    #[error("factor '{0}' is given twice: one column per factor")]
    Repeated(Factor),
    #[error("factor '{factor}': level '{level}' is empty or holds a space: one level per cell")]
    BadLevel { factor: Factor, level: String },
    #[error(
        "column '{column}' stands between 'descriptor' and 'trial' but is no factor (factors: {})",
        Factor::ALL.map(Factor::column).join(", ")
    )]
    Unknown { column: String },
}

/// One curve's levels of its experiment's factors, in column order. Every curve of an experiment
/// has the same factors in the same order (its rows share one header); an experiment that varies
/// only the descriptor has none.
#[derive(Debug, Clone, PartialEq, Eq, Hash, Default)]
pub struct Factors(Vec<(Factor, String)>);

impl Factors {
    /// No factor: the experiment varies only the descriptor.
    pub fn none() -> Self {
        Self(Vec::new())
    }

    /// `levels` in column order; see [`Factors::check`] for what makes them valid.
    pub fn new<L: Into<String>>(levels: impl IntoIterator<Item = (Factor, L)>) -> Self {
        Self(levels.into_iter().map(|(f, l)| (f, l.into())).collect())
    }

    /// Each factor once, each level a non-empty word without spaces. Writing a row checks it, so a
    /// bad level fails the unit that made it rather than writing a packed cell.
    pub fn check(&self) -> Result<(), FactorError> {
        for (i, (factor, level)) in self.0.iter().enumerate() {
            if self.0[..i].iter().any(|(f, _)| f == factor) {
                return Err(FactorError::Repeated(*factor));
            }
            if level.is_empty() || level.chars().any(char::is_whitespace) {
                return Err(FactorError::BadLevel {
                    factor: *factor,
                    level: level.clone(),
                });
            }
        }
        Ok(())
    }

    pub fn iter(&self) -> impl Iterator<Item = (Factor, &str)> {
        self.0.iter().map(|(f, l)| (*f, l.as_str()))
    }

    pub fn factors(&self) -> impl Iterator<Item = Factor> + '_ {
        self.0.iter().map(|(f, _)| *f)
    }

    pub fn len(&self) -> usize {
        self.0.len()
    }

    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// The level of `factor`, if the curve has that factor.
    pub fn level(&self, factor: Factor) -> Option<&str> {
        self.iter().find(|(f, _)| *f == factor).map(|(_, l)| l)
    }

    /// The columns of a row: `factor` = level, in order (after `descriptor`, before `trial`).
    pub(crate) fn serialize_columns<S: SerializeStruct>(&self, row: &mut S) -> Result<(), S::Error> {
        self.check().map_err(serde::ser::Error::custom)?;
        for (factor, level) in self.iter() {
            row.serialize_field(factor.column(), level)?;
        }
        Ok(())
    }
}

/// `a = x, b = y`; empty when there is no factor.
impl fmt::Display for Factors {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, (factor, level)) in self.iter().enumerate() {
            if i > 0 {
                f.write_str(", ")?;
            }
            write!(f, "{factor} = {level}")?;
        }
        Ok(())
    }
}

/// A map `{column: level}` (what `config.json` records of each curve).
impl Serialize for Factors {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let mut map = serializer.serialize_map(Some(self.len()))?;
        for (factor, level) in self.iter() {
            map.serialize_entry(factor.column(), level)?;
        }
        map.end()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_factor_reads_back_from_its_column() {
        for factor in Factor::ALL {
            assert_eq!(Factor::from_column(factor.column()), Some(factor));
        }
        assert_eq!(Factor::from_column("value"), None);
    }

    #[test]
    fn packed_empty_and_repeated_levels_are_refused() {
        let ok = Factors::new([(Factor::Data, "validation"), (Factor::Resolution, "6x6")]);
        assert_eq!(ok.check(), Ok(()));
        assert_eq!(ok.to_string(), "data = validation, resolution = 6x6");
        assert_eq!(ok.level(Factor::Resolution), Some("6x6"));
        let packed = Factors::new([(Factor::Data, "validation 6x6")]);
        assert!(matches!(packed.check(), Err(FactorError::BadLevel { .. })));
        let empty = Factors::new([(Factor::Strategy, "")]);
        assert!(matches!(empty.check(), Err(FactorError::BadLevel { .. })));
        let twice = Factors::new([(Factor::Data, "a"), (Factor::Data, "b")]);
        assert_eq!(twice.check(), Err(FactorError::Repeated(Factor::Data)));
    }
}
