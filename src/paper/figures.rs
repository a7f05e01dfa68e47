//! The recognition figures of Sec. V as [`RecognitionSweep`]s, with the paper's settings.
//!
//! Shared defaults (the paper's "Princeton set at 6x6 resolution and 10% covering thickness"):
//! 6x6 taxels on a 12 mm pad, covering 10% of the pad side (1.2 mm, see
//! [`crate::tactile::config::DEFAULT_THICKNESS_M`]), no noise; training and validation by the sampler; test readings by
//! the planner with L = 0.5, the middle of Fig. 8's range (the paper does not say which L its
//! other figures used). The top three descriptors are PF, MNTI and MN (Sec. V-B2); Figs. 11-13 add
//! Vectorize.
//!
//! Calibration: the figures on the default sensor that judge the arm's explorations (Figs. 7, 8
//! and 10) fit their posteriors' tempering and confidence map on the arm's own explorations
//! ([`CalibratedOn::ArmExplorations`]), as `end-to-end` and `active` do: the same six explorations
//! of each object, so `reproduce` collects them once for all five. Fitted on the sampler's
//! validation readings, those figures' posteriors were overconfident on the arm's touches (ECE
//! 0.1-0.5). Figs. 9 and 11-13 keep the validation calibration: Fig. 9 judges the validation data
//! itself, and the sensors of Figs. 11-13 would each need explorations of their own (about six
//! minutes more of `reproduce`). A calibration changes no guess, so no accuracy moves either way.

use super::context::Family;
use super::recognition::{CalibratedOn, Curve, RecognitionSweep, Setting, TestData};
use super::scale::PAPER_TRAINING_READINGS;
use crate::describe::DescriptorKind;
use crate::experiment::factor::{Factor, Factors};
use crate::explore::SamplerConfig;
use crate::sim::PerturbationBounds;
use crate::tactile::SensorConfig;
use crate::tactile::config::DEFAULT_PAD_M;

/// L of the test exploration in every figure but Fig. 8.
pub const DEFAULT_LOCAL_PROBABILITY: f64 = 0.5;

const TOP_THREE: [DescriptorKind; 3] = [
    DescriptorKind::PolarFourier,
    DescriptorKind::Mnti,
    DescriptorKind::MomentNormalized,
];

const TOP_THREE_AND_VECTORIZE: [DescriptorKind; 4] = [
    DescriptorKind::PolarFourier,
    DescriptorKind::Mnti,
    DescriptorKind::MomentNormalized,
    DescriptorKind::Vectorize,
];

/// The 6x6 sensor with 10% covering.
pub fn default_sensor() -> SensorConfig {
    sensor(6, 0.1, 0.0)
}

/// `taxels x taxels` on the 12 mm pad, covering `thickness_fraction` of the pad side, uniform
/// noise of `noise_fraction` of the range.
fn sensor(taxels: usize, thickness_fraction: f64, noise_fraction: f64) -> SensorConfig {
    SensorConfig {
        noise_fraction,
        ..SensorConfig::square(taxels, taxels, DEFAULT_PAD_M, thickness_fraction * DEFAULT_PAD_M)
    }
}

fn explored(local_probability: f64) -> TestData {
    TestData::Planner {
        local_probability,
        perturbation: PerturbationBounds::NONE,
    }
}

/// Fig. 7: all six descriptors at the default settings.
pub fn descriptors() -> RecognitionSweep {
    RecognitionSweep {
        name: "descriptors",
        description: "Fig. 7: the six descriptors on the 3D set, 6x6 taxels, 10% covering, planner test data",
        title: "Descriptors (6x6, 10% covering)",
        key_parameter: "",
        legend: None,
        family: Family::Shapes,
        descriptors: DescriptorKind::PAPER.to_vec(),
        settings: vec![Setting {
            calibrated_on: CalibratedOn::ArmExplorations,
            ..Setting::single(
                "6x6",
                Factors::none(),
                default_sensor(),
                SamplerConfig::default(),
                explored(DEFAULT_LOCAL_PROBABILITY),
            )
        }],
    }
}

/// Fig. 8: the exploration strategy, L in {0, 0.5, 1}; one model per descriptor.
pub fn strategy() -> RecognitionSweep {
    RecognitionSweep {
        name: "strategy",
        description: "Fig. 8: exploration with local-strategy probability L = 0, 0.5, 1 (top three descriptors)",
        title: "Exploration strategy (L = probability of the local strategy)",
        key_parameter: "local_probability",
        legend: None,
        family: Family::Shapes,
        descriptors: TOP_THREE.to_vec(),
        settings: vec![Setting {
            label: "0-0.5-1".into(),
            sensor: default_sensor(),
            sampler: SamplerConfig::default(),
            training_fraction: 1.0,
            calibrated_on: CalibratedOn::ArmExplorations,
            curves: [0.0, 0.5, 1.0]
                .into_iter()
                .map(|l| Curve {
                    factors: Factors::new([(Factor::LocalProbability, l.to_string())]),
                    test: explored(l),
                })
                .collect(),
        }],
    }
}

/// Fig. 9: validation (sampler) against exploration (planner) test data, MN and PF, at 6x6 and
/// 26x26.
pub fn validation() -> RecognitionSweep {
    let setting = |taxels: usize| {
        let size = format!("{taxels}x{taxels}");
        Setting {
            label: size.clone(),
            sensor: sensor(taxels, 0.1, 0.0),
            sampler: SamplerConfig::default(),
            training_fraction: 1.0,
            calibrated_on: CalibratedOn::Validation,
            curves: vec![
                Curve {
                    factors: Factors::new([
                        (Factor::Data, "validation"),
                        (Factor::Resolution, size.as_str()),
                    ]),
                    test: TestData::Validation,
                },
                Curve {
                    factors: Factors::new([
                        (Factor::Data, "exploration"),
                        (Factor::Resolution, size.as_str()),
                    ]),
                    test: explored(DEFAULT_LOCAL_PROBABILITY),
                },
            ],
        }
    };
    RecognitionSweep {
        name: "validation",
        description: "Fig. 9: sampler validation data against planner exploration data (MN, PF; 6x6 and 26x26)",
        title: "Validation (sampler) vs exploration (planner) test data",
        key_parameter: "data",
        legend: Some("data = {data} {resolution}"),
        family: Family::Shapes,
        descriptors: vec![DescriptorKind::MomentNormalized, DescriptorKind::PolarFourier],
        settings: vec![setting(6), setting(26)],
    }
}

/// Fig. 10: the object fixed, or perturbed after every reading by up to 10 degrees and 10% of its
/// width (Sec. V-B4).
pub fn perturbation() -> RecognitionSweep {
    let perturbed = PerturbationBounds::new(10.0, 0.1).unwrap_or(PerturbationBounds::NONE);
    RecognitionSweep {
        name: "perturbation",
        description: "Fig. 10: object fixed vs perturbed (<= 10 deg, <= 10% of its width) after every reading",
        title: "Fixed vs perturbed object",
        key_parameter: "object",
        legend: Some("object = {object_motion}"),
        family: Family::Shapes,
        descriptors: TOP_THREE.to_vec(),
        settings: vec![Setting {
            label: "fixed-perturbed".into(),
            sensor: default_sensor(),
            sampler: SamplerConfig::default(),
            training_fraction: 1.0,
            calibrated_on: CalibratedOn::ArmExplorations,
            curves: vec![
                Curve {
                    factors: Factors::new([(Factor::ObjectMotion, "fixed")]),
                    test: explored(DEFAULT_LOCAL_PROBABILITY),
                },
                Curve {
                    factors: Factors::new([(Factor::ObjectMotion, "perturbed")]),
                    test: TestData::Planner {
                        local_probability: DEFAULT_LOCAL_PROBABILITY,
                        perturbation: perturbed,
                    },
                },
            ],
        }],
    }
}

/// A sweep of Figs. 11-13: one setting per level of `factor`, the top three descriptors and
/// Vectorize.
fn sensor_sweep(
    name: &'static str,
    description: &'static str,
    title: &'static str,
    factor: Factor,
    levels: Vec<(String, SensorConfig)>,
) -> RecognitionSweep {
    RecognitionSweep {
        name,
        description,
        title,
        key_parameter: factor.column(),
        legend: None,
        family: Family::Shapes,
        descriptors: TOP_THREE_AND_VECTORIZE.to_vec(),
        settings: levels
            .into_iter()
            .map(|(level, sensor)| {
                Setting::single(
                    level.clone(),
                    Factors::new([(factor, level)]),
                    sensor,
                    SamplerConfig::default(),
                    explored(DEFAULT_LOCAL_PROBABILITY),
                )
            })
            .collect(),
    }
}

/// Fig. 11: covering thickness 5, 10, 20, 30% of the pad side (0.6 to 3.6 mm); the PSF widens with
/// it ([`crate::tactile::config::PSF_SIGMA_PER_THICKNESS`]).
pub fn thickness() -> RecognitionSweep {
    sensor_sweep(
        "thickness",
        "Fig. 11: covering thickness 5, 10, 20, 30% of the pad side (top three descriptors and Vectorize)",
        "Covering thickness (fraction of the pad side)",
        Factor::ThicknessFraction,
        [0.05, 0.1, 0.2, 0.3]
            .into_iter()
            .map(|t| (t.to_string(), sensor(6, t, 0.0)))
            .collect(),
    )
}

/// Fig. 12: 6x6 (the PPS sensor), 14x14 (a fingertip's Merkel receptors) and 26x26 (a Tekscan
/// sensor) on the same pad.
pub fn resolution() -> RecognitionSweep {
    sensor_sweep(
        "resolution",
        "Fig. 12: sensor resolution 6x6, 14x14, 26x26 on the 12 mm pad (top three descriptors and Vectorize)",
        "Sensor resolution (taxels per side)",
        Factor::Resolution,
        [6, 14, 26]
            .into_iter()
            .map(|n| (format!("{n}x{n}"), sensor(n, 0.1, 0.0)))
            .collect(),
    )
}

/// Fig. 13: uniform additive noise of 0, 10, 20, 40% of the sensing range, in training and test.
pub fn noise() -> RecognitionSweep {
    sensor_sweep(
        "noise",
        "Fig. 13: additive noise 0, 10, 20, 40% of the range in training and test (top three descriptors and Vectorize)",
        "Additive noise (fraction of the sensing range)",
        Factor::NoiseFraction,
        [0.0, 0.1, 0.2, 0.4]
            .into_iter()
            .map(|f| (f.to_string(), sensor(6, 0.1, f)))
            .collect(),
    )
}

/// Fig. 16a: the 52 raised letters, every reading by the sampler from above (Sec. V-D).
pub fn letters() -> RecognitionSweep {
    let from_above = SamplerConfig {
        from_above_only: true,
        ..SamplerConfig::default()
    };
    RecognitionSweep {
        name: "letters",
        description: "Fig. 16a: the 52 raised letters, sampler from above for training and test (PF, MNTI, MN)",
        title: "Raised letters (sampler from above)",
        key_parameter: "",
        legend: None,
        family: Family::Letters,
        descriptors: TOP_THREE.to_vec(),
        settings: vec![Setting::single(
            "6x6",
            Factors::none(),
            default_sensor(),
            from_above,
            TestData::Sampler,
        )],
    }
}

/// Training readings per object of "ours" in the end-to-end experiment, in multiples of the paper's
/// 1000 (scaled by `--scale` like every count).
pub const END_TO_END_TRAINING_FRACTION: f64 = 3.0;

/// Beyond the paper: the product's job, end to end. The arm explores each object blind (L = 0.5
/// and 1, the object fixed or perturbed after every reading, Sec. V-B3-4) and is recognised by a
/// model trained the paper's way (1000 sampler readings per object from every direction) or ours:
/// three times as many readings of the sampler restricted to the starts the arm can take from any
/// heading of the object (`SamplerConfig::reachable_by_arm`). Both carriers press alike
/// (`tests/carrier_parity.rs`). Both models' posteriors are calibrated on the arm's own
/// explorations ([`CalibratedOn::ArmExplorations`], as the `active` experiment's), so the two
/// settings differ in their training data alone and every curve's beliefs are judged as the product
/// forms them.
pub fn end_to_end() -> RecognitionSweep {
    let perturbed = PerturbationBounds::new(10.0, 0.1).unwrap_or(PerturbationBounds::NONE);
    let curves = |training: &str| {
        [
            (0.5, "fixed"),
            (1.0, "fixed"),
            (0.5, "perturbed"),
            (1.0, "perturbed"),
        ]
        .into_iter()
        .map(|(l, object)| Curve {
            factors: Factors::new([
                (Factor::Training, training.to_string()),
                (Factor::LocalProbability, l.to_string()),
                (Factor::ObjectMotion, object.to_string()),
            ]),
            test: TestData::Planner {
                local_probability: l,
                perturbation: if object == "perturbed" {
                    perturbed
                } else {
                    PerturbationBounds::NONE
                },
            },
        })
        .collect()
    };
    RecognitionSweep {
        name: "end-to-end",
        description: "Beyond the paper: blind arm exploration (L = 0.5, 1; fixed, perturbed) recognised by the paper's sampler training and by ours (3x readings, starts the arm can reach), posteriors calibrated on the arm's explorations",
        title: "End to end: the arm's own touches",
        key_parameter: "training",
        legend: Some("training = {training} L={local_probability} {object_motion}"),
        family: Family::Shapes,
        descriptors: vec![DescriptorKind::Mnti, DescriptorKind::PolarFourier],
        settings: vec![
            Setting {
                label: "paper".into(),
                sensor: default_sensor(),
                sampler: SamplerConfig::default(),
                training_fraction: 1.0,
                calibrated_on: CalibratedOn::ArmExplorations,
                curves: curves("paper"),
            },
            Setting {
                label: "reachable".into(),
                sensor: default_sensor(),
                sampler: SamplerConfig {
                    reachable_by_arm: true,
                    ..SamplerConfig::default()
                },
                training_fraction: END_TO_END_TRAINING_FRACTION,
                calibrated_on: CalibratedOn::ArmExplorations,
                curves: curves("reachable"),
            },
        ],
    }
}

/// Training readings per object in the training-size experiment, at scale 1 (`--scale` scales them).
pub const TRAINING_SIZES: [usize; 5] = [100, 300, 1000, 3000, 10_000];

/// Beyond the paper: what training data buys. The paper trains on 1000 sampler readings per object
/// throughout (Sec. V-B); here the same 3D set is trained on 100 to 10,000 and tested on sampler
/// readings, so the curves differ only in the model. Sampler readings are cheap next to the
/// arm's, which makes training data the cheapest lever; what it buys, and its cost, are measured in
/// `results/training-size/` and `docs/measurements.md` ("What training data buys").
pub fn training_size() -> RecognitionSweep {
    let paper = PAPER_TRAINING_READINGS as f64;
    RecognitionSweep {
        name: "training-size",
        description: "Beyond the paper: 100, 300, 1000, 3000, 10000 training readings per object (3D set, sampler test data; PF, MNTI, MN)",
        title: "Training readings per object (sampler test data)",
        key_parameter: "training_readings",
        legend: None,
        family: Family::Shapes,
        descriptors: TOP_THREE.to_vec(),
        settings: TRAINING_SIZES
            .iter()
            .map(|&n| Setting {
                training_fraction: n as f64 / paper,
                ..Setting::single(
                    n.to_string(),
                    Factors::new([(Factor::TrainingReadings, n.to_string())]),
                    default_sensor(),
                    SamplerConfig::default(),
                    TestData::Sampler,
                )
            })
            .collect(),
    }
}

/// Fig. 17: trained on simulated letters with 30% noise ("on the order of 30% of the observed
/// force range", Sec. V-F), tested on the recorded real frames after the square root and a small
/// Gaussian blur.
pub fn sim_to_real() -> RecognitionSweep {
    let from_above = SamplerConfig {
        from_above_only: true,
        ..SamplerConfig::default()
    };
    RecognitionSweep {
        name: "sim-to-real",
        description: "Fig. 17: trained on simulated letters (30% noise), tested on recorded real frames (trial 0 in recorded order)",
        title: "Trained on simulated letters, tested on",
        key_parameter: "",
        legend: None,
        family: Family::RealLabels,
        descriptors: TOP_THREE.to_vec(),
        settings: vec![Setting::single(
            "real",
            Factors::none(),
            sensor(6, 0.1, 0.3),
            from_above,
            TestData::Real,
        )],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dataset::recorded::{RealData, RealImport, parse_real_csv};
    use crate::paper::context::EXAMPLE_REAL_CSV;
    use crate::paper::scale::DataCounts;

    #[test]
    fn sim_to_real_on_the_synthetic_example_does_not_claim_a_real_sensor() {
        let example = parse_real_csv(EXAMPLE_REAL_CSV, "example", &RealImport::default()).unwrap();
        let title = sim_to_real().plot_title(Some(&example));
        assert_eq!(
            title,
            "Trained on simulated letters, tested on example frames (synthetic)"
        );
        let recorded = RealData {
            synthetic: false,
            ..example
        };
        assert!(
            sim_to_real()
                .plot_title(Some(&recorded))
                .ends_with("tested on real sensor frames")
        );
        assert_eq!(descriptors().plot_title(None), descriptors().title);
    }

    #[test]
    fn every_sweep_writes_one_valid_column_per_factor() {
        let sweeps = [
            descriptors(),
            strategy(),
            validation(),
            perturbation(),
            thickness(),
            resolution(),
            noise(),
            letters(),
            end_to_end(),
            training_size(),
            sim_to_real(),
        ];
        for sweep in sweeps {
            sweep.check_factors().unwrap_or_else(|e| panic!("{e}"));
        }
        let columns = |sweep: RecognitionSweep| -> Vec<&str> {
            sweep.settings[0].curves[0]
                .factors
                .factors()
                .map(Factor::column)
                .collect()
        };
        assert_eq!(columns(validation()), ["data", "resolution"]);
        assert_eq!(
            columns(end_to_end()),
            ["training", "local_probability", "object_motion"]
        );
        assert!(columns(descriptors()).is_empty());
    }

    #[test]
    fn training_size_settings_train_on_their_share_of_the_readings() {
        let sweep = training_size();
        let paper = DataCounts {
            training_per_object: 1000,
            validation_per_object: 100,
            test_per_object: 100,
            trials: 3,
        };
        let trained: Vec<usize> = (0..sweep.settings.len())
            .map(|s| sweep.settings[s].counts(paper).training_per_object)
            .collect();
        assert_eq!(trained, TRAINING_SIZES);
        // Everything but the training readings is the scale's; a tiny scale still trains on one.
        assert_eq!(sweep.settings[0].counts(paper).test_per_object, 100);
        let tiny = DataCounts {
            training_per_object: 2,
            ..paper
        };
        assert_eq!(sweep.settings[0].counts(tiny).training_per_object, 1);
        let labels: Vec<&str> = sweep.settings.iter().map(|s| s.label.as_str()).collect();
        assert_eq!(labels, ["100", "300", "1000", "3000", "10000"]);
    }
}
