//! Principal component analysis of the training features (Sec. IV-A: "discarding the least
//! significant components that account for up to 10% of the variance").

use nalgebra::{DMatrix, SymmetricEigen};
use serde::{Deserialize, Serialize};

use crate::recognize::RecognizeError;
use crate::recognize::features::FeatureMatrix;
use crate::valid::checked_f64;

checked_f64! {
    /// The fraction of the training variance the kept components must explain, in (0, 1].
    pub struct VarianceFraction(fraction) where fraction > 0.0 && fraction <= 1.0;
    refused as RecognizeError:
        |fraction| RecognizeError::InvalidParameter {
            name: "variance_kept",
            what: format!("{fraction} is not a fraction in (0, 1]"),
        },
        |text| RecognizeError::InvalidParameter {
            name: "variance_kept",
            what: format!("'{text}' is not a number"),
        };
}

impl VarianceFraction {
    /// The paper's choice: keep 90% of the variance.
    pub const PAPER: Self = Self(0.9);
    /// The neighbour codebook's default (`CodebookKind::default_variance_kept`): 99%.
    pub const NEIGHBOURS: Self = Self(0.99);
    /// The network's default (`CodebookKind::default_variance_kept`): all of it, so that it
    /// reads the features back exactly (`recognize::mlp`).
    pub const NETWORK: Self = Self(1.0);
}

impl Default for VarianceFraction {
    fn default() -> Self {
        Self::PAPER
    }
}

/// A PCA transform fitted on training features and reused, unchanged, at test time.
///
/// For features `x_1 .. x_n` in `R^d` with mean `m`, the sample covariance is diagonalised exactly
/// (symmetric eigendecomposition, not an iterative solver):
///
/// ```text
/// S = 1/(n-1) sum_l (x_l - m)(x_l - m)^T = V diag(lambda) V^T,   lambda_1 >= ... >= lambda_d >= 0
/// ```
///
/// The transform keeps the fewest `q` leading eigenvectors with
/// `sum_{i<=q} lambda_i / sum_i lambda_i >= kept`, and maps `x` to `y = V_q^T (x - m)` (no whitening).
/// Each eigenvector's sign is fixed so its largest-magnitude entry is positive, which makes the
/// transform a deterministic function of the data.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Pca {
    /// The training mean `m`.
    mean: Vec<f64>,
    /// The kept eigenvectors `V_q^T`, one row per component, in decreasing variance.
    components: Vec<Vec<f64>>,
    /// Every eigenvalue `lambda_1 .. lambda_d` (variance along each principal axis), decreasing.
    explained_variance: Vec<f64>,
}

impl Pca {
    /// Fits on `features` (at least two) keeping `kept` of the variance.
    pub fn fit(features: &FeatureMatrix, kept: VarianceFraction) -> Result<Self, RecognizeError> {
        let (n, d) = (features.rows(), features.dim());
        if n < 2 {
            return Err(RecognizeError::NoFeatures(format!(
                "PCA needs at least 2 features, got {n}"
            )));
        }
        let mut mean = vec![0.0; d];
        for row in features.iter_rows() {
            for (m, v) in mean.iter_mut().zip(row) {
                *m += v;
            }
        }
        mean.iter_mut().for_each(|m| *m /= n as f64);
        let centered = DMatrix::from_fn(n, d, |r, c| features.row(r)[c] - mean[c]);
        let covariance = (centered.transpose() * &centered) / (n as f64 - 1.0);
        let eigen = SymmetricEigen::new(covariance);
        let mut order: Vec<usize> = (0..d).collect();
        order.sort_by(|&a, &b| {
            eigen.eigenvalues[b]
                .total_cmp(&eigen.eigenvalues[a])
                .then(a.cmp(&b))
        });
        let explained_variance: Vec<f64> = order.iter().map(|&i| eigen.eigenvalues[i].max(0.0)).collect();
        let total: f64 = explained_variance.iter().sum();
        if total.is_nan() || total <= 0.0 {
            return Err(RecognizeError::ZeroVariance);
        }
        let mut cumulative = 0.0;
        let mut q = d;
        for (i, lambda) in explained_variance.iter().enumerate() {
            cumulative += lambda;
            if cumulative / total >= kept.get() {
                q = i + 1;
                break;
            }
        }
        let components = order[..q]
            .iter()
            .map(|&i| {
                let mut v: Vec<f64> = eigen.eigenvectors.column(i).iter().copied().collect();
                let peak = v
                    .iter()
                    .enumerate()
                    .fold(0, |best, (j, x)| if x.abs() > v[best].abs() { j } else { best });
                if v[peak] < 0.0 {
                    v.iter_mut().for_each(|x| *x = -*x);
                }
                v
            })
            .collect();
        Ok(Self {
            mean,
            components,
            explained_variance,
        })
    }

    /// Input feature length `d`.
    pub fn input_dim(&self) -> usize {
        self.mean.len()
    }

    /// Number of kept components `q`.
    pub fn output_dim(&self) -> usize {
        self.components.len()
    }

    /// Every eigenvalue of the training covariance, decreasing.
    pub fn explained_variance(&self) -> &[f64] {
        &self.explained_variance
    }

    /// `lambda_i / sum lambda` for every component, decreasing.
    pub fn explained_variance_ratio(&self) -> Vec<f64> {
        let total: f64 = self.explained_variance.iter().sum();
        self.explained_variance.iter().map(|l| l / total).collect()
    }

    /// The fraction of the training variance the kept components explain.
    pub fn kept_variance_ratio(&self) -> f64 {
        self.explained_variance_ratio()[..self.output_dim()].iter().sum()
    }

    pub fn mean(&self) -> &[f64] {
        &self.mean
    }

    /// The kept principal axes, one row per component.
    pub fn components(&self) -> &[Vec<f64>] {
        &self.components
    }

    /// `y = V_q^T (x - m)` into `out` (length [`output_dim`](Self::output_dim)); `x` must have
    /// length [`input_dim`](Self::input_dim), which the caller has checked.
    pub fn transform_into(&self, x: &[f64], out: &mut [f64]) {
        debug_assert_eq!(x.len(), self.mean.len());
        for (o, axis) in out.iter_mut().zip(&self.components) {
            *o = axis
                .iter()
                .zip(x)
                .zip(&self.mean)
                .map(|((a, x), m)| a * (x - m))
                .sum();
        }
    }

    /// Transforms every row of `features` (already checked to have [`input_dim`](Self::input_dim)).
    pub fn transform(&self, features: &FeatureMatrix) -> FeatureMatrix {
        let q = self.output_dim();
        let mut data = vec![0.0; features.rows() * q];
        for (row, out) in features.iter_rows().zip(data.chunks_exact_mut(q)) {
            self.transform_into(row, out);
        }
        FeatureMatrix::from_trusted(features.rows(), q, data)
    }

    /// Checks the shapes after deserialising; `Err` says what is wrong.
    pub(crate) fn check(&self) -> Result<(), String> {
        let d = self.mean.len();
        if d == 0 || self.components.is_empty() {
            return Err("PCA has no input dimensions or no components".into());
        }
        if self.explained_variance.len() != d {
            return Err(format!(
                "PCA has {} eigenvalues for {d} input dimensions",
                self.explained_variance.len()
            ));
        }
        if let Some(i) = self.components.iter().position(|c| c.len() != d) {
            return Err(format!(
                "PCA component {i} has {} values, expected {d}",
                self.components[i].len()
            ));
        }
        let all = self
            .mean
            .iter()
            .chain(self.components.iter().flatten())
            .chain(&self.explained_variance);
        if all.clone().any(|v| !v.is_finite()) {
            return Err("PCA has a non-finite value".into());
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn matrix(rows: &[[f64; 3]]) -> FeatureMatrix {
        let features: Vec<Vec<f64>> = rows.iter().map(|r| r.to_vec()).collect();
        FeatureMatrix::from_features(&features, "test").unwrap()
    }

    #[test]
    fn finds_the_axis_of_a_line_and_keeps_one_component() {
        // Points on the line t * (1, 2, 2)/3 + (1, 0, -1): all variance along one axis.
        let rows: Vec<[f64; 3]> = (0..7)
            .map(|i| i as f64 - 3.0)
            .map(|t| [1.0 + t / 3.0, 2.0 * t / 3.0, -1.0 + 2.0 * t / 3.0])
            .collect();
        let pca = Pca::fit(&matrix(&rows), VarianceFraction::PAPER).unwrap();
        assert_eq!(pca.output_dim(), 1);
        let axis = &pca.components()[0];
        for (a, e) in axis.iter().zip([1.0 / 3.0, 2.0 / 3.0, 2.0 / 3.0]) {
            assert!((a - e).abs() < 1e-12, "{axis:?}");
        }
        // Var of t over -3..3 with n-1 = 6: 28/6.
        assert!((pca.explained_variance()[0] - 28.0 / 6.0).abs() < 1e-12);
        let mut y = [0.0];
        pca.transform_into(&[1.0 + 1.0 / 3.0, 2.0 / 3.0, -1.0 + 2.0 / 3.0], &mut y);
        assert!((y[0] - 1.0).abs() < 1e-12);
    }

    #[test]
    fn keeps_the_fewest_components_reaching_the_fraction() {
        // Independent axes with variances in ratio 16 : 4 : 1 (scales 4, 2, 1 of the same +-1 pattern).
        let signs = [
            [1.0, 1.0, 1.0],
            [1.0, -1.0, -1.0],
            [-1.0, 1.0, -1.0],
            [-1.0, -1.0, 1.0],
        ];
        let rows: Vec<[f64; 3]> = signs.iter().map(|s| [4.0 * s[0], 2.0 * s[1], s[2]]).collect();
        let fm = matrix(&rows);
        let total = 21.0;
        let one = Pca::fit(&fm, VarianceFraction::new(0.7).unwrap()).unwrap();
        assert_eq!(one.output_dim(), 1);
        let two = Pca::fit(&fm, VarianceFraction::new(0.9).unwrap()).unwrap();
        assert_eq!(two.output_dim(), 2);
        let three = Pca::fit(&fm, VarianceFraction::new(1.0).unwrap()).unwrap();
        assert_eq!(three.output_dim(), 3);
        let ratio = three.explained_variance_ratio();
        for (r, e) in ratio.iter().zip([16.0 / total, 4.0 / total, 1.0 / total]) {
            assert!((r - e).abs() < 1e-12, "{ratio:?}");
        }
    }

    #[test]
    fn rejects_constant_features_and_bad_fractions() {
        let fm = matrix(&[[1.0, 2.0, 3.0], [1.0, 2.0, 3.0]]);
        assert!(matches!(
            Pca::fit(&fm, VarianceFraction::PAPER),
            Err(RecognizeError::ZeroVariance)
        ));
        assert!(VarianceFraction::new(0.0).is_err());
        assert!(VarianceFraction::new(1.5).is_err());
        assert!(VarianceFraction::new(f64::NAN).is_err());
    }
}
