//! The `taction train`, `taction recognize` and `taction dataset show` commands end to end on the
//! toy object set.

mod recognize_toy;

use std::process::Command;

fn taction(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_taction"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into(),
        String::from_utf8_lossy(&out.stderr).into(),
    )
}

/// `taction recognize` of `model` on `test`, readings `readings`, into `out`.
fn recognise(model: &str, test: &str, readings: &str, out: &str) -> (bool, String, String) {
    taction(&[
        "recognize",
        "--model",
        model,
        "--dataset",
        test,
        "--readings",
        readings,
        "--out",
        out,
    ])
}

/// `taction recognize` of `model` on `test`, readings 1 to 30, into `out`.
fn recognise_30(model: &str, test: &str, out: &str) -> (bool, String, String) {
    recognise(model, test, "1..30", out)
}

#[test]
fn train_then_recognise_writes_the_csvs_and_prints_accuracy() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).display().to_string();
    recognize_toy::dataset(40, 1)
        .write(dir.path().join("train.csv").as_path())
        .unwrap();
    recognize_toy::dataset(15, 2)
        .write(dir.path().join("val.csv").as_path())
        .unwrap();
    recognize_toy::dataset(30, 3)
        .write(dir.path().join("test.csv").as_path())
        .unwrap();

    let (ok, stdout, stderr) = taction(&["dataset", "show", &p("train.csv")]);
    assert!(ok, "{stderr}");
    assert!(
        stdout.contains("ridges") && stdout.contains("40") && stdout.contains("8x8 taxels"),
        "{stdout}"
    );

    let (ok, stdout, stderr) = taction(&[
        "train",
        "--dataset",
        &p("train.csv"),
        "--validation",
        &p("val.csv"),
        "--descriptor",
        "polar-fourier",
        "--codebook",
        "gmm",
        "--k",
        "3,5",
        "--restarts",
        "2",
        "--out",
        &p("model.json"),
    ]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("chosen k = "), "{stdout}");

    let (ok, stdout, stderr) = recognise_30(&p("model.json"), &p("test.csv"), &p("out"));
    assert!(ok, "{stderr}");
    assert!(
        stdout.contains("accuracy at   1 readings") && stdout.contains("accuracy at  30 readings: 1.000"),
        "{stdout}"
    );
    assert!(!stdout.contains("accuracy at 100"), "{stdout}");
    let posterior = std::fs::read_to_string(dir.path().join("out/posterior.csv")).unwrap();
    let mut lines = posterior.lines();
    assert_eq!(
        lines.next(),
        Some("trial,object_true,n_readings,object_guess,p_true,entropy_nats")
    );
    assert_eq!(lines.count(), 3 * 30);
    let accuracy = std::fs::read_to_string(dir.path().join("out/accuracy.csv")).unwrap();
    assert!(
        accuracy.starts_with("n_readings,trials,correct,accuracy,reliability\n1,3,"),
        "{accuracy}"
    );
    let confusion = std::fs::read_to_string(dir.path().join("out/confusion.csv")).unwrap();
    assert!(
        confusion.starts_with("n_readings,object_true,object_guess,count\n")
            && confusion.contains("30,ridges,ridges,1\n")
            && confusion.contains("30,flat,ridges,0\n"),
        "{confusion}"
    );
    // The whole posterior, one row per (trial, reading, object); each touch's row sums to one and
    // its true object's probability is the wide file's p_true.
    let rows = out_table(
        dir.path(),
        "posterior_long.csv",
        "trial,object_true,n_readings,object,probability",
    );
    assert_eq!(rows.len(), 3 * 30 * 3);
    for touch in rows.chunks(3) {
        let total: f64 = touch.iter().map(|r| r[4].parse::<f64>().unwrap()).sum();
        assert!((total - 1.0).abs() < 1e-9, "{touch:?}");
    }
    let p_true_wide: Vec<&str> = posterior
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(4).unwrap())
        .collect();
    let p_true_long: Vec<&str> = rows
        .iter()
        .filter(|r| r[1] == r[3])
        .map(|r| r[4].as_str())
        .collect();
    assert_eq!(p_true_wide, p_true_long);
}

#[test]
fn bad_inputs_fail_with_a_message_naming_the_problem() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).display().to_string();
    let (ok, _, stderr) = taction(&["dataset", "show", &p("missing.csv")]);
    assert!(!ok && stderr.contains("missing.csv"), "{stderr}");
    recognize_toy::dataset(3, 1)
        .write(dir.path().join("d.csv").as_path())
        .unwrap();
    let (ok, _, stderr) = taction(&[
        "train",
        "--dataset",
        &p("d.csv"),
        "--descriptor",
        "hog",
        "--out",
        &p("m.json"),
    ]);
    assert!(!ok && stderr.contains("unknown descriptor 'hog'"), "{stderr}");
    let (ok, _, stderr) = taction(&[
        "recognize",
        "--model",
        &p("d.csv"),
        "--dataset",
        &p("d.csv"),
        "--out",
        &p("o"),
    ]);
    assert!(!ok && stderr.contains("not a taction model"), "{stderr}");
    let (ok, _, stderr) = taction(&[
        "recognize",
        "--model",
        &p("m.json"),
        "--dataset",
        &p("d.csv"),
        "--readings",
        "5..2",
        "--out",
        &p("o"),
    ]);
    assert!(!ok && stderr.contains("5..2"), "{stderr}");
}

/// `train --codebook knn`: the neighbour codebook with its own defaults (PCA keeping 99% of the
/// variance, 10 and 20 neighbours tried), recognising the toy objects; an unknown codebook is
/// refused with the names that exist.
#[test]
fn the_neighbour_codebook_trains_with_its_own_defaults_and_recognises() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).display().to_string();
    recognize_toy::dataset(60, 1)
        .write(dir.path().join("train.csv").as_path())
        .unwrap();
    recognize_toy::dataset(30, 3)
        .write(dir.path().join("test.csv").as_path())
        .unwrap();
    let train = |codebook: &str| {
        taction(&[
            "train",
            "--dataset",
            &p("train.csv"),
            "--descriptor",
            "polar-fourier",
            "--codebook",
            codebook,
            "--out",
            &p("model.json"),
        ])
    };
    let (ok, stdout, stderr) = train("knn");
    assert!(ok, "{stderr}");
    assert!(
        stdout.contains("explain 99.") || stdout.contains("explain 100.0%"),
        "{stdout}"
    );
    // 60 readings of each of 3 objects: half an object's share is 30 neighbours.
    assert!(
        stdout.contains("k=10 ") && stdout.contains("k=20 ") && !stdout.contains("k=50 "),
        "{stdout}"
    );
    let (ok, stdout, stderr) = recognise_30(&p("model.json"), &p("test.csv"), &p("out"));
    assert!(ok, "{stderr}");
    assert!(stdout.contains("accuracy at  30 readings: 1.000"), "{stdout}");

    let (ok, _, stderr) = train("knnn");
    assert!(!ok);
    assert!(
        stderr.contains("unknown codebook 'knnn'; expected gmm, kmeans, knn"),
        "{stderr}"
    );
}

/// Trains a polar-fourier model of the toy objects on 40 readings each into `dir/model.json`.
/// The toy model trained in `dir` recognising a test set of 20 readings of each object (two
/// trials of ten), readings `readings`, into `dir/out`; its stdout and stderr.
fn recognise_toy(dir: &std::path::Path, readings: &str) -> (String, String) {
    toy_model(dir);
    recognize_toy::dataset(20, 3)
        .write(&dir.join("test.csv"))
        .unwrap();
    let p = |name: &str| dir.join(name).display().to_string();
    let (ok, stdout, stderr) = recognise(&p("model.json"), &p("test.csv"), readings, &p("out"));
    assert!(ok, "{stderr}");
    (stdout, stderr)
}

/// The rows of the CSV `name` that `recognize` wrote into `dir/out`, split at commas, once its
/// header is `header`.
fn out_table(dir: &std::path::Path, name: &str, header: &str) -> Vec<Vec<String>> {
    let text = std::fs::read_to_string(dir.join("out").join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some(header), "the header of {name}");
    lines.map(|l| l.split(',').map(String::from).collect()).collect()
}

fn toy_model(dir: &std::path::Path) {
    let train = dir.join("train.csv");
    recognize_toy::dataset(40, 1).write(&train).unwrap();
    let (ok, _, stderr) = taction(&[
        "train",
        "--dataset",
        train.to_str().unwrap(),
        "--descriptor",
        "polar-fourier",
        "--k",
        "3,5",
        "--restarts",
        "2",
        "--out",
        dir.join("model.json").to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
}

/// `--evidence` weighs a part of a model of appearance and contacts (`train --objects`); a
/// model of appearance alone has no contacts to weigh and says so, naming the flag, and its
/// appearance is what it weighs anyway.
#[test]
fn evidence_of_contacts_needs_a_model_that_knows_them() {
    let dir = tempfile::tempdir().unwrap();
    toy_model(dir.path());
    recognize_toy::dataset(10, 3)
        .write(&dir.path().join("test.csv"))
        .unwrap();
    let p = |name: &str| dir.path().join(name).display().to_string();
    let with = |evidence: &str, out: &str| {
        taction(&[
            "recognize",
            "--model",
            &p("model.json"),
            "--dataset",
            &p("test.csv"),
            "--readings",
            "10",
            "--evidence",
            evidence,
            "--out",
            &p(out),
        ])
    };
    let (ok, _, stderr) = with("contacts", "contacts");
    assert!(
        !ok && stderr.contains("--evidence contacts")
            && stderr.contains("model.json knows appearance alone")
            && stderr.contains("train --objects"),
        "{stderr}"
    );
    assert!(!dir.path().join("contacts").exists());
    let (ok, stdout, stderr) = with("appearance", "appearance");
    assert!(ok, "{stderr}");
    let (ok, plain, stderr) = recognise(&p("model.json"), &p("test.csv"), "10", &p("plain"));
    assert!(ok, "{stderr}");
    let accuracy = |out: &str| std::fs::read_to_string(dir.path().join(out).join("accuracy.csv")).unwrap();
    assert_eq!(accuracy("appearance"), accuracy("plain"));
    assert_eq!(stdout.lines().next(), plain.lines().next());
    let (ok, _, stderr) = with("touch", "touch");
    assert!(
        !ok && stderr.contains("'touch'") && stderr.contains("fused, appearance, contacts"),
        "{stderr}"
    );
}

/// `--readings 50` on 20 readings per object: the files say 20, the readings used, and stderr
/// says the request went beyond the data (confusion.csv once said 50).
#[test]
fn readings_beyond_the_data_are_labelled_as_used_and_warned_about() {
    let dir = tempfile::tempdir().unwrap();
    let (stdout, stderr) = recognise_toy(dir.path(), "50");
    let p = |name: &str| dir.path().join(name).display().to_string();
    assert!(
        stderr.contains("warning: --readings 1..50")
            && stderr.contains("more than 20 converged readings")
            && stderr.contains("accuracy.csv ends at 20"),
        "{stderr}"
    );
    assert!(stdout.contains("3 trials of up to 20 readings"), "{stdout}");
    let accuracy = std::fs::read_to_string(dir.path().join("out/accuracy.csv")).unwrap();
    assert!(
        accuracy.lines().last().unwrap().starts_with("20,3,"),
        "{accuracy}"
    );
    let confusion = std::fs::read_to_string(dir.path().join("out/confusion.csv")).unwrap();
    let rows: Vec<&str> = confusion.lines().skip(1).collect();
    assert_eq!(rows.len(), 9);
    assert!(rows.iter().all(|r| r.starts_with("20,")), "{confusion}");

    // 1..30 goes beyond the data too; 1..20 does not.
    let (ok, _, stderr) = recognise_30(&p("model.json"), &p("test.csv"), &p("out2"));
    assert!(ok && stderr.contains("warning"), "{stderr}");
    let (ok, _, stderr) = recognise(&p("model.json"), &p("test.csv"), "1..20", &p("out3"));
    assert!(ok && !stderr.contains("warning"), "{stderr}");
}

/// `recognize` plots accuracy against readings beside its CSVs, as the experiments do: 30 test
/// readings per object in trials of 10 are three trials per object, plotted as three trials with
/// their mean, the band from the lowest to the highest, and chance at 1/3. The first reading of
/// 'ridges' is a bump, so the first trial starts lower than the others.
#[test]
fn recognize_plots_accuracy_with_its_band_and_chance_beside_the_csvs() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).display().to_string();
    toy_model(dir.path());
    let test = recognize_toy::dataset(30, 3);
    let mut readings = test.readings().to_vec();
    assert_eq!(readings[0].object, "ridges");
    readings[0].image = recognize_toy::image(1, &mut taction::rng::stream(9, 0));
    taction::dataset::Dataset::new(test.header().clone(), readings)
        .unwrap()
        .write(dir.path().join("test.csv").as_path())
        .unwrap();
    let (ok, stdout, stderr) = recognise(&p("model.json"), &p("test.csv"), "1..10", &p("out"));
    assert!(ok, "{stderr}");
    assert!(
        stdout.contains("accuracy.svg") && stdout.contains("accuracy.png"),
        "{stdout}"
    );
    let svg = std::fs::read_to_string(dir.path().join("out/accuracy.svg")).unwrap();
    for needle in [
        "test.csv recognised by model.json",
        "number of readings",
        "accuracy (fraction correct)",
        "chance (1/3)",
        "band: lowest to highest trial",
    ] {
        assert!(svg.contains(needle), "accuracy.svg lacks '{needle}'");
    }
    let png = std::fs::read(dir.path().join("out/accuracy.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");

    // The plotted trials: trial k is every object's k-th trial; their mean is accuracy.csv's.
    let rows: Vec<taction::experiment::AccuracyRow> =
        csv::Reader::from_path(dir.path().join("out/accuracy_trials.csv"))
            .unwrap()
            .deserialize()
            .collect::<Result<_, _>>()
            .unwrap();
    assert_eq!(rows.len(), 3 * 10);
    assert!(
        rows.iter().all(|r| r.seed == 3 && r.stream_seed == 3),
        "the rows carry the test data's seed"
    );
    let first: Vec<f64> = rows
        .iter()
        .filter(|r| r.n_readings == 1)
        .map(|r| r.accuracy)
        .collect();
    assert_eq!(
        first,
        [2.0 / 3.0, 1.0, 1.0],
        "the bump read as ridges misleads trial 0"
    );
    let accuracy = std::fs::read_to_string(dir.path().join("out/accuracy.csv")).unwrap();
    for line in accuracy.lines().skip(1) {
        let fields: Vec<&str> = line.split(',').collect();
        let n: u32 = fields[0].parse().unwrap();
        let pooled: f64 = fields[3].parse().unwrap();
        let at_n: Vec<f64> = rows
            .iter()
            .filter(|r| r.n_readings == n)
            .map(|r| r.accuracy)
            .collect();
        assert_eq!(at_n.len(), 3, "three trials at {n} readings");
        let mean = at_n.iter().sum::<f64>() / 3.0;
        assert!((mean - pooled).abs() < 1e-12, "{n}: {mean} vs {pooled}");
    }
}

/// `recognize` measures calibration: reliability.csv bins every row of posterior.csv (10 bins of
/// top probability, empty bins with empty fields), its diagram is drawn beside it, and the ECE it
/// prints is the one the CSV gives, `sum_b (count_b / N) |accuracy_b - mean_confidence_b|`.
#[test]
fn recognize_writes_the_reliability_table_and_prints_its_ece() {
    let dir = tempfile::tempdir().unwrap();
    let (stdout, _) = recognise_toy(dir.path(), "1..10");
    let posterior = std::fs::read_to_string(dir.path().join("out/posterior.csv")).unwrap();
    let predictions = posterior.lines().count() - 1;
    assert_eq!(predictions, 3 * 2 * 10);

    let rows = out_table(
        dir.path(),
        "reliability.csv",
        "bin,confidence_low,confidence_high,count,mean_confidence,accuracy",
    );
    assert_eq!(rows.len(), 10);
    let count = |r: &Vec<String>| r[3].parse::<usize>().unwrap();
    assert_eq!(rows.iter().map(count).sum::<usize>(), predictions);
    let mut ece = 0.0;
    for (b, row) in rows.iter().enumerate() {
        assert_eq!(row[0], b.to_string());
        if count(row) == 0 {
            assert_eq!(
                (row[4].as_str(), row[5].as_str()),
                ("", ""),
                "an empty bin has no mean or accuracy"
            );
            continue;
        }
        let (confidence, accuracy): (f64, f64) = (row[4].parse().unwrap(), row[5].parse().unwrap());
        let low: f64 = row[1].parse().unwrap();
        assert!(confidence >= low && confidence <= low + 0.1 + 1e-12, "{row:?}");
        ece += count(row) as f64 / predictions as f64 * (accuracy - confidence).abs();
    }
    let printed = format!("ECE (10 bins): {ece:.3} over {predictions} predictions");
    assert!(stdout.contains(&printed), "expected '{printed}' in {stdout}");

    let svg = std::fs::read_to_string(dir.path().join("out/reliability.svg")).unwrap();
    let named = format!("(ECE {ece:.3})");
    for needle in ["mean confidence", "perfect calibration", &named] {
        assert!(svg.contains(needle), "reliability.svg lacks '{needle}'");
    }
    let png = std::fs::read(dir.path().join("out/reliability.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
}

/// Issue 38: `train --calibration` refits the posterior's tempering on another dataset (printed,
/// and stored: `recognize` then reports the same numbers), `recognize --posterior eq15` recognises
/// with the paper's rule (same accuracy, other probabilities), and an unknown rule is refused
/// naming the rules there are.
#[test]
fn train_calibrates_on_a_dataset_and_recognize_can_use_eq15() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).display().to_string();
    recognize_toy::dataset(40, 1)
        .write(dir.path().join("train.csv").as_path())
        .unwrap();
    recognize_toy::dataset(20, 5)
        .write(dir.path().join("arm.csv").as_path())
        .unwrap();
    recognize_toy::dataset(20, 3)
        .write(dir.path().join("test.csv").as_path())
        .unwrap();
    let train = |extra: &[&str], out: &str| {
        let (data, out) = (p("train.csv"), p(out));
        // The paper's GMM: the calibration's mechanics, on a codebook whose fitted temperings
        // differ with the trials' length on this toy data (the neighbour codebook's reach a bound).
        let mut args = vec![
            "train",
            "--dataset",
            &data,
            "--descriptor",
            "polar-fourier",
            "--codebook",
            "gmm",
        ];
        args.extend_from_slice(&["--k", "3", "--restarts", "1", "--out", &out]);
        args.extend_from_slice(extra);
        taction(&args)
    };
    let (ok, held_out, stderr) = train(&[], "held.json");
    assert!(ok, "{stderr}");
    let arm = p("arm.csv");
    let (ok, calibrated, stderr) = train(&["--calibration", &arm], "arm.json");
    assert!(ok, "{stderr}");
    let line = |out: &str, key: &str| -> String {
        out.lines()
            .find(|l| l.contains(key))
            .unwrap_or_default()
            .to_string()
    };
    let on_arm = line(&calibrated, "arm.csv");
    assert!(on_arm.contains("tau = "), "{calibrated}");
    // The trials' length is the runs' to be judged: each object's 20 readings as one trial by
    // default, shorter trials on request (fitted at other reading counts: another tempering).
    assert!(on_arm.contains("each object's readings one trial"), "{on_arm}");
    let (ok, short, stderr) = train(
        &["--calibration", &arm, "--calibration-trial-readings", "2"],
        "arm2.json",
    );
    assert!(ok, "{stderr}");
    let on_arm_short = line(&short, "arm.csv");
    assert!(on_arm_short.contains("trials of 2 readings"), "{short}");
    assert_ne!(
        on_arm_short.split("tau").nth(1),
        on_arm.split("tau").nth(1),
        "{on_arm_short}\n{on_arm}"
    );
    // Several calibration datasets are fitted on together: the arm's twice is the arm's (the same
    // mean loss over the same paths), the arm's with other runs another tempering. Twice, its 120
    // beliefs are enough for a confidence map (60 are not).
    let (ok, twice, stderr) = train(&["--calibration", &arm, "--calibration", &arm], "twice.json");
    assert!(ok, "{stderr}");
    let on_twice = line(&twice, "arm.csv + ");
    let tau_beta_floor = |line: &str| -> String {
        let fitted = line.split("tau").nth(1).unwrap_or_default();
        let fitted = fitted.split(" (").next().unwrap_or_default();
        fitted
            .split(", confidence map")
            .next()
            .unwrap_or_default()
            .to_string()
    };
    assert_eq!(
        tau_beta_floor(&on_twice),
        tau_beta_floor(&on_arm),
        "{twice}\n{on_arm}"
    );
    assert!(on_twice.contains("confidence map of "), "{on_twice}");
    assert!(!on_arm.contains("confidence map"), "{on_arm}");
    let wrong = p("wrong.csv");
    let relabelled: String = std::fs::read_to_string(&arm)
        .unwrap()
        .lines()
        .map(|l| match l.split_once(',') {
            Some(("ridges", rest)) => format!("bumps,{rest}\n"),
            Some(("bumps", rest)) => format!("flat,{rest}\n"),
            Some(("flat", rest)) => format!("ridges,{rest}\n"),
            _ => format!("{l}\n"),
        })
        .collect();
    std::fs::write(&wrong, relabelled).unwrap();
    let both_args = [
        "--calibration",
        &arm,
        "--calibration",
        &wrong,
        "--calibration-trial-readings",
        "2",
    ];
    let (ok, both, stderr) = train(&both_args, "both.json");
    assert!(ok, "{stderr}");
    let on_both = line(&both, "arm.csv + ");
    assert!(on_both.contains("wrong.csv"), "{both}");
    // Half the paths confidently wrong: the largest floor the fit tries, and far less evidence.
    assert!(on_both.contains("floor = 0.120"), "{on_both}");
    assert_ne!(
        on_both.split("tau").nth(1),
        on_arm_short.split("tau").nth(1),
        "{both}\n{on_arm_short}"
    );
    for (extra, needle) in [
        (
            vec!["--calibration", arm.as_str(), "--calibration-trial-readings", "0"],
            "--calibration-trial-readings: want 1 or more",
        ),
        (vec!["--calibration-trial-readings", "5"], "--calibration <FILE>"),
    ] {
        let (ok, _, stderr) = train(&extra, "refused.json");
        assert!(!ok && stderr.contains(needle), "{extra:?}: {stderr}");
        assert!(!dir.path().join("refused.json").exists());
    }
    assert_ne!(
        on_arm.split("tau").nth(1),
        line(&held_out, "posterior calibrated").split("tau").nth(1),
        "{held_out}\n{calibrated}"
    );
    let (ok, out, stderr) = recognise_30(&p("arm.json"), &p("test.csv"), &p("r_cal"));
    assert!(ok, "{stderr}");
    let tau = on_arm
        .split("tau = ")
        .nth(1)
        .and_then(|t| t.split(',').next())
        .unwrap();
    assert!(out.contains(&format!("tau = {tau}")), "{out}\n{on_arm}");
    let (ok, eq15, stderr) = taction(&[
        "recognize",
        "--model",
        &p("arm.json"),
        "--dataset",
        &p("test.csv"),
        "--readings",
        "1..30",
        "--out",
        &p("r_eq15"),
        "--posterior",
        "eq15",
    ]);
    assert!(ok, "{stderr}");
    assert!(eq15.contains("posterior Eq. 15"), "{eq15}");
    let accuracy = |out: &str| line(out, "accuracy at  30");
    assert_eq!(
        accuracy(&out).split('(').next(),
        accuracy(&eq15).split('(').next()
    );
    let read = |d: &str| std::fs::read_to_string(dir.path().join(d).join("posterior.csv")).unwrap();
    assert_ne!(read("r_cal"), read("r_eq15"));
    let (ok, _, stderr) = taction(&[
        "recognize",
        "--model",
        &p("arm.json"),
        "--dataset",
        &p("test.csv"),
        "--out",
        &p("r_bad"),
        "--posterior",
        "bayes",
    ]);
    assert!(
        !ok && stderr.contains("bayes") && stderr.contains("eq15"),
        "{stderr}"
    );
}

/// Issue 38: `recognize` replays the confidence stop on every trial (`stop.csv`, one row per
/// threshold, and a line each on stdout): the counts are those of posterior_long.csv replayed by
/// hand (the top guess held at or above the threshold over two touches). A range that does not
/// start at one reading has no stop to replay.
#[test]
fn recognize_replays_the_confidence_stop_as_posterior_long_shows_it() {
    let dir = tempfile::tempdir().unwrap();
    let (stdout, _) = recognise_toy(dir.path(), "1..10");
    let p = |name: &str| dir.path().join(name).display().to_string();

    // Per trial, in order of readings: the top guess and its probability.
    let mut traces: std::collections::BTreeMap<usize, Vec<(usize, String, f64, String)>> = Default::default();
    let long = out_table(
        dir.path(),
        "posterior_long.csv",
        "trial,object_true,n_readings,object,probability",
    );
    for f in &long {
        let (trial, truth, n, object, p) = (
            f[0].parse().unwrap(),
            &f[1],
            f[2].parse().unwrap(),
            &f[3],
            f[4].parse::<f64>().unwrap(),
        );
        let trace = traces.entry(trial).or_default();
        match trace.iter_mut().find(|t| t.0 == n) {
            Some(top) if p > top.2 => (top.1, top.2) = (object.to_string(), p),
            Some(_) => {}
            None => trace.push((n, object.to_string(), p, truth.to_string())),
        }
    }
    let rows = out_table(
        dir.path(),
        "stop.csv",
        "threshold,held_readings,budget,trials,stopped,right,share_right,mean_touches",
    );
    assert_eq!(rows.len(), 3);
    assert_ne!(rows[0][4], "0", "the toy's trials should reach 0.9: {rows:?}");
    for (row, threshold) in rows.iter().zip([0.9, 0.95, 0.99]) {
        let (mut stopped, mut right) = (0, 0);
        for trace in traces.values() {
            let fires = (1..trace.len()).find(|&k| {
                trace[k].1 == trace[k - 1].1 && trace[k].2 >= threshold && trace[k - 1].2 >= threshold
            });
            if let Some(k) = fires {
                stopped += 1;
                right += usize::from(trace[k].1 == trace[k].3);
            }
        }
        assert_eq!(
            row[..6],
            [
                threshold.to_string().as_str(),
                "2",
                "10",
                "6",
                &stopped.to_string(),
                &right.to_string()
            ]
        );
        let line =
            format!("stop at {threshold} (the guess held over 2 touches): {stopped} of 6 trials stopped");
        assert!(stdout.contains(&line), "expected '{line}' in {stdout}");
    }

    let (ok, _, stderr) = recognise(&p("model.json"), &p("test.csv"), "3..10", &p("later"));
    assert!(ok, "{stderr}");
    assert!(!dir.path().join("later/stop.csv").exists());
}

/// Issue 73: the shape index of a large array trains the network by default (a per-frame
/// posterior over the objects, frames combined by the product rule), with the same bytes from the
/// same seed, and recognises single presses of a simulated 20x30 pad on the chess set.
#[test]
fn the_shape_index_trains_the_network_by_default_and_recognises_single_presses() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).display().to_string();
    for (name, readings, seed) in [("train.csv", "100", "1"), ("test.csv", "40", "2")] {
        let (ok, _, stderr) = taction(&[
            "collect",
            "--objects",
            "chess",
            "--mode",
            "sampler",
            "--readings",
            readings,
            "--seed",
            seed,
            "--rows",
            "20",
            "--cols",
            "30",
            "--pad-width-m",
            "0.045",
            "--pad-height-m",
            "0.03",
            "--noise",
            "0.1",
            "--out",
            &p(name),
        ]);
        assert!(ok, "{stderr}");
    }
    let train = |out: &str| {
        taction(&[
            "train",
            "--dataset",
            &p("train.csv"),
            "--descriptor",
            "shape-index",
            "--out",
            &p(out),
        ])
    };
    let (ok, stdout, stderr) = train("a.json");
    assert!(ok, "{stderr}");
    assert!(
        stdout.contains("k=128 ") && stdout.contains("k=256 ") && stdout.contains("explain 100.0%"),
        "{stdout}"
    );
    assert!(train("b.json").0);
    let text = std::fs::read_to_string(p("a.json")).unwrap();
    assert_eq!(
        text,
        std::fs::read_to_string(p("b.json")).unwrap(),
        "same seed, same model"
    );
    let model: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(model["bag"]["codebook"]["kind"], serde_json::json!("mlp"));
    assert_eq!(model["bag"]["models"]["rule"], serde_json::json!("per-frame"));
    let (ok, stdout, stderr) = recognise(&p("a.json"), &p("test.csv"), "1", &p("out"));
    assert!(ok, "{stderr}");
    let accuracy: f64 = stdout
        .split("accuracy at   1 readings: ")
        .nth(1)
        .and_then(|rest| rest.split_whitespace().next())
        .and_then(|a| a.parse().ok())
        .unwrap_or_else(|| panic!("{stdout}"));
    assert!(accuracy >= 0.8, "one press of a pawn or a rook: {accuracy}");
}
