//! A codebook of nearest training features (beyond the paper): the clusters are the training
//! objects, and a feature's membership of cluster `i` is the share of its `k` nearest training
//! features (Euclidean, after the PCA) that come from object `i`:
//!
//! ```text
//! p(c_i | f) = |{ g in N_k(f) : label(g) = i }| / k
//! ```
//!
//! The rest of Fig. 4 is unchanged: each object's histogram `p(c_i | O_j)` is the mean membership of
//! its own training features, so it says which objects object `j`'s touches resemble (b's touches
//! often look like d's), and Eq. 4 compares the unknown object's histogram with them. A training
//! feature's membership is taken with every feature of its own reading left out; with itself among
//! its neighbours, every object would look perfectly distinct.
//!
//! Why: a GMM codebook of a few hundred components cuts the 52 letters' feature space into cells
//! too coarse to keep what tells letters apart (validation accuracy still rose at k = 400). The
//! neighbourhood of a feature adapts to the data's density instead, and on the raised letters it
//! recognises with fewer readings than the GMM; docs/measurements.md, "A neighbour codebook",
//! holds the measurements.
//!
//! Cost: the model keeps every training feature, and a membership scans them all (at most `n d`
//! flops; `cargo bench --bench recognize`, `per_touch`, times it against the GMM). Training scans
//! every training feature's neighbourhood once for all candidate `k` ([`LeaveOneReadingOut`]),
//! `n^2 d` flops; the bench's `knn_training` group times it against a scan per candidate.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::recognize::RecognizeError;
use crate::recognize::features::FeatureMatrix;
use crate::recognize::features::TrainingFeatures;
use crate::recognize::object_model::ClusterHistogram;

/// The training features (PCA-reduced), their objects, and the neighbour count `k`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NearestNeighbours {
    neighbours: usize,
    objects: usize,
    dim: usize,
    /// Row-major, `labels.len()` rows of `dim` values.
    points: Vec<f64>,
    labels: Vec<u32>,
}

impl NearestNeighbours {
    /// The codebook of `neighbours` nearest rows of `data`, row `r` a feature of object
    /// `labels[r]` (< `objects`).
    pub fn new(
        data: &FeatureMatrix,
        labels: Vec<u32>,
        objects: usize,
        neighbours: usize,
    ) -> Result<Self, RecognizeError> {
        let nn = Self {
            neighbours,
            objects,
            dim: data.dim(),
            points: data.as_slice().to_vec(),
            labels,
        };
        nn.check().map_err(|what| RecognizeError::InvalidParameter {
            name: "nearest-neighbour codebook",
            what,
        })?;
        Ok(nn)
    }

    /// The invariants a loaded model must hold.
    pub(crate) fn check(&self) -> Result<(), String> {
        let n = self.labels.len();
        if self.dim == 0 || self.points.len() != n * self.dim {
            return Err(format!(
                "{} values do not make {n} features of {} values",
                self.points.len(),
                self.dim
            ));
        }
        if self.neighbours == 0 || self.neighbours >= n {
            return Err(format!(
                "{} neighbours: want at least 1 and fewer than the {n} training features",
                self.neighbours
            ));
        }
        if let Some(label) = self.labels.iter().find(|&&l| l as usize >= self.objects) {
            return Err(format!("object {label} of {} objects", self.objects));
        }
        if let Some(v) = self.points.iter().find(|v| !v.is_finite()) {
            return Err(format!("a training feature holds {v}"));
        }
        Ok(())
    }

    /// `k`, the neighbours a membership counts.
    pub fn neighbours(&self) -> usize {
        self.neighbours
    }

    /// Number of clusters: the training objects.
    pub fn clusters(&self) -> usize {
        self.objects
    }

    /// Length of the features it takes.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Number of training features.
    pub fn len(&self) -> usize {
        self.labels.len()
    }

    /// Whether it holds no training feature (never, once checked).
    pub fn is_empty(&self) -> bool {
        self.labels.is_empty()
    }

    /// Writes `p(c_i | f)` into `out`.
    pub fn membership(&self, f: &[f64], out: &mut [f64]) {
        self.membership_skipping(f, out, |_| false);
    }

    /// The membership over the training features `skip` does not exclude.
    fn membership_skipping(&self, f: &[f64], out: &mut [f64], skip: impl Fn(usize) -> bool) {
        let nearest = nearest_rows(&self.points, self.dim, f, self.neighbours, skip);
        shares_of_objects(nearest.iter().map(|&row| self.labels[row]), out);
    }
}

/// `p(c_i | f)` from the objects of `f`'s nearest training features: each object's share of them.
/// The one definition, so that a training histogram ([`LeaveOneReadingOut`]) and a touch's
/// membership are the same arithmetic, bit for bit.
fn shares_of_objects(nearest_objects: impl ExactSizeIterator<Item = u32>, out: &mut [f64]) {
    let share = 1.0 / nearest_objects.len() as f64;
    out.fill(0.0);
    for object in nearest_objects {
        out[object as usize] += share;
    }
}

/// The rows of `points` (row-major, `dim` values each) nearest to `f`, at most `k` of those `skip`
/// does not exclude, nearest first. Ties in distance go to the lower row, so the neighbours are a
/// function of the data alone.
///
/// One pass keeps the `k` nearest so far, sorted by (distance, row); a row's squared distance
/// stops accumulating once it exceeds the `k`-th nearest's, since it can no longer enter.
fn nearest_rows(points: &[f64], dim: usize, f: &[f64], k: usize, skip: impl Fn(usize) -> bool) -> Vec<usize> {
    let mut nearest: Vec<(f64, usize)> = Vec::with_capacity(k + 1);
    for (row, g) in points.chunks_exact(dim).enumerate() {
        if skip(row) {
            continue;
        }
        let bound = if nearest.len() == k {
            nearest[k - 1].0
        } else {
            f64::INFINITY
        };
        let mut d = 0.0;
        for (a, b) in f.iter().zip(g) {
            d += (a - b) * (a - b);
            if d > bound {
                break;
            }
        }
        // Rows come in increasing order, so an equal distance never displaces an earlier row.
        if d < bound {
            let at = nearest.partition_point(|&(e, _)| e <= d);
            nearest.insert(at, (d, row));
            nearest.truncate(k);
        }
    }
    nearest.into_iter().map(|(_, row)| row).collect()
}

/// Every training feature's nearest other training features, its own reading's left out: what
/// the objects' histograms of a neighbour codebook are made of. A feature's membership with its
/// reading in its own neighbourhood would make every object look perfectly distinct.
///
/// The `k` nearest in (distance, row) order are the first `k` of the `k_max` nearest, so one scan
/// at the largest candidate `k` serves every candidate of model selection, with the histograms
/// each would have computed itself, bit for bit.
#[derive(Debug, Clone, PartialEq)]
pub struct LeaveOneReadingOut {
    objects: usize,
    /// Per training row, the objects of its nearest rows, nearest first.
    nearest_objects: Vec<Vec<u32>>,
    row_objects: Vec<u32>,
}

impl LeaveOneReadingOut {
    /// The `k_max` nearest of every row of `training` (fewer when fewer rows lie outside its
    /// reading), found in parallel.
    pub fn scan(training: TrainingFeatures, k_max: usize) -> Self {
        let (data, dim) = (training.data.as_slice(), training.data.dim());
        let readings = training.readings;
        debug_assert_eq!(readings.len(), training.data.rows());
        let nearest_objects = (0..training.data.rows())
            .into_par_iter()
            .map(|row| {
                let f = &data[row * dim..(row + 1) * dim];
                nearest_rows(data, dim, f, k_max, |other| readings[other] == readings[row])
                    .into_iter()
                    .map(|other| training.objects[other])
                    .collect()
            })
            .collect();
        Self {
            objects: training.object_count,
            nearest_objects,
            row_objects: training.objects.to_vec(),
        }
    }

    /// Every object's histogram of its own training features under the `k`-nearest codebook
    /// (`k` at most the scan's `k_max`), summed in row order.
    pub fn histograms(&self, k: usize) -> Vec<ClusterHistogram> {
        let mut histograms = vec![ClusterHistogram::new(self.objects); self.objects];
        let mut membership = vec![0.0; self.objects];
        for (nearest, &object) in self.nearest_objects.iter().zip(&self.row_objects) {
            let nearest = &nearest[..k.min(nearest.len())];
            shares_of_objects(nearest.iter().copied(), &mut membership);
            histograms[object as usize].add(&membership);
        }
        histograms
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn matrix(rows: &[[f64; 2]]) -> FeatureMatrix {
        FeatureMatrix::from_trusted(rows.len(), 2, rows.iter().flatten().copied().collect())
    }

    /// Object 0 near the origin, object 1 near (10, 0), one of object 1's features among object 0's.
    fn two_clouds() -> NearestNeighbours {
        let data = matrix(&[
            [0.0, 0.0],
            [1.0, 0.0],
            [0.0, 1.0],
            [10.0, 0.0],
            [11.0, 0.0],
            [0.5, 0.5],
        ]);
        NearestNeighbours::new(&data, vec![0, 0, 0, 1, 1, 1], 2, 3).unwrap()
    }

    /// The codebook's training histograms with the features of each reading (`readings[r]` per
    /// row) left out.
    fn leave_one_reading_out(nn: &NearestNeighbours, readings: &[u32]) -> Vec<ClusterHistogram> {
        let data = FeatureMatrix::from_trusted(nn.len(), nn.dim, nn.points.clone());
        let training = TrainingFeatures {
            data: &data,
            objects: &nn.labels,
            object_count: nn.objects,
            readings,
        };
        LeaveOneReadingOut::scan(training, nn.neighbours).histograms(nn.neighbours)
    }

    #[test]
    fn a_membership_is_the_share_of_each_object_among_the_nearest() {
        let nn = two_clouds();
        let mut out = [0.0; 2];
        // Nearest to (0.2, 0.2): (0, 0), (0.5, 0.5), then (1, 0) and (0, 1) tie; the lower row wins.
        nn.membership(&[0.2, 0.2], &mut out);
        assert_eq!(out, [2.0 / 3.0, 1.0 / 3.0]);
        nn.membership(&[10.4, 0.0], &mut out);
        assert_eq!(out, [1.0 / 3.0, 2.0 / 3.0]);
    }

    #[test]
    fn the_one_pass_scan_keeps_the_k_nearest_of_a_full_sort() {
        use rand::RngExt;
        let mut rng = crate::rng::rng(5);
        // Coordinates on a coarse grid, so that many distances tie.
        let mut coordinate = || f64::from(rng.random_range(0..6u8));
        let rows: Vec<[f64; 2]> = (0..300).map(|_| [coordinate(), coordinate()]).collect();
        let labels: Vec<u32> = (0..300).map(|i| (i * 7 % 5) as u32).collect();
        for k in [1, 7, 40] {
            let nn = NearestNeighbours::new(&matrix(&rows), labels.clone(), 5, k).unwrap();
            for q in 0..30 {
                let f = [coordinate() + 0.5 * f64::from(q % 2), coordinate()];
                let mut all: Vec<(f64, usize)> = rows
                    .iter()
                    .enumerate()
                    .map(|(r, g)| ((f[0] - g[0]).powi(2) + (f[1] - g[1]).powi(2), r))
                    .collect();
                all.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
                let mut expected = [0.0; 5];
                for &(_, r) in &all[..k] {
                    expected[labels[r] as usize] += 1.0 / k as f64;
                }
                let mut out = [0.0; 5];
                nn.membership(&f, &mut out);
                assert_eq!(out, expected, "k = {k}, query {f:?}");
            }
        }
    }

    #[test]
    fn training_memberships_leave_the_reading_out() {
        let nn = two_clouds();
        // Every feature its own reading: (0, 0) sees (0.5, 0.5), (1, 0), (0, 1) -> 2/3 object 0.
        let alone = leave_one_reading_out(&nn, &[0, 1, 2, 3, 4, 5]);
        assert_eq!(alone[0].features(), 3);
        assert_eq!(alone[1].features(), 3);
        // Object 1's two far features see each other, (1, 0) and (0.5, 0.5): 2/3 object 1 each;
        // (0.5, 0.5) sees only object 0's cloud.
        let far = alone[1].sums()[1];
        assert!((far - 4.0 / 3.0).abs() < 1e-12, "{far}");
        // Features 3 and 4 one reading: neither sees the other any more.
        let grouped = leave_one_reading_out(&nn, &[0, 1, 2, 3, 3, 5]);
        assert!(grouped[1].sums()[1] < far);
    }

    #[test]
    fn one_scan_at_the_largest_k_gives_every_smaller_k_its_own_histograms() {
        use rand::RngExt;
        let mut rng = crate::rng::rng(11);
        // A coarse grid (many tied distances) and readings of 1-3 features.
        let rows: Vec<[f64; 2]> = (0..200)
            .map(|_| {
                [
                    f64::from(rng.random_range(0..5u8)),
                    f64::from(rng.random_range(0..5u8)),
                ]
            })
            .collect();
        let labels: Vec<u32> = (0..200).map(|i| (i / 50) as u32).collect();
        let readings: Vec<u32> = (0..200).map(|i| (i / 3) as u32).collect();
        let data = matrix(&rows);
        let training = TrainingFeatures {
            data: &data,
            objects: &labels,
            object_count: 4,
            readings: &readings,
        };
        let shared = LeaveOneReadingOut::scan(training, 40);
        for k in [1, 5, 17, 40] {
            let own = LeaveOneReadingOut::scan(training, k).histograms(k);
            assert_eq!(shared.histograms(k), own, "k = {k}");
            // And each row's share is what the codebook's own membership says with its reading out.
            let nn = NearestNeighbours::new(&data, labels.clone(), 4, k).unwrap();
            let mut expected = vec![ClusterHistogram::new(4); 4];
            let mut m = [0.0; 4];
            for (row, f) in rows.iter().enumerate() {
                nn.membership_skipping(f, &mut m, |other| readings[other] == readings[row]);
                expected[labels[row] as usize].add(&m);
            }
            assert_eq!(own, expected, "k = {k}");
        }
    }

    #[test]
    fn a_broken_codebook_is_refused_naming_what_is_wrong() {
        let data = matrix(&[[0.0, 0.0], [1.0, 0.0]]);
        let err = |labels: Vec<u32>, k| {
            NearestNeighbours::new(&data, labels, 2, k)
                .unwrap_err()
                .to_string()
        };
        assert!(err(vec![0, 1], 2).contains("fewer than the 2 training features"));
        assert!(err(vec![0, 1], 0).contains("at least 1"));
        assert!(err(vec![0, 2], 1).contains("object 2 of 2 objects"));
        let mut nn = NearestNeighbours::new(&data, vec![0, 1], 2, 1).unwrap();
        nn.points[1] = f64::NAN;
        assert!(nn.check().unwrap_err().contains("NaN"));
    }
}
