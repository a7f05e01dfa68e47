//! A per-frame classifier (beyond the paper; issue 73): a network of one hidden layer that reads
//! one feature and says how likely each training object made it.
//!
//! The paper's codebooks cluster the features without their labels and let Eq. 4 compare
//! histograms; the neighbour codebook (`neighbours.rs`) already makes the objects the clusters. On
//! a large array's frames, whose one shape-index feature holds the whole contact, a classifier
//! trained to tell the objects apart does better than either: on the large-array benchmark
//! (docs/measurements.md, "A large array") it is right from one frame 9 to 15 points more often
//! than the neighbour codebook. The clusters are the training objects, and a feature's membership
//! is the network's posterior under a uniform prior over them:
//!
//! ```text
//! x = V^T y                                 y the PCA's output, back in the descriptor's units
//! h = max(0, W1 (x - m) / s + b1)          m, s each value's training mean and spread
//! p(c_i | f) = softmax_i(W2 h + b2 - ln pi_i)   pi_i the training share of object i
//! ```
//!
//! The network reads the feature in the descriptor's own values, each scaled to unit spread,
//! not in the PCA's axes: scaling each principal axis to unit spread would lift the axes of
//! least variance, mostly noise, to the weight of the first, and the L2 penalty would no longer
//! tell them apart (on the benchmark: 60.6% from one frame against 64.5%). The first two steps
//! are linear, so they are folded into `W1` and `b1` once trained: the model reads `y` directly.
//!
//! Dividing by the training shares makes `p(c_i | f)` proportional to `p(f | O_i)`, so several
//! frames combine by the product rule of Eq. 15 with each frame an independent draw:
//! `ln p(U | O_j) = sum_f ln p(c_j | f)` (`object_model::EvidenceRule::PerFrame`), which on the
//! benchmark is right after five frames more often than Eq. 4's cross-entropy of the summed
//! memberships (97.1% against 94.6%, measured with scikit-learn's network on the same features).
//!
//! Training follows scikit-learn's `MLPClassifier` defaults, whose results on the same features
//! the benchmark compares: Glorot-uniform weights, Adam (step 1e-3), mini-batches of 200 drawn
//! in a seeded order, an L2 penalty `alpha / (2 b) |W|^2` on every batch of `b`, at most
//! [`MlpConfig::epochs`] epochs, stopped when the epoch's loss has not fallen by
//! [`MlpConfig::tolerance`] for [`MlpConfig::patience`] epochs. Single-threaded and seeded: the
//! same features and seed give the same network bit for bit, whatever thread fits it.

use nalgebra::{DMatrix, DVector};
use rand::RngExt;
use rand::seq::SliceRandom;
use serde::{Deserialize, Serialize};

use crate::recognize::RecognizeError;
use crate::recognize::features::TrainingFeatures;
use crate::recognize::pca::Pca;
use crate::rng::Rng;

/// How the network is trained.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MlpConfig {
    /// At most this many passes over the training features.
    pub epochs: usize,
    /// Features per Adam step.
    pub batch: usize,
    /// Adam's step size.
    pub learning_rate: f64,
    /// The L2 penalty `alpha` on the weights (scikit-learn's `alpha`): 1 keeps a network of 128
    /// or 256 units from learning the training frames by heart (0.001 lost 2 points on the
    /// benchmark with scikit-learn's network, 3 lost 8).
    pub l2: f64,
    /// The least fall of the epoch's loss that counts as progress.
    pub tolerance: f64,
    /// Epochs without progress before training stops.
    pub patience: usize,
}

impl Default for MlpConfig {
    fn default() -> Self {
        Self {
            epochs: 300,
            batch: 200,
            learning_rate: 1e-3,
            l2: 1.0,
            tolerance: 1e-4,
            patience: 10,
        }
    }
}

impl MlpConfig {
    pub(crate) fn is_default(&self) -> bool {
        *self == Self::default()
    }
}

/// The fitted network on the PCA's output; weights row-major (`w1`: `hidden` rows of `dim`,
/// `w2`: `objects` rows of `hidden`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FrameClassifier {
    dim: usize,
    hidden: usize,
    objects: usize,
    w1: Vec<f64>,
    b1: Vec<f64>,
    w2: Vec<f64>,
    b2: Vec<f64>,
    /// `ln pi_i`, the training share of each object.
    log_prior: Vec<f64>,
}

impl FrameClassifier {
    /// Trains a network of `hidden` units on `training`'s features (the output of `pca`) and
    /// objects, drawing its initial weights and batch order from `rng`.
    pub fn fit(
        training: TrainingFeatures,
        pca: &Pca,
        hidden: usize,
        config: &MlpConfig,
        rng: &mut Rng,
    ) -> Result<Self, RecognizeError> {
        let (n, dim, objects) = (training.data.rows(), training.data.dim(), training.object_count);
        check_training(n, hidden, objects, config)?;
        if pca.output_dim() != dim {
            return Err(RecognizeError::InvalidParameter {
                name: "mlp",
                what: format!(
                    "features of {dim} values from a PCA that gives {}",
                    pca.output_dim()
                ),
            });
        }
        let (DescriptorUnits { lift, offset }, x) = DescriptorUnits::of(training, pca);
        let labels: Vec<usize> = training.objects.iter().map(|&o| o as usize).collect();
        let mut net = Network::glorot(lift.ncols(), hidden, objects, rng);
        net.train(&x, &labels, config, rng);
        // Folded: x W1 + b1 = y (lift W1) + (b1 - offset W1).
        let w1 = &lift * &net.w1;
        let b1 = &net.b1 - (DMatrix::from_row_slice(1, offset.len(), &offset) * &net.w1).transpose();
        let mut counts = vec![0usize; objects];
        labels.iter().for_each(|&o| counts[o] += 1);
        let log_prior = counts
            .iter()
            .map(|&c| (c.max(1) as f64 / n as f64).ln())
            .collect();
        Ok(Self {
            dim,
            hidden,
            objects,
            // Column-major `dim x hidden` is row-major `hidden x dim`.
            w1: w1.as_slice().to_vec(),
            b1: b1.as_slice().to_vec(),
            w2: net.w2.as_slice().to_vec(),
            b2: net.b2.as_slice().to_vec(),
            log_prior,
        })
    }

    /// The invariants a loaded model must hold.
    pub(crate) fn check(&self) -> Result<(), String> {
        let Self {
            dim,
            hidden,
            objects,
            w1,
            b1,
            w2,
            b2,
            log_prior,
        } = self;
        let lengths = [
            ("w1", w1.len(), hidden * dim),
            ("b1", b1.len(), *hidden),
            ("w2", w2.len(), objects * hidden),
            ("b2", b2.len(), *objects),
            ("log_prior", log_prior.len(), *objects),
        ];
        if *dim == 0 || *hidden == 0 || *objects < 2 {
            return Err(format!("{dim} inputs, {hidden} hidden units, {objects} objects"));
        }
        for (name, got, want) in lengths {
            if got != want {
                return Err(format!("{name} holds {got} values, not {want}"));
            }
        }
        let values = [w1, b1, w2, b2, log_prior];
        if values.iter().any(|v| v.iter().any(|x| !x.is_finite())) {
            return Err("a weight is not finite".into());
        }
        Ok(())
    }

    /// Number of objects (the clusters).
    pub fn clusters(&self) -> usize {
        self.objects
    }

    /// Length of the features it takes.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Writes `p(c_i | f)` under a uniform prior over the objects into `out`.
    pub fn membership(&self, f: &[f64], out: &mut [f64]) {
        let h: Vec<f64> = self
            .w1
            .chunks_exact(self.dim)
            .zip(&self.b1)
            .map(|(w, b)| (dot(w, f) + b).max(0.0))
            .collect();
        for (((o, w), b), lp) in out
            .iter_mut()
            .zip(self.w2.chunks_exact(self.hidden))
            .zip(&self.b2)
            .zip(&self.log_prior)
        {
            *o = dot(w, &h) + b - lp;
        }
        softmax_in_place(out);
    }
}

fn check_training(n: usize, hidden: usize, objects: usize, config: &MlpConfig) -> Result<(), RecognizeError> {
    let bad = |what: String| Err(RecognizeError::InvalidParameter { name: "mlp", what });
    if objects < 2 || n < objects {
        return bad(format!(
            "{n} training features of {objects} objects: want at least 2 objects and a feature each"
        ));
    }
    if hidden == 0 || config.epochs == 0 || config.batch == 0 || config.patience == 0 {
        return bad("hidden units, epochs, batch and patience must each be at least 1".into());
    }
    let non_negative = |v: f64| v.is_finite() && v >= 0.0;
    let sound = config.learning_rate > 0.0
        && [config.learning_rate, config.l2, config.tolerance]
            .into_iter()
            .all(non_negative);
    if !sound {
        return bad(format!(
            "learning rate {}, L2 {} and tolerance {}: want a positive step and the others non-negative",
            config.learning_rate, config.l2, config.tolerance
        ));
    }
    Ok(())
}

/// The linear map from the PCA's output to the descriptor's values scaled to unit spread:
/// `x = y lift - offset`, `lift = V_q diag(1 / s)` (`q x d`) and `offset` the lifted training
/// features' mean over their spread (the PCA's output is centred, so it is about 0).
struct DescriptorUnits {
    lift: DMatrix<f64>,
    offset: Vec<f64>,
}

/// A spread below this share of the largest is no spread: that value is constant in training
/// (a histogram's empty bin) and is left unscaled, so that rounding is not amplified.
const FLAT_SPREAD: f64 = 1e-9;

impl DescriptorUnits {
    /// The map of `training`'s features, and the features it maps them to (`n x d`).
    fn of(training: TrainingFeatures, pca: &Pca) -> (Self, DMatrix<f64>) {
        let (n, q) = (training.data.rows(), training.data.dim());
        let components = pca.components();
        let d = components.first().map_or(0, Vec::len);
        let basis = DMatrix::from_fn(q, d, |r, c| components[r][c]);
        let lifted = DMatrix::from_row_slice(n, q, training.data.as_slice()) * &basis;
        let mean: Vec<f64> = lifted.column_iter().map(|c| c.mean()).collect();
        let spread: Vec<f64> = lifted
            .column_iter()
            .zip(&mean)
            .map(|(c, m)| (c.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / n as f64).sqrt())
            .collect();
        let largest = spread.iter().copied().fold(0.0, f64::max);
        let scale: Vec<f64> = spread
            .iter()
            .map(|&s| {
                if s > FLAT_SPREAD * largest && s > 0.0 {
                    s
                } else {
                    1.0
                }
            })
            .collect();
        let lift = basis.map_with_location(|_, c, v| v / scale[c]);
        let offset: Vec<f64> = mean.iter().zip(&scale).map(|(m, s)| m / s).collect();
        let x = lifted.map_with_location(|_, c, v| (v - mean[c]) / scale[c]);
        (Self { lift, offset }, x)
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// `v <- softmax(v)`, shifted by its largest value so that no exponential overflows.
fn softmax_in_place(v: &mut [f64]) {
    let top = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    v.iter_mut().for_each(|x| *x = (*x - top).exp());
    let total: f64 = v.iter().sum();
    v.iter_mut().for_each(|x| *x /= total);
}

/// The network while it trains: `w1` is `dim x hidden` and `w2` `hidden x objects`, so a batch's
/// rows multiply them on the left.
struct Network {
    w1: DMatrix<f64>,
    b1: DVector<f64>,
    w2: DMatrix<f64>,
    b2: DVector<f64>,
}

/// Adam's first and second moments of every parameter, and its step count.
struct Adam {
    m: Vec<DMatrix<f64>>,
    v: Vec<DMatrix<f64>>,
    t: i32,
}

const ADAM_BETA1: f64 = 0.9;
const ADAM_BETA2: f64 = 0.999;
const ADAM_EPSILON: f64 = 1e-8;
/// The floor of a training probability's logarithm (scikit-learn's clip).
const LOG_FLOOR: f64 = 1e-10;

impl Network {
    /// Glorot-uniform weights for a ReLU layer (bound `sqrt(6 / (fan_in + fan_out))`) and biases.
    fn glorot(dim: usize, hidden: usize, objects: usize, rng: &mut Rng) -> Self {
        let mut layer = |fan_in: usize, fan_out: usize| {
            let bound = (6.0 / (fan_in + fan_out) as f64).sqrt();
            let mut uniform = || rng.random_range(-bound..bound);
            let w = DMatrix::from_fn(fan_in, fan_out, |_, _| uniform());
            let b = DVector::from_fn(fan_out, |_, _| uniform());
            (w, b)
        };
        let (w1, b1) = layer(dim, hidden);
        let (w2, b2) = layer(hidden, objects);
        Self { w1, b1, w2, b2 }
    }

    /// Mini-batch Adam until the loss stops falling or the epochs run out.
    fn train(&mut self, x: &DMatrix<f64>, labels: &[usize], config: &MlpConfig, rng: &mut Rng) {
        let n = x.nrows();
        let mut order: Vec<usize> = (0..n).collect();
        let mut adam = Adam::for_network(self);
        let (mut best, mut stale) = (f64::INFINITY, 0);
        for _ in 0..config.epochs {
            order.shuffle(rng);
            let mut loss = 0.0;
            for batch in order.chunks(config.batch.min(n)) {
                let xb = x.select_rows(batch);
                let yb: Vec<usize> = batch.iter().map(|&r| labels[r]).collect();
                let (batch_loss, grads) = self.gradients(&xb, &yb, config.l2);
                adam.step(self, grads, config.learning_rate);
                loss += batch_loss * batch.len() as f64;
            }
            loss /= n as f64;
            if loss > best - config.tolerance {
                stale += 1;
                if stale >= config.patience {
                    break;
                }
            } else {
                stale = 0;
            }
            best = best.min(loss);
        }
    }

    /// The batch's mean cross-entropy plus the L2 penalty, and its gradients (w1, b1, w2, b2).
    fn gradients(&self, xb: &DMatrix<f64>, yb: &[usize], l2: f64) -> (f64, [DMatrix<f64>; 4]) {
        let b = xb.nrows() as f64;
        let mut hidden = xb * &self.w1;
        for mut row in hidden.row_iter_mut() {
            row += self.b1.transpose();
            row.iter_mut().for_each(|v| *v = v.max(0.0));
        }
        // Transposed, a feature's outputs are one contiguous column: its softmax is `membership`'s.
        let mut p = (&hidden * &self.w2).transpose();
        let mut loss = 0.0;
        for (column, &y) in p.as_mut_slice().chunks_exact_mut(self.b2.len()).zip(yb) {
            column.iter_mut().zip(self.b2.iter()).for_each(|(z, b)| *z += b);
            softmax_in_place(column);
            loss -= column[y].max(LOG_FLOOR).ln();
            column[y] -= 1.0;
        }
        let penalty = 0.5 * l2 * (self.w1.norm_squared() + self.w2.norm_squared()) / b;
        let g = p.transpose() / b;
        let gw2 = hidden.transpose() * &g + &self.w2 * (l2 / b);
        let gb2 = DMatrix::from_row_slice(1, g.ncols(), g.row_sum().as_slice());
        let mut gh = &g * self.w2.transpose();
        gh.zip_apply(&hidden, |d, h| {
            if h <= 0.0 {
                *d = 0.0
            }
        });
        let gw1 = xb.transpose() * &gh + &self.w1 * (l2 / b);
        let gb1 = DMatrix::from_row_slice(1, gh.ncols(), gh.row_sum().as_slice());
        (loss / b + penalty, [gw1, gb1, gw2, gb2])
    }
}

impl Adam {
    fn for_network(net: &Network) -> Self {
        let zeros = [
            DMatrix::zeros(net.w1.nrows(), net.w1.ncols()),
            DMatrix::zeros(1, net.b1.len()),
            DMatrix::zeros(net.w2.nrows(), net.w2.ncols()),
            DMatrix::zeros(1, net.b2.len()),
        ];
        Self {
            m: zeros.to_vec(),
            v: zeros.to_vec(),
            t: 0,
        }
    }

    /// One bias-corrected Adam step of every parameter along its gradient.
    fn step(&mut self, net: &mut Network, grads: [DMatrix<f64>; 4], rate: f64) {
        self.t += 1;
        let step = rate * (1.0 - ADAM_BETA2.powi(self.t)).sqrt() / (1.0 - ADAM_BETA1.powi(self.t));
        let params: [&mut [f64]; 4] = [
            net.w1.as_mut_slice(),
            net.b1.as_mut_slice(),
            net.w2.as_mut_slice(),
            net.b2.as_mut_slice(),
        ];
        for (((param, grad), m), v) in params.into_iter().zip(&grads).zip(&mut self.m).zip(&mut self.v) {
            for (((w, g), m), v) in param
                .iter_mut()
                .zip(grad.iter())
                .zip(m.iter_mut())
                .zip(v.iter_mut())
            {
                *m = ADAM_BETA1 * *m + (1.0 - ADAM_BETA1) * g;
                *v = ADAM_BETA2 * *v + (1.0 - ADAM_BETA2) * g * g;
                *w -= step * *m / (v.sqrt() + ADAM_EPSILON);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::recognize::features::FeatureMatrix;
    use crate::recognize::object_model::guess_of;
    use crate::recognize::pca::VarianceFraction;
    use crate::rng::rng;
    use rand::RngExt;

    const CENTRES: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

    /// Three objects whose features are blobs around corners of a cube in 5 values, the last
    /// two of every object constant and one of them large (an input that a spread of 0 must
    /// not blow up), `per_object` features each.
    fn blobs(per_object: usize, seed: u64) -> (FeatureMatrix, Vec<u32>) {
        let mut r = rng(seed);
        let (mut values, mut labels) = (Vec::new(), Vec::new());
        for (object, centre) in CENTRES.iter().enumerate() {
            for _ in 0..per_object {
                values.extend(centre.iter().map(|c| c + r.random_range(-0.7..0.7)));
                values.extend([0.0, 7.0]);
                labels.push(object as u32);
            }
        }
        (FeatureMatrix::from_trusted(labels.len(), 5, values), labels)
    }

    /// A network of `hidden` units trained on blobs of `per_object` features each.
    fn fit_on_blobs(
        per_object: usize,
        hidden: usize,
        config: MlpConfig,
        seed: u64,
    ) -> (Result<FrameClassifier, RecognizeError>, Pca) {
        let (data, labels) = blobs(per_object, 1);
        let pca = Pca::fit(&data, VarianceFraction::NETWORK).unwrap();
        let reduced = pca.transform(&data);
        let readings: Vec<u32> = (0..labels.len() as u32).collect();
        let training = TrainingFeatures {
            data: &reduced,
            objects: &labels,
            object_count: 3,
            readings: &readings,
        };
        let net = FrameClassifier::fit(training, &pca, hidden, &config, &mut rng(seed));
        (net, pca)
    }

    fn fitted(seed: u64) -> (FrameClassifier, Pca) {
        let config = MlpConfig {
            batch: 20,
            ..MlpConfig::default()
        };
        let (net, pca) = fit_on_blobs(60, 16, config, seed);
        (net.unwrap(), pca)
    }

    /// Known answer: on new draws the network is right about as often as the nearest centre
    /// (the best rule for these blobs), and every membership is a distribution.
    #[test]
    fn it_tells_blobs_apart_and_its_memberships_are_distributions() {
        let (net, pca) = fitted(5);
        net.check().unwrap();
        let (test, labels) = blobs(100, 2);
        let reduced = pca.transform(&test);
        let mut out = [0.0; 3];
        let (mut right, mut nearest_right) = (0, 0);
        for ((x, raw), &label) in reduced.iter_rows().zip(test.iter_rows()).zip(&labels) {
            net.membership(x, &mut out);
            assert!(out.iter().all(|p| (0.0..=1.0).contains(p)));
            assert!((out.iter().sum::<f64>() - 1.0).abs() < 1e-12, "{out:?}");
            right += usize::from(guess_of(&out) == label as usize);
            let closeness: Vec<f64> = CENTRES
                .iter()
                .map(|c| -c.iter().zip(raw).map(|(a, b)| (a - b) * (a - b)).sum::<f64>())
                .collect();
            nearest_right += usize::from(guess_of(&closeness) == label as usize);
        }
        assert!(nearest_right < 295, "the blobs overlap: {nearest_right} of 300");
        assert!(
            right + 9 >= nearest_right,
            "{right} of 300 right, the nearest centre {nearest_right}"
        );
    }

    /// Same features and seed: the same network bit for bit; another seed starts elsewhere.
    #[test]
    fn seeded_training_is_deterministic() {
        let (a, _) = fitted(5);
        let (b, _) = fitted(5);
        let (c, _) = fitted(6);
        assert_eq!(a, b);
        assert_ne!(a.w1, c.w1);
    }

    /// The uniform prior: an object that is three times as common in training does not get three
    /// times the membership of a feature that lies between the two (the shares are divided out).
    #[test]
    fn the_training_shares_are_divided_out() {
        let net = FrameClassifier {
            dim: 1,
            hidden: 1,
            objects: 2,
            w1: vec![0.0],
            b1: vec![0.0],
            w2: vec![0.0, 0.0],
            b2: vec![0.75f64.ln(), 0.25f64.ln()],
            log_prior: vec![0.75f64.ln(), 0.25f64.ln()],
        };
        net.check().unwrap();
        let mut out = [0.0; 2];
        net.membership(&[0.3], &mut out);
        assert!(
            (out[0] - 0.5).abs() < 1e-15 && (out[1] - 0.5).abs() < 1e-15,
            "{out:?}"
        );
    }

    /// A corrupt model: a weight that is not finite, or a layer of the wrong size, is named.
    #[test]
    fn a_corrupt_network_is_refused_by_name() {
        let (net, _) = fitted(5);
        let mut nan = net.clone();
        nan.b2[1] = f64::NAN;
        assert!(nan.check().unwrap_err().contains("not finite"));
        let mut short = net.clone();
        short.w2.pop();
        assert!(short.check().unwrap_err().contains("w2"));
        let one = FrameClassifier { objects: 1, ..net };
        assert!(one.check().is_err());
    }

    /// Bad training input is an error naming what is wrong, not a panic.
    #[test]
    fn training_that_cannot_work_is_refused() {
        let fit = |hidden, config| fit_on_blobs(3, hidden, config, 1).0;
        assert!(
            fit(0, MlpConfig::default())
                .unwrap_err()
                .to_string()
                .contains("hidden units")
        );
        let nan_rate = MlpConfig {
            learning_rate: f64::NAN,
            ..MlpConfig::default()
        };
        assert!(
            fit(4, nan_rate)
                .unwrap_err()
                .to_string()
                .contains("learning rate")
        );
    }
}
