//! Gaussian mixture models with full covariances, fitted by expectation-maximisation (Sec. V-B1,
//! Eq. 9-10): the soft codebook of the paper.
//!
//! Implemented here rather than taken from linfa-clustering: on 10 objects x 1000 PCA'd features
//! (10k x 20) linfa's GMM took ~110 ms per EM iteration at k = 20 and returned an error instead of a
//! model when EM had not converged within `max_n_iterations`, and it draws from `rand` 0.8 RNGs, so
//! it could not use this crate's seeded streams. This version follows scikit-learn's
//! `GaussianMixture(covariance_type="full")` step for step (k-means initialisation, `reg_covar`,
//! precision Cholesky factors, convergence on the mean log-likelihood), does its heavy products
//! with nalgebra's blocked matrix multiply, and runs the components in parallel; every per-component
//! result is computed by one thread in a fixed order, so results are bit-identical for any thread
//! count.

use nalgebra::{Cholesky, DMatrix, DVector};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::recognize::RecognizeError;
use crate::recognize::exp::{
    Shift, add_exp_of_differences, exp_of_differences_in_place, sum_exp_of_differences,
};
use crate::recognize::features::FeatureMatrix;
use crate::recognize::gmm_products::{
    WhitenedDistances, weighted_column_sums, weighted_scatter, whitened_distances,
};
use crate::recognize::kmeans::{KMeans, KMeansConfig};
use crate::rng::Rng;

const LN_2PI: f64 = 1.837_877_066_409_345_5;

/// EM settings; the defaults are scikit-learn's.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GmmConfig {
    /// Upper bound on EM iterations (one E-step and one M-step each).
    pub max_iterations: usize,
    /// Stop when the mean log-likelihood per feature changes by less than this (nats); 0 runs
    /// all `max_iterations`.
    pub tolerance: f64,
    /// Added to every covariance diagonal so each stays positive definite.
    pub reg_covar: f64,
    /// The k-means run that gives the initial responsibilities.
    pub kmeans: KMeansConfig,
}

impl Default for GmmConfig {
    fn default() -> Self {
        Self {
            max_iterations: 100,
            tolerance: 1e-3,
            reg_covar: 1e-6,
            kmeans: KMeansConfig::default(),
        }
    }
}

/// How a fit went.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GmmFit {
    pub iterations: usize,
    pub converged: bool,
    /// Mean log-likelihood per training feature of the final model, nats.
    pub mean_log_likelihood: f64,
}

/// The stored parameters of a mixture: weights `pi_i`, means `mu_i`, covariances `Sigma_i`
/// (row-major `d x d`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GmmParameters {
    pub weights: Vec<f64>,
    pub means: Vec<Vec<f64>>,
    pub covariances: Vec<Vec<f64>>,
}

/// A mixture `P(x | G) = sum_i pi_i N(x; mu_i, Sigma_i)` (Eq. 9-10).
///
/// Densities are evaluated through the upper-triangular precision factor `P_i = L_i^-T`, where
/// `Sigma_i = L_i L_i^T` (Cholesky), so `P_i P_i^T = Sigma_i^-1` and
///
/// ```text
/// ln N(x; mu_i, Sigma_i) = -1/2 (d ln 2pi + |P_i^T (x - mu_i)|^2) + sum_j ln (P_i)_jj
/// ```
///
/// Soft membership is the posterior of the components (responsibilities), computed with
/// log-sum-exp: `p(g_i | x) = exp(ln pi_i + ln N_i(x) - ln sum_m pi_m N_m(x))`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "GmmParameters", into = "GmmParameters")]
pub struct GaussianMixture {
    params: GmmParameters,
    /// `P_i`, column-major `d x d`, upper triangular.
    precision_chol: Vec<DMatrix<f64>>,
    /// `sum_j ln (P_i)_jj = -1/2 ln det Sigma_i`.
    log_det_precision: Vec<f64>,
    log_weights: Vec<f64>,
}

impl From<GaussianMixture> for GmmParameters {
    fn from(g: GaussianMixture) -> Self {
        g.params
    }
}

impl TryFrom<GmmParameters> for GaussianMixture {
    type Error = String;
    fn try_from(params: GmmParameters) -> Result<Self, String> {
        Self::from_parameters(params).map_err(|e| e.to_string())
    }
}

impl GaussianMixture {
    /// Fits `k` components to `data`: responsibilities from a seeded k-means (k-means++ seeding),
    /// then EM until the mean log-likelihood changes by less than `config.tolerance` or
    /// `config.max_iterations` is reached. A covariance that is not positive definite even with
    /// `reg_covar` added is an error, as in scikit-learn.
    pub fn fit(
        data: &FeatureMatrix,
        k: usize,
        config: &GmmConfig,
        rng: &mut Rng,
    ) -> Result<(Self, GmmFit), RecognizeError> {
        if !(config.reg_covar >= 0.0 && config.reg_covar.is_finite()) {
            return Err(RecognizeError::InvalidParameter {
                name: "reg_covar",
                what: format!("{} is not a finite non-negative number", config.reg_covar),
            });
        }
        let (kmeans, _) = KMeans::fit(data, k, &config.kmeans, rng)?;
        let responsibilities: Vec<Vec<f64>> = {
            let labels = kmeans.labels(data);
            (0..k)
                .map(|i| labels.iter().map(|&l| if l == i { 1.0 } else { 0.0 }).collect())
                .collect()
        };
        let x = data.to_dmatrix();
        let mut model = m_step(&x, data.as_slice(), &responsibilities, config.reg_covar)?;
        let mut lower_bound = f64::NEG_INFINITY;
        let mut converged = false;
        let mut iterations = 0;
        let mut responsibilities = responsibilities;
        for iteration in 1..=config.max_iterations {
            iterations = iteration;
            let previous = lower_bound;
            let mean_ll = model.e_step(&x, &mut responsibilities);
            model = m_step(&x, data.as_slice(), &responsibilities, config.reg_covar)?;
            lower_bound = mean_ll;
            if (lower_bound - previous).abs() < config.tolerance {
                converged = true;
                break;
            }
        }
        let mean_log_likelihood = model.mean_log_likelihood(data);
        Ok((
            model,
            GmmFit {
                iterations,
                converged,
                mean_log_likelihood,
            },
        ))
    }

    /// A mixture from explicit parameters: weights positive and summing to 1, every covariance
    /// symmetric positive definite.
    pub fn from_parameters(params: GmmParameters) -> Result<Self, RecognizeError> {
        let invalid = |what: String| RecognizeError::InvalidParameter { name: "gmm", what };
        let k = params.weights.len();
        let d = params.means.first().map_or(0, Vec::len);
        if k == 0 || d == 0 {
            return Err(invalid(
                "a mixture needs at least one component of at least one dimension".into(),
            ));
        }
        if params.means.len() != k || params.covariances.len() != k {
            return Err(invalid(format!(
                "{k} weights, {} means, {} covariances",
                params.means.len(),
                params.covariances.len()
            )));
        }
        if let Some(i) = params
            .means
            .iter()
            .position(|m| m.len() != d || m.iter().any(|v| !v.is_finite()))
        {
            return Err(invalid(format!("mean {i} is not {d} finite values")));
        }
        if let Some(i) = params
            .covariances
            .iter()
            .position(|c| c.len() != d * d || c.iter().any(|v| !v.is_finite()))
        {
            return Err(invalid(format!("covariance {i} is not {d}x{d} finite values")));
        }
        if params.weights.iter().any(|w| !(w.is_finite() && *w > 0.0)) {
            return Err(invalid(format!("weights must be positive: {:?}", params.weights)));
        }
        let sum: f64 = params.weights.iter().sum();
        if (sum - 1.0).abs() > 1e-9 {
            return Err(invalid(format!("weights sum to {sum}, not 1")));
        }
        let mut precision_chol = Vec::with_capacity(k);
        let mut log_det_precision = Vec::with_capacity(k);
        for (i, c) in params.covariances.iter().enumerate() {
            let sigma = DMatrix::from_row_slice(d, d, c);
            let (p, log_det) =
                precision_cholesky(sigma).ok_or(RecognizeError::SingularCovariance { component: i })?;
            precision_chol.push(p);
            log_det_precision.push(log_det);
        }
        let log_weights = params.weights.iter().map(|w| w.ln()).collect();
        Ok(Self {
            params,
            precision_chol,
            log_det_precision,
            log_weights,
        })
    }

    /// Number of components `k`.
    pub fn k(&self) -> usize {
        self.params.weights.len()
    }

    /// Feature length `d`.
    pub fn dim(&self) -> usize {
        self.params.means[0].len()
    }

    pub fn parameters(&self) -> &GmmParameters {
        &self.params
    }

    pub fn weights(&self) -> &[f64] {
        &self.params.weights
    }

    pub fn means(&self) -> &[Vec<f64>] {
        &self.params.means
    }

    /// `ln pi_i + ln N(x; mu_i, Sigma_i)` for every component, into `out` (length `k`).
    pub fn weighted_log_densities(&self, x: &[f64], out: &mut [f64]) {
        let d = self.dim();
        let constant = -0.5 * d as f64 * LN_2PI;
        for (i, o) in out.iter_mut().enumerate() {
            let p = self.precision_chol[i].as_slice();
            let mu = &self.params.means[i];
            let mut q = 0.0;
            for j in 0..d {
                // Column j of the upper-triangular P_i has entries only in rows 0..=j.
                let y: f64 = p[j * d..=j * d + j]
                    .iter()
                    .zip(x)
                    .zip(mu)
                    .map(|((p, x), m)| p * (x - m))
                    .sum();
                q += y * y;
            }
            *o = constant - 0.5 * q + self.log_det_precision[i] + self.log_weights[i];
        }
    }

    /// The responsibilities `p(g_i | x)` into `out` (length `k`); they sum to 1. Returns
    /// `ln P(x | G)`.
    pub fn responsibilities(&self, x: &[f64], out: &mut [f64]) -> f64 {
        self.weighted_log_densities(x, out);
        let lse = log_sum_exp(out);
        exp_of_differences_in_place(out, Shift::All(lse));
        lse
    }

    /// `ln P(x | G)` of every feature.
    pub fn score_samples(&self, data: &FeatureMatrix) -> Vec<f64> {
        let x = data.to_dmatrix();
        log_sum_exp_rows(&self.weighted_log_prob_columns(&x))
    }

    /// Mean of `ln P(x | G)` over `data` (scikit-learn's `score`).
    pub fn mean_log_likelihood(&self, data: &FeatureMatrix) -> f64 {
        self.score_samples(data).iter().sum::<f64>() / data.rows() as f64
    }

    /// For each component `i`, `ln pi_i + ln N(x_r; mu_i, Sigma_i)` over all rows `x_r` of `x`,
    /// with `P_i^T (x - mu_i)` computed for all rows at once as `X P_i - mu_i^T P_i` (one
    /// triangular product per component, `gmm_products`).
    fn weighted_log_prob_columns(&self, x: &DMatrix<f64>) -> Vec<Vec<f64>> {
        (0..self.k())
            .into_par_iter()
            .map(|i| {
                let p = &self.precision_chol[i];
                let (shift, offset) = self.whitening(i, x.ncols());
                let mut q = whitened_distances(x, p, shift.as_slice())
                    .unwrap_or_else(|| whitened_distances_general(x, p, shift.as_slice()));
                log_densities_in_place(offset, &mut q);
                q
            })
            .collect()
    }

    /// Component `i`'s shift `P_i^T mu_i` of its whitened distances `q` to features of `d` values,
    /// and the offset `-d/2 ln 2 pi + ln det P_i + ln pi_i` of its weighted log-density
    /// `offset - q / 2`.
    fn whitening(&self, i: usize, d: usize) -> (DVector<f64>, f64) {
        let p = &self.precision_chol[i];
        let shift = p.tr_mul(&DVector::from_column_slice(&self.params.means[i]));
        let constant = -0.5 * d as f64 * LN_2PI;
        (shift, constant + self.log_det_precision[i] + self.log_weights[i])
    }

    /// The E-step: the mean log-likelihood, and the responsibilities into `columns` (`k` columns
    /// of length `n`, their earlier values overwritten). Where the distances are repeated on the
    /// triangle ([`WhitenedDistances`]) every block of rows takes its log-densities, their
    /// log-sum-exps and its responsibilities in one visit, while its values are in the cache:
    /// each row's values are the same bits as from whole columns.
    fn e_step(&self, x: &DMatrix<f64>, columns: &mut Vec<Vec<f64>>) -> f64 {
        let n = x.nrows();
        let norms = match self.component_distances(x) {
            Some(components) => {
                columns.resize_with(components.len(), Vec::new);
                columns.iter_mut().for_each(|column| column.resize(n, 0.0));
                let x = x.as_slice();
                normalise_rows(columns, |first, block| {
                    for (&(ref distances, offset), rows) in components.iter().zip(block) {
                        distances.of_rows(x, n, first, rows);
                        log_densities_in_place(offset, rows);
                    }
                })
            }
            None => {
                *columns = self.weighted_log_prob_columns(x);
                normalise_rows(columns, |_, _| {})
            }
        };
        norms.iter().sum::<f64>() / n as f64
    }

    /// Every component's [`WhitenedDistances`] to the rows of `x` and its offset `-d/2 ln 2 pi +
    /// ln det P_i + ln pi_i`; `None` where a distance needs the general product.
    fn component_distances(&self, x: &DMatrix<f64>) -> Option<Vec<(WhitenedDistances, f64)>> {
        (0..self.k())
            .map(|i| {
                let (shift, offset) = self.whitening(i, x.ncols());
                let distances = WhitenedDistances::new(x.nrows(), &self.precision_chol[i], shift.as_slice())?;
                Some((distances, offset))
            })
            .collect()
    }
}

/// A component's whitened distances `q` replaced by its weighted log-densities `offset - q / 2`
/// ([`GaussianMixture::whitening`]).
fn log_densities_in_place(offset: f64, q: &mut [f64]) {
    q.iter_mut().for_each(|q| *q = offset - 0.5 * *q);
}

/// `|P^T x_r - shift|^2` of every row of `x` as one general product `X P`: the sums that
/// [`whitened_distances`] repeats on the triangle, for the machines and sizes it leaves alone.
fn whitened_distances_general(x: &DMatrix<f64>, p: &DMatrix<f64>, shift: &[f64]) -> Vec<f64> {
    let n = x.nrows();
    let y = x * p;
    let mut q = vec![0.0; n];
    // Column j of the column-major `y` is one contiguous run of `n` values.
    for (column, &shift) in y.as_slice().chunks_exact(n).zip(shift) {
        for (q, v) in q.iter_mut().zip(column) {
            let t = v - shift;
            *q += t * t;
        }
    }
    q
}

/// The M-step: weights, means and covariances from responsibilities (scikit-learn's
/// `_estimate_gaussian_parameters` with `reg_covar`):
///
/// ```text
/// n_i = sum_r p_ri + 10 eps,   mu_i = (sum_r p_ri x_r) / n_i,
/// Sigma_i = (sum_r p_ri (x_r - mu_i)(x_r - mu_i)^T) / n_i + reg I,   pi_i = n_i / sum_m n_m
/// ```
///
/// `x` is the data column-major (nalgebra) and `x_rows` the same values row-major.
fn m_step(
    x: &DMatrix<f64>,
    x_rows: &[f64],
    responsibilities: &[Vec<f64>],
    reg_covar: f64,
) -> Result<GaussianMixture, RecognizeError> {
    let per_component: Vec<Result<Component, RecognizeError>> = responsibilities
        .par_iter()
        .enumerate()
        .map(|(i, resp)| {
            Component::estimate(x, x_rows, resp, reg_covar)
                .ok_or(RecognizeError::SingularCovariance { component: i })
        })
        .collect();
    let k = responsibilities.len();
    let mut weights = Vec::with_capacity(k);
    let mut means = Vec::with_capacity(k);
    let mut covariances = Vec::with_capacity(k);
    let mut precision_chol = Vec::with_capacity(k);
    let mut log_det_precision = Vec::with_capacity(k);
    for component in per_component {
        let c = component?;
        weights.push(c.n);
        means.push(c.mean);
        covariances.push(c.covariance);
        precision_chol.push(c.precision_chol);
        log_det_precision.push(c.log_det_precision);
    }
    let total: f64 = weights.iter().sum();
    weights.iter_mut().for_each(|w| *w /= total);
    let log_weights = weights.iter().map(|w| w.ln()).collect();
    Ok(GaussianMixture {
        params: GmmParameters {
            weights,
            means,
            covariances,
        },
        precision_chol,
        log_det_precision,
        log_weights,
    })
}

/// One component's M-step result.
struct Component {
    /// `n_i`, the summed responsibilities (the unnormalised weight).
    n: f64,
    mean: Vec<f64>,
    /// Row-major `d x d`.
    covariance: Vec<f64>,
    precision_chol: DMatrix<f64>,
    log_det_precision: f64,
}

impl Component {
    /// The M-step for the component with responsibilities `resp` (`x` column-major, `x_rows` the
    /// same data row-major); `None` when its covariance is not positive definite.
    fn estimate(x: &DMatrix<f64>, x_rows: &[f64], resp: &[f64], reg_covar: f64) -> Option<Self> {
        let d = x.ncols();
        let (sums, total) = weighted_column_sums(x, resp);
        let n = total + 10.0 * f64::EPSILON;
        let mean = DVector::from_vec(sums) / n;
        // The scatter's lower triangle; the general product fills the whole square.
        let scatter = match weighted_scatter(x_rows, mean.as_slice(), resp) {
            Some(lower) => DMatrix::from_row_slice(d, d, &lower),
            None => weighted_scatter_general(x, x_rows, mean.as_slice(), resp),
        };
        let mut sigma = scatter / n;
        for a in 0..d {
            sigma[(a, a)] += reg_covar;
            for b in 0..a {
                sigma[(b, a)] = sigma[(a, b)];
            }
        }
        let covariance = sigma.transpose().as_slice().to_vec();
        let (precision_chol, log_det_precision) = precision_cholesky(sigma)?;
        Some(Self {
            n,
            mean: mean.as_slice().to_vec(),
            covariance,
            precision_chol,
            log_det_precision,
        })
    }
}

/// `(D^T diag(r)) D` with `D = X - 1 mu^T` as one blocked general product: the sums that
/// [`weighted_scatter`] repeats on the lower triangle, for the machines and sizes it leaves alone.
/// `x` is the data column-major and `x_rows` the same values row-major.
fn weighted_scatter_general(x: &DMatrix<f64>, x_rows: &[f64], mean: &[f64], resp: &[f64]) -> DMatrix<f64> {
    let (n_rows, d) = x.shape();
    // D, column-major, one contiguous column at a time.
    let mut diff = Vec::with_capacity(n_rows * d);
    for (column, &m) in x.as_slice().chunks_exact(n_rows).zip(mean) {
        diff.extend(column.iter().map(|v| v - m));
    }
    let diff = DMatrix::from_vec(n_rows, d, diff);
    // D^T diag(r), a column-major d x n matrix: its column `row` is (x_row - mu) r_row, read
    // contiguously from the row-major copy of the data.
    let mut weighted_t = Vec::with_capacity(n_rows * d);
    for (row, &p) in x_rows.chunks_exact(d).zip(resp) {
        weighted_t.extend(row.iter().zip(mean).map(|(v, m)| (v - m) * p));
    }
    let weighted_t = DMatrix::from_vec(d, n_rows, weighted_t);
    &weighted_t * &diff
}

/// `(P, sum_j ln P_jj)` with `P = L^-T` for `Sigma = L L^T`; `None` when `Sigma` is not positive
/// definite.
fn precision_cholesky(sigma: DMatrix<f64>) -> Option<(DMatrix<f64>, f64)> {
    let d = sigma.nrows();
    let l = Cholesky::new(sigma)?.unpack();
    let p = l.transpose().solve_upper_triangular(&DMatrix::identity(d, d))?;
    let log_det = (0..d).map(|j| p[(j, j)].ln()).sum::<f64>();
    log_det.is_finite().then_some((p, log_det))
}

/// `ln sum_i exp(v_i)`, stable for any magnitudes; `-inf` for an empty slice.
pub fn log_sum_exp(v: &[f64]) -> f64 {
    let max = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if !max.is_finite() {
        return max;
    }
    log_sum_exp_of_parts(max, sum_exp_of_differences(v, max))
}

/// [`log_sum_exp`]'s result from its parts, where they are formed elsewhere with its bits: the
/// largest value `max` and `sum = sum_i exp(v_i - max)`; `max` itself where it is not finite.
pub(crate) fn log_sum_exp_of_parts(max: f64, sum: f64) -> f64 {
    if max.is_finite() { max + sum.ln() } else { max }
}

/// Rows per block of [`log_sum_exp_rows`] and [`normalise_rows`]: a block's values in every
/// column, its maxima and sums stay in the cache between the passes over them (at the letters' 400
/// components a block of 128 rows is 400 KB).
const ROW_BLOCK: usize = 128;

/// `ln sum_i exp(columns[i][r])` for every row `r`: the same arithmetic as [`log_sum_exp`] on each
/// row (the exponentials summed in component order), computed a block of rows at a time so every
/// pass reads contiguous memory, the blocks in parallel.
fn log_sum_exp_rows(columns: &[Vec<f64>]) -> Vec<f64> {
    let n = columns.first().map_or(0, Vec::len);
    let mut out = vec![0.0; n];
    out.par_chunks_mut(ROW_BLOCK).enumerate().for_each(|(b, out)| {
        let block: Vec<&[f64]> = columns.iter().map(|c| &c[b * ROW_BLOCK..][..out.len()]).collect();
        log_sum_exp_of_block(&block, out);
    });
    out
}

/// [`log_sum_exp_rows`] of one block of rows (`block[i]` is component `i`'s values there) into
/// `out`.
fn log_sum_exp_of_block(block: &[&[f64]], out: &mut [f64]) {
    let mut max = vec![f64::NEG_INFINITY; out.len()];
    for column in block {
        for (m, &v) in max.iter_mut().zip(*column) {
            *m = m.max(v);
        }
    }
    let mut sum = vec![0.0; out.len()];
    for column in block {
        add_exp_of_differences(&mut sum, column, Shift::Rows(&max));
    }
    for ((o, &m), &s) in out.iter_mut().zip(&max).zip(&sum) {
        *o = log_sum_exp_of_parts(m, s);
    }
}

/// The responsibilities from the weighted log-densities: every row `r` of `columns` replaced by
/// `exp(columns[i][r] - ln sum_m exp(columns[m][r]))`, the row's log-sum-exp returned. One block of
/// rows at a time, the blocks in parallel: `fill(first, block)` first writes the block's
/// log-densities (rows `first..`, `block[i]` component `i`'s), then the block's log-sum-exps are
/// formed as [`log_sum_exp_rows`] forms them and its exponentials taken while the block is in the
/// cache: the same bits as the log-sum-exp of every row and then the exponentials.
fn normalise_rows(columns: &mut [Vec<f64>], fill: impl Fn(usize, &mut [&mut [f64]]) + Sync) -> Vec<f64> {
    let n = columns.first().map_or(0, Vec::len);
    // Per block, its rows of every column.
    let mut blocks: Vec<Vec<&mut [f64]>> = (0..n.div_ceil(ROW_BLOCK)).map(|_| Vec::new()).collect();
    for column in columns.iter_mut() {
        for (block, rows) in blocks.iter_mut().zip(column.chunks_mut(ROW_BLOCK)) {
            block.push(rows);
        }
    }
    let mut norms = vec![0.0; n];
    norms
        .par_chunks_mut(ROW_BLOCK)
        .zip(blocks.par_iter_mut())
        .enumerate()
        .for_each(|(b, (norms, block))| {
            fill(b * ROW_BLOCK, block);
            let values: Vec<&[f64]> = block.iter().map(|rows| &**rows).collect();
            log_sum_exp_of_block(&values, norms);
            for rows in block.iter_mut() {
                exp_of_differences_in_place(rows, Shift::Rows(norms));
            }
        });
    norms
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simd::has_avx2_fma;

    #[test]
    fn density_matches_the_closed_form_in_two_dimensions() {
        // Sigma = [[4, 1], [1, 2]], det 7, Sigma^-1 = [[2, -1], [-1, 4]] / 7.
        let g = GaussianMixture::from_parameters(GmmParameters {
            weights: vec![1.0],
            means: vec![vec![1.0, -1.0]],
            covariances: vec![vec![4.0, 1.0, 1.0, 2.0]],
        })
        .unwrap();
        let x = [2.0, 0.5];
        let (dx, dy) = (1.0, 1.5);
        let maha = (2.0 * dx * dx - 2.0 * dx * dy + 4.0 * dy * dy) / 7.0;
        let expected = -LN_2PI - 0.5 * 7.0f64.ln() - 0.5 * maha;
        let mut out = [0.0];
        g.weighted_log_densities(&x, &mut out);
        assert!((out[0] - expected).abs() < 1e-12, "{} vs {expected}", out[0]);
        let data = FeatureMatrix::from_features(&[x.to_vec()], "x").unwrap();
        assert!((g.score_samples(&data)[0] - expected).abs() < 1e-12);
    }

    #[test]
    fn rejects_bad_parameters() {
        let bad_cov = GmmParameters {
            weights: vec![1.0],
            means: vec![vec![0.0]],
            covariances: vec![vec![-1.0]],
        };
        assert!(matches!(
            GaussianMixture::from_parameters(bad_cov),
            Err(RecognizeError::SingularCovariance { component: 0 })
        ));
        let bad_weights = GmmParameters {
            weights: vec![0.5, 0.4],
            means: vec![vec![0.0]; 2],
            covariances: vec![vec![1.0]; 2],
        };
        assert!(GaussianMixture::from_parameters(bad_weights).is_err());
    }

    fn random_matrix(rng: &mut crate::rng::Rng, rows: usize, cols: usize) -> DMatrix<f64> {
        use rand::RngExt;
        DMatrix::from_fn(rows, cols, |_, _| rng.random_range(-3.0..3.0))
    }

    /// Responsibilities as after k-means (0 and 1) and in between, or mostly exactly 0 (a whole
    /// block of 256 and a whole pass of 64 among them) as for most components of a large mixture.
    fn responsibilities(n: usize, sparse: bool, rng: &mut crate::rng::Rng) -> Vec<f64> {
        use rand::RngExt;
        (0..n)
            .map(|r| match (sparse, r % 7) {
                (true, _) if (256..512).contains(&r) || r % 11 != 3 => 0.0,
                (true, _) => rng.random_range(1e-300..1.0),
                (false, 0) => 0.0,
                (false, 1) => 1.0,
                (false, _) => rng.random_range(0.0..1.0),
            })
            .collect()
    }

    /// The E-step by blocks of rows (each block's distances, log-sum-exps and responsibilities in
    /// one visit) against the E-step by whole columns (every component's log-densities, then the
    /// rows normalised), bit for bit: nalgebra's own chains (`d` = 3) and the triangle's (`d` =
    /// 7, 10), rows in whole blocks and not, a buffer of another shape overwritten.
    #[test]
    fn the_e_step_by_blocks_of_rows_gives_the_e_step_by_columns_bits() {
        let mut rng = crate::rng::stream(12, 0);
        for (n, d, k) in [(300, 3, 5), (2 * ROW_BLOCK, 7, 9), (3 * ROW_BLOCK + 13, 10, 17)] {
            let x = random_matrix(&mut rng, n, d);
            let data = FeatureMatrix::from_features(
                &x.row_iter()
                    .map(|r| r.iter().copied().collect())
                    .collect::<Vec<_>>(),
                "e-step",
            )
            .unwrap();
            let config = GmmConfig {
                max_iterations: 3,
                ..GmmConfig::default()
            };
            let (model, _) = GaussianMixture::fit(&data, k, &config, &mut rng).unwrap();
            if d > 5 && !has_avx2_fma() {
                assert!(model.component_distances(&x).is_none());
                continue;
            }
            assert!(model.component_distances(&x).is_some(), "n {n}, d {d}");
            let mut columns = model.weighted_log_prob_columns(&x);
            let norms = normalise_rows(&mut columns, |_, _| {});
            let want = norms.iter().sum::<f64>() / n as f64;
            let mut blocks = vec![vec![0.5; 7]; 2];
            let mean = model.e_step(&x, &mut blocks);
            assert_eq!(mean.to_bits(), want.to_bits(), "n {n}, d {d}");
            assert_eq!(blocks.len(), k);
            for (i, (by_block, by_column)) in blocks.iter().zip(&columns).enumerate() {
                assert_eq!(by_block.len(), n);
                for (r, (a, b)) in by_block.iter().zip(by_column).enumerate() {
                    assert_eq!(a.to_bits(), b.to_bits(), "n {n}, d {d}, component {i}, row {r}");
                }
            }
        }
    }

    /// [`whitened_distances`] against the general product on `n` random features of `d` values,
    /// bit for bit.
    fn assert_distances_are_the_general_products(n: usize, d: usize, rng: &mut crate::rng::Rng) {
        use rand::RngExt;
        let x = random_matrix(rng, n, d);
        let a = random_matrix(rng, d, d);
        let sigma = &a * a.transpose() + DMatrix::identity(d, d) * 0.1;
        let (p, _) = precision_cholesky(sigma).expect("a random SPD matrix has a Cholesky factor");
        let mu = DVector::from_fn(d, |_, _| rng.random_range(-1.0..1.0));
        let shift = p.tr_mul(&mu);
        let fast = whitened_distances(&x, &p, shift.as_slice()).expect("a repeated product applies");
        let general = whitened_distances_general(&x, &p, shift.as_slice());
        for (r, (a, b)) in fast.iter().zip(&general).enumerate() {
            assert_eq!(a.to_bits(), b.to_bits(), "n {n}, d {d}, row {r}: {a} vs {b}");
        }
    }

    /// [`weighted_scatter`] against the general product on `n` random features of `d` values,
    /// bit for bit.
    fn assert_scatter_is_the_general_products(n: usize, d: usize, sparse: bool, rng: &mut crate::rng::Rng) {
        use rand::RngExt;
        let x = random_matrix(rng, n, d);
        let x_rows: Vec<f64> = x.transpose().as_slice().to_vec();
        let resp = responsibilities(n, sparse, rng);
        let mean: Vec<f64> = (0..d).map(|_| rng.random_range(-1.0..1.0)).collect();
        let lower = weighted_scatter(&x_rows, &mean, &resp).expect("a repeated product applies");
        let general = weighted_scatter_general(&x, &x_rows, &mean, &resp);
        for a in 0..d {
            for b in 0..=a {
                let (got, want) = (lower[a * d + b], general[(a, b)]);
                assert_eq!(
                    got.to_bits(),
                    want.to_bits(),
                    "n {n}, d {d}, sparse {sparse}, ({a}, {b}): {got} vs {want}"
                );
            }
        }
    }

    #[test]
    fn the_triangular_distances_give_the_general_products_bits() {
        if !has_avx2_fma() {
            return;
        }
        let mut rng = crate::rng::rng(41);
        // Row counts with and without a partial group of eight; d from nalgebra's smallest
        // product size to beyond one group, with and without a partial group of four.
        for (n, d) in [(1003, 6), (517, 7), (2000, 20), (64, 23), (300, 33)] {
            assert_distances_are_the_general_products(n, d, &mut rng);
        }
    }

    #[test]
    fn the_triangular_scatter_gives_the_general_products_bits() {
        if !has_avx2_fma() {
            return;
        }
        let mut rng = crate::rng::rng(43);
        // Feature counts within one block of the product's KC and across several (with a partial
        // pass); d with every remainder modulo eight, so every tile shape; dense and sparse
        // responsibilities.
        let cases = [
            (200, 6, false),
            (600, 20, false),
            (1000, 13, false),
            (257, 23, false),
            (1000, 20, true),
            (3000, 7, true),
            (800, 10, true),
            (400, 9, false),
            (400, 12, false),
            (400, 16, true),
            (400, 17, false),
            (400, 14, false),
            (300, 8, false),
        ];
        for (n, d, sparse) in cases {
            assert_scatter_is_the_general_products(n, d, sparse, &mut rng);
        }
    }

    #[test]
    fn the_small_products_give_nalgebras_bits() {
        let mut rng = crate::rng::rng(47);
        // A dimension of at most 5 on either side: nalgebra's own chains, on every machine.
        for (n, d) in [(1003, 4), (517, 1), (2000, 5), (4, 20), (5, 6), (1, 3)] {
            assert_distances_are_the_general_products(n, d, &mut rng);
            for sparse in [false, true] {
                assert_scatter_is_the_general_products(n, d, sparse, &mut rng);
            }
        }
    }

    #[test]
    fn a_small_scatter_that_sums_to_zero_keeps_the_sign_of_nalgebras_zero() {
        let mean = [0.5, 0.5];
        // The first coordinate above the mean, the second below: with every responsibility 0
        // nalgebra chains -0 terms ((x_1 - m_1) 0 = -0, times a positive residual) into -0 at
        // (1, 0), where the skipping sum has nothing. Then residuals of exactly 0 (the second
        // coordinate at its mean) under non-zero responsibilities.
        let below = [1.0, -2.0, 3.0, -0.25, 2.0, -1.0, 1.5, -3.0, 4.0, -0.5, 0.75, -1.5];
        let at_mean = [1.0, 0.5, 3.0, -0.25, 2.0, 0.5, 1.5, -3.0, 4.0, 0.5, 0.75, -1.5];
        let cases = [
            (below, [0.0; 6]),
            (at_mean, [0.0, 0.0, 0.7, 0.0, 0.2, 0.0]),
            (at_mean, [1.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
        ];
        let mut negative_zeros = 0;
        for (rows, resp) in cases {
            let x = DMatrix::from_row_slice(6, 2, &rows);
            let lower = weighted_scatter(&rows, &mean, &resp).expect("the small path applies");
            let general = weighted_scatter_general(&x, &rows, &mean, &resp);
            for a in 0..2 {
                for b in 0..=a {
                    let (got, want) = (lower[a * 2 + b], general[(a, b)]);
                    assert_eq!(
                        got.to_bits(),
                        want.to_bits(),
                        "{resp:?} ({a}, {b}): {got} vs {want}"
                    );
                    negative_zeros += usize::from(want.to_bits() == (-0.0f64).to_bits());
                }
            }
        }
        // Not vacuous: some of nalgebra's sums are -0.
        assert!(negative_zeros > 0);
    }

    #[test]
    fn the_weighted_column_sums_and_their_total_give_nalgebras_bits() {
        let mut rng = crate::rng::rng(53);
        // Row counts with every remainder modulo the dot product's eight chains, and fewer rows
        // than chains.
        for (n, d) in [(1000, 3), (1001, 4), (1007, 2), (7, 5), (3000, 10), (1, 1)] {
            let x = random_matrix(&mut rng, n, d);
            for sparse in [false, true] {
                let resp = responsibilities(n, sparse, &mut rng);
                let (got, total) = weighted_column_sums(&x, &resp);
                let want = x.tr_mul(&DVector::from_column_slice(&resp));
                let want_total = DVector::from_column_slice(&resp).sum();
                assert_eq!(total.to_bits(), want_total.to_bits(), "n {n}, sparse {sparse}");
                for (j, (a, b)) in got.iter().zip(want.iter()).enumerate() {
                    assert_eq!(
                        a.to_bits(),
                        b.to_bits(),
                        "n {n}, d {d}, sparse {sparse}, column {j}: {a} vs {b}"
                    );
                }
            }
        }
    }

    #[test]
    fn log_sum_exp_is_stable() {
        assert!((log_sum_exp(&[1000.0, 1000.0]) - (1000.0 + 2f64.ln())).abs() < 1e-12);
        assert!((log_sum_exp(&[-1000.0, -1000.0]) - (-1000.0 + 2f64.ln())).abs() < 1e-12);
        assert_eq!(log_sum_exp(&[]), f64::NEG_INFINITY);
    }
}
