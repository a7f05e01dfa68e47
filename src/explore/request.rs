//! How a user asks for readings (`taction collect --mode`, Python's `collect(mode=...)`): a mode
//! with the choices that belong to it ([`CollectRequest`]). Both edges parse their arguments into
//! [`ModeChoices`]; [`CollectRequest::of_mode`] refuses a choice of the other mode (it would be
//! ignored without a word, and the dataset would not be the one asked for), and
//! [`CollectRequest::collection`] is the one place a mode becomes a [`Collect`].

use std::fmt;

use crate::explore::collect::Collect;
use crate::explore::planner::PlannerConfig;
use crate::sim::ObjectSpec;
use crate::tactile::SensorConfig;

/// The two ways of collecting readings.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CollectModeName {
    /// The training sampler: area-weighted surface points, the free-floating pad (Sec. V-A3).
    Sampler,
    /// The arm exploring blind with the planner (Sec. III-A).
    Planner,
}

impl CollectModeName {
    /// Every mode's name, as the edges spell them.
    pub const NAMES: [&'static str; 2] = ["sampler", "planner"];

    /// The mode named `name` (`sampler` or `planner`).
    pub fn parse(name: &str) -> Option<Self> {
        match name {
            "sampler" => Some(Self::Sampler),
            "planner" => Some(Self::Planner),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Self::Sampler => "sampler",
            Self::Planner => "planner",
        }
    }
}

/// The choices of both modes as an edge parsed them: unset is `false` or `None`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ModeChoices {
    /// Sampler: approach only from above.
    pub from_above: bool,
    /// Sampler: only from starts the arm can take.
    pub reachable_by_arm: bool,
    /// Planner: the probability L of the local strategy (default 0.5).
    pub local_probability: Option<f64>,
    /// Planner: the iteration budget (default [`PlannerConfig::iterations_for`] the readings).
    pub max_iterations: Option<usize>,
}

/// A mode with its own choices.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CollectRequest {
    Sampler {
        from_above: bool,
        reachable_by_arm: bool,
    },
    Planner {
        local_probability: Option<f64>,
        max_iterations: Option<usize>,
    },
}

/// Choices given that belong to the other mode, named as [`ModeChoices`]' fields.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OtherModeChoices {
    pub mode: CollectModeName,
    pub choices: Vec<&'static str>,
}

impl fmt::Display for OtherModeChoices {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let what = if self.choices.len() == 1 {
            "a choice"
        } else {
            "choices"
        };
        write!(
            f,
            "{}: not {what} of mode {}",
            self.choices.join(", "),
            self.mode.name()
        )
    }
}

impl std::error::Error for OtherModeChoices {}

impl CollectRequest {
    /// `mode` with `choices`, refusing every choice given that belongs to the other mode.
    pub fn of_mode(mode: CollectModeName, choices: ModeChoices) -> Result<Self, OtherModeChoices> {
        let ModeChoices {
            from_above,
            reachable_by_arm,
            local_probability,
            max_iterations,
        } = choices;
        let others: Vec<&'static str> = match mode {
            CollectModeName::Sampler => [
                ("local_probability", local_probability.is_some()),
                ("max_iterations", max_iterations.is_some()),
            ],
            CollectModeName::Planner => [("from_above", from_above), ("reachable_by_arm", reachable_by_arm)],
        }
        .into_iter()
        .filter_map(|(name, given)| given.then_some(name))
        .collect();
        if !others.is_empty() {
            return Err(OtherModeChoices {
                mode,
                choices: others,
            });
        }
        Ok(match mode {
            CollectModeName::Sampler => Self::Sampler {
                from_above,
                reachable_by_arm,
            },
            CollectModeName::Planner => Self::Planner {
                local_probability,
                max_iterations,
            },
        })
    }

    /// The collection of `readings` converged readings per object of `objects` with `sensor`
    /// (the planner's workspace fitted to the objects); its parameters are checked by
    /// [`Collect::plan`].
    pub fn collection(
        self,
        sensor: SensorConfig,
        objects: &[ObjectSpec],
        readings: usize,
    ) -> Collect<'static> {
        match self {
            Self::Sampler {
                from_above,
                reachable_by_arm,
            } => {
                let collect = Collect::sampler(sensor);
                let collect = if from_above { collect.from_above() } else { collect };
                if reachable_by_arm {
                    collect.reachable_by_arm()
                } else {
                    collect
                }
            }
            Self::Planner {
                local_probability,
                max_iterations,
            } => Collect::planner(
                sensor,
                PlannerConfig::for_collection(
                    objects,
                    readings,
                    local_probability.unwrap_or(PlannerConfig::default().local_probability),
                    max_iterations,
                ),
            ),
        }
        .per_object(readings)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_choice_of_the_other_mode_is_refused_by_name_and_its_own_are_kept() {
        let planner_choices = ModeChoices {
            local_probability: Some(1.0),
            max_iterations: Some(500),
            ..ModeChoices::default()
        };
        let e = CollectRequest::of_mode(CollectModeName::Sampler, planner_choices).unwrap_err();
        assert_eq!(e.choices, ["local_probability", "max_iterations"]);
        assert_eq!(
            e.to_string(),
            "local_probability, max_iterations: not choices of mode sampler"
        );
        assert_eq!(
            CollectRequest::of_mode(CollectModeName::Planner, planner_choices),
            Ok(CollectRequest::Planner {
                local_probability: Some(1.0),
                max_iterations: Some(500)
            })
        );
        let from_above = ModeChoices {
            from_above: true,
            ..ModeChoices::default()
        };
        let e = CollectRequest::of_mode(CollectModeName::Planner, from_above).unwrap_err();
        assert_eq!(e.to_string(), "from_above: not a choice of mode planner");
        assert!(CollectRequest::of_mode(CollectModeName::Sampler, from_above).is_ok());
        assert_eq!(CollectModeName::parse("planner"), Some(CollectModeName::Planner));
        assert_eq!(CollectModeName::parse("arm"), None);
    }
}
