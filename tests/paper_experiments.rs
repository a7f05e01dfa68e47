//! The paper's experiments from the command line (issue: every figure as a run): `reproduce` end to
//! end at a tiny scale on two objects, kill-and-resume, and shards merged against one run. Real
//! MuJoCo, real sensor, real meshes (the two generated chess pieces and two raised letters).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use taction::experiment::{AccuracyRow, AttemptRow, Factor, PerObjectRow, ReliabilityRow};
use taction::mesh::Font;
use taction::mesh::LetterStyle;
use taction::mesh::ObjectSet;
use taction::paper::PaperExperiment;

/// The factor columns of each recognition experiment: one per thing it varies besides the
/// descriptor.
fn factor_columns(experiment: &str) -> &'static [&'static str] {
    match experiment {
        "strategy" => &["local_probability"],
        "validation" => &["data", "resolution"],
        "perturbation" => &["object_motion"],
        "thickness" => &["thickness_fraction"],
        "resolution" => &["resolution"],
        "noise" => &["noise_fraction"],
        "training-size" => &["training_readings"],
        "active" => &["strategy", "local_probability", "object_motion"],
        "end-to-end" => &["training", "local_probability", "object_motion"],
        "fusion" => &["evidence", "strategy", "local_probability", "object_motion"],
        "free-object" => &["evidence", "mount", "object_motion"],
        _ => &[],
    }
}

/// Runs `taction args`, which must fail, without a panic, with `says` on stderr.
fn refused(args: &[&str], says: &str) {
    let output = Command::new(env!("CARGO_BIN_EXE_taction"))
        .args(args)
        .output()
        .expect("the taction binary runs");
    let stderr = String::from_utf8_lossy(&output.stderr);
    let run = args.join(" ");
    assert!(!output.status.success(), "taction {run} succeeded");
    assert!(stderr.contains(says), "taction {run}: {stderr}");
    assert!(!stderr.contains("panicked"), "taction {run}: {stderr}");
}

fn taction(args: &[&str]) -> Output {
    let output = Command::new(env!("CARGO_BIN_EXE_taction"))
        .args(args)
        .output()
        .expect("the taction binary runs");
    assert!(
        output.status.success(),
        "taction {}: {}\n{}",
        args.join(" "),
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
    output
}

/// A manifest of two raised letters (upper A, lower b), as `--letters` takes it.
fn two_letters(dir: &Path) -> PathBuf {
    let font = Font::load_default().expect("DejaVu Sans (fonts-dejavu-core) is installed");
    let mut set = ObjectSet::letters(&font, LetterStyle::default());
    set.objects.retain(|o| o.name == "upper_A" || o.name == "lower_b");
    set.name = "two-letters".into();
    assert_eq!(set.objects.len(), 2);
    let path = dir.join("two-letters.json");
    set.save_manifest(&path).expect("manifest written");
    path
}

/// `csv`'s rows, after checking its header is `experiment,descriptor`, one column per factor of
/// the experiment, `trial` and `after`, and that no factor cell is empty or a packed pair.
fn tidy_rows<R: serde::de::DeserializeOwned>(csv: &Path, after: &str) -> Vec<R> {
    let text = std::fs::read_to_string(csv).unwrap_or_else(|e| panic!("{}: {e}", csv.display()));
    let experiment = csv
        .parent()
        .and_then(Path::file_name)
        .and_then(|n| n.to_str())
        .unwrap_or_default();
    let factors = factor_columns(experiment);
    let mut columns = vec!["experiment", "descriptor"];
    columns.extend(factors);
    columns.push("trial");
    let expected = format!("{},{after}", columns.join(","));
    let header = text.lines().next().unwrap_or_default();
    assert_eq!(header, expected, "{}", csv.display());
    for line in text.lines().skip(1) {
        let cells: Vec<&str> = line.split(',').collect();
        for (k, column) in factors.iter().enumerate() {
            let cell = cells.get(2 + k).copied().unwrap_or_default();
            assert!(
                !cell.is_empty() && !cell.contains(char::is_whitespace),
                "{}: {column} = '{cell}' is not one level: {line}",
                csv.display()
            );
        }
    }
    csv::Reader::from_reader(text.as_bytes())
        .deserialize()
        .collect::<Result<Vec<R>, _>>()
        .unwrap_or_else(|e| panic!("{}: {e}", csv.display()))
}

fn rows(csv: &Path) -> Vec<AccuracyRow> {
    // `active` adds the confidence stop's columns after the accuracy ones.
    let active = csv.file_stem().is_some_and(|s| s == "active");
    let after = "n_readings,accuracy,reliability,seed,stream_seed";
    if active {
        let stops =
            "confident_0.9,correct_at_stop_0.9,confident,correct_at_stop,confident_0.99,correct_at_stop_0.99";
        tidy_rows(csv, &format!("{after},{stops}"))
    } else {
        tidy_rows(csv, after)
    }
}

/// Checks the per-object table beside `name`'s accuracy table: one row per test object at every
/// point of every curve, whose mean `correct` is the point's accuracy and mean `p_true` its
/// reliability.
fn assert_per_object_rows_average_to(name: &str, out: &Path, rows: &[AccuracyRow]) {
    let csv = out.join(name).join(format!("{name}_per_object.csv"));
    let per_object: Vec<PerObjectRow> = tidy_rows(&csv, "object,n_readings,correct,p_true");
    let mut objects = BTreeSet::new();
    for row in rows {
        let at: Vec<&PerObjectRow> = per_object
            .iter()
            .filter(|o| {
                (&o.descriptor, &o.factors, o.trial, o.n_readings)
                    == (&row.descriptor, &row.factors, row.trial, row.n_readings)
            })
            .collect();
        assert!(!at.is_empty(), "{name}: no per-object rows for {row:?}");
        let k = at.len() as f64;
        let correct = at.iter().filter(|o| o.correct).count() as f64 / k;
        let p_true = at.iter().map(|o| o.p_true).sum::<f64>() / k;
        assert_eq!(correct, row.accuracy, "{name}: {row:?}");
        assert!((p_true - row.reliability).abs() < 1e-12, "{name}: {row:?}");
        objects.extend(at.iter().map(|o| o.object.clone()));
    }
    let points = rows.len();
    assert_eq!(
        per_object.len(),
        points * objects.len(),
        "{name}: every object at every point"
    );
}

/// Checks the reliability table beside `name`'s accuracy table: one curve per (descriptor, levels)
/// of the accuracy rows, pooled over its trials, ten bins each with the curve's ECE, at most one
/// belief per per-object row (an object whose trial ended early keeps its last belief there), and
/// its diagram.
fn assert_reliability_pools_every_curve(name: &str, out: &Path, rows: &[AccuracyRow]) {
    let csv = out.join(name).join(format!("{name}_reliability.csv"));
    let table: Vec<ReliabilityRow> = csv::Reader::from_path(&csv)
        .unwrap_or_else(|e| panic!("{}: {e}", csv.display()))
        .deserialize()
        .collect::<Result<_, _>>()
        .unwrap_or_else(|e| panic!("{}: {e}", csv.display()));
    let curves: BTreeSet<(String, String)> = rows
        .iter()
        .map(|r| (r.descriptor.clone(), r.factors.to_string()))
        .collect();
    assert_eq!(table.len(), 10 * curves.len(), "{name}: ten bins per curve");
    let per_object: Vec<PerObjectRow> =
        csv::Reader::from_path(out.join(name).join(format!("{name}_per_object.csv")))
            .unwrap()
            .deserialize()
            .collect::<Result<_, _>>()
            .unwrap();
    for (descriptor, levels) in &curves {
        let bins: Vec<&ReliabilityRow> = table
            .iter()
            .filter(|r| (&r.descriptor, &r.factors.to_string()) == (descriptor, levels))
            .collect();
        assert_eq!(bins.len(), 10, "{name} {descriptor} {levels}");
        let predictions: u64 = bins.iter().map(|r| r.count).sum();
        let beliefs = per_object
            .iter()
            .filter(|r| (&r.descriptor, &r.factors.to_string()) == (descriptor, levels))
            .count() as u64;
        assert!(
            predictions >= 1 && predictions <= beliefs,
            "{name} {descriptor} {levels}: {predictions} of {beliefs}"
        );
        let ece = bins[0].ece.expect("a curve with predictions has an ECE");
        assert!((0.0..=1.0).contains(&ece) && bins.iter().all(|r| r.ece == Some(ece)));
    }
    let stem = out.join(name).join(format!("{name}-reliability"));
    let svg = valid_svg_and_png(&stem);
    assert!(
        svg.contains("mean confidence") && svg.contains("perfect calibration") && svg.contains("(ECE "),
        "{}",
        stem.display()
    );
}

fn assert_svg_and_png(stem: &Path) {
    let svg = valid_svg_and_png(stem);
    assert!(
        svg.contains("number of readings")
            && svg.contains("accuracy (fraction correct)")
            && svg.contains("chance (1/")
    );
}

/// The text of `stem`.svg, once it and `stem`.png are valid.
fn valid_svg_and_png(stem: &Path) -> String {
    let svg = std::fs::read_to_string(stem.with_extension("svg")).expect("SVG written");
    let tree = resvg::usvg::Tree::from_str(&svg, &resvg::usvg::Options::default());
    assert!(tree.is_ok(), "{}: not a valid SVG", stem.display());
    let png = std::fs::read(stem.with_extension("png")).expect("PNG written");
    let decoded = png::Decoder::new(std::io::Cursor::new(png)).read_info();
    assert!(decoded.is_ok(), "{}: not a valid PNG", stem.display());
    svg
}

/// `<out>/timings.csv` has a line per experiment, in the run's order, whose phases add up to its
/// wall time; experiments that train models are charged training time (no more than their units
/// took), those that only collect or draw none; the table is printed too.
fn assert_phases_add_up(out: &Path, stdout: &str) {
    #[derive(serde::Deserialize)]
    struct Line {
        experiment: String,
        wall_s: f64,
        datasets_s: f64,
        units_s: f64,
        rest_s: f64,
        unit_thread_s: f64,
        training_thread_s: f64,
    }
    let lines: Vec<Line> = csv::Reader::from_path(out.join("timings.csv"))
        .expect("timings.csv written")
        .deserialize()
        .collect::<Result<_, _>>()
        .expect("timings.csv reads back");
    let names: Vec<&str> = lines.iter().map(|l| l.experiment.as_str()).collect();
    let all: Vec<&str> = PaperExperiment::ALL.iter().map(|e| e.name()).collect();
    assert_eq!(names, all);
    for l in &lines {
        let phases = l.datasets_s + l.units_s + l.rest_s;
        assert!(
            (phases - l.wall_s).abs() < 1e-6,
            "{}: {phases} vs {}",
            l.experiment,
            l.wall_s
        );
        assert!(l.training_thread_s <= l.unit_thread_s, "{}", l.experiment);
        // Fig. 7 trains the first models; a later experiment reading a model from the store is
        // charged nothing for it, and the two that recognise nothing train nothing.
        match l.experiment.as_str() {
            "descriptors" | "letters" | "real-frames" => {
                assert!(l.training_thread_s > 0.0, "{}", l.experiment)
            }
            "exploration" | "convergence" => {
                assert_eq!(l.training_thread_s, 0.0, "{}", l.experiment)
            }
            _ => {}
        }
    }
    assert!(
        stdout.contains("| experiment | wall s | datasets s |"),
        "{stdout}"
    );
    assert!(stdout.contains("| total |"), "{stdout}");
}

#[test]
fn reproduce_runs_every_experiment_end_to_end_at_a_tiny_scale() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("results");
    let letters = two_letters(dir.path());
    let output = taction(&[
        "reproduce",
        "--scale",
        "0.001",
        "--objects",
        "chess",
        "--letters",
        letters.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&output.stdout);

    let convergence = std::fs::read_to_string(out.join("convergence/convergence.csv")).expect("Fig. 14 CSV");
    let header = convergence.lines().next().unwrap_or_default();
    for column in [
        "noise_fraction",
        "attempts",
        "converged",
        "convergence_rate",
        "mean_iterations",
    ] {
        assert!(
            header.split(',').any(|c| c == column),
            "convergence.csv lacks {column}: {header}"
        );
    }
    assert_eq!(
        convergence.lines().count(),
        1 + 2 * 7,
        "both chess pieces at the seven noise levels"
    );
    for experiment in PaperExperiment::ALL.into_iter().filter(|e| e.is_recognition()) {
        let name = experiment.name();
        let root = out.join(name);
        let rows = rows(&root.join(format!("{name}.csv")));
        assert!(!rows.is_empty(), "{name}: no rows");
        let mut curves = BTreeSet::new();
        for r in &rows {
            assert_eq!(r.experiment, name);
            assert!(
                (0.0..=1.0).contains(&r.accuracy),
                "{name}: accuracy {}",
                r.accuracy
            );
            assert!(
                (0.0..=1.0).contains(&r.reliability),
                "{name}: reliability {}",
                r.reliability
            );
            assert!(r.n_readings >= 1);
            // `seed` is the run's --seed; each trial's derived stream is its own column.
            assert_eq!(r.seed, 1, "{name}: seed column");
            curves.insert((r.descriptor.clone(), r.factors.to_string(), r.trial));
        }
        // Every curve starts at one reading and counts up without gaps.
        for (descriptor, levels, trial) in &curves {
            let ns: Vec<u32> = rows
                .iter()
                .filter(|r| (&r.descriptor, &r.factors.to_string(), &r.trial) == (descriptor, levels, trial))
                .map(|r| r.n_readings)
                .collect();
            assert_eq!(
                ns,
                (1..=ns.len() as u32).collect::<Vec<_>>(),
                "{name} {descriptor} {levels}"
            );
        }
        assert_per_object_rows_average_to(name, &out, &rows);
        assert_reliability_pools_every_curve(name, &out, &rows);
        assert_svg_and_png(&root.join(name));
        let config = std::fs::read_to_string(root.join("config.json")).expect("config.json written");
        assert!(
            config.contains("\"seed\": 1"),
            "{name}: the config records the seed"
        );
    }
    // Curves the figures need: six descriptors in Fig. 7, three values of L in Fig. 8, fixed and
    // perturbed in Fig. 10, three resolutions in Fig. 12, two letters recognised in Fig. 16a.
    let values = |name: &str| -> BTreeSet<String> {
        rows(&out.join(name).join(format!("{name}.csv")))
            .into_iter()
            .map(|r| {
                let levels: Vec<&str> = r.factors.iter().map(|(_, level)| level).collect();
                levels.join(" ")
            })
            .collect()
    };
    let descriptors: BTreeSet<String> = rows(&out.join("descriptors/descriptors.csv"))
        .into_iter()
        .map(|r| r.descriptor)
        .collect();
    assert_eq!(descriptors.len(), 6);
    assert_eq!(
        values("strategy"),
        BTreeSet::from(["0".into(), "0.5".into(), "1".into()])
    );
    assert_eq!(
        values("perturbation"),
        BTreeSet::from(["fixed".into(), "perturbed".into()])
    );
    assert_eq!(values("resolution").len(), 3);
    assert_eq!(values("noise").len(), 4);
    assert_eq!(
        values("training-size"),
        BTreeSet::from([
            "100".into(),
            "300".into(),
            "1000".into(),
            "3000".into(),
            "10000".into()
        ])
    );
    assert_eq!(
        values("active"),
        BTreeSet::from([
            "blind 1 fixed".into(),
            "blind 1 perturbed".into(),
            "blind 0.5 fixed".into(),
            "blind 0.5 perturbed".into(),
            "active 0.5 fixed".into(),
            "active 0.5 perturbed".into(),
        ])
    );
    assert_eq!(
        values("validation"),
        BTreeSet::from([
            "validation 6x6".into(),
            "exploration 6x6".into(),
            "validation 26x26".into(),
            "exploration 26x26".into(),
        ])
    );
    let mut fusion_curves = BTreeSet::new();
    for motion in ["fixed", "perturbed"] {
        for evidence in ["appearance", "contacts", "fused"] {
            for l in ["0.5", "1"] {
                fusion_curves.insert(format!("{evidence} blind {l} {motion}"));
            }
        }
        fusion_curves.insert(format!("fused active 0.5 {motion}"));
    }
    assert_eq!(values("fusion"), fusion_curves);
    let mut free_curves = BTreeSet::new();
    for evidence in ["appearance", "contacts", "fused"] {
        free_curves.insert(format!("{evidence} mocap fixed"));
        free_curves.insert(format!("{evidence} mocap perturbed"));
        for density in ["250", "1000", "2500"] {
            for friction in ["0.2", "0.8"] {
                free_curves.insert(format!("{evidence} free_d{density}_mu{friction} fixed"));
            }
        }
        free_curves.insert(format!("{evidence} free_d1000_mu0.8 pushed"));
    }
    assert_eq!(values("free-object"), free_curves);
    assert_free_object_motion(&out);
    // The active curves explore under the plans of the blind L = 0.5 test explorations (the same
    // starts, streams and perturbations), trial by trial.
    let fusion = rows(&out.join("fusion/fusion.csv"));
    let plans = |strategy: &str| -> BTreeSet<(String, u32, i64)> {
        fusion
            .iter()
            .filter(|r| {
                r.factors.level(Factor::Strategy) == Some(strategy)
                    && r.factors.level(Factor::Evidence) == Some("fused")
                    && r.factors.level(Factor::LocalProbability) == Some("0.5")
            })
            .map(|r| {
                let motion = r.factors.level(Factor::ObjectMotion).unwrap_or_default();
                (motion.to_string(), r.trial, r.stream_seed)
            })
            .collect()
    };
    assert!(!plans("active").is_empty());
    assert_eq!(plans("active"), plans("blind"));
    assert_attempts_end_at_the_last_reading(&out);
    let e2e = rows(&out.join("end-to-end/end-to-end.csv"));
    assert!(
        e2e.iter()
            .any(|r| r.factors.level(Factor::Training) == Some("reachable"))
    );
    // Our Polar-Fourier model of end-to-end is active's (the same training, calibrated on the same
    // explorations of the arm) judging the same blind explorations: the same points, beliefs too.
    let point = |r: &AccuracyRow| {
        let level = |f| r.factors.level(f).unwrap_or_default().to_string();
        (
            level(Factor::LocalProbability),
            level(Factor::ObjectMotion),
            r.trial,
            r.n_readings,
        )
    };
    let ours: BTreeMap<_, _> = e2e
        .iter()
        .filter(|r| r.descriptor == "polar-fourier" && r.factors.level(Factor::Training) == Some("reachable"))
        .map(|r| (point(r), (r.accuracy, r.reliability)))
        .collect();
    let blind: BTreeMap<_, _> = rows(&out.join("active/active.csv"))
        .iter()
        .filter(|r| r.factors.level(Factor::Strategy) == Some("blind"))
        .map(|r| (point(r), (r.accuracy, r.reliability)))
        .collect();
    assert!(
        !ours.is_empty() && ours == blind,
        "end-to-end's ours against active's blind curves"
    );
    // Figs. 7, 8 and 10 calibrate on the arm's explorations of the default sensor, the ones
    // `active` and `end-to-end` use: the whole run explores each calibration stream once.
    for experiment in ["descriptors", "strategy", "perturbation", "end-to-end", "active"] {
        let config = std::fs::read_to_string(out.join(experiment).join("config.json")).expect("config.json");
        let config: serde_json::Value = serde_json::from_str(&config).expect("JSON");
        for setting in config["sweep"]["settings"].as_array().expect("settings") {
            assert_eq!(
                setting["calibrated_on"], "arm_explorations",
                "{experiment}: {setting}"
            );
        }
    }
    let trials = arm_calibration(&out, "descriptors").expect("calibrated on the arm");
    assert_eq!(calibration_explorations(&out), [trials, trials]);
    let index = std::fs::read_to_string(out.join("README.md")).expect("index written");
    for experiment in PaperExperiment::ALL {
        assert!(index.contains(experiment.name()), "index lists {experiment}");
    }
    assert_phases_add_up(&out, &stdout);
    // Fig. 1: the pawn explored by the planner, its placements as CSV, the picture in the index.
    let placements = std::fs::read_to_string(out.join("exploration/exploration.csv")).expect("Fig. 1 CSV");
    let mut lines = placements.lines();
    assert_eq!(
        lines.next(),
        Some("object,reading,center_x_m,center_y_m,center_z_m,normal_x,normal_y,normal_z,max_taxel,seed")
    );
    let placed: Vec<&str> = lines.collect();
    assert_eq!(placed.len(), 100, "Fig. 1's 100 converged readings");
    assert!(placed.iter().all(|l| l.starts_with("pawn,")));
    let png = std::fs::read(out.join("exploration/exploration.png")).expect("Fig. 1 picture");
    let decoder = png::Decoder::new(std::io::Cursor::new(png));
    let info = decoder.read_info().expect("a PNG").info().clone();
    assert!(
        info.width > info.height,
        "the object panel with the images to its right"
    );
    assert!(index.contains("## exploration") && index.contains("exploration/exploration.png"));
    assert!(
        stdout.contains("| descriptors | polar-fourier |"),
        "headline table printed:\n{stdout}"
    );
}

/// `fusion`'s attempts table: every curve and repetition counts up from one attempt without gaps,
/// and after its last attempt every object holds the belief of its last converged reading, so the
/// accuracy there is the accuracy row's at the repetition's longest sequence of readings.
fn assert_attempts_end_at_the_last_reading(out: &Path) {
    let accuracy = rows(&out.join("fusion/fusion.csv"));
    let attempts: Vec<AttemptRow> = tidy_rows(
        &out.join("fusion/fusion_attempts.csv"),
        "n_attempts,accuracy,reliability",
    );
    let mut last: BTreeMap<(String, u32), Vec<&AttemptRow>> = BTreeMap::new();
    for row in &attempts {
        last.entry((row.factors.to_string(), row.trial))
            .or_default()
            .push(row);
    }
    assert_eq!(
        last.len(),
        14 * 3,
        "twelve blind curves and two active, three repetitions each at any scale"
    );
    for ((curve, trial), rows_of) in &last {
        let ns: Vec<u32> = rows_of.iter().map(|r| r.n_attempts).collect();
        assert_eq!(ns, (1..=ns.len() as u32).collect::<Vec<_>>(), "{curve} {trial}");
        let final_reading = accuracy
            .iter()
            .filter(|r| (&r.factors.to_string(), &r.trial) == (curve, trial))
            .max_by_key(|r| r.n_readings)
            .expect("the curve's accuracy rows");
        let final_attempt = rows_of.last().expect("rows");
        assert_eq!(
            (final_attempt.accuracy, final_attempt.reliability),
            (final_reading.accuracy, final_reading.reliability),
            "{curve} {trial}"
        );
    }
}

/// `free-object`'s motion table: a row per mount, trial and object (nine mounts, three trials, two
/// chess pieces); a mocap object's touches measure nothing (no touch moves it), every touch of a
/// free one is measured, its statistics ordered (mean and 95th percentile at most the largest), a
/// free object's mass its density's (four times at 1000 kg/m3 what it is at 250), and the
/// convergence rate the counts'.
fn assert_free_object_motion(out: &Path) {
    let path = out.join("free-object/free-object_motion.csv");
    let rows: Vec<BTreeMap<String, String>> = csv::Reader::from_path(&path)
        .expect("free-object_motion.csv written")
        .deserialize()
        .collect::<Result<_, _>>()
        .expect("free-object_motion.csv reads");
    assert_eq!(rows.len(), 9 * 3 * 2, "{}", path.display());
    let number = |row: &BTreeMap<String, String>, column: &str| -> Option<f64> {
        let cell = &row[column];
        (!cell.is_empty()).then(|| cell.parse().unwrap_or_else(|_| panic!("{column}: '{cell}'")))
    };
    let mut mass_g = BTreeMap::new();
    for row in &rows {
        let attempts = number(row, "attempts").expect("attempts");
        let converged = number(row, "converged").expect("converged");
        if attempts > 0.0 {
            assert_eq!(
                number(row, "convergence_rate"),
                Some(converged / attempts),
                "{row:?}"
            );
        }
        let measured = number(row, "touches_measured").expect("touches_measured");
        if attempts > 0.0 && row["mount"] == "mocap" {
            // The start pose's drawn tilt (Sec. V-B4's 10 degrees at most).
            let tilt = number(row, "start_tilt_deg").expect("a start tilt");
            assert!((0.0..=10.0 + 1e-9).contains(&tilt), "{row:?}");
        }
        if row["mount"] == "mocap" {
            assert_eq!(measured, 0.0, "{row:?}");
            assert!(
                row["shift_mean_mm"].is_empty() && row["mass_g"].is_empty(),
                "{row:?}"
            );
            continue;
        }
        assert_eq!(
            measured, attempts,
            "every touch of a free object is measured: {row:?}"
        );
        mass_g.insert(
            (row["mount"].clone(), row["object"].clone()),
            number(row, "mass_g").expect("a free object's mass"),
        );
        if measured > 0.0 {
            for measure in ["shift", "turn"] {
                let unit = if measure == "shift" { "mm" } else { "deg" };
                let at = |s: &str| number(row, &format!("{measure}_{s}_{unit}")).expect("measured");
                assert!(at("mean") <= at("max") && at("p95") <= at("max"), "{row:?}");
            }
        }
    }
    for object in ["pawn", "rook"] {
        let of = |mount: &str| mass_g[&(mount.to_string(), object.to_string())];
        let ratio = of("free_d1000_mu0.8") / of("free_d250_mu0.2");
        assert!((ratio - 4.0).abs() < 1e-9, "{object}: {ratio}");
    }
}

/// Runs `experiment` into `out` and returns the assembled CSV's bytes.
fn run_experiment(name: &str, out: &Path, extra: &[&str]) -> Vec<u8> {
    let mut args = vec![
        "experiment",
        name,
        "--scale",
        "0.001",
        "--objects",
        "chess",
        "--out",
    ];
    args.push(out.to_str().unwrap());
    args.extend_from_slice(extra);
    taction(&args);
    std::fs::read(out.join(name).join(format!("{name}.csv"))).expect("assembled CSV")
}

#[test]
fn a_killed_run_resumes_to_the_rows_of_an_uninterrupted_run_and_shards_merge_to_it() {
    let dir = tempfile::tempdir().unwrap();
    let whole = dir.path().join("whole");
    let reference = run_experiment("descriptors", &whole, &["--threads", "2"]);
    let per_object = |root: &Path| {
        std::fs::read(root.join("descriptors/descriptors_per_object.csv")).expect("the per-object CSV")
    };
    let reference_objects = per_object(&whole);

    // Kill a run as soon as its first unit is on disk, then run it again.
    let killed = dir.path().join("killed");
    let units = killed.join("descriptors").join("units");
    let mut child = Command::new(env!("CARGO_BIN_EXE_taction"))
        .args([
            "experiment",
            "descriptors",
            "--scale",
            "0.001",
            "--objects",
            "chess",
            "--threads",
            "1",
        ])
        .arg("--out")
        .arg(&killed)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("taction starts");
    let started = Instant::now();
    let mut finished_before_kill = 0;
    while started.elapsed() < Duration::from_secs(600) {
        finished_before_kill = std::fs::read_dir(&units).map_or(0, |d| {
            d.filter_map(Result::ok)
                .filter(|e| e.path().extension().is_some_and(|x| x == "csv"))
                .count()
        });
        if finished_before_kill > 0 || child.try_wait().ok().flatten().is_some() {
            break;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.kill().ok();
    child.wait().ok();
    assert!(
        finished_before_kill >= 1,
        "the run saved a unit before it was killed"
    );
    let killed_dir = killed.join("descriptors");
    if !killed_dir.join("descriptors.csv").exists() {
        let resumed = run_experiment("descriptors", &killed, &["--threads", "2"]);
        assert_eq!(
            resumed, reference,
            "the resumed run has the rows of the uninterrupted one"
        );
        assert!(
            per_object(&killed) == reference_objects,
            "the resumed run has the per-object rows of the uninterrupted one"
        );
    }
    let lines: Vec<&[u8]> = reference
        .split(|&b| b == b'\n')
        .filter(|l| !l.is_empty())
        .collect();
    let distinct: BTreeSet<&[u8]> = lines.iter().copied().collect();
    assert_eq!(lines.len(), distinct.len(), "no row twice");

    // Shards 1/3..3/3 in separate roots, merged, give the unsharded files byte for byte.
    let mut shard_dirs = Vec::new();
    for k in 1..=3 {
        let shard_dir = dir.path().join(format!("shard{k}"));
        let shard = format!("{k}/3");
        let mut args = vec![
            "experiment",
            "descriptors",
            "--scale",
            "0.001",
            "--objects",
            "chess",
        ];
        args.extend(["--shard", &shard, "--out", shard_dir.to_str().unwrap()]);
        taction(&args);
        assert!(
            !shard_dir.join("descriptors/descriptors.csv").exists(),
            "a shard alone does not finish the experiment"
        );
        shard_dirs.push(shard_dir);
    }
    let merged = dir.path().join("merged");
    let mut args = vec!["merge".to_string()];
    args.extend(shard_dirs.iter().map(|d| d.display().to_string()));
    args.extend(["--out".to_string(), merged.display().to_string()]);
    taction(&args.iter().map(String::as_str).collect::<Vec<_>>());
    let merged_csv = std::fs::read(merged.join("descriptors/descriptors.csv")).expect("merged CSV");
    assert_eq!(merged_csv, reference, "merged shards == one run, byte for byte");
    assert!(
        per_object(&merged) == reference_objects,
        "merged shards' per-object rows == one run's"
    );
}

#[test]
fn bad_flags_and_unknown_experiments_are_clear_errors() {
    for (args, needle) in [
        (vec!["experiment", "figure-99"], "no experiment 'figure-99'"),
        (vec!["experiment", "descriptors", "--scale", "0"], "--scale"),
        (vec!["experiment", "descriptors", "--shard", "4/3"], "shard"),
        (vec!["reproduce", "--only", "noise,nope"], "no experiment 'nope'"),
        (
            vec!["experiment", "sim-to-real", "--real", "/nonexistent.csv"],
            "--real",
        ),
    ] {
        refused(&args, needle);
    }
}

/// The active experiment explores with the model in the loop inside its unit, in parallel over
/// objects: one thread and two give the same rows, bit for bit, and the confidence columns are
/// cumulative fractions.
#[test]
fn the_active_experiment_is_the_same_on_one_and_two_threads() {
    let dir = tempfile::tempdir().unwrap();
    let one = run_experiment("active", &dir.path().join("one"), &["--threads", "1"]);
    let two = run_experiment("active", &dir.path().join("two"), &["--threads", "2"]);
    assert!(one == two, "--threads 1 and 2 differ");
    let text = String::from_utf8(one).expect("UTF-8 CSV");
    let mut reader = csv::Reader::from_reader(text.as_bytes());
    let headers = reader.headers().expect("a header").clone();
    let column = |name: &str| headers.iter().position(|h| h == name).expect(name);
    let (strategy, local, motion, trial, confident, correct) = (
        column("strategy"),
        column("local_probability"),
        column("object_motion"),
        column("trial"),
        column("confident"),
        column("correct_at_stop"),
    );
    let mut last: Option<(String, String, f64)> = None;
    let mut active_rows = 0;
    for record in reader.records() {
        let record = record.expect("a CSV record");
        let c: f64 = record[confident].parse().expect("confident");
        let r: f64 = record[correct].parse().expect("correct_at_stop");
        assert!((0.0..=1.0).contains(&c) && r <= c + 1e-12, "{record:?}");
        let curve = (
            format!("{} {} {}", &record[strategy], &record[local], &record[motion]),
            record[trial].to_string(),
        );
        if let Some((v, t, previous)) = &last
            && (v, t) == (&curve.0, &curve.1)
        {
            assert!(c >= *previous, "confident falls along a curve: {record:?}");
        }
        active_rows += usize::from(curve.0.starts_with("active"));
        last = Some((curve.0, curve.1, c));
    }
    assert!(active_rows > 0, "no active rows:\n{text}");
    let trials = arm_calibration(&dir.path().join("one"), "active").expect("calibrated on the arm");
    assert_eq!(
        calibration_explorations(&dir.path().join("one")),
        [trials, trials]
    );
}

/// The end-to-end experiment judges the arm's touches with posteriors calibrated on the arm's
/// explorations, every setting's, as `active` does; under the paper's Eq. 15 it collects no
/// calibration exploration, and the guesses, so the accuracies, are the same.
#[test]
fn the_end_to_end_experiment_calibrates_on_the_arm_and_eq15_needs_no_calibration() {
    let dir = tempfile::tempdir().unwrap();
    let (calibrated, eq15) = (dir.path().join("calibrated"), dir.path().join("eq15"));
    run_experiment("end-to-end", &calibrated, &[]);
    let trials = arm_calibration(&calibrated, "end-to-end").expect("calibrated on the arm");
    assert_eq!(calibration_explorations(&calibrated), [trials, trials]);
    let config = std::fs::read_to_string(calibrated.join("end-to-end/config.json")).unwrap();
    let config: serde_json::Value = serde_json::from_str(&config).unwrap();
    let settings = config["sweep"]["settings"].as_array().expect("settings");
    assert_eq!(settings.len(), 2);
    for setting in settings {
        assert_eq!(setting["calibrated_on"], "arm_explorations", "{setting}");
    }
    run_experiment("end-to-end", &eq15, &["--posterior", "eq15"]);
    assert_eq!(arm_calibration(&eq15, "end-to-end"), None);
    assert_eq!(calibration_explorations(&eq15), [0, 0]);
    let (with_arm, paper) = (
        rows(&calibrated.join("end-to-end/end-to-end.csv")),
        rows(&eq15.join("end-to-end/end-to-end.csv")),
    );
    let accuracy = |rows: &[AccuracyRow]| -> Vec<(String, u32, f64)> {
        rows.iter()
            .map(|r| (r.factors.to_string(), r.n_readings, r.accuracy))
            .collect()
    };
    assert_eq!(accuracy(&with_arm), accuracy(&paper));
    let belief = |rows: &[AccuracyRow]| -> Vec<f64> { rows.iter().map(|r| r.reliability).collect() };
    assert_ne!(
        belief(&with_arm),
        belief(&paper),
        "the calibration moves the beliefs"
    );
}

/// Figs. 8 and 10 judge the same models (the top three descriptors on the default sensor),
/// calibrated on the same arm explorations: run after Fig. 8 in its folder, Fig. 10 fits nothing
/// (the calibrated models are read from the folder, none written again) and gives the rows it
/// gives alone.
#[test]
fn figures_on_the_default_sensor_share_their_arm_calibrated_models() {
    let dir = tempfile::tempdir().unwrap();
    let (shared, alone) = (dir.path().join("shared"), dir.path().join("alone"));
    run_experiment("strategy", &shared, &[]);
    let saved = |dir: &Path| -> Vec<(std::ffi::OsString, std::time::SystemTime)> {
        let mut files: Vec<_> = std::fs::read_dir(dir.join("models"))
            .expect("the run's models")
            .map(|entry| {
                let entry = entry.expect("a model file");
                let modified = entry.metadata().and_then(|m| m.modified()).expect("a time");
                (entry.file_name(), modified)
            })
            .collect();
        files.sort();
        files
    };
    let models = saved(&shared);
    let output = taction(&[
        "experiment",
        "perturbation",
        "--scale",
        "0.001",
        "--objects",
        "chess",
        "--out",
        shared.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("of which training 0.0)"), "{stderr}");
    assert_eq!(saved(&shared), models, "no model written again");
    let after = std::fs::read(shared.join("perturbation/perturbation.csv")).expect("assembled CSV");
    assert_eq!(after, run_experiment("perturbation", &alone, &[]));
    assert!(arm_calibration(&alone, "perturbation").is_some());
}

/// The trials of `experiment`'s calibration on the arm's explorations as its `config.json`
/// records them: at L = 0.5 and 1, as many explorations of each object at each as there are test
/// trials (`None`: no such calibration).
fn arm_calibration(out: &Path, experiment: &str) -> Option<u64> {
    let config = std::fs::read_to_string(out.join(experiment).join("config.json")).expect("config.json");
    let config: serde_json::Value = serde_json::from_str(&config).expect("JSON");
    let calibration = config.get("arm_calibration")?;
    assert_eq!(
        calibration["local_probabilities"],
        serde_json::json!([0.5, 1.0]),
        "{config}"
    );
    let trials = config["counts"]["trials"].as_u64().expect("counts.trials");
    assert_eq!(calibration["explorations"].as_u64(), Some(trials), "{config}");
    Some(trials)
}

/// The planner datasets of a run at L = 0.5 and at L = 1 on seeds of their own (no test curve
/// uses them: a test trial's stream is read at both L, common random numbers): the calibration
/// explorations, counted as files (a second sensor exploring the same streams adds its own).
fn calibration_explorations(out: &Path) -> [u64; 2] {
    // Per seed: the levels it was explored at, and its datasets (one per sensor that explored it).
    let mut seeds: std::collections::BTreeMap<u64, (BTreeSet<String>, u64)> = Default::default();
    for entry in std::fs::read_dir(out.join("data")).expect("the run's data") {
        let path = entry.expect("a data file").path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let Some(rest) = name.strip_prefix("chess-planner-L-") else {
            continue;
        };
        let level = rest.split('-').next().unwrap().to_string();
        let text = std::fs::read_to_string(&path).expect("a dataset");
        let header = text
            .lines()
            .nth(1)
            .and_then(|l| l.strip_prefix("# "))
            .expect("a header line");
        let header: serde_json::Value = serde_json::from_str(header).expect("a JSON header");
        // `fusion`'s own explorations start every object at a random pose: other datasets.
        if header.get("start_pose").is_some() {
            continue;
        }
        let seed = header["seed"].as_u64().expect("the dataset's seed");
        let (levels, files) = seeds.entry(seed).or_default();
        levels.insert(level);
        *files += 1;
    }
    ["0.5", "1"].map(|level| {
        seeds
            .values()
            .filter(|(levels, _)| levels.len() == 1 && levels.contains(level))
            .map(|(_, files)| files)
            .sum()
    })
}

/// `--codebook knn` trains every model of a run with the neighbour codebook: `config.json` says
/// so (with the PCA keeping 99%), the cached models are neighbour codebooks, and the same folder
/// refuses a run with the paper's GMM instead of mixing the two.
#[test]
fn an_experiment_runs_with_the_neighbour_codebook_and_keeps_it_apart() {
    let dir = tempfile::tempdir().unwrap();
    let letters = two_letters(dir.path());
    let out = dir.path().join("knn");
    let args = |codebook: &'static str| -> Vec<String> {
        [
            "experiment",
            "letters",
            "--scale",
            "0.02",
            "--letters",
            letters.to_str().unwrap(),
            "--codebook",
            codebook,
            "--out",
            out.to_str().unwrap(),
        ]
        .map(String::from)
        .to_vec()
    };
    let knn = args("knn");
    taction(&knn.iter().map(String::as_str).collect::<Vec<_>>());
    let config = std::fs::read_to_string(out.join("letters/config.json")).unwrap();
    let config: serde_json::Value = serde_json::from_str(&config).unwrap();
    assert_eq!(config["training"]["codebook"], "knn", "{config}");
    assert_eq!(config["training"]["variance_kept"], 0.99, "{config}");
    assert!(!rows(&out.join("letters/letters.csv")).is_empty());
    let models: Vec<_> = std::fs::read_dir(out.join("models")).unwrap().collect();
    assert_eq!(models.len(), 3, "one model per descriptor");
    for model in models {
        let text = std::fs::read_to_string(model.unwrap().path()).unwrap();
        assert!(text.contains("\"kind\":\"knn\""));
    }
    // A GMM run may not reuse the kNN run's folder.
    let gmm = args("gmm");
    refused(&gmm.iter().map(String::as_str).collect::<Vec<_>>(), "config.json");
}

#[test]
fn runs_of_two_seeds_pool_to_the_mean_of_every_trial_and_a_repeated_seed_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let (one, two) = (dir.path().join("one"), dir.path().join("two"));
    run_experiment("descriptors", &one, &["--seed", "1"]);
    run_experiment("descriptors", &two, &["--seed", "2"]);
    let pooled = dir.path().join("pooled");
    let arg = |p: &Path| p.display().to_string();
    let out = taction(&["pool", &arg(&one), &arg(&two), "--out", &arg(&pooled)]);
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(stdout.contains("descriptors: 2 seeds pooled (1, 2)"), "{stdout}");
    assert!(stdout.contains("calibration: "), "{stdout}");

    // Every seed's rows, then per point the mean over all of them and an interval around it.
    let union = rows(&pooled.join("descriptors/descriptors.csv"));
    let single = |root: &Path| rows(&root.join("descriptors/descriptors.csv"));
    assert_eq!(union, [single(&one), single(&two)].concat());
    let mut reader = csv::Reader::from_path(pooled.join("descriptors/descriptors_pooled.csv")).unwrap();
    let header = reader.headers().unwrap().clone();
    assert_eq!(
        header.iter().collect::<Vec<_>>(),
        [
            "experiment",
            "descriptor",
            "n_readings",
            "seeds",
            "trials",
            "accuracy",
            "accuracy_low",
            "accuracy_high",
            "reliability"
        ]
    );
    let mut points = 0;
    for record in reader.records() {
        let record = record.unwrap();
        let (descriptor, n): (&str, u32) = (&record[1], record[2].parse().unwrap());
        let number = |i: usize| record[i].parse::<f64>().unwrap();
        let at: Vec<&AccuracyRow> = union
            .iter()
            .filter(|r| r.descriptor == descriptor && r.n_readings == n)
            .collect();
        assert_eq!(record[4].parse::<usize>().unwrap(), at.len());
        let mean = at.iter().map(|r| r.accuracy).sum::<f64>() / at.len() as f64;
        assert!((number(5) - mean).abs() < 1e-12, "{descriptor} {n}");
        assert!(number(6) <= number(5) + 1e-12 && number(5) <= number(7) + 1e-12);
        points += 1;
    }
    assert_eq!(
        points,
        union.len() / 2 / union.iter().map(|r| r.trial).max().map_or(1, |t| t as usize + 1)
    );
    valid_svg_and_png(&pooled.join("descriptors/descriptors"));
    assert!(pooled.join("descriptors/descriptors_reliability.csv").is_file());

    // One seed twice is not two seeds; the output may not be one of the runs.
    let x = arg(&dir.path().join("x"));
    refused(&["pool", &arg(&one), &arg(&one), "--out", &x], "seed 1 in both");
    refused(
        &["pool", &arg(&one), &arg(&two), "--out", &arg(&two)],
        "holds an experiment's run",
    );

    // Every descriptor against the first, seed by seed: its difference at each point is the
    // difference of the two pooled curves.
    let first = union[0].descriptor.clone();
    let against = dir.path().join("against");
    let reference = format!("descriptor={first}");
    let out = taction(&[
        "pool",
        &arg(&one),
        &arg(&two),
        "--out",
        &arg(&against),
        "--against",
        &reference,
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(stdout.contains(&format!("against {reference} (")), "{stdout}");
    let pooled_accuracy = |descriptor: &str, n: u32| {
        let at: Vec<f64> = union
            .iter()
            .filter(|r| r.descriptor == descriptor && r.n_readings == n)
            .map(|r| r.accuracy)
            .collect();
        at.iter().sum::<f64>() / at.len() as f64
    };
    let differences = csv::Reader::from_path(against.join("descriptors/descriptors_differences.csv"))
        .unwrap()
        .into_records()
        .map(Result::unwrap)
        .collect::<Vec<_>>();
    let descriptors: std::collections::BTreeSet<&str> = union.iter().map(|r| r.descriptor.as_str()).collect();
    assert_eq!(
        differences.len(),
        (descriptors.len() - 1) * (points / descriptors.len())
    );
    for record in &differences {
        let (descriptor, n): (&str, u32) = (&record[1], record[3].parse().unwrap());
        assert_ne!(descriptor, first);
        let difference: f64 = record[7].parse().unwrap();
        let want = pooled_accuracy(descriptor, n) - pooled_accuracy(&first, n);
        assert!(
            (difference - want).abs() < 1e-12,
            "{descriptor} {n}: {difference} vs {want}"
        );
    }
    let y = arg(&dir.path().join("y"));
    refused(
        &[
            "pool",
            &arg(&one),
            &arg(&two),
            "--out",
            &y,
            "--against",
            "strategy=blind",
        ],
        "descriptors: its curves have no factor strategy",
    );
    assert!(!dir.path().join("y/descriptors").exists());
}
