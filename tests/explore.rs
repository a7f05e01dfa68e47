//! Exploration: the planner with the arm and the training sampler, on real MuJoCo scenes.

mod common;

use glam::DVec3;
use taction::control::ControlConfig;
use taction::dataset::ContactStatus;
use taction::dataset::Strategy;
use taction::explore::PlannerConfig;
use taction::explore::{CollectMode, CollectPlan};
use taction::sim::{ObjectSpec, PerturbationBounds, StartPose};
use taction::tactile::SensorConfig;
use taction::valid::Valid;

fn box_object() -> ObjectSpec {
    ObjectSpec::new("box", common::box_mesh(DVec3::new(0.10, 0.08, 0.10)))
}

/// Two objects of different shapes, each collected in its own scene.
fn box_and_sphere() -> [ObjectSpec; 2] {
    [
        box_object(),
        ObjectSpec::new(
            "sphere",
            common::sphere_mesh(0.04, DVec3::new(0.0, 0.0, 0.04), 12),
        ),
    ]
}

fn plan(mode: CollectMode, readings: usize, perturbation: PerturbationBounds) -> CollectPlan {
    CollectPlan {
        mode,
        sensor: SensorConfig::square(6, 6, 0.012, 0.0012),
        control: Valid::default(),
        perturbation,
        readings_per_object: readings,
        seed: 17,
        start_pose: StartPose::Canonical,
        free_object: None,
    }
}

#[test]
fn planner_collects_converged_readings_on_a_box() {
    for (perturbation, wanted) in [
        (PerturbationBounds::NONE, 20),
        (PerturbationBounds::new(10.0, 0.1).unwrap(), 10),
    ] {
        let t0 = std::time::Instant::now();
        let plan = plan(CollectMode::Planner(Valid::default()), wanted, perturbation);
        let report = plan.collect_object(&box_object(), 0).unwrap();
        eprintln!(
            "planner: {} converged of {} attempts in {} iterations, {} collisions, {} unreachable, {:?} ({:?})",
            report.converged(),
            report.readings.len(),
            report.iterations,
            report.collisions(),
            report.unreachable_steps,
            report.by_status(),
            t0.elapsed()
        );
        assert_eq!(report.converged(), wanted);
        // The pad reaches the box without wasting most attempts (the arm's rigid back meeting the
        // surface used to leave 3 of 4 attempts at `MaxIterations`).
        assert!(
            report.readings.len() <= 2 * wanted,
            "{} attempts for {wanted} converged readings: {:?}",
            report.readings.len(),
            report.by_status()
        );
        let box_min = DVec3::new(-0.05, -0.04, 0.0);
        let box_max = DVec3::new(0.05, 0.04, 0.10);
        let t = plan.sensor.thickness_m;
        for r in &report.readings {
            assert!(matches!(r.strategy, Strategy::Global | Strategy::Local));
            let pose = r.image.pose().expect("every reading carries its pad pose");
            if r.status != ContactStatus::Converged {
                continue;
            }
            // A converged reading is a real contact with the box: the covering (the pad rectangle
            // swept t along the normal) reaching the box, and the pad facing the box's normal cone
            // at the contact: a face's normal, or at an edge any direction between its two faces'
            // normals (within 10 degrees).
            assert!(r.image.max() < 1.0, "saturated image reported converged");
            // The most compressed taxel's centre on the pad plane, in the box frame.
            let (row, col) = (0..r.image.rows())
                .flat_map(|row| (0..r.image.cols()).map(move |col| (row, col)))
                .max_by(|&a, &b| r.image.get(a.0, a.1).total_cmp(&r.image.get(b.0, b.1)))
                .expect("a non-empty image");
            let x = ((col as f64 + 0.5) / r.image.cols() as f64 - 0.5) * plan.sensor.pad_width_m;
            let y = (0.5 - (row as f64 + 0.5) / r.image.rows() as f64) * plan.sensor.pad_height_m;
            let p = r
                .object_pose
                .inverse()
                .transform_point(pose.center_m + pose.right() * x + pose.up * y);
            // Within the covering's thickness of the surface: outside it, or, where the pad's
            // back passed an edge before any taxel saturated (Press ends on the image alone,
            // Sec. III-B, as for the training sampler's pad), inside it.
            let q = p.clamp(box_min, box_max);
            let inside_m = (p - box_min).min(box_max - p).min_element().max(0.0);
            assert!(
                p.distance(q) < t && inside_m < t,
                "the most pressed taxel is {} m from the box (t = {t}); normal {:?}, image {:?}",
                p.distance(q).max(inside_m),
                pose.normal,
                r.image.values()
            );
            // Pressed to the target mean, or as far as the rigid back allows: over an edge the
            // back meets the box before the mean reaches it (the saturation termination, Sec.
            // III-B). The back's front is the pad rectangle; its gap to the box, on a grid 0.5 mm
            // apart (so "at the box" is within that spacing):
            let to_box = r.object_pose.inverse();
            let back_gap = (0..=24)
                .flat_map(|i| (0..=24).map(move |j| (i, j)))
                .map(|(i, j)| {
                    let x = (j as f64 / 24.0 - 0.5) * plan.sensor.pad_width_m;
                    let y = (i as f64 / 24.0 - 0.5) * plan.sensor.pad_height_m;
                    let point = to_box.transform_point(pose.center_m + pose.right() * x + pose.up * y);
                    point.distance(point.clamp(box_min, box_max))
                })
                .fold(f64::INFINITY, f64::min);
            let mean = r.image.mean();
            assert!(
                (mean - plan.control.target_mean_pressure).abs() <= 0.05 || back_gap < 0.5e-3,
                "mean pressure {mean} with the back {back_gap} m from the box"
            );
            let outward = -(r.object_pose.rotation.inverse() * pose.normal);
            let slack = 10f64.to_radians().sin();
            for axis in 0..3 {
                let (n, on_min, on_max) = (
                    outward[axis],
                    // A face within the covering's thickness of the contact is part of it.
                    q[axis] <= box_min[axis] + t,
                    q[axis] >= box_max[axis] - t,
                );
                let in_cone = match (on_min, on_max) {
                    (true, _) => n <= slack,
                    (_, true) => n >= -slack,
                    _ => n.abs() <= slack,
                };
                assert!(
                    in_cone,
                    "pad normal {outward:?} outside the normal cone of the box at {q:?}"
                );
            }
        }
        let moved = report
            .readings
            .windows(2)
            .any(|w| w[0].object_pose != w[1].object_pose);
        assert_eq!(moved, !perturbation.is_none());
    }
}

/// 60 converged readings of the box by the sampler `mode`, with the plan that took them.
fn sampled_box(mode: CollectMode) -> (CollectPlan, taction::explore::ExplorationReport) {
    let plan = plan(mode, 60, PerturbationBounds::NONE);
    let report = plan.collect_object(&box_object(), 0).unwrap();
    assert_eq!(report.converged(), 60);
    (plan, report)
}

/// The converged readings of `report`.
fn converged(
    report: &taction::explore::ExplorationReport,
) -> impl Iterator<Item = &taction::dataset::Reading> {
    report
        .readings
        .iter()
        .filter(|r| r.status == ContactStatus::Converged)
}

#[test]
fn sampler_readings_cover_every_face_of_a_box() {
    let (plan, report) = sampled_box(CollectMode::Sampler(Valid::default()));
    let mut faces = std::collections::BTreeSet::new();
    for r in converged(&report) {
        let n = r.image.pose().unwrap().normal;
        let axis = if n.x.abs() > 0.7 {
            0
        } else if n.y.abs() > 0.7 {
            1
        } else if n.z.abs() > 0.7 {
            2
        } else {
            9
        };
        faces.insert((axis, n.x + n.y + n.z > 0.0));
        assert_eq!(r.strategy, Strategy::Sampler);
        assert!(
            (r.image.mean() - plan.control.target_mean_pressure).abs() <= 0.05,
            "mean pressure {}",
            r.image.mean()
        );
        // The pad centre is on the face it looks at, within the covering thickness.
        let p = r.image.pose().unwrap().center_m;
        let half = DVec3::new(0.05, 0.04, 0.05);
        let centre = DVec3::new(0.0, 0.0, 0.05);
        let outside = ((p - centre).abs() - half).max_element();
        assert!(
            outside > 0.0 && outside < plan.sensor.thickness_m + 1e-4,
            "pad centre {p:?} is {outside} m outside the box"
        );
    }
    assert_eq!(faces.len(), 6, "faces read: {faces:?}");
    assert!(
        report.readings.len() <= 70,
        "{} attempts for 60 converged readings",
        report.readings.len()
    );
}

/// The sampler restricted to starts the arm can reach (`SamplerConfig::reachable_by_arm`) reads
/// the box's four sides and its top, never the bottom resting on the table, which the free sampler
/// reads as often as its area says; every start it keeps is one the arm's IK and collision check
/// accept.
#[test]
fn reachable_sampler_reads_every_face_but_the_one_on_the_table() {
    use taction::explore::SamplerConfig;
    let reachable = Valid::new(SamplerConfig {
        reachable_by_arm: true,
        ..SamplerConfig::default()
    })
    .unwrap();
    let (_, report) = sampled_box(CollectMode::Sampler(reachable));
    let mut faces = std::collections::BTreeSet::new();
    for r in converged(&report) {
        let n = r.image.pose().unwrap().normal;
        let axis = (0..3).max_by(|&a, &b| n[a].abs().total_cmp(&n[b].abs())).unwrap();
        faces.insert((axis, n[axis] > 0.0));
    }
    // The bottom face is read by a pad looking up (+z).
    assert!(!faces.contains(&(2, true)), "the bottom face was read: {faces:?}");
    assert_eq!(faces.len(), 5, "faces read: {faces:?}");
}

/// The dataset a collection writes depends on the seed only: 1 and 2 worker threads write
/// byte-identical files, for the sampler and for the planner; another seed writes another file.
#[test]
fn datasets_are_identical_for_one_and_two_threads() {
    use taction::dataset::{Dataset, DatasetHeader};
    let dir = tempfile::tempdir().unwrap();
    let objects = box_and_sphere();
    let perturbation = PerturbationBounds::new(5.0, 0.05).unwrap();
    let write = |mode: CollectMode, seed: u64, threads: usize, name: &str| {
        let mut plan = plan(mode, 3, perturbation);
        plan.seed = seed;
        plan.sensor.noise_fraction = 0.1;
        plan.control = Valid::new(ControlConfig {
            expected_noise_fraction: 0.1,
            ..ControlConfig::default()
        })
        .unwrap();
        let reports = plan.collect(&objects, threads).unwrap();
        let header = DatasetHeader::new(
            plan.sensor,
            "test",
            objects.iter().map(|o| o.name.clone()).collect(),
            name,
            seed,
        );
        let readings: Vec<_> = reports.into_iter().flat_map(|r| r.readings).collect();
        for object in &objects {
            assert!(
                readings
                    .iter()
                    .any(|r| r.object == object.name && r.status == ContactStatus::Converged),
                "{name}: no converged reading of {}",
                object.name
            );
        }
        let path = dir.path().join(format!("{name}-{seed}-{threads}.csv"));
        Dataset::new(header, readings).unwrap().write(&path).unwrap();
        std::fs::read(&path).unwrap()
    };
    for (name, mode) in [
        ("sampler", CollectMode::Sampler(Valid::default())),
        ("planner", CollectMode::Planner(Valid::default())),
    ] {
        let serial = write(mode, 5, 1, name);
        let parallel = write(mode, 5, 2, name);
        assert!(
            serial == parallel,
            "{name}: 1 and 2 threads wrote different datasets"
        );
        assert!(
            write(mode, 6, 2, name) != serial,
            "{name}: seed 6 wrote the same dataset as seed 5"
        );
    }
}

/// A batch of datasets collected on one pool gives each dataset the bytes its own collection gives,
/// on one thread and on two, hands each over exactly once (a dataset of no objects too), counts
/// every converged reading, and stops at the first error of the caller's hand-over, returning it.
#[test]
fn a_batch_of_datasets_gives_each_the_bytes_of_its_own_collection() {
    use std::sync::Mutex;
    use std::sync::atomic::{AtomicUsize, Ordering};
    use taction::dataset::Dataset;
    use taction::explore::{BatchDataset, collect_datasets};
    let dir = tempfile::tempdir().unwrap();
    let objects = box_and_sphere();
    let perturbation = PerturbationBounds::new(5.0, 0.05).unwrap();
    let sampler = plan(CollectMode::Sampler(Valid::default()), 3, perturbation);
    let planner = plan(CollectMode::Planner(Valid::default()), 2, perturbation);
    let bytes = |dataset: &Dataset, name: &str| {
        let path = dir.path().join(name);
        dataset.write(&path).unwrap();
        std::fs::read(&path).unwrap()
    };
    let alone: Vec<Vec<u8>> = [sampler, planner]
        .iter()
        .enumerate()
        .map(|(i, p)| {
            bytes(
                &p.collect_dataset("test", &objects, 1, &|| {}).unwrap(),
                &format!("alone-{i}.csv"),
            )
        })
        .collect();
    let batch = [
        BatchDataset {
            plan: sampler,
            object_set: "test",
            objects: &objects,
        },
        BatchDataset {
            plan: planner,
            object_set: "test",
            objects: &objects,
        },
        BatchDataset {
            plan: sampler,
            object_set: "test",
            objects: &[],
        },
    ];
    for threads in [1, 2] {
        let handed: Mutex<Vec<(usize, Vec<u8>, usize)>> = Mutex::new(Vec::new());
        let converged = AtomicUsize::new(0);
        collect_datasets(
            &batch,
            threads,
            &|| {
                converged.fetch_add(1, Ordering::Relaxed);
            },
            &|n, dataset| -> Result<(), taction::explore::CollectError> {
                let file = bytes(&dataset, &format!("batch-{threads}-{n}.csv"));
                handed.lock().unwrap().push((n, file, dataset.len()));
                Ok(())
            },
        )
        .unwrap();
        let mut handed = handed.into_inner().unwrap();
        handed.sort_by_key(|(n, ..)| *n);
        assert_eq!(
            handed.iter().map(|(n, ..)| *n).collect::<Vec<_>>(),
            [0, 1, 2],
            "{threads} threads"
        );
        assert!(
            handed[0].1 == alone[0],
            "{threads} threads: the batch's sampler dataset differs"
        );
        assert!(
            handed[1].1 == alone[1],
            "{threads} threads: the batch's planner dataset differs"
        );
        assert_eq!(handed[2].2, 0, "the dataset of no objects has readings");
        assert_eq!(
            converged.into_inner(),
            2 * (3 + 2),
            "{threads} threads: converged readings counted"
        );
    }
    let handed = Mutex::new(Vec::new());
    type BoxError = Box<dyn std::error::Error + Send + Sync>;
    let error = collect_datasets(&batch[..2], 1, &|| {}, &|n, _| -> Result<(), BoxError> {
        handed.lock().unwrap().push(n);
        Err(format!("dataset {n} refused").into())
    })
    .unwrap_err();
    let handed = handed.into_inner().unwrap();
    assert_eq!(handed.len(), 1, "the batch went on after an error: {handed:?}");
    assert_eq!(error.to_string(), format!("dataset {} refused", handed[0]));
}

/// With L = 0 (global strategy only) the tree grows toward uniform targets from the nearest vertex
/// (RRT), so its vertices spread over the workspace: every octant of the workspace box holds vertices,
/// and their spread along each axis approaches that of a uniform distribution over the box (standard
/// deviation side / sqrt(12)). Expanding from a fixed or random vertex instead of the nearest one
/// leaves the tree near the arm's start, outside most octants.
#[test]
fn global_strategy_covers_the_workspace() {
    use taction::control::sensor_reader;
    use taction::explore::Planner;
    use taction::sim::PAD_SITE;
    use taction::sim::SceneBuilder;
    use taction::tactile::{CoveringSensor, add_sensor};

    let sensor = SensorConfig::square(6, 6, 0.012, 0.0012);
    // No object: nothing stops the expansion, so the tree shows the strategy alone.
    let mut scene = add_sensor(
        SceneBuilder::with_arm_and_table(),
        &Valid::new(sensor).unwrap(),
        PAD_SITE,
    )
    .build()
    .unwrap();
    let reader = sensor_reader(CoveringSensor::on_site(scene.model(), PAD_SITE).unwrap());
    let config = PlannerConfig {
        local_probability: 0.0,
        max_iterations: 300,
        ..PlannerConfig::default()
    };
    let mut planner = Planner::new(
        &scene,
        Valid::new(config).unwrap(),
        taction::explore::TouchSetup {
            sensor,
            control: Valid::default(),
            perturbation: PerturbationBounds::NONE,
        },
        taction::rng::rng(3),
        reader,
    )
    .unwrap();
    let report = planner.explore(&mut scene, "nothing", 1).unwrap();
    assert_eq!(report.iterations, 300);
    // Only the table can be touched, and a reading of the table is not a converged reading.
    assert_eq!(report.converged(), 0, "{:?}", report.by_status());
    let (lo, hi) = (config.workspace_min_m, config.workspace_max_m);
    let inside: Vec<DVec3> = planner
        .tree()
        .vertices()
        .iter()
        .map(|v| v.pad_m)
        .filter(|p| p.cmpge(lo - 0.01).all() && p.cmple(hi + 0.01).all())
        .collect();
    assert!(inside.len() >= 300, "{} vertices in the workspace", inside.len());
    let mid = (lo + hi) * 0.5;
    let mut octants = [0usize; 8];
    for p in &inside {
        let o = (p.x > mid.x) as usize | ((p.y > mid.y) as usize) << 1 | ((p.z > mid.z) as usize) << 2;
        octants[o] += 1;
    }
    assert!(
        octants.iter().all(|&n| n >= inside.len() / 40),
        "vertices per octant: {octants:?}"
    );
    let n = inside.len() as f64;
    let mean = inside.iter().copied().sum::<DVec3>() / n;
    let sd = (inside.iter().map(|p| (*p - mean) * (*p - mean)).sum::<DVec3>() / n).sqrt();
    let uniform_sd = (hi - lo) / 12f64.sqrt();
    let ratio = sd / uniform_sd;
    assert!(
        ratio.cmpgt(DVec3::splat(0.6)).all(),
        "spread {sd:?} against a uniform box's {uniform_sd:?}"
    );
}

/// Converged / attempts and time of the planner on the box, the pawn and two CGAL meshes (run by
/// hand: `cargo test --release --test explore -- --ignored --nocapture planner_rates`).
#[test]
#[ignore]
fn planner_rates() {
    use taction::mesh::{BuildOptions, ObjectSet};
    let shapes = ObjectSet::shapes();
    let options = BuildOptions {
        fetch: true,
        ..BuildOptions::default()
    };
    let mut objects = vec![box_object()];
    for name in ["pawn", "rook", "bunny", "fandisk"]
        .into_iter()
        .filter(|n| std::env::var("RATES_ONLY").map_or(true, |o| o == *n))
    {
        let built = shapes.build_object(name, &options).unwrap();
        objects.push(ObjectSpec::new(name, built.mesh));
    }
    for object in &objects {
        let plan = plan(
            CollectMode::Planner(Valid::default()),
            40,
            PerturbationBounds::NONE,
        );
        let t0 = std::time::Instant::now();
        let report = plan.collect_object(object, 0).unwrap();
        let s = t0.elapsed().as_secs_f64();
        eprintln!(
            "{:8}: {} converged of {} attempts ({:.0}%), {} iterations, {} collisions, {:?}, {:.2} s = {:.1} converged/s",
            object.name,
            report.converged(),
            report.readings.len(),
            100.0 * report.converged() as f64 / report.readings.len() as f64,
            report.iterations,
            report.collisions(),
            report.by_status(),
            s,
            report.converged() as f64 / s
        );
    }
}

/// `taction collect` writes a contact sheet per object beside the dataset, with as many images as
/// asked for (12 a row, 8 pixels a taxel at 6x6, 2-pixel gutters), and none with
/// `--contact-sheet 0`.
#[test]
fn collect_writes_contact_sheets_beside_the_dataset() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = dir.path().join("block.obj");
    taction::mesh::write_obj(&common::box_mesh(DVec3::new(0.10, 0.08, 0.10)), &mesh, "block").unwrap();
    let run = |sheet: usize, out: &str| {
        let output = std::process::Command::new(env!("CARGO_BIN_EXE_taction"))
            .args([
                "collect",
                "--mode",
                "sampler",
                "--readings",
                "5",
                "--threads",
                "1",
            ])
            .arg("--objects")
            .arg(&mesh)
            .arg("--contact-sheet")
            .arg(sheet.to_string())
            .arg("--out")
            .arg(dir.path().join(out))
            .output()
            .unwrap();
        assert!(
            output.status.success(),
            "{}",
            String::from_utf8_lossy(&output.stderr)
        );
    };
    run(3, "three.csv");
    let sheet = dir.path().join("three.block.png");
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&sheet).unwrap()));
    let info = decoder.read_info().unwrap().info().clone();
    // 3 images of 6x6 taxels at 8 px, 2-px gutters: 3 * (48 + 2) + 2 wide, 48 + 2 + 2 high.
    assert_eq!((info.width, info.height), (152, 52));
    run(0, "none.csv");
    assert!(dir.path().join("none.csv").exists());
    assert!(!dir.path().join("none.block.png").exists());
}

/// `taction collect` of two sampler readings of a 10 x 8 x 10 cm block written into `dir`, one
/// thread, no contact sheet, with `extra` flags, into `out`.
fn collect_two_readings_of_a_block(
    dir: &std::path::Path,
    extra: &[&str],
    out: &std::path::Path,
) -> std::process::Output {
    let mesh = dir.join("block.obj");
    taction::mesh::write_obj(&common::box_mesh(DVec3::new(0.10, 0.08, 0.10)), &mesh, "block").unwrap();
    std::process::Command::new(env!("CARGO_BIN_EXE_taction"))
        .args([
            "collect",
            "--readings",
            "2",
            "--threads",
            "1",
            "--contact-sheet",
            "0",
        ])
        .args(extra)
        .arg("--objects")
        .arg(&mesh)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap()
}

/// A `--from-above` dataset says so in its header: the CLI names its generator by the one
/// definition (`CollectMode::generator_name`), as the experiments do (it wrote `sampler`).
#[test]
fn a_from_above_dataset_says_so_in_its_header() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("above.csv");
    let output = collect_two_readings_of_a_block(dir.path(), &["--from-above"], &out);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let dataset = taction::dataset::Dataset::read(&out).unwrap();
    assert_eq!(dataset.header().generator, "sampler from above");
}

/// `taction collect --control FILE.json` runs the sampler with those controllers: on a raised bar
/// touched from above, the edge guard keeps the readings level where the default Orient tips the
/// pad over the bar's edges; a file naming an unknown field is refused, naming the file and the
/// field.
#[test]
fn collect_takes_the_controllers_from_a_control_file() {
    use taction::dataset::{ContactStatus, Dataset};
    use taction::mesh::TriMesh;
    let dir = tempfile::tempdir().unwrap();
    let mesh = dir.path().join("bar.obj");
    let mut bar = TriMesh::cuboid(DVec3::new(0.02, 0.02, 0.001)).translated(DVec3::new(0.0, 0.0, 0.001));
    bar.append(&TriMesh::cuboid(DVec3::new(0.004, 0.02, 0.0015)).translated(DVec3::new(0.0, 0.0, 0.0035)));
    taction::mesh::write_obj(&bar, &mesh, "bar").unwrap();
    let run = |control: Option<&str>, out: &str| {
        let mut command = std::process::Command::new(env!("CARGO_BIN_EXE_taction"));
        command
            .args([
                "collect",
                "--from-above",
                "--readings",
                "100",
                "--contact-sheet",
                "0",
            ])
            .arg("--objects")
            .arg(&mesh)
            .arg("--out")
            .arg(dir.path().join(out));
        if let Some(json) = control {
            let file = dir.path().join(format!("{out}.json"));
            std::fs::write(&file, json).unwrap();
            command.arg("--control").arg(file);
        }
        command.output().unwrap()
    };
    let tipped = |out: &str| {
        let dataset = Dataset::read(&dir.path().join(out)).unwrap();
        let converged: Vec<_> = dataset
            .readings()
            .iter()
            .filter(|r| r.status == ContactStatus::Converged)
            .collect();
        assert_eq!(converged.len(), 100);
        converged
            .iter()
            .filter(|r| {
                r.image
                    .pose()
                    .unwrap()
                    .normal
                    .angle_between(DVec3::NEG_Z)
                    .to_degrees()
                    > 12.0
            })
            .count()
    };
    assert!(run(None, "plain.csv").status.success());
    assert!(
        run(Some("{\"orient_edge_guard\": true}"), "guarded.csv")
            .status
            .success()
    );
    let (plain, guarded) = (tipped("plain.csv"), tipped("guarded.csv"));
    assert!(
        plain >= 10 && guarded * 3 < plain,
        "tipped over 12 deg: {plain} plain, {guarded} guarded"
    );

    let refused = run(Some("{\"orient_edge_gard\": true}"), "refused.csv");
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert!(!refused.status.success());
    assert!(
        stderr.contains("--control")
            && stderr.contains("refused.csv.json")
            && stderr.contains("orient_edge_gard"),
        "{stderr}"
    );
}

/// A reader that corrupts the world's state just before its reads number `at` (counting from 1),
/// with `corrupt`, then reads as `reader` does.
fn faulting<R: taction::control::ReadTactile + Send>(
    mut reader: R,
    at: &'static [usize],
    corrupt: fn(&mut taction::sim::Scene),
) -> impl taction::control::ReadTactile + Send {
    let mut reads = 0;
    move |scene: &mut taction::sim::Scene| {
        reads += 1;
        if at.contains(&reads) {
            corrupt(scene);
        }
        reader(scene)
    }
}

/// The free pad's sampler on the box for 10 converged readings, the state corrupted (the mocap
/// poses not finite, as a blown-up integration leaves positions) at reads `faults`.
fn faulted_sampler(faults: &'static [usize]) -> taction::explore::ExplorationReport {
    use taction::control::{FreePad, sensor_reader};
    let sensor = SensorConfig::square(6, 6, 0.012, 0.0012);
    let pad = FreePad::new(box_object(), &Valid::new(sensor).unwrap()).unwrap();
    let reader = faulting(sensor_reader(pad.covering().clone()), faults, |scene| {
        for p in scene.data_mut().mocap_pos_mut() {
            p[2] = f64::NAN;
        }
    });
    let mut pad = pad.with_reader(reader);
    taction::explore::TrainingSampler::new(
        Valid::default(),
        taction::explore::TouchSetup {
            sensor,
            control: Valid::default(),
            perturbation: PerturbationBounds::NONE,
        },
        taction::rng::stream(17, 0),
    )
    .sample(&mut pad, "box", 10)
    .unwrap()
}

/// The arm's planner on the box for 8 converged readings, the arm's velocities made NaN (an
/// unstable step's) at reads `faults`.
fn faulted_planner(faults: &'static [usize]) -> taction::explore::ExplorationReport {
    use taction::control::sensor_reader;
    use taction::explore::Planner;
    use taction::sim::PAD_SITE;
    use taction::sim::SceneBuilder;
    use taction::tactile::{CoveringSensor, add_sensor};
    let sensor = SensorConfig::square(6, 6, 0.012, 0.0012);
    let builder = SceneBuilder::with_arm_and_table().object(box_object());
    let mut scene = add_sensor(builder, &Valid::new(sensor).unwrap(), PAD_SITE)
        .build()
        .unwrap();
    let reader = faulting(
        sensor_reader(CoveringSensor::on_site(scene.model(), PAD_SITE).unwrap()),
        faults,
        |scene| scene.data_mut().qvel_mut().fill(f64::NAN),
    );
    let mut planner = Planner::new(
        &scene,
        Valid::default(),
        taction::explore::TouchSetup {
            sensor,
            control: Valid::default(),
            perturbation: PerturbationBounds::NONE,
        },
        taction::rng::stream(17, 0),
        reader,
    )
    .unwrap();
    planner.explore(&mut scene, "box", 8).unwrap()
}

/// A physics fault in the middle of a run, for either carrier: the run goes on to its converged
/// readings, the fault counted as `physics_fault` (an `aborted` reading when it struck during an
/// attempt), and the same faults give the same run. The sampler's draws do not depend on what
/// an attempt did, so every other attempt is the one the run without faults made.
#[test]
fn a_physics_fault_is_counted_and_the_run_goes_on_with_nothing_else_lost() {
    use taction::dataset::{AttemptCause, CauseKind};
    let aborted = |report: &taction::explore::ExplorationReport| -> Vec<usize> {
        report
            .readings
            .iter()
            .enumerate()
            .filter(|(_, r)| r.status == ContactStatus::Aborted)
            .map(|(i, r)| {
                assert_eq!(r.cause, Some(AttemptCause::PhysicsFault));
                i
            })
            .collect()
    };

    let clean = faulted_sampler(&[]);
    let faulted = faulted_sampler(&[30, 150]);
    assert_eq!(faulted.physics_faults(), 2);
    let lost = aborted(&faulted);
    assert_eq!(lost.len(), 2, "{:?}", faulted.by_status());
    assert_eq!(faulted.converged(), 10);
    assert!(aborted(&clean).is_empty());
    for (i, (with, without)) in faulted.readings.iter().zip(&clean.readings).enumerate() {
        if !lost.contains(&i) {
            assert_eq!(with, without, "attempt {i}");
        }
    }
    assert_eq!(faulted_sampler(&[30, 150]), faulted);

    // The planner reads while it expands and while it settles: the first fault strikes an
    // expansion step, the second an attempt.
    let clean = faulted_planner(&[]);
    let faulted = faulted_planner(&[8, 60]);
    assert_eq!(clean.physics_faults(), 0);
    assert_eq!(faulted.physics_faults(), 2);
    assert_eq!(
        (
            faulted.expansion_stops.get(&CauseKind::PhysicsFault).copied(),
            aborted(&faulted).len()
        ),
        (Some(1), 1),
        "{:?}, expansion stops {:?}",
        faulted.by_status(),
        faulted.expansion_stops
    );
    assert_eq!(faulted.converged(), 8);
    assert_eq!(faulted_planner(&[8, 60]), faulted);
}

/// The causes table `collect` and `dataset show` print: its column names, and each object's counts.
fn causes_table(printed: &str) -> (Vec<String>, std::collections::BTreeMap<(String, String), usize>) {
    let mut lines = printed.lines().skip_while(|l| !l.starts_with("causes "));
    let names: Vec<String> = lines
        .next()
        .unwrap_or_else(|| panic!("no causes table in {printed}"))
        .split_whitespace()
        .skip(1)
        .map(str::to_string)
        .collect();
    let mut counts = std::collections::BTreeMap::new();
    for line in lines.take_while(|l| !l.starts_with("strategies:")) {
        let mut fields = line.split_whitespace();
        let object = fields.next().unwrap().to_string();
        for (name, n) in names.iter().zip(fields) {
            let n: usize = n.parse().unwrap();
            if n > 0 {
                counts.insert((object.clone(), name.clone()), n);
            }
        }
    }
    (names, counts)
}

/// One vocabulary: the `cause` column of a collected dataset holds exactly the names of the table
/// `collect` prints (and `dataset show` prints again from the file), each counted as the table
/// counts it; the bodies that touched are beside it in `touched_bodies`.
#[test]
fn a_collected_datasets_causes_are_the_names_its_table_prints() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("chess.csv");
    let taction = |args: &[&str]| {
        let output = std::process::Command::new(env!("CARGO_BIN_EXE_taction"))
            .args(args)
            .output()
            .unwrap();
        assert!(
            output.status.success(),
            "{}",
            String::from_utf8_lossy(&output.stderr)
        );
        String::from_utf8_lossy(&output.stdout).into_owned()
    };
    let printed = taction(&[
        "collect",
        "--mode",
        "planner",
        "--objects",
        "chess",
        "--readings",
        "20",
        "--seed",
        "3",
        "--threads",
        "2",
        "--contact-sheet",
        "0",
        "--out",
        out.to_str().unwrap(),
    ]);
    let (names, table) = causes_table(&printed);

    let text = std::fs::read_to_string(&out).unwrap();
    let rows: String = text
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| format!("{l}\n"))
        .collect();
    let mut csv = csv::Reader::from_reader(rows.as_bytes());
    let columns = csv.headers().unwrap().clone();
    let column = |name: &str| columns.iter().position(|c| c == name).unwrap();
    let (object, cause, bodies) = (column("object"), column("cause"), column("touched_bodies"));
    let mut written = std::collections::BTreeMap::new();
    for record in csv.records() {
        let record = record.unwrap();
        if record[cause].is_empty() {
            continue;
        }
        assert!(
            names.iter().any(|n| n == &record[cause]),
            "cause '{}' is not a column of the table {names:?}",
            &record[cause]
        );
        let touch =
            ["pad_on_object", "arm_on_object", "arm_on_table", "arm_on_arm"].contains(&&record[cause]);
        assert_eq!(!record[bodies].is_empty(), touch, "{record:?}");
        *written
            .entry((record[object].to_string(), record[cause].to_string()))
            .or_insert(0) += 1;
    }
    assert_eq!(written, table);
    // Not a vacuous run: bodies touched and a contact was lost.
    let causes: std::collections::BTreeSet<&str> = written.keys().map(|(_, c)| c.as_str()).collect();
    assert!(
        causes.contains("pad_on_object") && causes.contains("lost_contact"),
        "{causes:?}"
    );
    let shown = taction(&["dataset", "show", out.to_str().unwrap()]);
    assert_eq!(causes_table(&shown), (names, table));
}

/// A dataset `collect` wrote in format 2, before the causes had one vocabulary (`taction collect
/// --mode planner --objects chess --readings 20 --seed 4 --rows 3 --cols 3`, its `cause` column
/// holding `sensor/object` and no lost contact), reads in this one: the touches are
/// `pad_on_object` with their bodies kept, the `no_contact` after pressing is `lost_contact`, and
/// `dataset show` counts them so.
#[test]
fn a_format_2_dataset_from_collect_reads_in_the_tables_vocabulary() {
    use taction::dataset::{AttemptCause, CauseKind, Dataset, FORMAT_VERSION};
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/dataset_v2/chess_planner_seed4.csv");
    assert!(
        std::fs::read_to_string(&path)
            .unwrap()
            .contains("\"format_version\":2")
    );
    let dataset = Dataset::read(&path).unwrap();
    assert_eq!(dataset.header().format_version, FORMAT_VERSION);
    assert_eq!(dataset.len(), 44);
    let causes: Vec<&AttemptCause> = dataset
        .readings()
        .iter()
        .filter_map(|r| r.cause.as_ref())
        .collect();
    let touched = AttemptCause::Touched {
        body_a: "sensor".into(),
        body_b: "object".into(),
    };
    assert_eq!(causes, [&touched, &touched, &touched, &AttemptCause::LostContact]);
    let summary = dataset.summary();
    assert_eq!(summary.causes[1][&CauseKind::PadOnObject], 3);
    assert_eq!(summary.causes[1][&CauseKind::LostContact], 1);
    let shown = std::process::Command::new(env!("CARGO_BIN_EXE_taction"))
        .args(["dataset", "show"])
        .arg(&path)
        .output()
        .unwrap();
    assert!(
        shown.status.success(),
        "{}",
        String::from_utf8_lossy(&shown.stderr)
    );
    let (_, table) = causes_table(&String::from_utf8_lossy(&shown.stdout));
    let expected: std::collections::BTreeMap<(String, String), usize> = [
        (("rook".to_string(), "pad_on_object".to_string()), 3),
        (("rook".to_string(), "lost_contact".to_string()), 1),
    ]
    .into();
    assert_eq!(table, expected);
}

/// The lowest point of `object`'s mesh at `pose` (world z, metres) and its tilt: the angle between
/// its own vertical and the world's, degrees.
fn rest_and_tilt(object: &ObjectSpec, pose: &taction::pose::Pose) -> (f64, f64) {
    let lowest = object.mesh.lowest_z_at(pose).expect("a mesh with vertices");
    let up = pose.transform_vector(DVec3::Z);
    (lowest, up.z.clamp(-1.0, 1.0).acos().to_degrees())
}

/// The heading of `pose`: where its own x axis points in the horizontal plane, degrees in
/// (-180, 180].
fn heading_deg(pose: &taction::pose::Pose) -> f64 {
    let x = pose.transform_vector(DVec3::X);
    x.y.atan2(x.x).to_degrees()
}

/// The arm's scene with `object` where it was built, no sensor (placing needs none).
fn arm_scene(object: &ObjectSpec) -> taction::sim::Scene {
    taction::sim::SceneBuilder::with_arm_and_table()
        .object(object.clone())
        .build()
        .unwrap()
}

/// A random start (`--start-pose random`) stands each object on the table, tilted at most 10
/// degrees, at a pose drawn from its own stream: the same for the same seed and object, another
/// for another object or seed; a canonical start leaves the object where it was built; the
/// letters' heading stays within 10 degrees where the 3D objects take any; the full turn is the
/// demo's draw, bit for bit; and the placed object stays inside the planner's workspace.
#[test]
fn a_random_start_stands_each_object_on_the_table_at_a_pose_of_its_own() {
    use rand::RngExt;
    use taction::mesh::ObjectSet;
    use taction::pose::{MaxHeading, Pose};
    use taction::sim::{Perturbation, PerturbationBounds};

    let chess = ObjectSpec::all_of(&ObjectSet::chess()).unwrap();
    let random = StartPose::random(MaxHeading::ANY);
    let placed = |plan: &CollectPlan, object: &ObjectSpec, index: usize| -> Pose {
        let mut scene = arm_scene(object);
        plan.place_at_start(&mut scene, index).unwrap();
        scene.object_pose().unwrap()
    };
    let mut random_plan = plan(
        CollectMode::Planner(Valid::default()),
        1,
        PerturbationBounds::NONE,
    );
    random_plan.start_pose = random;
    let canonical = plan(
        CollectMode::Planner(Valid::default()),
        1,
        PerturbationBounds::NONE,
    );
    assert_eq!(placed(&canonical, &chess[0], 0), Pose::IDENTITY);
    let first = placed(&random_plan, &chess[0], 0);
    assert_eq!(placed(&random_plan, &chess[0], 0), first, "one seed, one pose");
    assert_ne!(placed(&random_plan, &chess[0], 1), first, "each object its own");
    let reseeded = CollectPlan {
        seed: random_plan.seed + 1,
        ..random_plan
    };
    assert_ne!(placed(&reseeded, &chess[0], 0), first, "each seed its own");

    // Every start rests on the table, tilted at most 10 degrees, inside the planner's workspace
    // (fitted to the objects where they were built; its floor is above the table by design).
    let workspace = PlannerConfig::default().fitted_to(&chess);
    let (lo, hi) = (workspace.workspace_min_m, workspace.workspace_max_m);
    let mut letters = Vec::new();
    let mut any = Vec::new();
    for (index, object) in chess.iter().enumerate() {
        for seed in 0..6 {
            let at = |start_pose: StartPose| CollectPlan {
                seed,
                start_pose,
                ..random_plan
            };
            for (start_pose, headings) in [
                (random, &mut any),
                (StartPose::random(MaxHeading::LETTERS), &mut letters),
            ] {
                let pose = placed(&at(start_pose), object, index);
                assert_ne!(pose, Pose::IDENTITY);
                let (lowest, tilt) = rest_and_tilt(object, &pose);
                assert!(
                    lowest.abs() < 1e-9,
                    "{}: lowest vertex at z = {lowest}",
                    object.name
                );
                assert!(tilt <= 10.0 + 1e-9, "{}: tilted {tilt} deg", object.name);
                for v in &object.mesh.vertices {
                    let p = pose.transform_point(*v);
                    assert!(
                        p.x >= lo.x && p.y >= lo.y && p.x <= hi.x && p.y <= hi.y && p.z <= hi.z,
                        "{}: {p} outside the workspace {lo} .. {hi}",
                        object.name
                    );
                }
                headings.push(heading_deg(&pose));
            }
        }
    }
    // A heading within 10 degrees, tilted by at most 10 more, points its x axis within 10 +
    // asin(sin 10 / cos 10) = 20.2 degrees of the built heading; any heading does not.
    assert!(
        letters.iter().all(|h| h.abs() <= 20.2),
        "letters' headings {letters:?}"
    );
    assert!(any.iter().any(|h| h.abs() > 30.0), "any heading: {any:?}");

    // The full turn is the demo's draw: a heading over [0, 2 pi) from the stream, then the
    // perturbation of Sec. V-B4 (10 degrees, 10% of the width) from the same stream.
    for seed in 0..4 {
        let mut demo = arm_scene(&chess[1]);
        let mut r = taction::rng::stream(seed, 0xDE30);
        let width = demo.object_width_m().unwrap();
        demo.perturb_object(&Perturbation {
            axis: DVec3::Z,
            angle_rad: r.random_range(0.0..std::f64::consts::TAU),
            translation_m: DVec3::ZERO,
        })
        .unwrap();
        let shuffle = PerturbationBounds::new(10.0, 0.1).unwrap().draw(width, &mut r);
        let expected = demo.perturb_object(&shuffle).unwrap();
        let mut library = arm_scene(&chess[1]);
        let got = library
            .place_at_start(&random, &mut taction::rng::stream(seed, 0xDE30))
            .unwrap();
        assert_eq!(got, expected, "seed {seed}");
    }
}

/// A planner run from a random start records the placed pose in every reading, the object
/// resting on the table where no reading of a canonical start is anything but the identity, and
/// its header records the start, through the file and back; a canonical start's file has no
/// `start_pose` in its header, as every file before start poses had none.
#[test]
fn a_collection_from_a_random_start_records_it_in_readings_and_header() {
    use taction::dataset::Dataset;
    use taction::mesh::ObjectSet;
    use taction::pose::{MaxHeading, Pose};

    let dir = tempfile::tempdir().unwrap();
    let rook: Vec<ObjectSpec> = ObjectSpec::all_of(&ObjectSet::chess())
        .unwrap()
        .into_iter()
        .filter(|o| o.name == "rook")
        .collect();
    assert_eq!(rook.len(), 1);
    let config = PlannerConfig::for_collection(&rook, 2, 0.5, None);
    let collected = |start_pose: StartPose, name: &str| {
        let plan = CollectPlan {
            start_pose,
            ..plan(
                CollectMode::Planner(Valid::new(config).unwrap()),
                2,
                PerturbationBounds::NONE,
            )
        };
        let dataset = plan
            .dataset_of("chess", &rook, plan.collect(&rook, 1).unwrap())
            .unwrap();
        let path = dir.path().join(name);
        dataset.write(&path).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        let header_line = text.lines().nth(1).unwrap().to_string();
        let back = Dataset::read(&path).unwrap();
        assert_eq!(back, dataset, "{name}: the file reads back as written");
        (back, header_line)
    };

    let start = StartPose::random(MaxHeading::ANY);
    let (random, header) = collected(start, "random.csv");
    assert_eq!(random.header().start_pose, start);
    assert!(
        header.contains(r#""start_pose":{"random":{"max_heading_rad":3.141592653589793}}"#),
        "{header}"
    );
    assert!(random.converged().count() >= 2, "{:?}", random.summary());
    let pose = random.readings()[0].object_pose;
    assert_ne!(pose, Pose::IDENTITY);
    let (lowest, tilt) = rest_and_tilt(&rook[0], &pose);
    assert!(
        lowest.abs() < 1e-9 && tilt <= 10.0 + 1e-9,
        "z {lowest}, tilt {tilt}"
    );
    // Unperturbed, the object stays where it started.
    assert!(random.readings().iter().all(|r| r.object_pose == pose));
    assert!(
        random
            .summary()
            .to_string()
            .contains(", start pose random (any heading)\n")
    );

    let (canonical, header) = collected(StartPose::Canonical, "canonical.csv");
    assert!(!header.contains("start_pose"), "{header}");
    assert_eq!(canonical.header().start_pose, StartPose::Canonical);
    assert!(
        canonical
            .readings()
            .iter()
            .all(|r| r.object_pose == Pose::IDENTITY)
    );
    assert!(!canonical.summary().to_string().contains("start pose"));
}

/// `taction collect --start-pose random` draws each object's start and says so in the dataset's
/// header, which `dataset show` prints; `turned:90` faces every object one way; an unknown start
/// is refused, naming the flag and the starts there are.
#[test]
fn collect_starts_the_objects_where_start_pose_says() {
    use taction::dataset::Dataset;
    use taction::pose::{MaxHeading, Pose};

    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("random.csv");
    let run = |start: &str| collect_two_readings_of_a_block(dir.path(), &["--start-pose", start], &out);
    // The dataset `start` collects, and what `dataset show` says of its start.
    let collected = |start: &str| {
        let output = run(start);
        assert!(
            output.status.success(),
            "{}",
            String::from_utf8_lossy(&output.stderr)
        );
        let shown = std::process::Command::new(env!("CARGO_BIN_EXE_taction"))
            .args(["dataset", "show"])
            .arg(&out)
            .output()
            .unwrap();
        (
            Dataset::read(&out).unwrap(),
            String::from_utf8_lossy(&shown.stdout).into_owned(),
        )
    };
    let (dataset, text) = collected("random");
    assert_eq!(dataset.header().start_pose, StartPose::random(MaxHeading::ANY));
    assert!(dataset.readings().iter().all(|r| r.object_pose != Pose::IDENTITY));
    assert!(text.contains(", start pose random (any heading)"), "{text}");

    let (turned, text) = collected("turned:90");
    let StartPose::Turned { heading } = turned.header().start_pose else {
        panic!("{:?}", turned.header().start_pose);
    };
    assert!((heading.deg() - 90.0).abs() < 1e-9);
    // The random start's tilt and shift, the heading the one asked for.
    for r in turned.readings() {
        assert!(
            (heading_deg(&r.object_pose) - 90.0).abs() <= 10.2 + 1e-9,
            "{:?}",
            r.object_pose
        );
    }
    assert!(text.contains(", start pose turned (heading 90 deg)"), "{text}");

    for bad in ["upside-down", "turned:north"] {
        let refused = run(bad);
        assert_eq!(refused.status.code(), Some(2));
        let message = String::from_utf8_lossy(&refused.stderr);
        assert!(
            message.contains(&format!(
                "--start-pose {bad}: want one of canonical, random, turned:DEG"
            )),
            "{message}"
        );
    }
}
