//! The experiment framework's own costs, to compare with the work units it runs: the sim-to-real
//! preprocessing per image (Sec. V-F), importing the example real-data file, the runner's overhead
//! per unit (atomic write, resume check, assembly), and drawing one figure.

use std::hint::black_box;
use std::path::Path;

use criterion::{BatchSize, BenchmarkId, Criterion, criterion_group, criterion_main};
use rand::RngExt;
use taction::dataset::{RealImport, import_real_csv};
use taction::experiment::ACCURACY_LABEL;
use taction::experiment::{BAND_LABEL, Figure, Panel, ReferenceLine, Series};
use taction::experiment::{Experiment, ExperimentSpec, RunOptions, SafeName, Unit, run};
use taction::paper::SimToRealPreprocess;
use taction::tactile::TactileImage;

fn preprocess(c: &mut Criterion) {
    let pre = SimToRealPreprocess::default();
    let mut group = c.benchmark_group("sim_to_real/preprocess");
    for n in [6, 14, 26] {
        let mut rng = taction::rng::stream(5, n as u64);
        let image =
            TactileImage::new(n, n, (0..n * n).map(|_| rng.random_range(0.0..1.0)).collect()).unwrap();
        group.bench_with_input(
            BenchmarkId::from_parameter(format!("{n}x{n}")),
            &image,
            |b, image| b.iter(|| pre.apply(black_box(image))),
        );
    }
    group.finish();
}

fn import(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/real_letters_example.csv");
    c.bench_function("real_data/import_example_40_frames", |b| {
        b.iter(|| import_real_csv(black_box(&path), &RealImport::default()).unwrap())
    });
}

#[derive(serde::Serialize, serde::Deserialize)]
struct Row {
    i: u64,
    twice: u64,
}

/// 20 units of one row each, no plots: the framework's cost with trivial work.
fn runner(c: &mut Criterion) {
    let spec = ExperimentSpec {
        name: SafeName::new("bench").unwrap(),
        description: String::new(),
        plots: vec![],
    };
    let experiment = || Experiment {
        spec: spec.clone(),
        config: 1u64,
        units: (0..20u64)
            .map(|i| {
                Unit::new(SafeName::builder("u").param("i", i).build().unwrap(), move || {
                    Ok(vec![Row { i, twice: i * 2 }])
                })
            })
            .collect(),
    };
    let mut group = c.benchmark_group("runner/20_units");
    group.sample_size(20);
    group.bench_function("fresh", |b| {
        b.iter_batched(
            || tempfile::tempdir().unwrap(),
            |dir| {
                run(&experiment(), &RunOptions::new(dir.path())).unwrap();
                dir
            },
            BatchSize::PerIteration,
        )
    });
    let done = tempfile::tempdir().unwrap();
    run(&experiment(), &RunOptions::new(done.path())).unwrap();
    group.bench_function("resume_all_done", |b| {
        b.iter(|| run(&experiment(), &RunOptions::new(done.path())).unwrap())
    });
    group.finish();
}

/// A two-panel accuracy figure of 4 x 100 points, drawn as SVG text and as PNG bytes.
fn figure(c: &mut Criterion) {
    let accuracy = |n: f64, k: f64| 1.0 - (-n / (10.0 + 40.0 * k)).exp();
    let series = |k: f64| Series {
        label: format!("noise_fraction = {k}"),
        points: (1..=100).map(|n| (n as f64, accuracy(n as f64, k))).collect(),
        band: (1..=100)
            .map(|n| {
                (
                    n as f64,
                    0.9 * accuracy(n as f64, k),
                    accuracy(n as f64, k).powf(0.9),
                )
            })
            .collect(),
    };
    let panel = |title: &str| Panel {
        title: title.to_string(),
        x_label: "number of readings".into(),
        y_label: ACCURACY_LABEL.into(),
        x_range: (1.0, 100.0),
        y_range: (0.0, 1.0),
        series: vec![series(0.0), series(0.2)],
        markers: false,
        legend: true,
        integer_x: true,
        reference: Some(ReferenceLine {
            y: 1.0 / 12.0,
            label: "chance (1/12)".into(),
        }),
        band_label: BAND_LABEL,
    };
    let figure = Figure {
        title: "bench".into(),
        panels: vec![panel("polar-fourier"), panel("mnti")],
    };
    let mut group = c.benchmark_group("figure/two_panels");
    group.sample_size(20);
    group.bench_function("svg", |b| b.iter(|| figure.to_svg().unwrap()));
    group.bench_function("png", |b| b.iter(|| figure.to_png().unwrap()));
    group.finish();
}

criterion_group!(benches, preprocess, import, runner, figure);
criterion_main!(benches);
