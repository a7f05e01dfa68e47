//! Recognition speed (issue 7): the GMM codebook fit at the paper's training-set size (10 objects x
//! 1000 readings of ~20-dimensional PCA'd features, Sec. V-B), the per-touch cost of the online
//! posterior, the neighbour codebook's training histograms, and the posterior's tempering fit.
//!
//! Two GMM groups: `gmm_fit_10x1000x20` runs exactly 100 EM iterations (tolerance 0, the same work
//! for every implementation) and `gmm_fit_10x1000x20_tol1e-3` runs with the default settings (stop
//! when the mean log-likelihood changes by < 1e-3, at most 100 iterations), each for k = 10, 20, 50,
//! 100 (the grid model selection tries for 10 objects, [`codebook_sizes`](taction::recognize::codebook_sizes))
//! and 200, 400 (the range of the letters' grid, 26 and 52 objects).
//! The features are written to `target/bench-data/gmm_features.csv` and each fit's iterations and
//! final mean log-likelihood to `target/bench-data/gmm_taction.json`, so that
//! `benches/gmm_sklearn.py` times scikit-learn's `GaussianMixture` on exactly the same data with the
//! same settings and prints the side-by-side table with the ratios (see README, "Benchmarks"):
//!
//! ```text
//! cargo bench --bench recognize
//! target/parity-venv/bin/python benches/gmm_sklearn.py
//! ```

use std::hint::black_box;
use std::path::{Path, PathBuf};

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use rand::RngExt;
use taction::describe::Feature;
use taction::recognize::pipeline::{
    FeatureMatrix, GaussianMixture, GmmConfig, GmmFit, LeaveOneReadingOut, TrainingFeatures,
};
use taction::recognize::{
    CodebookConfig, CodebookKind, EvidencePath, LabelledFeatures, Tempering, TrainConfig, train,
};
use taction::rng::{Rng, stream};
use taction::units::round_trip;
use taction::valid::Valid;

const OBJECTS: usize = 10;
const READINGS: usize = 1000;
const DIM: usize = 20;
/// EM iterations, run to the end (tolerance 0) so both implementations do the same work.
const ITERATIONS: usize = 100;

fn normal(rng: &mut Rng) -> f64 {
    let u = 1.0 - rng.random::<f64>();
    let v = rng.random::<f64>();
    (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
}

/// Per object, a mixture of 5 correlated Gaussians in `DIM` dimensions (covariance `A A^T / DIM`
/// with a random `A`), `READINGS` features each: the shape of PCA'd descriptor features.
fn object_features(seed: u64) -> Vec<Vec<Feature>> {
    (0..OBJECTS)
        .map(|o| {
            let mut rng = stream(seed, o as u64);
            let blobs: Vec<(Vec<f64>, Vec<Vec<f64>>)> = (0..5)
                .map(|_| {
                    let mean = (0..DIM).map(|_| 3.0 * normal(&mut rng)).collect();
                    let a = (0..DIM)
                        .map(|_| (0..DIM).map(|_| normal(&mut rng) / (DIM as f64).sqrt()).collect())
                        .collect();
                    (mean, a)
                })
                .collect();
            (0..READINGS)
                .map(|i| {
                    let (mean, a) = &blobs[i % blobs.len()];
                    let z: Vec<f64> = (0..DIM).map(|_| normal(&mut rng)).collect();
                    mean.iter()
                        .zip(a)
                        .map(|(m, row)| m + row.iter().zip(&z).map(|(x, y)| x * y).sum::<f64>())
                        .collect()
                })
                .collect()
        })
        .collect()
}

fn bench_data_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("target/bench-data")
}

fn export(path: &Path, data: &FeatureMatrix) {
    let mut text = String::new();
    for row in data.iter_rows() {
        let line: Vec<String> = row.iter().map(|&v| round_trip(v)).collect();
        text.push_str(&line.join(","));
        text.push('\n');
    }
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).expect("create target/bench-data");
    }
    std::fs::write(path, text).expect("write the benchmark features");
}

/// Adds `entries` (under the group, keyed by k) to the JSON summary of our fits that
/// `benches/gmm_sklearn.py` reads, keeping the entries of groups and k not run this time.
fn record_fits(group: &str, entries: &[(usize, GmmFit)]) {
    let path = bench_data_dir().join("gmm_taction.json");
    let mut summary: serde_json::Map<String, serde_json::Value> = std::fs::read(&path)
        .ok()
        .and_then(|bytes| serde_json::from_slice(&bytes).ok())
        .unwrap_or_default();
    summary.insert("threads".into(), rayon::current_num_threads().into());
    let mut fits = match summary.remove(group) {
        Some(serde_json::Value::Object(fits)) => fits,
        _ => serde_json::Map::new(),
    };
    for (k, fit) in entries {
        fits.insert(
            k.to_string(),
            serde_json::json!({
                "iterations": fit.iterations,
                "converged": fit.converged,
                "mean_log_likelihood": fit.mean_log_likelihood,
            }),
        );
    }
    summary.insert(group.into(), fits.into());
    let text = serde_json::to_string_pretty(&summary).expect("a JSON object");
    std::fs::write(&path, text).expect("write target/bench-data/gmm_taction.json");
}

fn gmm_fit(c: &mut Criterion) {
    let features: Vec<Feature> = object_features(2011).into_iter().flatten().collect();
    let data = FeatureMatrix::from_features(&features, "benchmark").expect("finite features");
    export(&bench_data_dir().join("gmm_features.csv"), &data);
    let fixed = GmmConfig {
        max_iterations: ITERATIONS,
        tolerance: 0.0,
        ..GmmConfig::default()
    };
    for (name, config) in [
        ("gmm_fit_10x1000x20", fixed),
        ("gmm_fit_10x1000x20_tol1e-3", GmmConfig::default()),
    ] {
        let mut group = c.benchmark_group(name);
        group.sample_size(10);
        let mut fits = Vec::new();
        for k in [10, 20, 50, 100, 200, 400] {
            let mut last = None;
            group.bench_with_input(BenchmarkId::new("k", k), &k, |b, &k| {
                b.iter(|| {
                    // The same seeded fit every time: deterministic, so any run's summary will do.
                    let (model, fit) =
                        GaussianMixture::fit(&data, k, &config, &mut stream(1, 0)).expect("fit");
                    last = Some(fit);
                    black_box(model)
                })
            });
            // `last` is None when a filter skipped this k.
            fits.extend(last.map(|fit| (k, fit)));
        }
        group.finish();
        if !fits.is_empty() {
            record_fits(name, &fits);
        }
    }
}

fn per_touch(c: &mut Criterion) {
    // A model at the paper's scale: 10 objects, GMM with k = 50 (or 20 nearest of the 10 000
    // training features) on the PCA'd features; a touch is one 38-value feature (Polar-Fourier at
    // 6x6) through PCA, the codebook and Eq. 16.
    let raw_dim = 38;
    let lift: Vec<Vec<f64>> = {
        let mut rng = stream(7, 0);
        (0..raw_dim)
            .map(|_| (0..DIM).map(|_| normal(&mut rng)).collect())
            .collect()
    };
    let to_raw = |f: &Feature| -> Feature {
        lift.iter()
            .map(|row| row.iter().zip(f).map(|(a, b)| a * b).sum())
            .collect()
    };
    let per_object = object_features(99);
    let readings: Vec<Vec<Vec<Feature>>> = per_object
        .iter()
        .map(|o| o.iter().map(|f| vec![to_raw(f)]).collect())
        .collect();
    let names = (0..OBJECTS).map(|o| format!("object{o}")).collect();
    let training = LabelledFeatures::new(names, readings).expect("distinct names");
    let gmm = TrainConfig {
        codebook: CodebookKind::Gmm,
        ks: vec![50],
        restarts: 1,
        fitting: CodebookConfig {
            gmm: GmmConfig {
                max_iterations: 20,
                ..GmmConfig::default()
            },
            ..Default::default()
        },
        ..TrainConfig::default()
    };
    // The neighbour codebook scans every training feature per touch (README, "A neighbour
    // codebook"); beside the GMM it shows what that costs.
    let knn = TrainConfig {
        codebook: CodebookKind::Knn,
        ks: vec![20],
        variance_kept: CodebookKind::Knn.default_variance_kept(),
        ..gmm.clone()
    };
    // The network: one hidden layer of 128 units, its membership two small products per touch.
    let mlp = TrainConfig {
        codebook: CodebookKind::Mlp,
        ks: vec![128],
        variance_kept: CodebookKind::Mlp.default_variance_kept(),
        ..gmm.clone()
    };
    let touch = training.readings(3)[17].clone();
    let mut group = c.benchmark_group("per_touch");
    for (name, config) in [("gmm_k50", gmm), ("knn_k20", knn), ("mlp_h128", mlp)] {
        let config = Valid::new(config).expect("a valid configuration");
        let trained = train(&config, &training, None, &mut |_| {}).expect("train");
        group.bench_function(
            format!("{name}_{}objects_pca{}", OBJECTS, trained.bag.pca().output_dim()),
            |b| {
                let mut posterior = trained.bag.posterior();
                b.iter(|| black_box(posterior.observe(black_box(&touch)).expect("valid touch")))
            },
        );
    }
    group.finish();
}

/// The neighbour codebook's training histograms for model selection's four candidates (10, 20, 50,
/// 100 neighbours) on 10 objects x 1000 single-feature readings: a scan per candidate (the
/// baseline) against one scan at the largest k whose prefixes serve the rest (what `train` does;
/// the histograms are the same bit for bit, `neighbours.rs` tests it).
fn knn_training(c: &mut Criterion) {
    let features: Vec<Feature> = object_features(2011).into_iter().flatten().collect();
    let data = FeatureMatrix::from_features(&features, "benchmark").expect("finite features");
    let objects: Vec<u32> = (0..OBJECTS * READINGS).map(|r| (r / READINGS) as u32).collect();
    let readings: Vec<u32> = (0..(OBJECTS * READINGS) as u32).collect();
    let training = TrainingFeatures {
        data: &data,
        objects: &objects,
        object_count: OBJECTS,
        readings: &readings,
    };
    let ks = [10, 20, 50, 100];
    let mut group = c.benchmark_group("knn_training_histograms_10x1000x20");
    group.sample_size(10);
    group.bench_function("scan_per_k", |b| {
        b.iter(|| ks.map(|k| black_box(LeaveOneReadingOut::scan(training, k).histograms(k))))
    });
    group.bench_function("one_scan", |b| {
        b.iter(|| {
            let shared = LeaveOneReadingOut::scan(training, 100);
            ks.map(|k| black_box(shared.histograms(k)))
        })
    });
    group.finish();
}

/// The posterior's tempering fit (`Tempering::fit`, 192 golden-section searches over every prefix
/// of every validation trial) at the shapes of its two heavy uses: the 52 letters' validation
/// trials (520 of 10 readings) and the `active` experiment's calibration explorations (12 objects,
/// 36 whole explorations of 100 readings). Log-likelihoods as a codebook gives them: per reading,
/// the true object a little likelier on average.
fn tempering_fit(c: &mut Criterion) {
    let mut group = c.benchmark_group("tempering_fit");
    group.sample_size(10);
    for (objects, trials, readings) in [(52, 520, 10), (12, 36, 100)] {
        let mut rng = stream(53, objects as u64);
        let paths: Vec<EvidencePath> = (0..trials)
            .map(|t| {
                let object = t % objects;
                let mut sums = vec![0.0; objects];
                let log_likelihoods = (0..readings)
                    .map(|_| {
                        for (j, s) in sums.iter_mut().enumerate() {
                            let mean = if j == object { -3.0 } else { -4.0 };
                            *s += mean + 2.0 * normal(&mut rng);
                        }
                        sums.clone()
                    })
                    .collect();
                EvidencePath {
                    object,
                    log_likelihoods,
                }
            })
            .collect();
        group.bench_function(format!("{objects}objects_{trials}x{readings}"), |b| {
            b.iter(|| black_box(Tempering::fit(black_box(&paths))))
        });
    }
    group.finish();
}

criterion_group!(benches, gmm_fit, per_touch, knn_training, tempering_fit);
criterion_main!(benches);
