//! The bad inputs and inconsistent flags a new user runs into, one test each, through the built
//! binary on real files in a temporary folder: each ends in one line naming the file or flag and
//! what is wrong (exit code 2 for a flag, 1 for a failure), never a panic or a backtrace, or in
//! what a Unix user expects.

mod recognize_toy;

use std::fs::{File, OpenOptions};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

use taction::dataset::ContactStatus;
use taction::dataset::Strategy;
use taction::dataset::{Dataset, DatasetHeader, Reading};
use taction::pose::Pose;
use taction::tactile::{SensorConfig, TactileImage};

fn taction(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_taction"))
        .args(args)
        .stdin(Stdio::null())
        .output()
        .unwrap()
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// The run failed with `code` and one `taction: ...` line (after any warnings), no panic; returns
/// that line.
fn fails_with(out: &Output, code: i32) -> String {
    let text = stderr(out);
    assert_eq!(out.status.code(), Some(code), "{text}");
    assert!(
        !text.contains("panicked") && !text.contains("RUST_BACKTRACE"),
        "{text}"
    );
    let last = text.lines().last().unwrap_or("").to_string();
    assert!(
        last.starts_with("taction: ")
            || last.starts_with("error: ")
            || last.starts_with("For more information"),
        "{text}"
    );
    if code == 2 && text.contains("For more information") {
        // clap's own refusal: the first line is the message.
        return text.lines().next().unwrap_or("").to_string();
    }
    last
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path.display().to_string()
}

/// `taction collect --objects chess FLAGS --out <temp>` fails with `code`; its message line.
fn chess_collect_fails(flags: &[&str], code: i32) -> String {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("d.csv").display().to_string();
    let mut args = vec!["collect", "--objects", "chess", "--out", &out];
    args.extend(flags);
    fails_with(&taction(&args), code)
}

const TETRA: &str = "v 0 0 0\nv 0.05 0 0\nv 0 0.05 0\nv 0 0 0.05\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";

/// The sense flags that put the pad 5 cm above the origin looking down.
fn sense_args<'a>(mesh: &'a str, out: &'a str) -> Vec<&'a str> {
    vec![
        "sense",
        "--mesh",
        mesh,
        "--pad-center",
        "0.01,0.01,0.1",
        "--pad-normal",
        "0,0,-1",
        "--out",
        out,
    ]
}

#[test]
fn a_closed_stdout_ends_the_program_quietly_with_success() {
    let dir = tempfile::tempdir().unwrap();
    let image = write(dir.path(), "image.csv", "0,0.5,1\n0.25,0.75,0\n");
    // `println!` (experiment list) and a buffered writer (describe) alike.
    for args in [
        vec!["experiment", "list"],
        vec!["describe", "--descriptor", "vectorize", "--image", &image],
    ] {
        let (reader, writer) = std::io::pipe().unwrap();
        drop(reader);
        let out = Command::new(env!("CARGO_BIN_EXE_taction"))
            .args(&args)
            .stdout(writer)
            .stderr(Stdio::piped())
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(0), "{args:?}: {}", stderr(&out));
        assert_eq!(stderr(&out), "", "{args:?}");
    }
}

#[test]
fn threads_beyond_a_few_per_core_are_refused_and_zero_means_every_core_everywhere() {
    let line = chess_collect_fails(&["--readings", "5", "--threads", "100000"], 2);
    assert!(line.contains("--threads") && line.contains("per core"), "{line}");
    // 0 is one meaning in both commands that have the flag: one thread per core.
    let listed = taction(&["experiment", "list", "--threads", "0"]);
    assert!(listed.status.success(), "{}", stderr(&listed));
    for command in ["collect", "experiment", "reproduce"] {
        let help = String::from_utf8_lossy(&taction(&[command, "--help"]).stdout).into_owned();
        assert!(
            help.contains("0 uses one per core; at most 4 per core"),
            "{command}: {help}"
        );
    }
}

#[test]
fn a_mesh_of_three_vertices_is_refused_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = write(
        dir.path(),
        "triangle.obj",
        "v 0 0 0\nv 0.05 0 0\nv 0 0.05 0\nf 1 2 3\n",
    );
    let out = dir.path().join("r.csv").display().to_string();
    for args in [
        sense_args(&mesh, &out),
        vec!["collect", "--objects", &mesh, "--readings", "2", "--out", &out],
    ] {
        let line = fails_with(&taction(&args), 1);
        assert!(
            line.contains("triangle.obj") && line.contains("at least 4") && !line.contains("MJCF"),
            "{line}"
        );
    }
}

#[test]
fn coordinates_that_are_not_metres_are_refused_with_the_fix() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = write(dir.path(), "huge.obj", &TETRA.replace("0.05", "1e30"));
    let out = dir.path().join("r.csv").display().to_string();
    let line = fails_with(&taction(&sense_args(&mesh, &out)), 1);
    assert!(
        line.contains("huge.obj") && line.contains("bounding diagonal 1.732e30 m"),
        "{line}"
    );
    assert!(!Path::new(&out).exists());
    let ds = dir.path().join("d.csv").display().to_string();
    let line = fails_with(
        &taction(&["collect", "--objects", &mesh, "--readings", "2", "--out", &ds]),
        1,
    );
    assert!(
        line.contains("huge.obj") && line.contains("--object-size-m"),
        "{line}"
    );
    assert!(!Path::new(&ds).exists());
}

/// Every command that builds objects refuses a mesh in millimetres before it simulates or writes
/// anything, and takes the one rescale flag, `--object-size-m`.
#[test]
fn every_command_refuses_millimetres_and_takes_object_size_m() {
    let dir = tempfile::tempdir().unwrap();
    let meshes = dir.path().join("mm");
    std::fs::create_dir(&meshes).unwrap();
    // A 50 mm tetrahedron written in millimetres: an 86.6 m diagonal when read as metres.
    let mesh = write(&meshes, "box_mm.obj", &TETRA.replace("0.05", "50"));
    let folder = meshes.display().to_string();
    let out = dir.path().join("out").display().to_string();
    let sense_out = dir.path().join("sense.csv").display().to_string();
    let commands: [&[&str]; 6] = [
        &[
            "experiment",
            "descriptors",
            "--objects",
            &folder,
            "--scale",
            "0.02",
            "--out",
            &out,
        ],
        &[
            "reproduce",
            "--only",
            "noise",
            "--objects",
            &folder,
            "--scale",
            "0.02",
            "--out",
            &out,
        ],
        &["demo", "--objects", &folder, "--out", &out],
        &["scene", "export", "--object", &mesh, "--out", &out],
        &["objects", "export", &folder, "--out", &out],
        &sense_args(&mesh, &sense_out),
    ];
    for args in commands {
        let line = fails_with(&taction(args), 1);
        assert!(
            line.contains("box_mm") && line.contains("86.6 m") && line.contains("--object-size-m"),
            "{args:?}: {line}"
        );
        assert!(!Path::new(&out).join("scene.xml").exists(), "{args:?}");
    }
    // A metre-sized object is a table-top object for the free pad but out of the arm's reach.
    let metre = write(dir.path(), "metre.obj", &TETRA.replace("0.05", "1"));
    let line = fails_with(
        &taction(&["scene", "export", "--object", &metre, "--out", &out]),
        1,
    );
    assert!(line.contains("the arm's workspace"), "{line}");
    // Rescaled, the same file exports, at the size asked for.
    let scene = dir.path().join("scene");
    let done = taction(&[
        "scene",
        "export",
        "--object",
        &mesh,
        "--object-size-m",
        "0.1",
        "--out",
        &scene.display().to_string(),
    ]);
    assert!(done.status.success(), "{}", stderr(&done));
    let exported = taction::mesh::load(scene.join("box_mm.obj")).unwrap().mesh;
    let diagonal_m = exported.bounding_diagonal_m().unwrap();
    assert!((diagonal_m - 0.1).abs() < 1e-9, "{diagonal_m}");
    let line = fails_with(
        &taction(&[
            "objects",
            "export",
            &folder,
            "--object-size-m",
            "0",
            "--out",
            &out,
        ]),
        2,
    );
    assert!(line.contains("not a positive number of metres"), "{line}");
    // The free pad's commands take the flag their refusal names.
    let mut sensed = sense_args(&mesh, &sense_out);
    sensed.extend(["--object-size-m", "0.1"]);
    let done = taction(&sensed);
    assert!(done.status.success(), "{}", stderr(&done));
}

/// A quick look into the folder of an earlier run of another scale stops at once, naming the
/// folder and what differs, before any estimate or data collection.
#[test]
fn an_experiment_refuses_a_folder_of_another_scale_before_it_starts() {
    let dir = tempfile::tempdir().unwrap();
    let earlier = dir.path().join("strategy");
    std::fs::create_dir(&earlier).unwrap();
    std::fs::write(
        earlier.join("config.json"),
        r#"{"scale": 1.0, "seed": 1, "training": {"codebook": "gmm"}}"#,
    )
    .unwrap();
    let out = dir.path().display().to_string();
    let run = taction(&["experiment", "strategy", "--scale", "0.1", "--out", &out]);
    let line = fails_with(&run, 1);
    assert!(
        line.contains("scale 1, seed 1, codebook gmm")
            && line.contains("scale 0.1")
            && line.contains("--out"),
        "{line}"
    );
    assert!(!stderr(&run).contains("estimated duration"), "{}", stderr(&run));
    assert!(!earlier.join("units").exists());
    // Same scale, seed and codebook, but another configuration (e.g. written before a field was
    // added): refused before any dataset is collected.
    std::fs::write(
        earlier.join("config.json"),
        r#"{"scale": 0.1, "seed": 1, "training": {"codebook": "gmm"}}"#,
    )
    .unwrap();
    let line = fails_with(
        &taction(&["experiment", "strategy", "--scale", "0.1", "--out", &out]),
        1,
    );
    assert!(line.contains("different configuration"), "{line}");
    assert!(!dir.path().join("data").exists(), "no dataset collected");
}

/// Without `--codebook`, the experiments on the arm's own touches train with the product's
/// neighbour codebook and the paper's figures with its GMM: a folder of an earlier `active` run
/// with the GMM (the default before) is refused, and so is a figure's folder of a kNN run, each
/// naming both codebooks, before any data is collected.
#[test]
fn the_experiments_on_the_arms_touches_default_to_the_neighbour_codebook() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().display().to_string();
    for (experiment, theirs, ours) in [("active", "gmm", "knn"), ("strategy", "knn", "gmm")] {
        let earlier = dir.path().join(experiment);
        std::fs::create_dir(&earlier).unwrap();
        std::fs::write(
            earlier.join("config.json"),
            format!(r#"{{"scale": 0.1, "seed": 1, "training": {{"codebook": "{theirs}"}}}}"#),
        )
        .unwrap();
        let line = fails_with(
            &taction(&["experiment", experiment, "--scale", "0.1", "--out", &out]),
            1,
        );
        assert!(
            line.contains(&format!("scale 0.1, seed 1, codebook {theirs}"))
                && line.contains(&format!("scale 0.1, seed 1, codebook {ours}")),
            "{experiment}: {line}"
        );
    }
    assert!(!dir.path().join("data").exists(), "no dataset collected");
}

#[test]
fn an_obj_index_out_of_range_is_quoted_as_the_file_writes_it() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = write(
        dir.path(),
        "idx.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 2 3 5\n",
    );
    let out = dir.path().join("r.csv").display().to_string();
    let line = fails_with(&taction(&sense_args(&mesh, &out)), 1);
    assert!(
        line.contains(
            "idx.obj: line 5: vertex index 5 is out of range (the file has 4 vertices, numbered 1 to 4)"
        ),
        "{line}"
    );
}

#[test]
fn collect_warns_about_an_open_mesh_as_sense_does() {
    let dir = tempfile::tempdir().unwrap();
    let open = TETRA.rsplit_once("f 2 3 4").unwrap().0.to_string();
    let mesh = write(dir.path(), "open.obj", &open);
    let ds = dir.path().join("d.csv").display().to_string();
    let out = taction(&[
        "collect",
        "--objects",
        &mesh,
        "--readings",
        "2",
        "--contact-sheet",
        "0",
        "--allow-short",
        "--out",
        &ds,
    ]);
    let text = stderr(&out);
    assert!(out.status.success(), "{text}");
    assert!(
        text.contains("warning: object 'open'")
            && text.contains("open.obj")
            && text.contains("open boundary"),
        "{text}"
    );
}

/// `per_object` readings of each of `objects`, every one the same flat image of `sensor`'s size.
fn flat_dataset(sensor: SensorConfig, objects: &[&str], per_object: usize) -> Dataset {
    let header = DatasetHeader::new(
        sensor,
        "flat",
        objects.iter().map(|s| s.to_string()).collect(),
        "test",
        1,
    );
    let image = TactileImage::new(sensor.rows, sensor.cols, vec![0.5; sensor.rows * sensor.cols]).unwrap();
    let readings = (0..per_object)
        .flat_map(|_| objects.iter())
        .map(|object| Reading {
            image: image.clone(),
            object: object.to_string(),
            object_pose: Pose::IDENTITY,
            object_pose_after: None,
            status: ContactStatus::Converged,
            iterations: 3,
            strategy: Strategy::Sampler,
            cause: None,
            contact: None,
        })
        .collect();
    Dataset::new(header, readings).unwrap()
}

/// A model trained on the toy set (8x8 taxels: ridges, bumps, flat), in `dir`.
fn toy_model(dir: &Path) -> String {
    let train = dir.join("train.csv");
    recognize_toy::dataset(20, 1).write(&train).unwrap();
    let model = dir.join("model.json").display().to_string();
    let out = taction(&[
        "train",
        "--dataset",
        &train.display().to_string(),
        "--descriptor",
        "vectorize",
        "--k",
        "3",
        "--restarts",
        "1",
        "--out",
        &model,
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    model
}

#[test]
fn recognising_data_of_another_set_or_sensor_names_both_files_without_debug_dumps() {
    let dir = tempfile::tempdir().unwrap();
    let model = toy_model(dir.path());
    let other_set = dir.path().join("dragons.csv");
    flat_dataset(recognize_toy::sensor(), &["dragon", "bunny"], 12)
        .write(&other_set)
        .unwrap();
    let out_dir = dir.path().join("out").display().to_string();
    let line = fails_with(
        &taction(&[
            "recognize",
            "--model",
            &model,
            "--dataset",
            &other_set.display().to_string(),
            "--readings",
            "3",
            "--out",
            &out_dir,
        ]),
        1,
    );
    assert!(
        line.contains("dragons.csv: object 'bunny'") || line.contains("dragons.csv: object 'dragon'"),
        "{line}"
    );
    assert!(
        line.contains("model.json") && line.contains("ridges, bumps, flat"),
        "{line}"
    );

    let big = SensorConfig {
        rows: 14,
        cols: 14,
        ..recognize_toy::sensor()
    };
    let other_sensor = dir.path().join("14x14.csv");
    flat_dataset(big, &recognize_toy::OBJECTS, 4)
        .write(&other_sensor)
        .unwrap();
    let out = taction(&[
        "recognize",
        "--model",
        &model,
        "--dataset",
        &other_sensor.display().to_string(),
        "--out",
        &out_dir,
    ]);
    let line = fails_with(&out, 1);
    assert!(
        line.contains("14x14.csv") && line.contains("rows 8 (model) vs 14 (data)"),
        "{line}"
    );
    assert!(!stderr(&out).contains("SensorConfig"), "{}", stderr(&out));
    assert_eq!(stderr(&out).lines().count(), 1, "{}", stderr(&out));
}

#[test]
fn negative_numbers_reach_the_range_check_of_their_flag() {
    let line = chess_collect_fails(&["--perturb-deg", "-10"], 2);
    assert!(
        line.contains("--perturb-deg -10: is outside [0, 180] degrees"),
        "{line}"
    );
}

#[test]
fn every_command_with_a_seed_documents_it_alike_with_one_default() {
    let mut lines = Vec::new();
    for command in [
        "collect",
        "demo",
        "experiment",
        "reproduce",
        "scene export",
        "sense",
        "touch",
        "train",
    ] {
        let words: Vec<&str> = command.split(' ').chain(["--help"]).collect();
        let help = String::from_utf8_lossy(&taction(&words).stdout).into_owned();
        let at = help
            .find("--seed <N>")
            .unwrap_or_else(|| panic!("{command} has no --seed: {help}"));
        // The flag's own line (clap puts a short help beside the flag, a long one below it)
        // and the lines up to the next flag.
        let rest = &help[at + "--seed <N>".len()..];
        let (first, below) = rest.split_once('\n').unwrap_or((rest, ""));
        let entry: String = std::iter::once(first)
            .chain(below.lines().take_while(|l| !l.trim_start().starts_with('-')))
            .collect::<Vec<_>>()
            .join(" ");
        assert!(entry.contains("[default: 1]"), "{command}: {entry}");
        lines.push(entry.split_whitespace().collect::<Vec<_>>().join(" "));
    }
    assert!(lines.windows(2).all(|w| w[0] == w[1]), "{lines:#?}");
}

#[test]
fn a_covering_thicker_than_half_the_pad_is_refused_naming_the_limit() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = write(dir.path(), "t.obj", TETRA);
    let out = dir.path().join("r.csv").display().to_string();
    let mut args = sense_args(&mesh, &out);
    args.extend(["--thickness-m", "0.5"]);
    let line = fails_with(&taction(&args), 2);
    assert!(
        line.contains("--thickness-m: 0.5 is out of range: want <= half the pad side, 6 mm"),
        "{line}"
    );
}

#[test]
fn an_absurd_reading_count_is_refused_before_any_work() {
    let line = chess_collect_fails(&["--readings", "100000000000"], 2);
    assert!(
        line.contains("--readings 100000000000: want 1 to 1000000"),
        "{line}"
    );
}

#[test]
fn no_help_text_points_to_rust_code() {
    for command in [
        vec!["collect"],
        vec!["demo"],
        vec!["describe"],
        vec!["experiment"],
        vec!["reproduce"],
        vec!["merge"],
        vec!["pool"],
        vec!["objects", "export"],
        vec!["objects", "letters"],
        vec!["sense"],
        vec!["dataset", "show"],
        vec!["dataset", "export"],
        vec!["recognize"],
        vec!["touch"],
        vec!["train"],
    ] {
        let mut args = command.clone();
        args.push("--help");
        let help = String::from_utf8_lossy(&taction(&args).stdout).into_owned();
        assert!(
            !help.contains("::") && !help.contains("Config`"),
            "{command:?}: {help}"
        );
    }
    let help = String::from_utf8_lossy(&taction(&["experiment", "--help"]).stdout).into_owned();
    assert!(help.contains("a header `label,r0c0,r0c1,...`"), "{help}");
}

#[test]
fn dataset_show_prints_lengths_in_millimetres() {
    let dir = tempfile::tempdir().unwrap();
    let sensor = SensorConfig::square(6, 6, 0.012, 0.1 * 0.012);
    assert_eq!(sensor.thickness_m.to_string(), "0.0012000000000000001");
    let path = dir.path().join("d.csv");
    flat_dataset(sensor, &["a", "b"], 2).write(&path).unwrap();
    let out = taction(&["dataset", "show", &path.display().to_string()]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        text.contains("pad 12 mm x 12 mm, covering 1.2 mm, PSF sigma 0.5761 mm"),
        "{text}"
    );
}

#[test]
fn dataset_export_names_a_missing_dataset_and_refuses_to_overwrite_it() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.csv").display().to_string();
    let out = dir.path().join("d.npz");
    let out_arg = out.display().to_string();
    let line = fails_with(
        &taction(&[
            "dataset", "export", &missing, "--format", "npz", "--out", &out_arg,
        ]),
        1,
    );
    assert!(line.contains(&missing), "{line}");
    assert!(!out.exists());

    let path = dir.path().join("d.csv");
    flat_dataset(SensorConfig::square(6, 4, 0.012, 0.0012), &["a", "b"], 2)
        .write(&path)
        .unwrap();
    let csv = path.display().to_string();
    let line = fails_with(
        &taction(&["dataset", "export", &csv, "--format", "npz", "--out", &csv]),
        2,
    );
    assert!(line.contains("is the dataset itself"), "{line}");
    let line = fails_with(
        &taction(&["dataset", "export", &csv, "--format", "csv", "--out", &out_arg]),
        2,
    );
    assert!(
        line.contains("'csv' is not an export format (npz or parquet)"),
        "{line}"
    );

    let done = taction(&[
        "dataset", "export", &csv, "--format", "parquet", "--out", &out_arg,
    ]);
    assert!(done.status.success(), "{}", stderr(&done));
    let text = String::from_utf8_lossy(&done.stdout).into_owned();
    assert_eq!(
        text.trim(),
        format!("wrote 4 readings of 6x4 taxels as parquet to {out_arg}")
    );
}

#[test]
fn a_second_run_into_a_locked_output_folder_names_the_holder() {
    let dir = tempfile::tempdir().unwrap();
    let results = dir.path().join("results");
    std::fs::create_dir_all(&results).unwrap();
    let mut holder: File = OpenOptions::new()
        .read(true)
        .write(true)
        .create(true)
        .truncate(true)
        .open(results.join(".taction.lock"))
        .unwrap();
    holder.try_lock().unwrap();
    writeln!(holder, "4242").unwrap();
    let out = results.display().to_string();
    let line = fails_with(
        &taction(&["experiment", "descriptors", "--scale", "0.01", "--out", &out]),
        1,
    );
    assert!(
        line.contains(&format!(
            "--out {out}: another taction run (pid 4242) is writing there"
        )),
        "{line}"
    );
    assert_eq!(
        std::fs::read_dir(&results).unwrap().count(),
        1,
        "only the lock file"
    );
}

#[test]
fn a_failed_export_leaves_no_folder() {
    let dir = tempfile::tempdir().unwrap();
    let good = write(dir.path(), "good.obj", TETRA);
    let bad = write(dir.path(), "bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n");
    let out: PathBuf = dir.path().join("exported");
    let line = fails_with(
        &taction(&[
            "objects",
            "export",
            &good,
            &bad,
            "--out",
            &out.display().to_string(),
        ]),
        1,
    );
    assert!(line.contains("bad.obj: line 4"), "{line}");
    assert!(!out.exists());
}

#[test]
fn an_unknown_sim_to_real_label_is_named_with_its_line() {
    let dir = tempfile::tempdir().unwrap();
    let header: Vec<String> = (0..4)
        .flat_map(|r| (0..4).map(move |c| format!("r{r}c{c}")))
        .collect();
    let frame = vec!["1"; 16].join(",");
    let csv = format!(
        "label,{}\n# a comment\nA,{frame}\nbanana,{frame}\nA,{frame}\n",
        header.join(",")
    );
    let real = write(dir.path(), "real.csv", &csv);
    let out = dir.path().join("results").display().to_string();
    let sim_to_real = |real: &str| {
        let args = [
            "experiment",
            "sim-to-real",
            "--real",
            real,
            "--scale",
            "0.01",
            "--out",
            &out,
        ];
        fails_with(&taction(&args), 1)
    };
    let line = sim_to_real(&real);
    assert!(
        line.contains("real.csv: line 4: label 'banana' names no letter"),
        "{line}"
    );
    // Frames of another grid than the simulated sensor's are refused before any collection.
    let real = write(dir.path(), "real4.csv", &csv.replace("banana", "A"));
    let line = sim_to_real(&real);
    assert!(
        line.contains("--real: the frames are 4x4 taxels but the simulated sensor is 6x6"),
        "{line}"
    );
    assert!(!Path::new(&out).join("data").exists(), "nothing was collected");
}

#[test]
fn a_reference_curve_that_is_not_column_equals_level_is_refused_before_any_run_is_read() {
    for (against, says) in [
        ("speed=3", "'speed' is neither 'descriptor' nor a factor"),
        ("strategy", "'strategy' is not column=level"),
        ("strategy=blind,strategy=active", "'strategy' is given twice"),
    ] {
        let line = fails_with(
            &taction(&[
                "pool",
                "no-such-run",
                "nor-this",
                "--out",
                "x",
                "--against",
                against,
            ]),
            2,
        );
        assert!(
            line.contains("--against") && line.contains(says),
            "{against}: {line}"
        );
    }
}

/// An `--out` that names a folder where a file is written, or a file where a folder is, is refused
/// before any collecting or training (the system's "Not a directory" came after all the work).
#[test]
fn an_output_path_of_the_wrong_kind_is_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let folder = dir.path().display().to_string();
    let line = fails_with(
        &taction(&[
            "collect",
            "--objects",
            "chess",
            "--readings",
            "1",
            "--out",
            &folder,
        ]),
        2,
    );
    assert!(line.contains("is a folder; give the file to write"), "{line}");
    let model = toy_model(dir.path());
    let train = dir.path().join("train.csv").display().to_string();
    let line = fails_with(&train_vectorize(&train, &[], &folder), 2);
    assert!(line.contains("is a folder"), "{line}");
    let line = fails_with(
        &taction(&[
            "recognize",
            "--model",
            &model,
            "--dataset",
            &train,
            "--out",
            &train,
        ]),
        2,
    );
    assert!(line.contains("is a file; give the folder"), "{line}");
    let with_slash = format!("{train}/");
    let line = fails_with(
        &taction(&[
            "recognize",
            "--model",
            &model,
            "--dataset",
            &train,
            "--out",
            &with_slash,
        ]),
        2,
    );
    assert!(line.contains("is a file; give the folder"), "{line}");
    let line = fails_with(&train_vectorize(&train, &[], &with_slash), 2);
    assert!(line.contains("ends in '/'"), "{line}");
    let inside_a_file = format!("{train}/scene");
    let line = fails_with(
        &taction(&["scene", "export", "--object", "pawn", "--out", &inside_a_file]),
        2,
    );
    assert!(line.contains("is a file, not a folder"), "{line}");
}

/// `taction train --dataset TRAIN --descriptor vectorize EXTRA --out OUT`.
fn train_vectorize(train: &str, extra: &[&str], out: &str) -> Output {
    let mut args = vec!["train", "--dataset", train, "--descriptor", "vectorize"];
    args.extend(extra);
    args.extend(["--out", out]);
    taction(&args)
}

/// `train`'s own flags are checked before the dataset is read and named as the user wrote them.
#[test]
fn training_flags_out_of_range_exit_2_named_by_their_flag() {
    let dir = tempfile::tempdir().unwrap();
    toy_model(dir.path());
    // No dataset at this path: a flag's refusal comes before the dataset is read.
    let train = dir.path().join("missing.csv").display().to_string();
    let out = dir.path().join("m.json").display().to_string();
    for (flag, value) in [
        ("--k", "0"),
        ("--variance-kept", "1.5"),
        ("--pseudo-count", "0"),
        ("--restarts", "0"),
        ("--trial-readings", "0"),
    ] {
        let line = fails_with(&train_vectorize(&train, &[flag, value], &out), 2);
        assert!(line.starts_with(&format!("taction: {flag}: ")), "{flag}: {line}");
    }
}

#[test]
fn an_unknown_experiment_is_a_bad_flag() {
    let line = fails_with(&taction(&["experiment", "bogus"]), 2);
    assert!(line.contains("no experiment 'bogus'"), "{line}");
}

/// A controller file is an object of named fields: an array would set them by position, and the
/// expected noise is the sensor's.
#[test]
fn a_control_file_names_its_fields_and_leaves_the_noise_to_the_sensor() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = write(dir.path(), "tetra.obj", TETRA);
    for (name, text, what) in [
        ("array.json", "[0.9]", "want a JSON object"),
        (
            "noise.json",
            r#"{"expected_noise_fraction": 0.5}"#,
            "not the sensor's --noise 0",
        ),
    ] {
        let control = write(dir.path(), name, text);
        let line = fails_with(
            &taction(&[
                "touch",
                "--mesh",
                &mesh,
                "--pad-center",
                "0.01,0.01,0.1",
                "--pad-normal",
                "0,0,-1",
                "--control",
                &control,
            ]),
            1,
        );
        assert!(line.contains(name) && line.contains(what), "{line}");
    }
    // An experiment's config.json holds the sensor's own noise there: a copy of it is taken.
    let control = write(dir.path(), "copied.json", r#"{"expected_noise_fraction": 0.0}"#);
    let done = taction(&[
        "touch",
        "--mesh",
        &mesh,
        "--pad-center",
        "0.01,0.01,0.1",
        "--pad-normal",
        "0,0,-1",
        "--control",
        &control,
    ]);
    assert!(done.status.success(), "{}", stderr(&done));
}

/// A model calibrated on the sampler's held-out readings warns when it judges the arm's
/// exploration; `dataset show` tells a file's own format version from the one it is read as.
#[test]
fn recognize_warns_of_a_sampler_calibration_on_the_arms_touches() {
    let dir = tempfile::tempdir().unwrap();
    let model = toy_model(dir.path());
    let toy = recognize_toy::dataset(6, 2);
    let header = DatasetHeader::new(
        recognize_toy::sensor(),
        "toy",
        recognize_toy::OBJECTS.iter().map(|s| s.to_string()).collect(),
        "planner L=0.5",
        2,
    );
    let explored = dir.path().join("explored.csv");
    Dataset::new(header, toy.readings().to_vec())
        .unwrap()
        .write(&explored)
        .unwrap();
    let sampled = dir.path().join("sampled.csv");
    toy.write(&sampled).unwrap();
    let recognize = |data: &Path, posterior: &str| {
        let out = dir.path().join("runs").display().to_string();
        let done = taction(&[
            "recognize",
            "--model",
            &model,
            "--dataset",
            &data.display().to_string(),
            "--posterior",
            posterior,
            "--out",
            &out,
        ]);
        assert!(done.status.success(), "{}", stderr(&done));
        stderr(&done)
    };
    assert!(recognize(&explored, "calibrated").contains("--calibration"));
    assert!(!recognize(&explored, "eq15").contains("--calibration"));
    assert!(!recognize(&sampled, "calibrated").contains("--calibration"));

    let v2 = format!(
        "{}/tests/dataset_v2/chess_planner_seed4.csv",
        env!("CARGO_MANIFEST_DIR")
    );
    let shown = taction(&["dataset", "show", &v2]);
    let text = String::from_utf8_lossy(&shown.stdout);
    assert!(
        text.contains("written in format version 2; read as version 5"),
        "{text}"
    );
}

/// `train` names the file at fault: a validation set of another sensor or of other objects, a
/// training set with an object that has nothing to train on.
#[test]
fn training_data_that_cannot_train_is_named_by_its_flag_and_file() {
    let dir = tempfile::tempdir().unwrap();
    toy_model(dir.path());
    let train = dir.path().join("train.csv").display().to_string();
    let out = dir.path().join("m.json").display().to_string();
    let big = SensorConfig {
        rows: 14,
        cols: 14,
        ..recognize_toy::sensor()
    };
    let other_sensor = dir.path().join("big.csv");
    flat_dataset(big, &recognize_toy::OBJECTS, 4)
        .write(&other_sensor)
        .unwrap();
    let other_objects = dir.path().join("dragons.csv");
    flat_dataset(recognize_toy::sensor(), &["dragon"], 4)
        .write(&other_objects)
        .unwrap();
    for (validation, what) in [
        (&other_sensor, "another sensor than --dataset"),
        (&other_objects, "object 'dragon' is not one of --dataset"),
    ] {
        let validation = validation.display().to_string();
        let line = fails_with(&train_vectorize(&train, &["--validation", &validation], &out), 1);
        assert!(
            line.contains(&format!("--validation {validation}: {what}")),
            "{line}"
        );
    }
    let toy = recognize_toy::dataset(4, 3);
    let mut objects: Vec<String> = recognize_toy::OBJECTS.iter().map(|s| s.to_string()).collect();
    objects.push("ghost".into());
    let header = DatasetHeader::new(recognize_toy::sensor(), "toy", objects, "toy", 3);
    let ghostly = dir.path().join("ghostly.csv");
    Dataset::new(header, toy.readings().to_vec())
        .unwrap()
        .write(&ghostly)
        .unwrap();
    let ghostly = ghostly.display().to_string();
    let line = fails_with(&train_vectorize(&ghostly, &[], &out), 1);
    assert!(
        line.contains(&format!(
            "--dataset {ghostly}: object 'ghost' has no converged reading"
        )),
        "{line}"
    );
}

/// A flag of the other collection mode would be ignored: it is refused, naming it.
#[test]
fn a_flag_of_the_other_collection_mode_is_refused() {
    for (flags, named) in [
        (&["--mode", "sampler", "--local-prob", "0.9"][..], "--local-prob"),
        (
            &["--mode", "sampler", "--max-iterations", "3"][..],
            "--max-iterations",
        ),
        (&["--mode", "planner", "--reachable"][..], "--reachable"),
        (
            &["--mode", "planner", "--from-above", "--reachable"][..],
            "--from-above, --reachable",
        ),
    ] {
        let line = chess_collect_fails(flags, 2);
        assert!(
            line.contains(&format!("{named}: not a flag")) || line.contains(&format!("{named}: not flags")),
            "{line}"
        );
    }
}

#[test]
fn a_free_objects_flags_are_the_planners_and_in_range() {
    for (flags, says) in [
        (
            &["--mode", "sampler", "--free-object"][..],
            "--free-object: not a flag of --mode sampler",
        ),
        (
            &["--mode", "planner", "--object-friction", "0.3"][..],
            "--object-friction: only with --free-object",
        ),
        (
            &["--mode", "planner", "--free-object", "--object-density", "-5"][..],
            "--object-density -5: object density -5 kg/m3 is outside [10, 20000]",
        ),
        (
            &["--mode", "planner", "--free-object", "--object-friction", "NaN"][..],
            "--object-friction NaN: object friction NaN is outside [0, 2]",
        ),
        (
            &["--mode", "planner", "--perturb-deg", "5", "--perturb-by", "push"][..],
            "--perturb-by push: want teleport for a mocap object (a push needs a free object's dynamics)",
        ),
        (
            &[
                "--mode",
                "planner",
                "--free-object",
                "--object-friction",
                "0",
                "--perturb-deg",
                "5",
                "--perturb-by",
                "push",
            ][..],
            "--perturb-by push: want teleport for a frictionless object",
        ),
        (
            &["--mode", "planner", "--perturb-by", "shove"][..],
            "--perturb-by shove: want one of teleport, push",
        ),
    ] {
        let line = chess_collect_fails(flags, 2);
        assert!(line.contains(says), "{line}");
    }
}

#[test]
fn train_with_objects_but_nothing_to_weigh_them_on_is_refused_before_any_dataset_is_read() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.csv").display().to_string();
    let out = dir.path().join("m.json").display().to_string();
    let line = fails_with(
        &taction(&[
            "train",
            "--dataset",
            &missing,
            "--descriptor",
            "mnti",
            "--objects",
            "chess",
            "--out",
            &out,
        ]),
        2,
    );
    assert!(
        line.contains("--objects: ") && line.contains("give calibration") && !line.contains(&missing),
        "{line}"
    );
}
