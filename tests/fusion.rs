//! Descriptor fusion: `a+b` names, the fused posterior as the normalised product of the parts'
//! likelihoods, fused model files, and `taction train/recognize --descriptor mnti+mn`, on the toy
//! object set.

mod recognize_toy;

use std::process::Command;

use taction::describe::DescriptorKind;
use taction::recognize::{
    CodebookKind, DescriptorChoice, FusedModel, LabelledFeatures, ReadingRange, Recognizer, TrainChoices,
    TrainConfig, TrainData, TrainedModel, make_trials, train_recognizer,
};
use taction::valid::Valid;

fn config() -> Valid<TrainConfig> {
    Valid::new(TrainConfig {
        ks: vec![4],
        restarts: 1,
        seed: 5,
        ..TrainConfig::default()
    })
    .unwrap()
}

fn fused() -> FusedModel {
    let training = recognize_toy::dataset(30, 8);
    let choices = TrainChoices {
        codebook: CodebookKind::Gmm,
        ks: Some(vec![4]),
        restarts: 1,
        seed: 5,
        ..TrainChoices::of(DescriptorChoice::parse("mnti+mn").unwrap())
    };
    let data = TrainData {
        training: &training,
        validation: None,
        calibration: &[],
        contacts: None,
    };
    match train_recognizer(&Valid::new(choices).unwrap(), data, &mut ()).unwrap() {
        Recognizer::Fused(model) => *model,
        _ => panic!("two descriptors train a fused model"),
    }
}

#[test]
fn fused_names_parse_and_bad_ones_are_named() {
    let choice = DescriptorChoice::parse("mnti+mn").unwrap();
    assert_eq!(
        choice.kinds(),
        [DescriptorKind::Mnti, DescriptorKind::MomentNormalized]
    );
    assert!(choice.is_fused());
    assert_eq!(choice.name(), "mnti+mn");
    assert_eq!(DescriptorChoice::parse("mnti+moment-normalized").unwrap(), choice);
    let single = DescriptorChoice::parse("polar-fourier").unwrap();
    assert!(!single.is_fused());
    assert_eq!(single.kinds(), [DescriptorKind::PolarFourier]);
    let e = DescriptorChoice::parse("mnti+hog").unwrap_err().to_string();
    assert!(e.contains("'hog'") && e.contains("mnti+sift"), "{e}");
    let e = DescriptorChoice::parse("mn+moment-normalized")
        .unwrap_err()
        .to_string();
    assert!(e.contains("twice"), "{e}");
}

#[test]
fn fused_posterior_is_the_normalised_product_of_the_parts() {
    let model = fused();
    let test = recognize_toy::dataset(6, 77);
    let range = ReadingRange::new(1, 6).unwrap();
    let trials = model.trials(&test, 6).unwrap();
    let fused_eval = model.evaluate(&trials, range).unwrap();
    // Each part alone on the same readings.
    let parts: Vec<_> = model
        .fused
        .iter()
        .map(|m| {
            let d = m.build_descriptor().unwrap();
            let f = LabelledFeatures::from_dataset(&test, d.as_ref());
            let t = make_trials(&f, m.bag.objects(), 6).unwrap();
            (m, t)
        })
        .collect();
    for (trial_index, trial) in trials.iter().enumerate() {
        let mut fused_posterior = model.posterior();
        let mut singles: Vec<_> = parts.iter().map(|(m, _)| m.bag.posterior()).collect();
        for (n, reading) in trial.readings.iter().enumerate() {
            let belief = fused_posterior.observe(reading).unwrap();
            let product: Vec<f64> = (0..model.objects().len())
                .map(|j| {
                    singles
                        .iter_mut()
                        .zip(&parts)
                        .map(|(p, (_, t))| {
                            if j == 0 {
                                p.observe(&t[trial_index].readings[n]).unwrap();
                            }
                            p.belief().probabilities()[j]
                        })
                        .product()
                })
                .collect();
            let total: f64 = product.iter().sum();
            for (p, q) in belief.probabilities().iter().zip(&product) {
                assert!((p - q / total).abs() < 1e-9, "{p} vs {}", q / total);
            }
            assert_eq!(belief.readings, n + 1);
        }
    }
    // The evaluation rows come from the same beliefs.
    assert_eq!(fused_eval.objects, model.objects());
    assert_eq!(fused_eval.touches.len(), trials.len() * 6);
    // Wrong number of feature lists: a named error, state unchanged.
    let mut posterior = model.posterior();
    let e = posterior.observe(&trials[0].readings[0][..1]).unwrap_err();
    assert!(e.to_string().contains("fused"), "{e}");
    assert_eq!(posterior.belief().readings, 0);
}

#[test]
fn fused_models_save_load_and_are_checked() {
    let model = fused();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("fused.json");
    model.save(&path).unwrap();
    let Recognizer::Fused(loaded) = Recognizer::load(&path).unwrap() else {
        panic!("a fused file loaded as a single model")
    };
    assert_eq!(*loaded, model);
    let test = recognize_toy::dataset(5, 9);
    let range = ReadingRange::new(1, 5).unwrap();
    let (a, _) = Recognizer::Fused(Box::new(model.clone()))
        .evaluate(&test, range)
        .unwrap();
    let (b, trials) = Recognizer::Fused(loaded).evaluate(&test, range).unwrap();
    assert_eq!(trials, 3);
    let bits = |e: &taction::recognize::Evaluation| -> Vec<u64> {
        e.touches.iter().map(|t| t.p_true().to_bits()).collect()
    };
    assert_eq!(bits(&a), bits(&b));

    // A single model file still loads as one.
    let single_path = dir.path().join("single.json");
    model.fused[0].save(&single_path).unwrap();
    assert!(matches!(
        Recognizer::load(&single_path).unwrap(),
        Recognizer::Single(_)
    ));

    // A corrupt part is named.
    let mut value: serde_json::Value = serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    value["fused"][1]["bag"] = serde_json::json!(null);
    std::fs::write(&path, serde_json::to_vec(&value).unwrap()).unwrap();
    let e = Recognizer::load(&path).unwrap_err().to_string();
    assert!(e.contains("fused model 2"), "{e}");

    // Models of different objects cannot be fused.
    let other = recognize_toy::dataset(30, 8);
    let mut renamed = other.clone();
    let relabelled = TrainedModel::fit(
        &config(),
        &renamed_objects(&mut renamed),
        None,
        DescriptorKind::Mnti.build().as_ref(),
        &mut |_| {},
    )
    .unwrap();
    let e = FusedModel::new(vec![model.fused[1].clone(), relabelled]).unwrap_err();
    assert!(e.to_string().contains("different objects"), "{e}");
    let e = FusedModel::new(vec![model.fused[0].clone()]).unwrap_err();
    assert!(e.to_string().contains("at least two"), "{e}");
}

/// The toy dataset with its objects renamed.
fn renamed_objects(data: &mut taction::dataset::Dataset) -> taction::dataset::Dataset {
    let mut header = data.header().clone();
    header.objects = header.objects.iter().map(|o| format!("other-{o}")).collect();
    let readings = data
        .readings()
        .iter()
        .cloned()
        .map(|mut r| {
            r.object = format!("other-{}", r.object);
            r
        })
        .collect();
    taction::dataset::Dataset::new(header, readings).unwrap()
}

#[test]
fn train_and_recognise_a_fused_descriptor_from_the_cli() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).display().to_string();
    recognize_toy::dataset(30, 1)
        .write(dir.path().join("train.csv").as_path())
        .unwrap();
    recognize_toy::dataset(10, 3)
        .write(dir.path().join("test.csv").as_path())
        .unwrap();
    let run = |args: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_taction"))
            .args(args)
            .output()
            .unwrap();
        (
            out.status.success(),
            String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr),
        )
    };
    let (ok, out) = run(&[
        "train",
        "--dataset",
        &p("train.csv"),
        "--descriptor",
        "mnti+mn",
        "--k",
        "4",
        "--restarts",
        "1",
        "--out",
        &p("fused.json"),
    ]);
    assert!(ok, "{out}");
    assert!(out.contains("fused model (mnti+mn)"), "{out}");
    let (ok, out) = run(&[
        "recognize",
        "--model",
        &p("fused.json"),
        "--dataset",
        &p("test.csv"),
        "--readings",
        "5",
        "--out",
        &p("results"),
    ]);
    assert!(ok, "{out}");
    assert!(out.contains("mnti+mn"), "{out}");
    assert!(dir.path().join("results/accuracy.csv").exists());
    // A fused model's beliefs are measured for calibration like any model's.
    assert!(
        out.contains("ECE (10 bins): ") && out.contains("over 30 predictions"),
        "{out}"
    );
    assert!(dir.path().join("results/reliability.csv").exists());
    assert!(dir.path().join("results/reliability.svg").exists());
    let (ok, out) = run(&[
        "train",
        "--dataset",
        &p("train.csv"),
        "--descriptor",
        "mnti+nope",
        "--out",
        &p("x.json"),
    ]);
    assert!(!ok && out.contains("'nope'"), "{out}");
}
