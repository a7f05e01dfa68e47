//! Recognition speed (issue 7): the GMM codebook fit at the paper's training-set size (10 objects x
//! 1000 readings of ~20-dimensional PCA'd features, Sec. V-B) and the per-touch cost of the online
//! posterior.
//!
//! The GMM data are also written to `target/bench-data/gmm_features.csv`, so scikit-learn can be
//! timed on exactly the same features with the same k and iteration count:
//!
//! ```text
//! cargo bench --bench recognize -- gmm_fit
//! target/parity-venv/bin/python tests/parity/bench_sklearn_gmm.py target/bench-data/gmm_features.csv
//! ```

use std::hint::black_box;
use std::path::Path;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use rand::RngExt;
use taction::dataset::format_f64;
use taction::describe::Feature;
use taction::recognize::{
    CodebookConfig, CodebookKind, FeatureMatrix, GaussianMixture, GmmConfig, LabelledFeatures, TrainConfig,
    train,
};
use taction::rng::{Rng, stream};

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

fn export(path: &Path, data: &FeatureMatrix) {
    let mut text = String::new();
    for row in data.iter_rows() {
        let line: Vec<String> = row.iter().map(|&v| format_f64(v)).collect();
        text.push_str(&line.join(","));
        text.push('\n');
    }
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).expect("create target/bench-data");
    }
    std::fs::write(path, text).expect("write the benchmark features");
}

fn gmm_fit(c: &mut Criterion) {
    let features: Vec<Feature> = object_features(2011).into_iter().flatten().collect();
    let data = FeatureMatrix::from_features(&features, "benchmark").expect("finite features");
    export(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("target/bench-data/gmm_features.csv"),
        &data,
    );
    let config = GmmConfig {
        max_iterations: ITERATIONS,
        tolerance: 0.0,
        ..GmmConfig::default()
    };
    let mut group = c.benchmark_group("gmm_fit_10x1000x20");
    group.sample_size(10);
    for k in [10, 20, 50] {
        group.bench_with_input(BenchmarkId::new("k", k), &k, |b, &k| {
            b.iter(|| black_box(GaussianMixture::fit(&data, k, &config, &mut stream(1, 0)).expect("fit")))
        });
    }
    group.finish();
}

fn per_touch(c: &mut Criterion) {
    // A model at the paper's scale: 10 objects, GMM with k = 50 on the PCA'd features; a touch is
    // one 38-value feature (Polar-Fourier at 6x6) through PCA, the codebook and Eq. 16.
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
    let config = TrainConfig {
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
    let trained = train(&training, None, &config, &mut |_| {}).expect("train");
    let touch = training.readings(3)[17].clone();
    let mut group = c.benchmark_group("per_touch");
    group.bench_function(
        format!("gmm_k50_{}objects_pca{}", OBJECTS, trained.bag.pca().output_dim()),
        |b| {
            let mut posterior = trained.bag.posterior();
            b.iter(|| black_box(posterior.observe(black_box(&touch)).expect("valid touch")))
        },
    );
    group.finish();
}

criterion_group!(benches, gmm_fit, per_touch);
criterion_main!(benches);
