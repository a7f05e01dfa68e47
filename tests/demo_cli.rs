//! The README's run command (`cargo xtask demo` runs `taction demo`) end to end: exactly as the README
//! writes it (no flags: the 12 `shapes`, 3000 training readings each from starts the arm can
//! reach, up to 30 touches of an object drawn with seed 1, stopping when sure), then `demo --object NAME` for every object of that set on the model the first run
//! cached, and on a tiny set (the two generated chess pieces) the exit status, every output file,
//! the model cache on a second run, and that the second run writes the same per-touch CSV.

use std::path::Path;
use std::process::Command;

const TOUCHES: usize = 2;
const HEADER: &str = "touch,object_true,object_guess,p_guess,p_true,entropy_nats";

/// `taction demo ARGS` run in `cwd` (where its default `results/demo` lands); the CGAL meshes come
/// from the user's cache whatever `cwd` is.
fn taction_demo(cwd: &Path, args: &[&str]) -> (bool, String, String) {
    let output = Command::new(env!("CARGO_BIN_EXE_taction"))
        .arg("demo")
        .args(args)
        .current_dir(cwd)
        .output()
        .expect("the taction binary runs");
    (
        output.status.success(),
        String::from_utf8_lossy(&output.stdout).into_owned(),
        String::from_utf8_lossy(&output.stderr).into_owned(),
    )
}

/// The rows of a `touches.csv` as fields.
fn touch_rows(out: &Path) -> Vec<Vec<String>> {
    let text = std::fs::read_to_string(out.join("touches.csv")).expect("touches.csv is written");
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some(HEADER), "{text}");
    lines
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect()
}

#[test]
fn the_readme_demo_command_succeeds_and_every_object_can_be_explored() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let (ok, stdout, stderr) = taction_demo(dir.path(), &[]);
    assert!(ok, "`taction demo` failed\nstdout:\n{stdout}\nstderr:\n{stderr}");
    let out = dir.path().join("results/demo");
    let rows = touch_rows(&out);
    let record: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).expect("run.json"))
            .expect("JSON");
    assert_eq!(record["model_evidence"], "appearance+contacts", "{record}");
    assert_eq!(record["touches_asked"], 30, "{record}");
    assert_eq!(record["stop_at_confidence"], 0.9, "{record}");
    let stop = record["stop_at_confidence"].as_f64().expect("the stop");
    // By default the run stops once one guess has held p >= 0.9 over two touches, else spends
    // the 30 touches.
    let p_guess = |row: &Vec<String>| -> f64 { row[3].parse().expect("p_guess is a number") };
    let last = rows.len() - 1;
    if record["ending"] == "stopped: confident" {
        assert!(last >= 1 && rows.len() <= 30, "{rows:?}");
        assert!(
            rows[last][2] == rows[last - 1][2]
                && p_guess(&rows[last]) >= stop
                && p_guess(&rows[last - 1]) >= stop,
            "the stop fires on a guess held at the default over two touches: {rows:?}"
        );
        assert!(
            !rows[..last]
                .windows(2)
                .any(|w| w[0][2] == w[1][2] && p_guess(&w[0]) >= stop && p_guess(&w[1]) >= stop),
            "and not before: {rows:?}"
        );
    } else {
        assert_eq!(rows.len(), 30, "{record}\n{rows:?}");
    }
    assert!(
        stdout.contains(&format!("after {} touches", rows.len())),
        "the touches used are reported:\n{stdout}"
    );
    // Evidence accumulates toward the truth: after the last touch the true object is more probable
    // than under the uniform prior over the 12 objects.
    let p_true: f64 = rows[last][4].parse().expect("p_true is a number");
    assert!(p_true > 1.0 / 12.0, "{:?}\n{stdout}", rows[last]);
    assert_eq!(record["p_true"].as_f64(), Some(p_true), "{record}");

    for object in taction::mesh::ObjectSet::shapes().object_names() {
        let (ok, stdout, stderr) =
            taction_demo(dir.path(), &["--object", object, "--touches", "3", "--no-stop"]);
        assert!(
            ok,
            "`taction demo --object {object}` failed\nstdout:\n{stdout}\nstderr:\n{stderr}"
        );
        assert!(stdout.contains("using the model trained before"), "{stdout}");
        let rows = touch_rows(&out);
        assert_eq!(rows.len(), 3, "{object}: {rows:?}");
        assert!(rows.iter().all(|r| r[1] == object), "{object}: {rows:?}");
    }
}

fn demo(out: &Path, extra: &[&str]) -> (bool, String, String) {
    let output = Command::new(env!("CARGO_BIN_EXE_taction"))
        .args(["demo", "--objects", "chess", "--training-readings", "12"])
        .args(["--touches", &TOUCHES.to_string(), "--seed", "3", "--out"])
        .arg(out)
        .args(extra)
        .output()
        .expect("the taction binary runs");
    (
        output.status.success(),
        String::from_utf8_lossy(&output.stdout).into_owned(),
        String::from_utf8_lossy(&output.stderr).into_owned(),
    )
}

/// Checks `touches.csv` row by row; returns its text.
fn check_touches(out: &Path) -> String {
    let text = std::fs::read_to_string(out.join("touches.csv")).expect("touches.csv is written");
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some(HEADER), "{text}");
    let rows: Vec<&str> = lines.collect();
    assert_eq!(rows.len(), TOUCHES, "one row per touch:\n{text}");
    let pieces = ["pawn", "rook"];
    let mut truth = None;
    for (i, row) in rows.iter().enumerate() {
        let fields: Vec<&str> = row.split(',').collect();
        assert_eq!(fields.len(), 6, "{row}");
        assert_eq!(fields[0].parse::<usize>().ok(), Some(i + 1), "{row}");
        // The same unknown object throughout, one of the set, and a guess among the set.
        assert!(pieces.contains(&fields[1]), "{row}");
        assert_eq!(*truth.get_or_insert(fields[1]), fields[1], "{row}");
        assert!(pieces.contains(&fields[2]), "{row}");
        let number = |s: &str| s.parse::<f64>().unwrap_or_else(|_| panic!("not a number: {row}"));
        let (p_guess, p_true, entropy) = (number(fields[3]), number(fields[4]), number(fields[5]));
        for p in [p_guess, p_true] {
            assert!((0.0..=1.0).contains(&p), "{row}");
        }
        // The guess is the most probable object: nothing, the true object included, beats it;
        // when the guess is the true object the two probabilities are the same number.
        assert!(p_guess >= p_true, "{row}");
        if fields[1] == fields[2] {
            assert_eq!(p_guess, p_true, "{row}");
        } else {
            // Two objects: the guess and the truth share the whole probability.
            assert!((p_guess + p_true - 1.0).abs() < 1e-9, "{row}");
        }
        // Two objects: the entropy of (p, 1 - p) in nats, at most ln 2.
        let h = |p: f64| if p > 0.0 { -p * p.ln() } else { 0.0 };
        assert!((entropy - (h(p_guess) + h(1.0 - p_guess))).abs() < 1e-9, "{row}");
        assert!(entropy <= 2f64.ln() + 1e-12, "{row}");
    }
    text
}

fn check_images(out: &Path) {
    let svg = std::fs::read_to_string(out.join("posterior.svg")).expect("posterior.svg is written");
    let doc = roxmltree::Document::parse(&svg).expect("posterior.svg is well-formed XML");
    assert_eq!(doc.root_element().tag_name().name(), "svg");
    assert!(
        doc.descendants().count() > 20,
        "posterior.svg has almost nothing in it:\n{svg}"
    );
    const PNG: &[u8] = b"\x89PNG\r\n\x1a\n";
    for name in ["posterior.png", "contact_sheet.png"] {
        let bytes = std::fs::read(out.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(bytes.starts_with(PNG) && bytes.len() > 100, "{name} is not a PNG");
    }
}

#[test]
fn demo_on_the_chess_pieces_writes_its_outputs_and_reuses_its_model() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let out = dir.path().join("demo");

    let (ok, stdout, stderr) = demo(&out, &[]);
    assert!(ok, "demo failed\nstdout:\n{stdout}\nstderr:\n{stderr}");
    assert!(stdout.contains("training:"), "{stdout}");
    assert!(!stdout.contains("using the model trained before"), "{stdout}");
    let first = check_touches(&out);
    check_images(&out);
    let models: Vec<_> = std::fs::read_dir(&out)
        .expect("the output folder")
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().starts_with("model-"))
        .collect();
    assert_eq!(models.len(), 1, "one cached model");

    let (ok, stdout, stderr) = demo(&out, &[]);
    assert!(ok, "second demo failed\nstdout:\n{stdout}\nstderr:\n{stderr}");
    assert!(
        stdout.contains("using the model trained before") && !stdout.contains("training:"),
        "the second run should reuse the cached model:\n{stdout}"
    );
    assert_eq!(check_touches(&out), first, "same arguments, same touches");
}

/// `--free-object` stands the unknown object on a free joint, made of the material asked for:
/// `run.json` records it and how far the arm's touches moved the object from where it settled;
/// for the paper's mocap object it records none.
#[test]
fn the_demo_records_a_free_objects_material_and_how_far_it_moved() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let out = dir.path().join("demo");
    let record = |out: &Path| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).expect("run.json")).expect("JSON")
    };
    let (ok, stdout, stderr) = demo(&out, &[]);
    assert!(ok, "demo failed\nstdout:\n{stdout}\nstderr:\n{stderr}");
    assert!(record(&out)["free_object"].is_null(), "{}", record(&out));
    let free = [
        "--free-object",
        "--object-density",
        "300",
        "--object-friction",
        "0.3",
    ];
    let (ok, stdout, stderr) = demo(&out, &free);
    assert!(ok, "free demo failed\nstdout:\n{stdout}\nstderr:\n{stderr}");
    let free = &record(&out)["free_object"];
    assert_eq!(free["density_kg_m3"], 300.0, "{free}");
    assert_eq!(free["friction"], 0.3, "{free}");
    let shift_mm = free["centre_shift_mm"].as_f64().expect("a shift");
    let turn_deg = free["turn_deg"].as_f64().expect("a turn");
    assert!(shift_mm >= 0.0 && turn_deg >= 0.0, "{free}");
    assert!(
        ["standing", "tipped", "off_table"].contains(&free["outcome"].as_str().unwrap_or("")),
        "{free}"
    );
    assert!(
        stdout.contains(&format!("the free object's centre moved {shift_mm:.2} mm")),
        "the motion is printed as recorded:\n{stdout}"
    );
}

/// `demo --strategy active` on the chess pieces in `out` with `extra` flags: its stdout and the
/// rows of its `touches.csv`. The paper's posterior (`--posterior eq15`): a model of 12 training
/// readings per object, calibrated, rightly stays near 0.5, and these tests are about the stop.
fn active_demo(out: &Path, extra: &[&str]) -> (String, Vec<Vec<String>>) {
    let output = Command::new(env!("CARGO_BIN_EXE_taction"))
        .args([
            "demo",
            "--objects",
            "chess",
            "--training-readings",
            "12",
            "--posterior",
            "eq15",
        ])
        .args(["--strategy", "active", "--touches", "8", "--seed", "4", "--out"])
        .arg(out)
        .args(extra)
        .output()
        .expect("the taction binary runs");
    let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
    assert!(
        output.status.success(),
        "active demo failed\nstdout:\n{stdout}\nstderr:\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    (stdout, touch_rows(out))
}

/// The confidence stop fires once one guess has held the threshold over the last
/// `--stop-held-readings` touches (two by default; one: the first touch whose best guess reaches
/// it), and the stopped run is the run without the stop cut short there (the stop changes no
/// random draw).
#[test]
fn the_active_demo_stops_exactly_when_the_threshold_is_crossed() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let out = dir.path().join("demo");
    let (stdout, full) = active_demo(&out, &["--no-stop"]);
    assert_eq!(full.len(), 8, "no stop: the whole budget\n{stdout}");
    let guess: Vec<&str> = full.iter().map(|r| r[2].as_str()).collect();
    let p_guess: Vec<f64> = full.iter().map(|r| r[3].parse().expect("p_guess")).collect();
    // A threshold strictly between two touches' confidences, crossed after the first touch.
    let crossing = (1..p_guess.len())
        .find(|&i| p_guess[i] > p_guess[..i].iter().cloned().fold(0.0, f64::max) + 1e-6)
        .unwrap_or_else(|| panic!("confidence never rises after touch 1: {p_guess:?}"));
    let below = p_guess[..crossing].iter().cloned().fold(0.0, f64::max);
    let threshold = 0.5 * (below + p_guess[crossing]);
    // Held over two touches: the first touch after the crossing that, with the one before it,
    // names one object at or above the threshold (or no stop within the budget).
    let held_twice = (crossing + 1..p_guess.len())
        .find(|&i| guess[i] == guess[i - 1] && p_guess[i] >= threshold && p_guess[i - 1] >= threshold);
    assert!(
        held_twice.is_some(),
        "the run holds the threshold over two touches after the crossing: {guess:?} {p_guess:?}"
    );
    let expected = [("1", Some(crossing)), ("2", held_twice)];
    for (held, stop) in expected {
        let args = [
            "--stop-at-confidence",
            &threshold.to_string(),
            "--stop-held-readings",
            held,
        ];
        let (stdout, stopped) = active_demo(&out, &args);
        let used = stop.map_or(full.len(), |i| i + 1);
        assert_eq!(
            stopped.len(),
            used,
            "held over {held}: threshold {threshold}, {guess:?} {p_guess:?}\n{stdout}"
        );
        assert_eq!(
            stopped[..],
            full[..used],
            "the stopped run is a prefix of the full run"
        );
        assert_eq!(stdout.contains("stopped: confident"), stop.is_some(), "{stdout}");
        assert!(
            stdout.contains(&format!("after {used} touches")),
            "the touches used are reported:\n{stdout}"
        );
        // run.json says which run the files beside it are.
        let record: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).expect("run.json"))
                .expect("JSON");
        assert_eq!(record["strategy"], "active");
        assert_eq!(record["posterior"], "eq15");
        assert_eq!(record["seed"], 4);
        assert_eq!(
            record["stop_held_readings"].as_u64(),
            Some(held.parse().expect("a count"))
        );
        assert_eq!(record["stop_at_confidence"].as_f64(), Some(threshold));
        assert_eq!(record["touches"].as_u64(), Some(used as u64));
        assert_eq!(record["touches_asked"], 8);
        let ending = if stop.is_some() {
            "stopped: confident"
        } else {
            "the touch budget spent"
        };
        assert_eq!(record["ending"], ending);
    }
    let (_, _, stderr) = taction_demo(dir.path(), &["--stop-at-confidence", "1.5"]);
    assert!(stderr.contains("--stop-at-confidence"), "{stderr}");
    let (ok, _, stderr) = taction_demo(dir.path(), &["--no-stop", "--stop-at-confidence", "0.9"]);
    assert!(
        !ok && stderr.contains("--no-stop") && stderr.contains("--stop-at-confidence"),
        "a stop and no stop at once is refused: {stderr}"
    );
}

/// `--gain` is recorded in `run.json` (`appearance` by default), and the contact's gain, on a model
/// that weighs contacts, chooses other touches from the same seed (the first differs: the
/// appearance gain scores every candidate alike before any reading, the contact's does not).
#[test]
fn the_gain_is_recorded_and_the_contacts_gain_chooses_other_touches() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let out = dir.path().join("demo");
    let read_record = || -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).expect("run.json")).expect("JSON")
    };
    let (_, appearance) = active_demo(&out, &["--no-stop"]);
    let record = read_record();
    assert_eq!(record["gain"], "appearance");
    assert_eq!(record["model_evidence"], "appearance+contacts");
    let (_, identity) = active_demo(&out, &["--no-stop", "--gain", "identity"]);
    assert_eq!(read_record()["gain"], "identity");
    assert_eq!(identity.len(), appearance.len());
    assert_ne!(
        identity[0], appearance[0],
        "the first touch is chosen differently"
    );
    let (_, again) = active_demo(&out, &["--no-stop", "--gain", "identity"]);
    assert_eq!(again, identity, "the same seed, the same touches");
}
