//! The experiment framework on real files in temporary directories: resuming, sharding, threads,
//! plots, the index, and the sim-to-real import.

use std::collections::{BTreeMap, BTreeSet};
use std::num::NonZeroUsize;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use rand::RngExt;
use serde::{Deserialize, Serialize};

use taction::dataset::parse_real_csv;
use taction::dataset::{FramePlace, Normalisation, RealImport, import_real_csv};
use taction::experiment::build_figure;
use taction::experiment::{
    AccuracyCurve, AccuracyRow, Axis, DetailRow, DetailTables, Experiment, ExperimentError, ExperimentSpec,
    Factor, Factors, PlotSpec, ReliabilityRow, RunOptions, SafeName, Shard, Unit, merge, run,
};
use taction::paper::square_root;
use taction::paper::{GaussianBlur, SimToRealPreprocess, SplitSizes, split_per_label};
use taction::recognize::{AccuracyPoint, ReliabilityTable, TrialOutcome};
use taction::tactile::TactileImage;

// ---------------------------------------------------------------------------------------------
// Toy experiments: rows are deterministic functions of (unit index, seed).

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct ToyRow {
    unit: String,
    step: u32,
    value: f64,
    draw: u64,
}

#[derive(Debug, Serialize)]
struct ToyConfig {
    seed: u64,
    units: usize,
}

const TOY_UNITS: usize = 10;

fn toy_spec() -> ExperimentSpec {
    ExperimentSpec {
        name: SafeName::new("toy").unwrap(),
        description: "A toy experiment: three random steps per unit.".into(),
        plots: vec![PlotSpec::lines(
            SafeName::new("toy").unwrap(),
            "Toy values",
            Axis::new("step", "step (-)"),
            vec![Axis::new("value", "value (-)")],
            &[],
        )],
    }
}

/// `fail_on_call`: the unit run as the k-th call (1-based, counted in `calls`) fails instead.
fn toy<'a>(
    seed: u64,
    calls: &'a AtomicUsize,
    fail_on_call: Option<usize>,
) -> Experiment<'a, ToyRow, ToyConfig> {
    paced_toy(seed, calls, fail_on_call, Duration::ZERO)
}

/// [`toy`] whose units each take at least `pace` (to be killed in the middle of a run).
fn paced_toy<'a>(
    seed: u64,
    calls: &'a AtomicUsize,
    fail_on_call: Option<usize>,
    pace: Duration,
) -> Experiment<'a, ToyRow, ToyConfig> {
    let units = (0..TOY_UNITS)
        .map(|i| {
            let work = toy_work(seed, i, calls, fail_on_call, pace);
            Unit::new(toy_key(i), work)
        })
        .collect();
    toy_experiment(seed, units)
}

/// The toy experiment of `units`, made with `seed`.
fn toy_experiment<'a, D: DetailTables>(
    seed: u64,
    units: Vec<Unit<'a, ToyRow, D>>,
) -> Experiment<'a, ToyRow, ToyConfig, D> {
    Experiment {
        spec: toy_spec(),
        config: ToyConfig {
            seed,
            units: TOY_UNITS,
        },
        units,
    }
}

fn toy_key(i: usize) -> SafeName {
    SafeName::builder("toy")
        .param("noise", (i % 3) as f64 * 0.1)
        .param("trial", i)
        .build()
        .unwrap()
}

/// The work of toy unit `i`: three random steps, after `pace`, failing as the `fail_on_call`-th call.
fn toy_work<'a>(
    seed: u64,
    i: usize,
    calls: &'a AtomicUsize,
    fail_on_call: Option<usize>,
    pace: Duration,
) -> impl Fn() -> Result<Vec<ToyRow>, taction::experiment::BoxError> + Send + Sync + 'a {
    let name = toy_key(i).to_string();
    move || {
        std::thread::sleep(pace);
        let call = calls.fetch_add(1, Ordering::SeqCst) + 1;
        if Some(call) == fail_on_call {
            return Err("simulated crash".into());
        }
        let mut rng = taction::rng::stream(seed, i as u64);
        Ok((0..3)
            .map(|step| ToyRow {
                unit: name.clone(),
                step,
                value: rng.random_range(-1.0..1.0),
                draw: rng.random(),
            })
            .collect())
    }
}

fn options(out: &Path, threads: usize, shard: &str) -> RunOptions {
    RunOptions {
        out: out.to_path_buf(),
        threads: NonZeroUsize::new(threads),
        shard: shard.parse().unwrap(),
    }
}

/// Every file under `root` (relative path -> bytes).
fn tree(root: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    fn walk(root: &Path, dir: &Path, out: &mut BTreeMap<PathBuf, Vec<u8>>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(root, &path, out);
            } else {
                out.insert(
                    path.strip_prefix(root).unwrap().to_path_buf(),
                    std::fs::read(&path).unwrap(),
                );
            }
        }
    }
    let mut out = BTreeMap::new();
    walk(root, root, &mut out);
    out
}

fn assert_same_tree(a: &Path, b: &Path) {
    let (ta, tb) = (tree(a), tree(b));
    assert_eq!(
        ta.keys().collect::<Vec<_>>(),
        tb.keys().collect::<Vec<_>>(),
        "file lists differ"
    );
    for (path, bytes) in &ta {
        assert!(bytes == &tb[path], "{} differs", path.display());
    }
}

fn read_toy_csv(path: &Path) -> Vec<ToyRow> {
    csv::Reader::from_path(path)
        .unwrap()
        .deserialize()
        .collect::<Result<_, _>>()
        .unwrap()
}

#[test]
fn a_run_writes_units_csv_config_plots_and_index() {
    let dir = tempfile::tempdir().unwrap();
    let calls = AtomicUsize::new(0);
    let report = run(&toy(5, &calls, None), &options(dir.path(), 2, "1/1")).unwrap();
    assert_eq!(
        (report.ran, report.reused, report.total, report.missing),
        (TOY_UNITS, 0, TOY_UNITS, 0)
    );
    let exp = dir.path().join("toy");
    for file in ["toy.csv", "config.json", "manifest.json", "toy.svg", "toy.png"] {
        assert!(exp.join(file).is_file(), "{file} missing");
    }
    assert_eq!(std::fs::read_dir(exp.join("units")).unwrap().count(), TOY_UNITS);
    let rows = read_toy_csv(&exp.join("toy.csv"));
    assert_eq!(rows.len(), 3 * TOY_UNITS);
    // Units in the experiment's order, one header.
    let text = std::fs::read_to_string(exp.join("toy.csv")).unwrap();
    assert_eq!(text.lines().filter(|l| l.starts_with("unit,")).count(), 1);
    assert!(rows[0].unit.ends_with("trial=0") && rows[3 * TOY_UNITS - 1].unit.ends_with("trial=9"));
    let config: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(exp.join("config.json")).unwrap()).unwrap();
    assert_eq!(config["seed"], 5);
    let index = std::fs::read_to_string(dir.path().join("README.md")).unwrap();
    assert!(
        index.contains("## toy") && index.contains("three random steps") && index.contains("toy/toy.svg")
    );
}

#[test]
fn a_failed_run_resumes_to_the_same_files_without_duplicates() {
    let reference = tempfile::tempdir().unwrap();
    let calls = AtomicUsize::new(0);
    run(&toy(11, &calls, None), &options(reference.path(), 1, "1/1")).unwrap();

    let resumed = tempfile::tempdir().unwrap();
    let calls = AtomicUsize::new(0);
    let e = run(&toy(11, &calls, Some(4)), &options(resumed.path(), 1, "1/1")).unwrap_err();
    assert!(
        matches!(&e, ExperimentError::UnitsFailed { failures } if failures.len() == 1),
        "{e}"
    );
    assert!(
        e.to_string().contains("simulated crash") && e.to_string().contains("toy__noise=0"),
        "{e}"
    );
    // One thread: the first three units finished and were kept, nothing after the failure started.
    let saved = std::fs::read_dir(resumed.path().join("toy/units"))
        .unwrap()
        .count();
    assert_eq!(saved, 3);
    assert!(!resumed.path().join("toy/toy.csv").exists());

    let calls = AtomicUsize::new(0);
    let report = run(&toy(11, &calls, None), &options(resumed.path(), 2, "1/1")).unwrap();
    assert_eq!((report.reused, report.ran), (3, TOY_UNITS - 3));
    assert_eq!(
        calls.load(Ordering::SeqCst),
        TOY_UNITS - 3,
        "finished units are not rerun"
    );
    assert_same_tree(reference.path(), resumed.path());

    // A third run reuses everything and changes nothing.
    let calls = AtomicUsize::new(0);
    let report = run(&toy(11, &calls, None), &options(resumed.path(), 2, "1/1")).unwrap();
    assert_eq!(
        (report.reused, report.ran, calls.load(Ordering::SeqCst)),
        (TOY_UNITS, 0, 0)
    );
    assert_same_tree(reference.path(), resumed.path());
    let rows = read_toy_csv(&resumed.path().join("toy/toy.csv"));
    let distinct: BTreeSet<(String, u32)> = rows.iter().map(|r| (r.unit.clone(), r.step)).collect();
    assert_eq!(distinct.len(), rows.len(), "no duplicated rows");
}

/// Set in the child process of the kill test: the output root it runs the paced toy into.
const KILL_CHILD_ENV: &str = "TACTION_TEST_KILL_CHILD_OUT";

#[test]
fn a_killed_process_resumes_to_the_same_files() {
    if let Some(out) = std::env::var_os(KILL_CHILD_ENV) {
        // The child: a slow run that the parent kills part-way.
        let calls = AtomicUsize::new(0);
        run(
            &paced_toy(21, &calls, None, Duration::from_millis(150)),
            &options(Path::new(&out), 1, "1/1"),
        )
        .unwrap();
        return;
    }
    let reference = tempfile::tempdir().unwrap();
    let calls = AtomicUsize::new(0);
    run(&toy(21, &calls, None), &options(reference.path(), 2, "1/1")).unwrap();

    let killed = tempfile::tempdir().unwrap();
    let mut child = std::process::Command::new(std::env::current_exe().unwrap())
        .args([
            "--exact",
            "a_killed_process_resumes_to_the_same_files",
            "--test-threads",
            "1",
        ])
        .env(KILL_CHILD_ENV, killed.path())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let units = killed.path().join("toy/units");
    let count = || {
        std::fs::read_dir(&units).map_or(0, |dir| {
            dir.filter(|e| !e.as_ref().unwrap().file_name().to_string_lossy().starts_with('.'))
                .count()
        })
    };
    let start = Instant::now();
    while count() < 3 && start.elapsed() < Duration::from_secs(60) {
        std::thread::sleep(Duration::from_millis(5));
    }
    child.kill().unwrap(); // SIGKILL: no clean-up runs in the child
    child.wait().unwrap();
    let finished = count();
    assert!(
        (3..TOY_UNITS).contains(&finished),
        "killed after {finished} units"
    );
    assert!(!killed.path().join("toy/toy.csv").exists());

    let calls = AtomicUsize::new(0);
    let report = run(&toy(21, &calls, None), &options(killed.path(), 2, "1/1")).unwrap();
    assert_eq!((report.reused, report.ran), (finished, TOY_UNITS - finished));
    assert_same_tree(reference.path(), killed.path());
}

#[test]
fn a_panicking_unit_is_reported_and_a_stale_temporary_is_removed() {
    let dir = tempfile::tempdir().unwrap();
    let spec = ExperimentSpec {
        name: SafeName::new("panics").unwrap(),
        description: "d".into(),
        plots: vec![],
    };
    let units = vec![
        Unit::new(SafeName::new("good").unwrap(), || {
            Ok(vec![ToyRow {
                unit: "good".into(),
                step: 0,
                value: 1.0,
                draw: 2,
            }])
        }),
        Unit::new(
            SafeName::new("bad").unwrap(),
            || -> Result<Vec<ToyRow>, taction::experiment::BoxError> { panic!("boom") },
        ),
    ];
    let e = run(
        &Experiment {
            spec: spec.clone(),
            config: 1,
            units,
        },
        &options(dir.path(), 1, "1/1"),
    )
    .unwrap_err();
    assert!(e.to_string().contains("bad: panicked: boom"), "{e}");
    // A killed run can leave a half-written hidden temporary; it is never read as a unit.
    let stale = dir.path().join("panics/units/.bad.csv.999999999.0.tmp");
    std::fs::write(&stale, "unit,st").unwrap();
    let units = vec![
        Unit::new(SafeName::new("good").unwrap(), || {
            Ok(vec![ToyRow {
                unit: "good".into(),
                step: 0,
                value: 1.0,
                draw: 2,
            }])
        }),
        Unit::new(SafeName::new("bad").unwrap(), || {
            Ok(vec![ToyRow {
                unit: "bad".into(),
                step: 0,
                value: 3.0,
                draw: 4,
            }])
        }),
    ];
    let report = run(
        &Experiment {
            spec,
            config: 1,
            units,
        },
        &options(dir.path(), 1, "1/1"),
    )
    .unwrap();
    assert_eq!((report.reused, report.ran), (1, 1));
    let text = std::fs::read_to_string(dir.path().join("panics/panics.csv")).unwrap();
    assert_eq!(text, "unit,step,value,draw\ngood,0,1.0,2\nbad,0,3.0,4\n");
    assert!(!stale.exists(), "the dead process's temporary is cleaned up");
}

#[test]
fn shards_merged_equal_one_unsharded_run_byte_for_byte() {
    let whole = tempfile::tempdir().unwrap();
    let calls = AtomicUsize::new(0);
    run(&toy(3, &calls, None), &options(whole.path(), 2, "1/1")).unwrap();

    let shards: Vec<tempfile::TempDir> = (0..3).map(|_| tempfile::tempdir().unwrap()).collect();
    let mut covered = 0;
    for (k, dir) in shards.iter().enumerate() {
        let calls = AtomicUsize::new(0);
        let report = run(
            &toy(3, &calls, None),
            &options(dir.path(), 1 + k % 2, &format!("{}/3", k + 1)),
        )
        .unwrap();
        assert!(report.finished.is_none(), "a shard alone does not assemble");
        assert_eq!(report.ran, calls.load(Ordering::SeqCst));
        covered += report.ran;
    }
    assert_eq!(covered, TOY_UNITS, "shards are disjoint and cover every unit");

    let merged = tempfile::tempdir().unwrap();
    let inputs: Vec<PathBuf> = shards.iter().map(|d| d.path().to_path_buf()).collect();
    let report = merge(&inputs, merged.path()).unwrap();
    assert_eq!(report.copied, TOY_UNITS);
    assert_same_tree(whole.path(), merged.path());

    // Merging again, or into one of the shard directories, gives the same files.
    assert_eq!(merge(&inputs, merged.path()).unwrap().copied, 0);
    assert_same_tree(whole.path(), merged.path());
    merge(&inputs, shards[0].path()).unwrap();
    assert_same_tree(whole.path(), shards[0].path());
}

#[test]
fn thread_count_does_not_change_the_output() {
    let one = tempfile::tempdir().unwrap();
    let two = tempfile::tempdir().unwrap();
    let calls = AtomicUsize::new(0);
    run(&toy(8, &calls, None), &options(one.path(), 1, "1/1")).unwrap();
    run(&toy(8, &calls, None), &options(two.path(), 2, "1/1")).unwrap();
    assert_same_tree(one.path(), two.path());
}

/// A second table: each toy step split into two parts (the shape of per-object rows beside
/// averaged ones).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct ToyPart {
    unit: String,
    step: u32,
    part: u32,
    share: f64,
}

impl DetailRow for ToyPart {
    const TABLE: Option<&'static str> = Some("per_part");
}

/// [`toy`] whose units also write [`ToyPart`] rows: each step's value in two equal shares.
fn detailed_toy<'a>(
    seed: u64,
    calls: &'a AtomicUsize,
    fail_on_call: Option<usize>,
) -> Experiment<'a, ToyRow, ToyConfig, ToyPart> {
    let units = (0..TOY_UNITS)
        .map(|i| {
            let work = toy_work(seed, i, calls, fail_on_call, Duration::ZERO);
            Unit::with_detail(toy_key(i), move || {
                let rows = work()?;
                let parts = rows
                    .iter()
                    .flat_map(|r| {
                        (0..2).map(|part| ToyPart {
                            unit: r.unit.clone(),
                            step: r.step,
                            part,
                            share: r.value / 2.0,
                        })
                    })
                    .collect();
                Ok((rows, parts))
            })
        })
        .collect();
    toy_experiment(seed, units)
}

#[test]
fn detail_rows_survive_resume_and_merge_and_old_units_without_them_are_kept() {
    let reference = tempfile::tempdir().unwrap();
    let calls = AtomicUsize::new(0);
    let report = run(
        &detailed_toy(7, &calls, None),
        &options(reference.path(), 2, "1/1"),
    )
    .unwrap();
    let detail = reference.path().join("toy/toy_per_part.csv");
    assert_eq!(report.finished.unwrap().details, vec![detail.clone()]);
    let parts: Vec<ToyPart> = csv::Reader::from_path(&detail)
        .unwrap()
        .deserialize()
        .collect::<Result<_, _>>()
        .unwrap();
    let rows = read_toy_csv(&reference.path().join("toy/toy.csv"));
    assert_eq!(parts.len(), 2 * rows.len(), "two parts per row, units in order");
    for (row, pair) in rows.iter().zip(parts.chunks(2)) {
        assert!(pair.iter().all(|p| (&p.unit, p.step) == (&row.unit, row.step)));
        assert_eq!(pair[0].share + pair[1].share, row.value);
    }
    let manifest = std::fs::read_to_string(reference.path().join("toy/manifest.json")).unwrap();
    assert!(
        manifest.contains("\"details\": [\n    \"per_part\"\n  ]"),
        "{manifest}"
    );
    let index = std::fs::read_to_string(reference.path().join("README.md")).unwrap();
    assert!(
        index.contains("Data: [toy.csv](toy/toy.csv), [toy_per_part.csv](toy/toy_per_part.csv)\n"),
        "{index}"
    );

    // A failed run resumes to the same files, detail rows included.
    let resumed = tempfile::tempdir().unwrap();
    let calls = AtomicUsize::new(0);
    run(
        &detailed_toy(7, &calls, Some(4)),
        &options(resumed.path(), 1, "1/1"),
    )
    .unwrap_err();
    let calls = AtomicUsize::new(0);
    let report = run(&detailed_toy(7, &calls, None), &options(resumed.path(), 2, "1/1")).unwrap();
    assert_eq!((report.reused, report.ran), (3, TOY_UNITS - 3));
    assert_same_tree(reference.path(), resumed.path());

    // Shards merged give the same files.
    let (a, b, merged) = (
        tempfile::tempdir().unwrap(),
        tempfile::tempdir().unwrap(),
        tempfile::tempdir().unwrap(),
    );
    run(&detailed_toy(7, &calls, None), &options(a.path(), 1, "1/2")).unwrap();
    run(&detailed_toy(7, &calls, None), &options(b.path(), 2, "2/2")).unwrap();
    let report = merge(&[a.path().to_path_buf(), b.path().to_path_buf()], merged.path()).unwrap();
    assert_eq!(report.copied, 2 * TOY_UNITS, "each unit's two files");
    assert_same_tree(reference.path(), merged.path());

    // Units saved before the experiment had its second table are reused, not rerun; the main
    // table is assembled as before and the index says why the second one is missing.
    std::fs::remove_dir_all(resumed.path().join("toy/units/per_part")).unwrap();
    std::fs::remove_file(resumed.path().join("toy/toy_per_part.csv")).unwrap();
    let calls = AtomicUsize::new(0);
    let report = run(&detailed_toy(7, &calls, None), &options(resumed.path(), 2, "1/1")).unwrap();
    assert_eq!((report.reused, report.ran), (TOY_UNITS, 0));
    assert_eq!(report.finished.unwrap().details, Vec::<PathBuf>::new());
    assert!(!resumed.path().join("toy/toy_per_part.csv").exists());
    assert_eq!(
        std::fs::read(resumed.path().join("toy/toy.csv")).unwrap(),
        std::fs::read(reference.path().join("toy/toy.csv")).unwrap()
    );
    let index = std::fs::read_to_string(resumed.path().join("README.md")).unwrap();
    assert!(
        index.contains("`toy_per_part.csv` is not here: 10 of 10 units were saved before"),
        "{index}"
    );
}

/// [`detailed_toy`] with a third table, the reliability rows of the recognition experiments: each
/// unit a curve whose predictions are its steps (confidence (value + 1) / 2, right when value > 0),
/// and the reliability diagram beside the toy plot.
fn calibrated_toy<'a>(
    seed: u64,
    calls: &'a AtomicUsize,
    fail_on_call: Option<usize>,
) -> Experiment<'a, ToyRow, ToyConfig, (ToyPart, ReliabilityRow)> {
    let units = (0..TOY_UNITS)
        .map(|i| {
            let work = toy_work(seed, i, calls, fail_on_call, Duration::ZERO);
            Unit::with_detail(toy_key(i), move || {
                let rows = work()?;
                let parts = rows
                    .iter()
                    .map(|r| ToyPart {
                        unit: r.unit.clone(),
                        step: r.step,
                        part: 0,
                        share: r.value,
                    })
                    .collect();
                let mut table = ReliabilityTable::default();
                for r in &rows {
                    table.add((r.value + 1.0) / 2.0, r.value > 0.0);
                }
                let curve = AccuracyCurve {
                    experiment: "toy".into(),
                    descriptor: toy_key(i).to_string(),
                    factors: Factors::none(),
                    trial: 0,
                    seed,
                    stream_seed: 0,
                };
                Ok((rows, (parts, curve.reliability_rows(&table))))
            })
        })
        .collect();
    let mut experiment = toy_experiment(seed, units);
    experiment
        .spec
        .plots
        .push(PlotSpec::reliability(SafeName::new("toy-reliability").unwrap(), "Toy calibration").unwrap());
    experiment
}

#[test]
fn reliability_tables_survive_resume_and_units_saved_without_them_are_kept() {
    let reference = tempfile::tempdir().unwrap();
    let calls = AtomicUsize::new(0);
    let report = run(
        &calibrated_toy(7, &calls, None),
        &options(reference.path(), 2, "1/1"),
    )
    .unwrap();
    let table = reference.path().join("toy/toy_reliability.csv");
    let done = report.finished.clone().unwrap();
    assert_eq!(
        done.details,
        vec![reference.path().join("toy/toy_per_part.csv"), table.clone()]
    );
    assert!(
        done.plots
            .contains(&reference.path().join("toy/toy-reliability.svg"))
    );
    assert_eq!(
        done.calibration.len(),
        TOY_UNITS,
        "one curve per unit, each with its ECE"
    );
    let said = report.to_string();
    assert!(
        said.contains("\ncalibration (10 bins): toy__noise=0__trial=0 (ECE "),
        "{said}"
    );
    let rows: Vec<ReliabilityRow> = csv::Reader::from_path(&table)
        .unwrap()
        .deserialize()
        .collect::<Result<_, _>>()
        .unwrap();
    assert_eq!(rows.len(), 10 * TOY_UNITS, "ten bins per unit's curve");
    for curve in rows.chunks(10) {
        assert_eq!(
            curve.iter().map(|r| r.count).sum::<u64>(),
            3,
            "three steps per unit"
        );
        let ece = curve[0].ece.unwrap();
        let recomputed: f64 = curve
            .iter()
            .filter_map(|r| Some(r.count as f64 / 3.0 * (r.accuracy? - r.mean_confidence?).abs()))
            .sum();
        assert!((ece - recomputed).abs() < 1e-12);
        assert!(curve.iter().all(|r| r.ece == Some(ece)));
    }
    let text = std::fs::read_to_string(&table).unwrap();
    assert!(
        text.starts_with(
            "experiment,descriptor,bin,confidence_low,confidence_high,count,mean_confidence,accuracy,ece\n"
        ),
        "{text}"
    );
    let svg = std::fs::read_to_string(reference.path().join("toy/toy-reliability.svg")).unwrap();
    assert!(svg.contains("perfect calibration") && svg.contains("(ECE "));

    // A failed run resumes to the same files, every table included.
    let resumed = tempfile::tempdir().unwrap();
    let calls = AtomicUsize::new(0);
    run(
        &calibrated_toy(7, &calls, Some(4)),
        &options(resumed.path(), 1, "1/1"),
    )
    .unwrap_err();
    let calls = AtomicUsize::new(0);
    let report = run(
        &calibrated_toy(7, &calls, None),
        &options(resumed.path(), 2, "1/1"),
    )
    .unwrap();
    assert_eq!((report.reused, report.ran), (3, TOY_UNITS - 3));
    assert_same_tree(reference.path(), resumed.path());

    // Units saved by a build that had only the per-part table, under its manifest: reused, not
    // rerun; the reliability table and its plot are left out and the report and index say why.
    let manifest = resumed.path().join("toy/manifest.json");
    let text = std::fs::read_to_string(&manifest).unwrap();
    let old = text.replace(
        "\"details\": [\n    \"per_part\",\n    \"reliability\"\n  ]",
        "\"detail\": \"per_part\"",
    );
    assert_ne!(old, text, "{text}");
    std::fs::write(&manifest, old).unwrap();
    std::fs::remove_dir_all(resumed.path().join("toy/units/reliability")).unwrap();
    for file in [
        "toy_reliability.csv",
        "toy-reliability.svg",
        "toy-reliability.png",
    ] {
        std::fs::remove_file(resumed.path().join("toy").join(file)).unwrap();
    }
    let calls = AtomicUsize::new(0);
    let report = run(
        &calibrated_toy(7, &calls, None),
        &options(resumed.path(), 2, "1/1"),
    )
    .unwrap();
    assert_eq!((report.reused, report.ran), (TOY_UNITS, 0));
    let done = report.finished.clone().unwrap();
    assert_eq!(done.details, vec![resumed.path().join("toy/toy_per_part.csv")]);
    assert_eq!(
        done.incomplete,
        vec![(SafeName::new("reliability").unwrap(), TOY_UNITS)]
    );
    assert!(!resumed.path().join("toy/toy-reliability.svg").exists());
    assert!(
        report
            .to_string()
            .contains("no reliability table: 10 units were saved by a build before it")
    );
    assert_eq!(
        std::fs::read_to_string(&manifest).unwrap(),
        text,
        "the manifest is rewritten"
    );
    let index = std::fs::read_to_string(resumed.path().join("README.md")).unwrap();
    assert!(
        index.contains("`toy_reliability.csv` is not here: 10 of 10 units were saved before"),
        "{index}"
    );
    assert!(!index.contains("toy-reliability.svg"), "{index}");
}

#[test]
fn merge_rejects_mismatched_incomplete_and_empty_inputs() {
    let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let calls = AtomicUsize::new(0);
    run(&toy(1, &calls, None), &options(a.path(), 1, "1/2")).unwrap();
    run(&toy(2, &calls, None), &options(b.path(), 1, "2/2")).unwrap();
    let out = tempfile::tempdir().unwrap();
    let e = merge(&[a.path().to_path_buf(), b.path().to_path_buf()], out.path())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("config.json") && e.contains(&a.path().join("toy").display().to_string()),
        "{e}"
    );
    assert!(e.contains(&b.path().join("toy").display().to_string()), "{e}");

    let e = merge(&[a.path().to_path_buf()], out.path()).unwrap_err();
    assert!(
        matches!(
            e,
            ExperimentError::Incomplete {
                missing: 5,
                total: 10,
                ..
            }
        ),
        "{e}"
    );

    let empty = tempfile::tempdir().unwrap();
    let e = merge(&[empty.path().to_path_buf()], out.path())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("no experiment output") && e.contains(&empty.path().display().to_string()),
        "{e}"
    );
}

#[test]
fn corrupt_units_and_changed_configs_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let calls = AtomicUsize::new(0);
    run(&toy(4, &calls, None), &options(dir.path(), 2, "1/1")).unwrap();
    let key = "toy__noise=0.1__trial=1";
    let unit = dir.path().join(format!("toy/units/{key}.csv"));
    let text = std::fs::read_to_string(&unit).unwrap();
    let edited = text.replacen(",", ",abc,", 2);
    std::fs::write(&unit, &edited).unwrap();

    let e = run(&toy(4, &calls, None), &options(dir.path(), 2, "1/1")).unwrap_err();
    assert!(matches!(e, ExperimentError::CorruptUnit { .. }), "{e}");
    assert!(
        e.to_string().contains(key) && e.to_string().contains("line"),
        "{e}"
    );
    let out = tempfile::tempdir().unwrap();
    let e = merge(&[dir.path().to_path_buf()], out.path())
        .unwrap_err()
        .to_string();
    assert!(e.contains(key) && e.contains("corrupt"), "{e}");

    std::fs::write(&unit, "unit,step,value,draw\n").unwrap();
    let e = run(&toy(4, &calls, None), &options(dir.path(), 2, "1/1"))
        .unwrap_err()
        .to_string();
    assert!(e.contains(key) && e.contains("no rows"), "{e}");

    std::fs::write(&unit, text).unwrap();
    let e = run(&toy(5, &calls, None), &options(dir.path(), 2, "1/1")).unwrap_err();
    assert!(matches!(e, ExperimentError::ChangedSinceLastRun { .. }), "{e}");
    assert!(e.to_string().contains("config.json"), "{e}");

    // A new title is fine; other units are not.
    let mut retitled = toy(4, &calls, None);
    retitled.spec.plots[0].title = "Toy values, retitled".into();
    run(&retitled, &options(dir.path(), 2, "1/1")).unwrap();
    assert!(
        std::fs::read_to_string(dir.path().join("toy/toy.svg"))
            .unwrap()
            .contains("retitled")
    );
    let mut fewer = toy(4, &calls, None);
    fewer.units.pop();
    let e = run(&fewer, &options(dir.path(), 2, "1/1"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("manifest.json") && e.contains("different units"),
        "{e}"
    );
}

#[test]
fn bad_output_dirs_keys_and_shards_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("a-file");
    std::fs::write(&file, "x").unwrap();
    let calls = AtomicUsize::new(0);
    let e = run(&toy(1, &calls, None), &options(&file.join("out"), 1, "1/1"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("a-file"), "{e}");

    let twice = vec![
        Unit::new(SafeName::new("same").unwrap(), || Ok(vec![1u8])),
        Unit::new(SafeName::new("same").unwrap(), || Ok(vec![2u8])),
    ];
    let e = run(
        &Experiment {
            spec: toy_spec(),
            config: 0,
            units: twice,
        },
        &options(dir.path(), 1, "1/1"),
    );
    assert!(e.unwrap_err().to_string().contains("'same' twice"));

    let tuples = vec![Unit::new(SafeName::new("t").unwrap(), || Ok(vec![(1u8, 2u8)]))];
    let e = run(
        &Experiment {
            spec: toy_spec(),
            config: 0,
            units: tuples,
        },
        &options(dir.path(), 1, "1/1"),
    );
    assert!(
        e.unwrap_err()
            .to_string()
            .contains("t: its rows do not read back")
    );

    for bad in ["0/3", "4/3", "2", "x/y", "1/0"] {
        let e = bad.parse::<Shard>().unwrap_err().to_string();
        assert!(e.contains(bad), "{e}");
    }
}

#[test]
fn the_merge_command_merges_and_reports_errors() {
    let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let calls = AtomicUsize::new(0);
    run(&toy(6, &calls, None), &options(a.path(), 1, "1/2")).unwrap();
    run(&toy(6, &calls, None), &options(b.path(), 1, "2/2")).unwrap();
    let out = tempfile::tempdir().unwrap();
    let bin = env!("CARGO_BIN_EXE_taction");
    let status = std::process::Command::new(bin)
        .args([
            "merge",
            a.path().to_str().unwrap(),
            b.path().to_str().unwrap(),
            "--out",
        ])
        .arg(out.path())
        .output()
        .unwrap();
    assert!(
        status.status.success(),
        "{}",
        String::from_utf8_lossy(&status.stderr)
    );
    assert!(out.path().join("toy/toy.csv").is_file());
    let failed = std::process::Command::new(bin)
        .args(["merge", a.path().to_str().unwrap(), "--out"])
        .arg(out.path().join("partial"))
        .output()
        .unwrap();
    assert!(!failed.status.success());
    assert!(String::from_utf8_lossy(&failed.stderr).contains("incomplete"));
}

// ---------------------------------------------------------------------------------------------
// Plots and the index.

/// An evaluation's point after `n_readings` readings: `correct` of `trials` right, each trial
/// giving `reliability` to its true object.
fn point(n_readings: usize, correct: usize, trials: usize, reliability: f64) -> AccuracyPoint {
    let outcomes = (0..trials)
        .map(|t| TrialOutcome {
            object: t,
            correct: t < correct,
            p_true: reliability,
        })
        .collect();
    AccuracyPoint::new(n_readings, outcomes)
}

fn accuracy_experiment<'a>() -> Experiment<'a, AccuracyRow, u64> {
    let mut units = Vec::new();
    for descriptor in ["polar-fourier", "mnti"] {
        for (v, noise) in [0.0, 0.2].into_iter().enumerate() {
            for trial in 0..2u32 {
                let key = SafeName::builder(descriptor)
                    .param("noise", noise)
                    .param("trial", trial)
                    .build()
                    .unwrap();
                let seed = taction::rng::substream(42, (v * 10 + trial as usize) as u64);
                units.push(Unit::new(key, move || {
                    let mut rng = taction::rng::rng(seed);
                    let curve = AccuracyCurve {
                        experiment: "noise".into(),
                        descriptor: descriptor.into(),
                        factors: Factors::new([(Factor::NoiseFraction, noise.to_string())]),
                        trial,
                        seed: 42,
                        stream_seed: seed,
                    };
                    let points: Vec<AccuracyPoint> = (1..=100)
                        .map(|n| {
                            let a = (1.0 - (-(n as f64) / (10.0 + 40.0 * noise)).exp())
                                * rng.random_range(0.9..1.0);
                            point(n, (a * 1000.0).round() as usize, 1000, a * 0.8)
                        })
                        .collect();
                    Ok(curve.rows(&points))
                }));
            }
        }
    }
    let spec = ExperimentSpec {
        name: SafeName::new("noise").unwrap(),
        description: "Fig. 13: accuracy under additive noise.".into(),
        plots: vec![
            PlotSpec::accuracy(SafeName::new("noise").unwrap(), "Robustness to noise (Fig. 13)")
                .with_chance(12),
        ],
    };
    Experiment {
        spec,
        config: 42,
        units,
    }
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct ConvergenceRow {
    noise_fraction: f64,
    attempts: u32,
    converged: u32,
    convergence_rate: f64,
    mean_iterations: f64,
}

fn convergence_experiment<'a>() -> Experiment<'a, ConvergenceRow, &'static str> {
    let units = (0..5)
        .map(|i| {
            let noise = i as f64 * 0.25;
            let key = SafeName::builder("convergence")
                .param("noise", noise)
                .build()
                .unwrap();
            Unit::new(key, move || {
                let attempts = 100 + 20 * i;
                Ok(vec![ConvergenceRow {
                    noise_fraction: noise,
                    attempts,
                    converged: 100,
                    convergence_rate: 100.0 / attempts as f64,
                    mean_iterations: 10.0 + 8.0 * noise * noise,
                }])
            })
        })
        .collect();
    let spec = ExperimentSpec {
        name: SafeName::new("convergence").unwrap(),
        description: "Fig. 14: local controller convergence against noise.".into(),
        plots: vec![PlotSpec::lines(
            SafeName::new("convergence").unwrap(),
            "Convergence of the local controllers (Fig. 14)",
            Axis::new("noise_fraction", "noise (fraction of range)"),
            vec![
                Axis::new("convergence_rate", "convergence rate (fraction)"),
                Axis::new("mean_iterations", "mean iterations (count)"),
            ],
            &[],
        )],
    };
    Experiment {
        spec,
        config: "dragon",
        units,
    }
}

fn assert_valid_svg(path: &Path, needles: &[&str]) {
    let text = std::fs::read_to_string(path).unwrap();
    let doc = roxmltree::Document::parse(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert_eq!(doc.root_element().tag_name().name(), "svg");
    let texts: String = doc
        .descendants()
        .filter_map(|n| n.text())
        .collect::<Vec<_>>()
        .join("\n");
    for needle in needles {
        assert!(texts.contains(needle), "{}: no text '{needle}'", path.display());
    }
}

/// Decodes a PNG; returns (width, height, number of distinct colours).
fn decode_png(path: &Path) -> (u32, u32, usize) {
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    let mut reader = png::Decoder::new(std::io::Cursor::new(bytes))
        .read_info()
        .unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    let colours: BTreeSet<&[u8]> = buf[..info.buffer_size()].chunks(3).collect();
    (info.width, info.height, colours.len())
}

#[test]
fn plots_are_valid_svg_and_png_and_the_index_quotes_headlines() {
    let dir = tempfile::tempdir().unwrap();
    run(&accuracy_experiment(), &options(dir.path(), 2, "1/1")).unwrap();
    run(&convergence_experiment(), &options(dir.path(), 2, "1/1")).unwrap();

    let noise = dir.path().join("noise");
    assert_valid_svg(
        &noise.join("noise.svg"),
        &[
            "accuracy (fraction correct)",
            "number of readings",
            "chance (1/12)",
            "Robustness to noise",
            "polar-fourier",
            "noise_fraction = 0.2",
            // The shaded band says what it is.
            "band: lowest to highest trial",
        ],
    );
    let (w, h, colours) = decode_png(&noise.join("noise.png"));
    assert_eq!((w, h), (1280, 510), "two panels side by side");
    assert!(colours > 10, "the PNG has lines and text, {colours} colours");
    let figure = build_figure(&accuracy_experiment().spec.plots[0], &noise.join("noise.csv")).unwrap();
    assert_eq!(figure.panels.len(), 2, "one panel per descriptor");
    let first = &figure.panels[0].series[0];
    assert_eq!(
        (first.label.as_str(), first.points.len()),
        ("noise_fraction = 0", 100)
    );
    // Plotted as in the CSV (a fraction), with chance level and the two trials as a band around
    // their mean, at integer readings only.
    assert!(first.points.iter().all(|&(_, y)| (0.0..=1.0).contains(&y)));
    let panel = &figure.panels[0];
    assert!(panel.integer_x);
    assert_eq!(panel.reference.as_ref().map(|r| r.y), Some(1.0 / 12.0));
    assert_eq!(first.band.len(), first.points.len());
    for (&(x, mean), &(bx, low, high)) in first.points.iter().zip(&first.band) {
        assert_eq!(x, bx);
        assert!(low <= mean && mean <= high, "{low} <= {mean} <= {high}");
    }
    assert!(
        first.band.iter().any(|&(_, low, high)| high > low),
        "two trials differ somewhere"
    );

    let conv = dir.path().join("convergence");
    assert_valid_svg(
        &conv.join("convergence.svg"),
        &[
            "convergence rate (fraction)",
            "mean iterations (count)",
            "noise (fraction of range)",
        ],
    );
    assert_eq!(decode_png(&conv.join("convergence.png")).0, 1280);
    // One row per noise level: no band, so no legend entry for one.
    let convergence_svg = std::fs::read_to_string(conv.join("convergence.svg")).unwrap();
    assert!(!convergence_svg.contains("band: lowest to highest trial"));

    let index = std::fs::read_to_string(dir.path().join("README.md")).unwrap();
    assert!(
        index.find("## convergence").unwrap() < index.find("## noise").unwrap(),
        "experiments in name order"
    );
    assert!(index.contains("Fig. 13: accuracy under additive noise."));
    assert!(
        index.contains("| accuracy (%) at n readings | 10 | 30 | 60 | 100 |"),
        "{index}"
    );
    assert!(index.contains("| noise_fraction = 0.2 |"), "{index}");
    // Convergence rate at noise 0 is 100/100 = 1, at noise 1 it is 100/180.
    assert!(
        index.contains("| convergence rate (fraction) | 1 | 0.8333 | 0.7143 | 0.625 | 0.5556 |"),
        "{index}"
    );
}

#[test]
fn accuracy_rows_out_of_range_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let spec = ExperimentSpec {
        name: SafeName::new("bad").unwrap(),
        description: "d".into(),
        plots: vec![PlotSpec::accuracy(SafeName::new("bad").unwrap(), "t")],
    };
    let curve = AccuracyCurve {
        experiment: "bad".into(),
        descriptor: "mnti".into(),
        factors: Factors::none(),
        trial: 0,
        seed: 0,
        stream_seed: 0,
    };
    let units = vec![Unit::new(SafeName::new("u").unwrap(), move || {
        // 3 of 2 trials right: an accuracy no evaluation gives, which the runner must reject.
        let impossible = AccuracyPoint {
            correct: 3,
            ..point(2, 2, 2, 0.5)
        };
        Ok(curve.rows(&[point(1, 1, 2, 0.5), impossible]))
    })];
    let e = run(
        &Experiment {
            spec,
            config: (),
            units,
        },
        &options(dir.path(), 1, "1/1"),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("bad.csv") && e.contains("line 3") && e.contains("accuracy 1.5"),
        "{e}"
    );
}

// ---------------------------------------------------------------------------------------------
// Sim-to-real import.

fn example_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("data/real_letters_example.csv")
}

/// The vowels as 6x6 taxel patterns.
const VOWELS: [(&str, [&str; 6]); 5] = [
    ("A", ["..##..", ".#..#.", ".#..#.", ".####.", "#....#", "#....#"]),
    ("E", ["#####.", "#.....", "####..", "#.....", "#.....", "#####."]),
    ("I", ["..##..", "..##..", "..##..", "..##..", "..##..", "..##.."]),
    ("O", [".####.", "#....#", "#....#", "#....#", "#....#", ".####."]),
    ("U", ["#....#", "#....#", "#....#", "#....#", "#....#", ".####."]),
];

/// Writes what `data/real_letters_example.csv` holds: for each vowel, 8 frames of its pattern
/// shifted by up to one taxel, scaled to 600-900 raw units, plus 0-40 units of uniform noise,
/// rounded to whole units (seed 2024, one stream per vowel).
fn synthetic_letters_csv() -> String {
    let mut text = String::from(
        "# SYNTHETIC example in the real-sensor import format of taction::paper::real_data: NOT a\n\
         # recording. Five vowels as 6x6 taxel patterns, shifted by up to one taxel, 600-900 raw units\n\
         # plus 0-40 units of noise; made by synthetic_letters_csv() in tests/experiment_framework.rs.\n",
    );
    let header: Vec<String> = (0..36).map(|k| format!("r{}c{}", k / 6, k % 6)).collect();
    text.push_str(&format!("label,{}\n", header.join(",")));
    for (i, (label, pattern)) in VOWELS.iter().enumerate() {
        let mut rng = taction::rng::stream(2024, i as u64);
        for _ in 0..8 {
            let (dr, dc): (i32, i32) = (rng.random_range(-1..=1), rng.random_range(-1..=1));
            let amplitude: f64 = rng.random_range(600.0..900.0);
            let mut values = Vec::new();
            for r in 0..6i32 {
                for c in 0..6i32 {
                    let (sr, sc) = (r - dr, c - dc);
                    let on = (0..6).contains(&sr)
                        && (0..6).contains(&sc)
                        && pattern[sr as usize].as_bytes()[sc as usize] == b'#';
                    let noise: f64 = rng.random_range(0.0..40.0);
                    values.push(format!("{:.0}", if on { amplitude } else { 0.0 } + noise));
                }
            }
            text.push_str(&format!("{label},{}\n", values.join(",")));
        }
    }
    text
}

#[test]
fn the_example_file_is_what_its_generator_writes() {
    let expected = synthetic_letters_csv();
    if std::env::var_os("TACTION_WRITE_EXAMPLE").is_some() {
        std::fs::write(example_path(), &expected).unwrap();
    }
    assert_eq!(std::fs::read_to_string(example_path()).unwrap(), expected);
}

#[test]
fn the_example_file_imports_and_splits() {
    let allowed: BTreeSet<String> = ["A", "E", "I", "O", "U"].iter().map(|s| s.to_string()).collect();
    let data = import_real_csv(
        &example_path(),
        &RealImport {
            normalisation: Normalisation::FileMax,
            allowed_labels: Some(allowed),
            calibration: None,
        },
    )
    .unwrap();
    assert_eq!((data.rows, data.cols, data.readings.len()), (6, 6, 40));
    assert_eq!(
        data.labels().into_iter().collect::<Vec<_>>(),
        ["A", "E", "I", "O", "U"]
    );
    assert_eq!(
        data.readings[0].place,
        FramePlace::Line(5),
        "three comment lines and the header come first"
    );
    let max = data.readings.iter().map(|r| r.image.max()).fold(0.0, f64::max);
    assert_eq!(max, 1.0, "normalised by the file's largest value");

    let sizes = SplitSizes {
        train: 4,
        validation: 2,
        test: 2,
    };
    let split = split_per_label(data.readings.clone(), |r| &r.label, sizes, 7).unwrap();
    assert_eq!(
        (split.train.len(), split.validation.len(), split.test.len()),
        (20, 10, 10)
    );
    let lines: BTreeSet<String> = split
        .train
        .iter()
        .chain(&split.validation)
        .chain(&split.test)
        .map(|r| r.place.to_string())
        .collect();
    assert_eq!(lines.len(), 40, "disjoint and complete");
    assert_eq!(
        split,
        split_per_label(data.readings, |r| &r.label, sizes, 7).unwrap()
    );
}

/// The header of a 4x4 recording, `label,r0c0,...,r3c3`.
fn header_4x4() -> String {
    let cells: Vec<String> = (0..16).map(|k| format!("r{}c{}", k / 4, k % 4)).collect();
    format!("label,{}\n", cells.join(","))
}

/// A 4x4 frame of `label`: taxel k reads `k + 1`, except the `(k, text)` replacements.
fn frame_4x4(label: &str, replace: &[(usize, &str)]) -> String {
    let values: Vec<String> = (0..16)
        .map(|k| {
            replace
                .iter()
                .find(|(at, _)| *at == k)
                .map_or_else(|| (k + 1).to_string(), |(_, text)| text.to_string())
        })
        .collect();
    format!("{label},{}\n", values.join(","))
}

#[test]
fn malformed_real_csvs_name_the_line() {
    let header = header_4x4();
    let opts = RealImport {
        normalisation: Normalisation::FileMax,
        allowed_labels: Some(["A", "E"].iter().map(|s| s.to_string()).collect()),
        calibration: None,
    };
    let cases = [
        ("A,1,2,3\n".to_string(), "line 3: 4 columns, expected 17"),
        (
            frame_4x4("A", &[(4, "x")]),
            "line 3: column r1c0: 'x' is not a number",
        ),
        (
            frame_4x4("A", &[(1, "NaN")]),
            "line 3: column r0c1: NaN is not finite",
        ),
        (
            frame_4x4("A", &[(1, "inf")]),
            "line 3: column r0c1: inf is not finite",
        ),
        (
            frame_4x4("A", &[(4, "-3")]),
            "line 3: column r1c0: -3 is negative",
        ),
        (frame_4x4("Q", &[]), "line 3: unknown label 'Q' (allowed: A, E)"),
        (frame_4x4("", &[]), "line 3: empty label"),
    ];
    for (bad, needle) in cases {
        let text = format!("{header}{}{bad}", frame_4x4("E", &[]));
        let e = parse_real_csv(&text, "f.csv", &opts).unwrap_err().to_string();
        assert!(e.starts_with("f.csv: ") && e.contains(needle), "{bad:?}: {e}");
    }
    let header_cases = [
        ("name,r0c0\n", "first column must be 'label'"),
        ("label,r0c0,r1c1\n", "expected r0c1"),
        ("label,r0c0,x\n", "'x' is not r<row>c<col>"),
        ("label,r0c0,r0c1,r1c0\n", "do not fill a 2x2 grid"),
        ("label,r0c0,r0c1\n", "a 1x2 sensor; accepted are 2 to 128"),
    ];
    for (bad, needle) in header_cases {
        let e = parse_real_csv(&format!("# c\n{bad}A,1,2,3\n"), "f.csv", &opts)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("line 2: bad header") && e.contains(needle),
            "{bad:?}: {e}"
        );
    }
    let range = RealImport {
        normalisation: Normalisation::Range(3.0),
        allowed_labels: None,
        calibration: None,
    };
    let e = parse_real_csv(&format!("{header}{}", frame_4x4("A", &[])), "f.csv", &range)
        .unwrap_err()
        .to_string();
    assert!(e.contains("line 2: column r0c3: 4 exceeds the range 3"), "{e}");
    let zeros: Vec<(usize, &str)> = (0..16).map(|k| (k, "0")).collect();
    let e = parse_real_csv(
        &format!("{header}{}", frame_4x4("A", &zeros)),
        "f.csv",
        &RealImport::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("every value is zero"), "{e}");
    let e = parse_real_csv(&header, "f.csv", &RealImport::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("no frames"), "{e}");
}

#[test]
fn import_normalises_by_the_file_maximum_or_the_range() {
    // Taxel k of A reads k + 1 but r0c0 (0) and r0c1 (50); B reads 200 at r0c0, 100 at r0c1.
    let text = format!(
        "{}{}{}",
        header_4x4(),
        frame_4x4("A", &[(0, "0"), (1, "50")]),
        frame_4x4("B", &[(0, "200"), (1, "100")])
    );
    let data = parse_real_csv(&text, "t", &RealImport::default()).unwrap();
    assert_eq!(&data.readings[0].image.values()[..2], &[0.0, 0.25]);
    assert_eq!(&data.readings[1].image.values()[..2], &[1.0, 0.5]);
    assert_eq!(
        (data.readings[1].label.as_str(), &data.readings[1].place),
        ("B", &FramePlace::Line(3))
    );
    assert_eq!("max".parse::<Normalisation>(), Ok(Normalisation::FileMax));
    assert_eq!("400".parse::<Normalisation>(), Ok(Normalisation::Range(400.0)));
    assert!(
        "-1".parse::<Normalisation>()
            .unwrap_err()
            .to_string()
            .contains("'-1'")
    );
    let ranged = RealImport {
        normalisation: "400".parse().unwrap(),
        allowed_labels: None,
        calibration: None,
    };
    assert_eq!(
        &parse_real_csv(&text, "t", &ranged).unwrap().readings[1]
            .image
            .values()[..2],
        &[0.5, 0.25]
    );
}

fn delta(rows: usize, cols: usize, at: (usize, usize), value: f64) -> TactileImage {
    let mut values = vec![0.0; rows * cols];
    values[at.0 * cols + at.1] = value;
    TactileImage::new(rows, cols, values).unwrap()
}

#[test]
fn preprocessing_takes_square_roots_then_blurs() {
    let image = TactileImage::new(1, 4, vec![0.0, 0.25, 0.81, 1.0]).unwrap();
    assert_eq!(square_root(&image).values(), &[0.0, 0.5, 0.9, 1.0]);

    // A delta becomes the Gaussian kernel (the outer product of the 1-D kernel).
    let blur = GaussianBlur::new(0.5).unwrap();
    let k = blur.kernel().to_vec();
    assert_eq!(k.len(), 5);
    let g = |a: f64| (-a * a / 0.5).exp();
    let norm = g(0.0) + 2.0 * g(1.0) + 2.0 * g(2.0);
    for (i, a) in (-2..=2).enumerate() {
        assert!((k[i] - g(a as f64) / norm).abs() < 1e-15);
    }
    // The blur of a delta at `at` on a `rows x cols` frame, away from its borders.
    let assert_kernel_around = |rows: usize, cols: usize, at: (usize, usize)| {
        let out = blur.apply(&delta(rows, cols, at, 1.0));
        for r in 0..rows {
            for c in 0..cols {
                let (dr, dc) = (r as i64 - at.0 as i64, c as i64 - at.1 as i64);
                let expected = if dr.abs() <= 2 && dc.abs() <= 2 {
                    k[(dr + 2) as usize] * k[(dc + 2) as usize]
                } else {
                    0.0
                };
                assert!(
                    (out.get(r, c) - expected).abs() < 1e-15,
                    "{rows}x{cols}: ({r}, {c})"
                );
            }
        }
    };
    assert_kernel_around(12, 12, (6, 6));

    // A frame of another shape than square (a 28x50 array's, smaller) is blurred along each axis
    // over that axis's length: a delta gives the same outer product, and blurring the transposed
    // frame gives the transposed blur, borders included.
    assert_kernel_around(9, 13, (4, 8));
    let values: Vec<f64> = (0..21).map(|i| ((i * 7) % 11) as f64 / 10.0).collect();
    let wide = TactileImage::new(3, 7, values).unwrap();
    let transpose = |im: &TactileImage| {
        let t = (0..im.cols()).flat_map(|c| (0..im.rows()).map(move |r| (r, c)));
        TactileImage::new(im.cols(), im.rows(), t.map(|(r, c)| im.get(r, c)).collect()).unwrap()
    };
    let (blurred, tall) = (blur.apply(&wide), blur.apply(&transpose(&wide)));
    for (a, b) in transpose(&blurred).values().iter().zip(tall.values()) {
        assert!((a - b).abs() < 1e-12, "{a} against {b}");
    }

    // Mass is preserved away from the borders; a uniform image stays uniform up to the borders.
    let sum = |im: &TactileImage| im.values().iter().sum::<f64>();
    let mut values = vec![0.0; 144];
    for (r, c, v) in [(4, 4, 0.3), (5, 7, 0.9), (7, 6, 0.5)] {
        values[r * 12 + c] = v;
    }
    let image = TactileImage::new(12, 12, values).unwrap();
    assert!((sum(&blur.apply(&image)) - sum(&image)).abs() < 1e-12);
    let flat = TactileImage::new(6, 6, vec![0.4; 36]).unwrap();
    assert!(blur.apply(&flat).values().iter().all(|v| (v - 0.4).abs() < 1e-15));

    // The full Sec. V-F chain on a delta of 0.25: sqrt gives 0.5, then the kernel scaled by 0.5.
    let pre = SimToRealPreprocess::default();
    let out = pre.apply(&delta(12, 12, (6, 6), 0.25));
    assert!((out.get(6, 6) - 0.5 * k[2] * k[2]).abs() < 1e-15);
    assert_eq!(
        SimToRealPreprocess::new(0.0).unwrap().apply(&image).values(),
        square_root(&image).values()
    );
    assert!(GaussianBlur::new(-1.0).is_err() && GaussianBlur::new(f64::NAN).is_err());
}
