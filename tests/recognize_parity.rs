//! Parity with a reference implementation outside the project (issue 7, item 9): scikit-learn's
//! PCA and GaussianMixture on the same exported features. The test installs numpy and scikit-learn
//! into a throwaway virtual environment cached under `target/parity-venv`; when Python or PyPI is
//! unreachable it prints why and returns.

mod recognize_toy;

use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::{Value, json};
use taction::describe::{DescriptorKind, Feature};
use taction::recognize::pipeline::{FeatureMatrix, GaussianMixture, GmmConfig, Pca};
use taction::recognize::{LabelledFeatures, VarianceFraction};
use taction::rng::stream;
use taction::units::round_trip;

/// The venv's python, creating the venv on first use; `Err` says why it cannot be had.
fn reference_python() -> Result<PathBuf, String> {
    let venv = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("target")
        .join("parity-venv");
    let python = venv.join("bin").join("python");
    let marker = venv.join("taction-parity-ready");
    if marker.exists() {
        return Ok(python);
    }
    let run = |cmd: &mut Command, what: &str| -> Result<(), String> {
        let out = cmd.output().map_err(|e| format!("{what}: {e}"))?;
        if out.status.success() {
            Ok(())
        } else {
            Err(format!(
                "{what} failed: {}",
                String::from_utf8_lossy(&out.stderr).lines().last().unwrap_or("")
            ))
        }
    };
    run(
        Command::new("python3").args(["-m", "venv"]).arg(&venv),
        "python3 -m venv",
    )?;
    run(
        Command::new(&python).args(["-m", "pip", "install", "--quiet", "numpy", "scikit-learn"]),
        "pip install numpy scikit-learn",
    )?;
    std::fs::write(&marker, "numpy scikit-learn\n").map_err(|e| e.to_string())?;
    Ok(python)
}

fn write_features(path: &Path, rows: impl IntoIterator<Item = impl AsRef<[f64]>>) {
    let mut text = String::new();
    for row in rows {
        let line: Vec<String> = row.as_ref().iter().map(|&v| round_trip(v)).collect();
        text.push_str(&line.join(","));
        text.push('\n');
    }
    std::fs::write(path, text).unwrap();
}

/// Five elongated Gaussian clusters in 6 dimensions, linearly mixed into 12 (so PCA has
/// redundant directions to drop), plus small isotropic noise.
fn mixed_clusters() -> Vec<Feature> {
    let mut rng = stream(21, 0);
    let mixing: Vec<Vec<f64>> = (0..12)
        .map(|_| (0..6).map(|_| recognize_toy::normal(&mut rng)).collect())
        .collect();
    let centers: Vec<Vec<f64>> = (0..5)
        .map(|_| (0..6).map(|_| 6.0 * recognize_toy::normal(&mut rng)).collect())
        .collect();
    (0..2000)
        .map(|i| {
            let c = &centers[i % 5];
            let latent: Vec<f64> = (0..6)
                .map(|d| c[d] + (0.3 + 0.2 * d as f64) * recognize_toy::normal(&mut rng))
                .collect();
            mixing
                .iter()
                .map(|row| {
                    row.iter().zip(&latent).map(|(m, l)| m * l).sum::<f64>()
                        + 0.01 * recognize_toy::normal(&mut rng)
                })
                .collect()
        })
        .collect()
}

#[test]
fn pca_and_gmm_agree_with_scikit_learn() {
    let python = match reference_python() {
        Ok(p) => p,
        Err(why) => {
            println!("skipping the scikit-learn parity check: {why}");
            return;
        }
    };
    let dir = tempfile::tempdir().unwrap();
    let kept = VarianceFraction::PAPER;

    // 1. PCA on real descriptor output: Polar-Fourier features of the toy object set.
    let descriptor = DescriptorKind::PolarFourier.build();
    let toy = LabelledFeatures::from_dataset(&recognize_toy::dataset(100, 5), descriptor.as_ref());
    let toy_features: Vec<&Feature> = toy.features().collect();
    write_features(
        &dir.path().join("features_pf.csv"),
        toy_features.iter().map(|f| f.as_slice()),
    );
    let toy_pca = Pca::fit(
        &FeatureMatrix::from_features(toy_features.iter().copied(), "toy").unwrap(),
        kept,
    )
    .unwrap();

    // 2. PCA then a 5-component GMM (best of 3 seeded fits) on mixed Gaussian clusters.
    let clusters = mixed_clusters();
    write_features(&dir.path().join("features_clusters.csv"), clusters.iter());
    let raw = FeatureMatrix::from_features(&clusters, "clusters").unwrap();
    let pca = Pca::fit(&raw, kept).unwrap();
    let reduced = pca.transform(&raw);
    write_features(&dir.path().join("reduced_clusters.csv"), reduced.iter_rows());
    let (gmm, fit) = (0..3)
        .map(|restart| {
            GaussianMixture::fit(&reduced, 5, &GmmConfig::default(), &mut stream(8, restart)).unwrap()
        })
        .max_by(|a, b| a.1.mean_log_likelihood.total_cmp(&b.1.mean_log_likelihood))
        .unwrap();

    let task = json!({
        "pca": [{"file": "features_pf.csv", "variance_kept": kept.get()}],
        "gmm": [{
            "file": "features_clusters.csv", "variance_kept": kept.get(), "k": 5,
            "rust_parameters": gmm.parameters(), "rust_reduced": "reduced_clusters.csv",
        }],
    });
    std::fs::write(dir.path().join("task.json"), task.to_string()).unwrap();
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/parity/sklearn_parity.py");
    let out = Command::new(&python)
        .arg(&script)
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let reference: Value = serde_json::from_slice(&out.stdout).unwrap();

    let floats = |v: &Value| -> Vec<f64> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect()
    };
    for (ours, theirs) in [(&toy_pca, &reference["pca"][0]), (&pca, &reference["gmm"][0])] {
        let ratio = floats(&theirs["explained_variance_ratio"]);
        let variance = floats(&theirs["explained_variance"]);
        // scikit-learn keeps min(n, d) components; compare those.
        for (i, (a, b)) in ours.explained_variance_ratio().iter().zip(&ratio).enumerate() {
            assert!((a - b).abs() < 1e-10, "ratio {i}: {a} vs {b}");
        }
        for (i, (a, b)) in ours.explained_variance().iter().zip(&variance).enumerate() {
            assert!((a - b).abs() <= 1e-9 * variance[0], "variance {i}: {a} vs {b}");
        }
        assert_eq!(
            ours.output_dim() as u64,
            theirs["components_kept"].as_u64().unwrap()
        );
    }
    let theirs = &reference["gmm"][0];
    let rust_by_sklearn = theirs["rust_model_mean_log_likelihood"].as_f64().unwrap();
    assert!(
        (rust_by_sklearn - fit.mean_log_likelihood).abs() < 1e-9,
        "scikit-learn scores our mixture {rust_by_sklearn}, we say {}",
        fit.mean_log_likelihood
    );
    let sklearn_fit = theirs["sklearn_mean_log_likelihood"].as_f64().unwrap();
    assert!(
        (sklearn_fit - fit.mean_log_likelihood).abs() < 1e-3,
        "best of 3 fits: scikit-learn {sklearn_fit}, taction {}",
        fit.mean_log_likelihood
    );
    println!(
        "parity: PCA keeps {} / {} components; mean log-likelihood taction {:.6}, scikit-learn {:.6}",
        toy_pca.output_dim(),
        pca.output_dim(),
        fit.mean_log_likelihood,
        sklearn_fit
    );
}
