//! Fig. 16b, trained and tested on recorded frames (`taction experiment real-frames`): the shipped
//! example end to end, known answers on constructed recordings, the per-trial splits, and the
//! import of user recordings (sizes, bad values, calibration). Real descriptors, real training.

use std::collections::BTreeSet;
use std::path::Path;
use std::process::{Command, Output};

use taction::dataset::{Calibration, RealImport, parse_real_csv};
use taction::dataset::{ContactStatus, Dataset, Strategy};
use taction::experiment::{AccuracyRow, PerObjectRow, ReliabilityRow};
use taction::paper::EXAMPLE_REAL_CSV;
use taction::paper::{prune, scaled_split_sizes, trial_split};

/// The figure varies only the descriptor: no factor column.
const ACCURACY_HEADER: &str = "experiment,descriptor,trial,n_readings,accuracy,reliability,seed,stream_seed";
const PER_OBJECT_HEADER: &str = "experiment,descriptor,trial,object,n_readings,correct,p_true";

fn taction(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_taction"))
        .args(args)
        .output()
        .expect("the taction binary runs")
}

/// The rows of `experiment real-frames --trials 2` on the recording `text`, and its per-object
/// rows.
fn two_trials_of(text: &str) -> (Vec<AccuracyRow>, Vec<PerObjectRow>) {
    let dir = tempfile::tempdir().unwrap();
    let out = trials_of(text, 2, dir.path());
    assert_reliability_per_descriptor(&out);
    (
        rows(&out),
        read_csv(
            &out.join("real-frames/real-frames_per_object.csv"),
            PER_OBJECT_HEADER,
        ),
    )
}

/// Runs `experiment real-frames --trials N` on the recording `text`, written in `dir`; its output
/// folder.
fn trials_of(text: &str, trials: usize, dir: &Path) -> std::path::PathBuf {
    let real = dir.join("recording.csv");
    std::fs::write(&real, text).unwrap();
    let out = dir.join("out");
    run_ok(&[
        "experiment",
        "real-frames",
        "--real",
        real.to_str().unwrap(),
        "--trials",
        &trials.to_string(),
        "--out",
        out.to_str().unwrap(),
    ]);
    out
}

/// The run's reliability table: one curve per descriptor, its ten bins pooling both trials'
/// beliefs, with the curve's ECE on each row; and its diagram.
fn assert_reliability_per_descriptor(out: &Path) {
    let table: Vec<ReliabilityRow> =
        csv::Reader::from_path(out.join("real-frames/real-frames_reliability.csv"))
            .unwrap()
            .deserialize()
            .collect::<Result<_, _>>()
            .unwrap();
    assert_eq!(table.len(), 10 * 6, "ten bins for each of the six descriptors");
    for curve in table.chunks(10) {
        assert!(
            curve
                .iter()
                .all(|r| r.descriptor == curve[0].descriptor && r.ece == curve[0].ece)
        );
        assert!(curve.iter().map(|r| r.count).sum::<u64>() > 0);
        assert!(curve[0].ece.is_some_and(|e| (0.0..=1.0).contains(&e)));
    }
    assert!(out.join("real-frames/real-frames-reliability.svg").is_file());
}

fn run_ok(args: &[&str]) {
    let output = taction(args);
    assert!(
        output.status.success(),
        "taction {}: {}\n{}",
        args.join(" "),
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
}

fn rows(out: &Path) -> Vec<AccuracyRow> {
    read_csv(&out.join("real-frames/real-frames.csv"), ACCURACY_HEADER)
}

/// The rows of `csv`, whose first line must be `header`.
fn read_csv<R: serde::de::DeserializeOwned>(csv: &Path, header: &str) -> Vec<R> {
    let text = std::fs::read_to_string(csv).unwrap_or_else(|e| panic!("{}: {e}", csv.display()));
    assert_eq!(text.lines().next(), Some(header), "{}", csv.display());
    csv::Reader::from_reader(text.as_bytes())
        .deserialize()
        .collect::<Result<Vec<R>, _>>()
        .unwrap_or_else(|e| panic!("{}: {e}", csv.display()))
}

/// A 6x6 recording: `frames[label]` lists each frame's 36 raw values.
fn recording(frames: &[(&str, Vec<Vec<f64>>)]) -> String {
    recording_of_grid(6, 6, frames)
}

/// A `rows x cols` recording: `frames[label]` lists each frame's raw values, row by row.
fn recording_of_grid(rows: usize, cols: usize, frames: &[(&str, Vec<Vec<f64>>)]) -> String {
    let mut text = String::from("label");
    for r in 0..rows {
        for c in 0..cols {
            text.push_str(&format!(",r{r}c{c}"));
        }
    }
    text.push('\n');
    for (label, list) in frames {
        for frame in list {
            let values: Vec<String> = frame.iter().map(|v| v.to_string()).collect();
            text.push_str(&format!("{label},{}\n", values.join(",")));
        }
    }
    text
}

/// Mean accuracy and reliability over every row with `n_readings == n`.
fn mean_at(rows: &[AccuracyRow], n: u32) -> (f64, f64) {
    let at: Vec<&AccuracyRow> = rows.iter().filter(|r| r.n_readings == n).collect();
    assert!(!at.is_empty(), "no rows at {n} readings");
    let k = at.len() as f64;
    (
        at.iter().map(|r| r.accuracy).sum::<f64>() / k,
        at.iter().map(|r| r.reliability).sum::<f64>() / k,
    )
}

#[test]
fn the_shipped_example_runs_end_to_end_with_every_descriptor_and_trial() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    run_ok(&[
        "experiment",
        "real-frames",
        "--scale",
        "0.02",
        "--trials",
        "3",
        "--out",
        out,
    ]);
    let rows = rows(dir.path());
    let descriptors: BTreeSet<&str> = rows.iter().map(|r| r.descriptor.as_str()).collect();
    assert_eq!(descriptors.len(), 6, "{descriptors:?}");
    let trials: BTreeSet<u32> = rows.iter().map(|r| r.trial).collect();
    assert_eq!(trials, BTreeSet::from([0, 1, 2]));
    // 8 frames per vowel, scale 0.02 -> 7 used: 4 training, 1 validation, 2 test.
    assert!(
        rows.iter()
            .all(|r| r.experiment == "real-frames" && r.factors.is_empty())
    );
    assert!(rows.iter().all(|r| (1..=2).contains(&r.n_readings)));
    assert!(rows.iter().all(|r| (0.0..=1.0).contains(&r.accuracy)));
    let config = std::fs::read_to_string(dir.path().join("real-frames/config.json")).unwrap();
    for needle in [
        "\"train\": 4",
        "\"validation\": 1",
        "\"test\": 2",
        "\"dropped\": 0",
        "\"kept\": 8",
        "\"seed\": 1",
    ] {
        assert!(config.contains(needle), "config.json lacks {needle}:\n{config}");
    }
    assert!(dir.path().join("real-frames/real-frames.png").exists());
    // The shipped example is synthetic: its plot does not claim a real sensor, and its band says
    // what it spans.
    let svg = std::fs::read_to_string(dir.path().join("real-frames/real-frames.svg")).unwrap();
    assert!(
        svg.contains("Trained and tested on example frames (synthetic)") && !svg.contains("real sensor"),
        "the title of the example's plot"
    );
    assert!(svg.contains("band: lowest to highest trial"));
}

#[test]
fn two_labels_with_disjoint_constant_frames_are_told_apart_after_one_reading() {
    let bar = |rows: std::ops::Range<usize>| -> Vec<f64> {
        (0..36)
            .map(|k| if rows.contains(&(k / 6)) { 900.0 } else { 0.0 })
            .collect()
    };
    let cross: Vec<f64> = (0..36)
        .map(|k| if k / 6 == 2 || k % 6 == 2 { 500.0 } else { 0.0 })
        .collect();
    let (rows, per_object) = two_trials_of(&recording(&[("A", vec![bar(0..3); 14]), ("B", vec![cross; 14])]));
    for r in rows.iter().filter(|r| r.n_readings == 1) {
        assert_eq!(r.accuracy, 1.0, "{} trial {}", r.descriptor, r.trial);
        // Each label, named, right on its own.
        let labels: Vec<(&str, bool)> = per_object
            .iter()
            .filter(|o| (&o.descriptor, o.trial, o.n_readings) == (&r.descriptor, r.trial, 1))
            .map(|o| (o.object.as_str(), o.correct))
            .collect();
        assert_eq!(
            labels,
            [("A", true), ("B", true)],
            "{} trial {}",
            r.descriptor,
            r.trial
        );
    }
}

#[test]
fn labels_sharing_the_same_frames_stay_at_chance() {
    let frame: Vec<f64> = (0..36).map(|k| (k % 7) as f64 * 100.0).collect();
    let labels = ["A", "E", "I", "O"];
    let frames: Vec<(&str, Vec<Vec<f64>>)> = labels.iter().map(|l| (*l, vec![frame.clone(); 14])).collect();
    let (rows, per_object) = two_trials_of(&recording(&frames));
    assert!(
        per_object.iter().all(|o| (o.p_true - 0.25).abs() < 1e-9),
        "every label's own probability stays at 1/4"
    );
    // Identical evidence for every label: the belief stays at the uniform prior.
    for n in 1..=4 {
        let (_, reliability) = mean_at(&rows, n);
        assert!(
            (reliability - 0.25).abs() < 1e-9,
            "p(true) {reliability} after {n}"
        );
    }
    let (accuracy, _) = mean_at(&rows, 1);
    assert!(accuracy <= 0.25 + 1e-9, "accuracy {accuracy} above chance");
}

#[test]
fn splits_are_disjoint_seeded_and_differ_across_trials() {
    let real = parse_real_csv(EXAMPLE_REAL_CSV, "example", &RealImport::default()).unwrap();
    let (kept, counts) = prune(&real, 0.1);
    assert_eq!(kept.len(), 40);
    assert!(counts.values().all(|c| (c.kept, c.dropped) == (8, 0)));
    let kept: Vec<_> = kept.into_iter().cloned().collect();
    let sizes = scaled_split_sizes(8, 1.0).unwrap();
    let lines = |part: &[&taction::dataset::RealReading]| -> Vec<String> {
        part.iter().map(|r| r.place.to_string()).collect()
    };
    let mut trials = Vec::new();
    for trial in 0..7 {
        let split = trial_split(&kept, sizes, 1, trial).unwrap();
        let (train, validation, test) = (lines(&split.train), lines(&split.validation), lines(&split.test));
        assert_eq!((train.len(), validation.len(), test.len()), (25, 5, 10));
        let all: BTreeSet<&String> = train.iter().chain(&validation).chain(&test).collect();
        assert_eq!(all.len(), 40, "trial {trial}: a frame is in two sets");
        let again = trial_split(&kept, sizes, 1, trial).unwrap();
        assert_eq!(lines(&again.test), test, "trial {trial} is not deterministic");
        trials.push(test);
    }
    let distinct: BTreeSet<&Vec<String>> = trials.iter().collect();
    assert_eq!(distinct.len(), 7, "every trial has its own split");
}

#[test]
fn frames_below_the_contact_threshold_are_pruned_and_counted() {
    let contact: Vec<f64> = (0..36).map(|k| if k % 5 == 0 { 800.0 } else { 10.0 }).collect();
    let touchless = vec![30.0; 36];
    let text = recording(&[
        ("A", vec![contact.clone(), touchless.clone(), contact.clone()]),
        ("B", vec![touchless.clone(), touchless]),
    ]);
    let real = parse_real_csv(&text, "t.csv", &RealImport::default()).unwrap();
    let (kept, counts) = prune(&real, 0.1);
    assert_eq!(kept.len(), 2);
    assert_eq!((counts["A"].kept, counts["A"].dropped), (2, 1));
    assert_eq!((counts["B"].kept, counts["B"].dropped), (0, 2));
}

#[test]
fn too_few_frames_after_pruning_is_an_error_naming_the_label() {
    let contact: Vec<f64> = (0..36).map(|k| if k % 4 == 0 { 800.0 } else { 0.0 }).collect();
    let text = recording(&[("A", vec![contact.clone(); 10]), ("B", vec![contact; 2])]);
    let dir = tempfile::tempdir().unwrap();
    let real = dir.path().join("short.csv");
    std::fs::write(&real, text).unwrap();
    let output = taction(&[
        "experiment",
        "real-frames",
        "--real",
        real.to_str().unwrap(),
        "--out",
        dir.path().join("out").to_str().unwrap(),
    ]);
    assert!(!output.status.success());
    let err = String::from_utf8_lossy(&output.stderr);
    assert!(err.contains("short.csv") && err.contains("'B'"), "{err}");
}

#[test]
fn imports_reject_bad_frames_with_their_line_and_accept_2_to_128_taxels() {
    let frame = vec!["1"; 36].join(",");
    let header = recording(&[]);
    let short = format!("{header}A,{frame}\nA,1,2,3\n");
    let err = parse_real_csv(&short, "f.csv", &RealImport::default())
        .unwrap_err()
        .to_string();
    assert!(err.contains("f.csv") && err.contains("line 3"), "{err}");
    let nan = format!("{header}A,{frame}\n\nA,{}\n", ["nan"; 36].join(","));
    let err = parse_real_csv(&nan, "f.csv", &RealImport::default())
        .unwrap_err()
        .to_string();
    assert!(err.contains("line 4") && err.contains("not finite"), "{err}");

    let grid = |side: usize| -> String {
        let names: Vec<String> = (0..side * side)
            .map(|k| format!("r{}c{}", k / side, k % side))
            .collect();
        let values = vec!["5"; side * side].join(",");
        format!("label,{}\nA,{values}\n", names.join(","))
    };
    for side in [2, 4, 32, 128] {
        let data = parse_real_csv(&grid(side), "g.csv", &RealImport::default()).unwrap();
        assert_eq!((data.rows, data.cols), (side, side));
    }
    for side in [1, 129] {
        let err = parse_real_csv(&grid(side), "g.csv", &RealImport::default())
            .unwrap_err()
            .to_string();
        assert!(err.contains("2 to 128"), "{side}: {err}");
    }
}

#[test]
fn a_calibration_applies_gain_and_offset_per_taxel() {
    let mut calibration = String::from("# gains and offsets\ntaxel,gain,offset\n");
    for k in 0..36 {
        let (gain, offset) = if k == 0 { (2.0, 10.0) } else { (1.0, 0.0) };
        calibration.push_str(&format!("r{}c{},{gain},{offset}\n", k / 6, k % 6));
    }
    let calibration = Calibration::parse(&calibration, "cal.csv").unwrap();
    let mut frame = vec![50.0; 36];
    frame[0] = 60.0;
    frame[1] = 100.0;
    let text = recording(&[("A", vec![frame])]);
    let options = RealImport {
        calibration: Some(calibration),
        ..RealImport::default()
    };
    let data = parse_real_csv(&text, "f.csv", &options).unwrap();
    let values = data.readings[0].image.values();
    // Taxel 0: 2 * (60 - 10) = 100, the file's largest value with taxel 1.
    assert_eq!((values[0], values[1], values[2]), (1.0, 1.0, 0.5));

    let missing = "taxel,gain,offset\nr0c0,1,0\nr1c1,1,0\n";
    let err = Calibration::parse(missing, "cal.csv").unwrap_err().to_string();
    assert!(err.contains("cal.csv") && err.contains("missing"), "{err}");
    let bad = "taxel,gain,offset\nr0c0,inf,0\n";
    let err = Calibration::parse(bad, "cal.csv").unwrap_err().to_string();
    assert!(err.contains("line 2") && err.contains("gain"), "{err}");
}

#[test]
fn a_synthetic_mark_says_the_frames_are_not_a_real_sensors() {
    let example = parse_real_csv(EXAMPLE_REAL_CSV, "example", &RealImport::default()).unwrap();
    assert!(example.synthetic);
    assert_eq!(example.frames_words(), "example frames (synthetic)");
    let frame: Vec<f64> = (0..36).map(|k| k as f64).collect();
    let recorded =
        parse_real_csv(&recording(&[("A", vec![frame])]), "r.csv", &RealImport::default()).unwrap();
    assert!(!recorded.synthetic);
    assert_eq!(recorded.frames_words(), "real sensor frames");
}

/// The largest raw value of a frames file: what import divides by.
fn file_max(text: &str) -> f64 {
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("label"))
        .flat_map(|l| l.split(',').skip(1))
        .map(|v| v.trim().parse::<f64>().unwrap())
        .fold(0.0, f64::max)
}

/// `dataset import` of the shipped example, then `train` and `recognize` on it: the recorded frames
/// go through the ordinary pipeline, with the very images the real-frames experiment describes.
#[test]
fn imported_frames_train_and_recognise_with_the_experiments_images() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).display().to_string();
    let example = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/real_letters_example.csv");
    // The frames themselves are no dataset; the error says how to make one.
    let output = taction(&[
        "train",
        "--dataset",
        example.to_str().unwrap(),
        "--descriptor",
        "polar-fourier",
        "--out",
        &p("never.json"),
    ]);
    let err = String::from_utf8_lossy(&output.stderr);
    assert!(
        !output.status.success()
            && err.contains("not a taction dataset")
            && err.contains("taction dataset import"),
        "{err}"
    );
    run_ok(&[
        "dataset",
        "import",
        example.to_str().unwrap(),
        "--out",
        &p("example.csv"),
    ]);
    let imported = Dataset::read(&dir.path().join("example.csv")).unwrap();
    assert_eq!(imported.header().objects, ["A", "E", "I", "O", "U"]);
    assert_eq!(
        (imported.header().sensor.rows, imported.header().sensor.cols),
        (6, 6)
    );
    assert_eq!(imported.len(), 40);
    assert!(
        imported
            .readings()
            .iter()
            .all(|r| r.status == ContactStatus::Converged && r.strategy == Strategy::Recorded)
    );
    // Known answers: the first frame is `A,7,12,34,38,...`, divided by the file's largest value.
    let max = file_max(EXAMPLE_REAL_CSV);
    assert!(max > 800.0, "{max}");
    let first = imported.readings()[0].image.values();
    assert_eq!(&first[..4], &[7.0 / max, 12.0 / max, 34.0 / max, 38.0 / max]);
    // Every image is the one the experiment keeps, in file order.
    let real = parse_real_csv(EXAMPLE_REAL_CSV, "example", &RealImport::default()).unwrap();
    let (kept, _) = prune(&real, 0.1);
    assert_eq!(kept.len(), imported.len());
    for (frame, reading) in kept.iter().zip(imported.readings()) {
        assert_eq!((&frame.label, &frame.image), (&reading.object, &reading.image));
    }
    // The square root of Sec. V-F, as `experiment real-frames --square-root` takes it.
    run_ok(&[
        "dataset",
        "import",
        example.to_str().unwrap(),
        "--square-root",
        "--out",
        &p("rooted.csv"),
    ]);
    let rooted = Dataset::read(&dir.path().join("rooted.csv")).unwrap();
    assert_eq!(rooted.readings()[0].image.values()[1], (12.0 / max).sqrt());

    run_ok(&[
        "train",
        "--dataset",
        &p("example.csv"),
        "--descriptor",
        "polar-fourier",
        "--out",
        &p("model.json"),
    ]);
    run_ok(&[
        "recognize",
        "--model",
        &p("model.json"),
        "--dataset",
        &p("example.csv"),
        "--readings",
        "1..4",
        "--out",
        &p("out"),
    ]);
    let accuracy = std::fs::read_to_string(dir.path().join("out/accuracy.csv")).unwrap();
    assert_eq!(accuracy.lines().count(), 1 + 4, "{accuracy}");
    assert!(dir.path().join("out/accuracy.svg").exists());
}

/// Import keeps the frames the experiment prunes as `no_contact` readings, applies a calibration,
/// and names the file and line of a malformed frame (writing nothing).
#[test]
fn import_prunes_calibrates_and_names_a_malformed_line() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).display().to_string();
    let contact: Vec<f64> = (0..36).map(|k| if k % 5 == 0 { 800.0 } else { 10.0 }).collect();
    let touchless = vec![30.0; 36];
    let text = recording(&[
        ("A", vec![contact.clone(), touchless.clone(), contact.clone()]),
        ("B", vec![touchless, contact]),
    ]);
    std::fs::write(dir.path().join("frames.csv"), &text).unwrap();
    let mut calibration = String::from("taxel,gain,offset\n");
    for k in 0..36 {
        let (gain, offset) = if k == 0 { (0.5, 0.0) } else { (1.0, 0.0) };
        calibration.push_str(&format!("r{}c{},{gain},{offset}\n", k / 6, k % 6));
    }
    std::fs::write(dir.path().join("cal.csv"), calibration).unwrap();
    run_ok(&[
        "dataset",
        "import",
        &p("frames.csv"),
        "--calibration",
        &p("cal.csv"),
        "--out",
        &p("d.csv"),
    ]);
    let d = Dataset::read(&dir.path().join("d.csv")).unwrap();
    let statuses: Vec<(&str, ContactStatus)> = d
        .readings()
        .iter()
        .map(|r| (r.object.as_str(), r.status))
        .collect();
    use ContactStatus::{Converged, NoContact};
    assert_eq!(
        statuses,
        [
            ("A", Converged),
            ("A", NoContact),
            ("A", Converged),
            ("B", NoContact),
            ("B", Converged)
        ]
    );
    // Taxel r0c0 reads 800 at half gain: 400 of the file's largest, 800 (taxel r0c5).
    assert_eq!(&d.readings()[0].image.values()[..2], &[0.5, 10.0 / 800.0]);

    let lines: Vec<&str> = text.lines().collect();
    let short = text.replace(lines[2], "A,1,2,3");
    std::fs::write(dir.path().join("bad.csv"), short).unwrap();
    let output = taction(&["dataset", "import", &p("bad.csv"), "--out", &p("bad_dataset.csv")]);
    assert_eq!(output.status.code(), Some(1));
    let err = String::from_utf8_lossy(&output.stderr);
    assert!(err.contains("bad.csv") && err.contains("line 3"), "{err}");
    assert!(!dir.path().join("bad_dataset.csv").exists());

    let output = taction(&[
        "dataset",
        "import",
        &p("frames.csv"),
        "--contact-threshold",
        "2",
        "--out",
        &p("x.csv"),
    ]);
    assert_eq!(output.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&output.stderr).contains("--contact-threshold"));
}

/// Fig. 17 on a recording of another grid than the paper's 6x6 (issue 73): given the array's
/// taxel pitch, the simulated pad follows the recording (its grid at that pitch, the figure's 10%
/// covering and 30% noise), and the models learn and are judged on frames of that grid; without
/// the pitch the run is refused by name before anything is collected.
#[test]
fn sim_to_real_simulates_a_pad_of_the_recordings_grid_at_its_pitch() {
    let frames: Vec<(&str, Vec<Vec<f64>>)> = ["A", "B"]
        .into_iter()
        .enumerate()
        .map(|(j, label)| {
            let frame = |i: usize| (0..40).map(|t| ((t * (i + j + 2)) % 7) as f64).collect();
            (label, (0..6).map(frame).collect())
        })
        .collect();
    let dir = tempfile::tempdir().unwrap();
    let real = dir.path().join("recording.csv");
    std::fs::write(&real, recording_of_grid(5, 8, &frames)).unwrap();
    let out = dir.path().join("out");
    let args = |pitch: &[&'static str]| {
        let mut args = vec!["experiment", "sim-to-real", "--scale", "0.01"];
        args.extend(pitch);
        args.extend(["--real", real.to_str().unwrap(), "--out", out.to_str().unwrap()]);
        args
    };
    let refused = taction(&args(&[]));
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert!(!refused.status.success(), "{stderr}");
    assert!(
        stderr.contains(
            "the frames are 5x8 taxels but the simulated sensor is 6x6: give the recording's --taxel-pitch-m"
        ),
        "{stderr}"
    );
    assert!(!out.join("data").exists(), "nothing was collected");

    run_ok(&args(&["--taxel-pitch-m", "0.0015"]));
    let config: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("sim-to-real/config.json")).unwrap()).unwrap();
    let sensor = &config["sweep"]["settings"][0]["sensor"];
    assert_eq!(
        (sensor["rows"].as_u64(), sensor["cols"].as_u64()),
        (Some(5), Some(8))
    );
    let near = |key: &str, want: f64| (sensor[key].as_f64().unwrap() - want).abs() < 1e-12;
    assert!(
        near("pad_width_m", 0.012) && near("pad_height_m", 0.0075) && near("thickness_m", 0.00075),
        "{sensor}"
    );
    assert!(near("noise_fraction", 0.3), "{sensor}");
    let datasets: Vec<_> = std::fs::read_dir(out.join("data"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    assert!(!datasets.is_empty());
    for path in datasets {
        let header = Dataset::read(&path).unwrap().header().sensor;
        assert_eq!((header.rows, header.cols), (5, 8), "{}", path.display());
    }
    let rows: Vec<AccuracyRow> = read_csv(&out.join("sim-to-real/sim-to-real.csv"), ACCURACY_HEADER);
    let described: BTreeSet<&str> = rows.iter().map(|r| r.descriptor.as_str()).collect();
    assert_eq!(
        described.len(),
        3,
        "the figure's three descriptors: {described:?}"
    );
}

/// A 6x6 recording of `presses` presses per label of `frames` frames each (`label,contact,...`):
/// each press its own blob, its frames nearly the same.
fn sequence_recording(labels: &[&str], presses: usize, frames: usize) -> String {
    let mut text = String::from("label,contact");
    for k in 0..36 {
        text.push_str(&format!(",r{}c{}", k / 6, k % 6));
    }
    text.push('\n');
    for (l, label) in labels.iter().enumerate() {
        for press in 0..presses {
            for frame in 0..frames {
                let centre = ((press * 7 + l * 3) % 5) as f64;
                let values: Vec<String> = (0..36)
                    .map(|k| {
                        let (r, c) = ((k / 6) as f64 - centre, (k % 6) as f64 - 2.5);
                        let v = 900.0 * (-(r * r + c * c) / (2.0 + l as f64)).exp() + frame as f64;
                        format!("{v:.0}")
                    })
                    .collect();
                text.push_str(&format!("{label},press-{press},{}\n", values.join(",")));
            }
        }
    }
    text
}

#[test]
fn a_recording_of_sequences_is_split_by_press_and_single_frames_as_before() {
    let real = parse_real_csv(
        &sequence_recording(&["A", "B"], 14, 3),
        "seq",
        &RealImport::default(),
    )
    .unwrap();
    let (kept, _) = prune(&real, 0.1);
    let kept: Vec<_> = kept.into_iter().cloned().collect();
    assert_eq!(kept.len(), 84);
    // Sizes count presses: 14 a label, 8 / 2 / 4 of them.
    let sizes = scaled_split_sizes(14, 1.0).unwrap();
    assert_eq!((sizes.train, sizes.validation, sizes.test), (8, 2, 4));
    for trial in 0..5 {
        let split = trial_split(&kept, sizes, 3, trial).unwrap();
        let presses = |part: &[&taction::dataset::RealReading]| -> BTreeSet<Option<u32>> {
            part.iter().map(|r| r.contact).collect()
        };
        let (train, validation, test) = (
            presses(&split.train),
            presses(&split.validation),
            presses(&split.test),
        );
        assert_eq!(
            (train.len(), validation.len(), test.len()),
            (16, 4, 8),
            "trial {trial}"
        );
        assert_eq!(
            (split.train.len(), split.validation.len(), split.test.len()),
            (48, 12, 24),
            "trial {trial}: every press whole"
        );
        assert!(
            train.is_disjoint(&test) && train.is_disjoint(&validation) && validation.is_disjoint(&test),
            "trial {trial}: a press lends frames to two parts"
        );
    }
    // A recording of single frames: each frame its own contact, the split the frames' own, as
    // before contacts existed (trial 2's seed: the experiment's split stream 6).
    let single = parse_real_csv(EXAMPLE_REAL_CSV, "example", &RealImport::default()).unwrap();
    let (kept, _) = prune(&single, 0.1);
    let kept: Vec<_> = kept.into_iter().cloned().collect();
    let sizes = scaled_split_sizes(8, 1.0).unwrap();
    let seed = taction::rng::substream(taction::rng::substream(1, 6), 2);
    let by_frame = taction::paper::split_per_label(kept.iter().collect(), |r| r.label.as_str(), sizes, seed);
    let split = trial_split(&kept, sizes, 1, 2).unwrap();
    let places = |part: &[&taction::dataset::RealReading]| -> Vec<String> {
        part.iter().map(|r| r.place.to_string()).collect()
    };
    let by_frame = by_frame.unwrap();
    assert_eq!(places(&split.test), places(&by_frame.test));
    assert_eq!(places(&split.train), places(&by_frame.train));
}

#[test]
fn the_experiment_on_sequences_counts_presses_in_its_config() {
    let dir = tempfile::tempdir().unwrap();
    let out = trials_of(&sequence_recording(&["A", "B"], 8, 2), 1, dir.path());
    let config: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("real-frames/config.json")).unwrap()).unwrap();
    assert_eq!(
        config["contacts"],
        serde_json::json!({"A": 8, "B": 8}),
        "{config}"
    );
    assert_eq!(
        config["split"],
        serde_json::json!({"train": 5, "validation": 1, "test": 2})
    );
    assert_eq!(config["pruning"]["A"]["kept"], 16);
    // The test part is two presses of two frames a label: the curve reaches four readings.
    let longest = rows(&out).iter().map(|r| r.n_readings).max();
    assert_eq!(longest, Some(4));
}
