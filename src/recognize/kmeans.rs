//! k-means clustering with k-means++ seeding (Sec. V-B1; the initialisation of the paper's [52],
//! Arthur and Vassilvitskii 2007), used as a hard codebook and to initialise the Gaussian mixture.

use rand::RngExt;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::recognize::RecognizeError;
use crate::recognize::features::FeatureMatrix;
use crate::rng::Rng;

/// How Lloyd's iterations stop.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct KMeansConfig {
    /// Upper bound on Lloyd iterations.
    pub max_iterations: usize,
    /// Stop when the summed squared centre shift falls below `tolerance` times the mean
    /// per-dimension variance of the data (scikit-learn's convention), or when no label changes.
    pub tolerance: f64,
}

impl Default for KMeansConfig {
    fn default() -> Self {
        Self {
            max_iterations: 300,
            tolerance: 1e-4,
        }
    }
}

/// How a fit went.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KMeansFit {
    pub iterations: usize,
    /// Sum of squared distances of the features to their centres.
    pub inertia: f64,
}

/// `k` centres; a feature's cluster is its nearest centre (Euclidean, ties to the lower index).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct KMeans {
    centers: Vec<Vec<f64>>,
}

/// Squared Euclidean distance.
#[inline]
pub(crate) fn squared_distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum()
}

/// k-means++ seeding: the first centre is a uniformly drawn feature, each next one a feature drawn
/// with probability proportional to `D(x)^2`, its squared distance to the nearest centre so far.
/// Returns the indices of the `k` chosen features. When every remaining `D(x)^2` is 0 (fewer
/// distinct features than `k`) the next centre is drawn uniformly.
pub fn kmeans_plus_plus(data: &FeatureMatrix, k: usize, rng: &mut Rng) -> Vec<usize> {
    let n = data.rows();
    let mut chosen = Vec::with_capacity(k);
    if k == 0 {
        return chosen;
    }
    let first = rng.random_range(0..n);
    chosen.push(first);
    let mut d2: Vec<f64> = data
        .iter_rows()
        .map(|x| squared_distance(x, data.row(first)))
        .collect();
    while chosen.len() < k {
        let total: f64 = d2.iter().sum();
        let pick = if total > 0.0 {
            let target = rng.random::<f64>() * total;
            let mut cumulative = 0.0;
            let mut pick = None;
            for (i, &w) in d2.iter().enumerate() {
                cumulative += w;
                if w > 0.0 && cumulative > target {
                    pick = Some(i);
                    break;
                }
            }
            // Rounding can leave `target` at the very top; take the last feature with weight.
            pick.or_else(|| d2.iter().rposition(|&w| w > 0.0)).unwrap_or(0)
        } else {
            rng.random_range(0..n)
        };
        chosen.push(pick);
        let c = data.row(pick);
        for (d, x) in d2.iter_mut().zip(data.iter_rows()) {
            *d = d.min(squared_distance(x, c));
        }
    }
    chosen
}

impl KMeans {
    /// Clusters `data` into `k` groups: k-means++ seeding from `rng`, then Lloyd's iterations. An
    /// emptied cluster is re-seeded with the feature farthest from its centre. Deterministic for
    /// a given `rng` state, whatever the thread count.
    pub fn fit(
        data: &FeatureMatrix,
        k: usize,
        config: &KMeansConfig,
        rng: &mut Rng,
    ) -> Result<(Self, KMeansFit), RecognizeError> {
        let (n, d) = (data.rows(), data.dim());
        if k == 0 {
            return Err(RecognizeError::InvalidParameter {
                name: "k",
                what: "needs at least one cluster".into(),
            });
        }
        if n < k {
            return Err(RecognizeError::TooFewFeatures { k, n });
        }
        let mut centers: Vec<Vec<f64>> = kmeans_plus_plus(data, k, rng)
            .into_iter()
            .map(|i| data.row(i).to_vec())
            .collect();
        let threshold = config.tolerance * mean_variance(data);
        let mut labels = vec![usize::MAX; n];
        let mut distances = vec![0.0; n];
        let mut bounds = LowerBounds::new(data);
        let mut iterations = 0;
        while iterations < config.max_iterations {
            iterations += 1;
            let changed = assign(data, &centers, &mut labels, &mut distances, &mut bounds).changed;
            let mut sums = vec![vec![0.0; d]; k];
            let mut counts = vec![0usize; k];
            for (x, &l) in data.iter_rows().zip(&labels) {
                counts[l] += 1;
                for (s, v) in sums[l].iter_mut().zip(x) {
                    *s += v;
                }
            }
            reseed_empty(
                data,
                &mut labels,
                &mut distances,
                &mut sums,
                &mut counts,
                &mut bounds,
            );
            let mut shift = 0.0;
            let mut largest_move: f64 = 0.0;
            for ((center, sum), &count) in centers.iter_mut().zip(&sums).zip(&counts) {
                let mut moved = 0.0;
                for (c, s) in center.iter_mut().zip(sum) {
                    let new = s / count as f64;
                    shift += (new - *c) * (new - *c);
                    moved += (new - *c) * (new - *c);
                    *c = new;
                }
                // `max` would pass over a move that is not a number; it bounds nothing.
                largest_move = if moved.is_nan() {
                    f64::INFINITY
                } else {
                    largest_move.max(f64::sqrt(moved))
                };
            }
            bounds.centres_moved(largest_move);
            if changed == 0 || shift <= threshold {
                break;
            }
        }
        let model = Self { centers };
        let inertia = nearest_centres(data, &CentreBlocks::new(&model.centers))
            .into_iter()
            .map(|nearest| nearest.distance)
            .sum();
        Ok((model, KMeansFit { iterations, inertia }))
    }

    /// Centres from explicit coordinates (all the same, non-zero length, finite).
    pub fn from_centers(centers: Vec<Vec<f64>>) -> Result<Self, RecognizeError> {
        let model = Self { centers };
        model.check().map_err(|what| RecognizeError::InvalidParameter {
            name: "centers",
            what,
        })?;
        Ok(model)
    }

    pub fn centers(&self) -> &[Vec<f64>] {
        &self.centers
    }

    pub fn k(&self) -> usize {
        self.centers.len()
    }

    pub fn dim(&self) -> usize {
        self.centers[0].len()
    }

    /// The index of the centre nearest to `x` (ties to the lower index). One feature at a time;
    /// [`labels`](Self::labels) gives the same answers for many at once, faster.
    pub fn nearest(&self, x: &[f64]) -> usize {
        let mut best = (0, f64::INFINITY);
        for (i, c) in self.centers.iter().enumerate() {
            let d = squared_distance(x, c);
            if d < best.1 {
                best = (i, d);
            }
        }
        best.0
    }

    /// The cluster of every feature.
    pub fn labels(&self, data: &FeatureMatrix) -> Vec<usize> {
        nearest_centres(data, &CentreBlocks::new(&self.centers))
            .into_iter()
            .map(|nearest| nearest.index)
            .collect()
    }

    pub(crate) fn check(&self) -> Result<(), String> {
        let d = self.centers.first().map_or(0, Vec::len);
        if d == 0 {
            return Err("k-means has no centres or centres of zero length".into());
        }
        if let Some(i) = self.centers.iter().position(|c| c.len() != d) {
            return Err(format!(
                "k-means centre {i} has {} values, expected {d}",
                self.centers[i].len()
            ));
        }
        if self.centers.iter().flatten().any(|v| !v.is_finite()) {
            return Err("k-means has a non-finite centre".into());
        }
        Ok(())
    }
}

/// Mean over dimensions of the per-dimension variance (population form).
fn mean_variance(data: &FeatureMatrix) -> f64 {
    let (n, d) = (data.rows() as f64, data.dim());
    let mut mean = vec![0.0; d];
    for x in data.iter_rows() {
        mean.iter_mut().zip(x).for_each(|(m, v)| *m += v / n);
    }
    let total: f64 = data.iter_rows().map(|x| squared_distance(x, &mean)).sum();
    total / (n * d as f64)
}

/// Hamerly's lower bounds (2010, "Making k-means even faster"): per feature, at most its distance
/// to every centre but its own. A Lloyd iteration then skips the full search for a feature whose
/// distance to its own centre is clearly below both this bound and half the gap from its centre
/// to the next (the triangle inequality puts every other centre farther), and only measures that
/// one distance, which `distances` needs anyway. Skipped or not, a feature gets the label and
/// distance of the full search, to the bit: "clearly" leaves a margin of [`BOUND_MARGIN`] of the
/// data's extent, far above the rounding of the bounds and of the distances.
struct LowerBounds {
    /// Per feature; `-inf` until a full search has set it.
    lower: Vec<f64>,
    /// The margin of a skip: [`BOUND_MARGIN`] times the diagonal of the data's bounding box.
    margin: f64,
}

/// The margin of a skip, relative to the data's extent: the bounds' rounding over hundreds of
/// iterations stays below 1e-12 of it.
const BOUND_MARGIN: f64 = 1e-9;

impl LowerBounds {
    fn new(data: &FeatureMatrix) -> Self {
        let d = data.dim();
        let mut low = vec![f64::INFINITY; d];
        let mut high = vec![f64::NEG_INFINITY; d];
        for x in data.iter_rows() {
            for ((low, high), &v) in low.iter_mut().zip(&mut high).zip(x) {
                *low = low.min(v);
                *high = high.max(v);
            }
        }
        let diagonal = low
            .iter()
            .zip(&high)
            .map(|(l, h)| (h - l) * (h - l))
            .sum::<f64>()
            .sqrt();
        Self {
            lower: vec![f64::NEG_INFINITY; data.rows()],
            margin: BOUND_MARGIN * diagonal,
        }
    }

    /// After the centres moved, every distance to another centre may have shrunk by the largest
    /// move (infinite when a move is not a number: then nothing is bounded).
    fn centres_moved(&mut self, largest_move: f64) {
        self.lower.iter_mut().for_each(|l| *l -= largest_move);
    }

    /// Feature `i` was given another centre outside a search: nothing bounds its other distances.
    fn forget(&mut self, i: usize) {
        self.lower[i] = f64::NEG_INFINITY;
    }
}

/// Half the distance from every centre to its nearest other centre (infinite for a lone centre).
/// A feature nearer than this to its centre is nearer to it than to any other.
fn half_gaps(centers: &[Vec<f64>]) -> Vec<f64> {
    let mut gaps = vec![f64::INFINITY; centers.len()];
    for (i, a) in centers.iter().enumerate() {
        for (j, b) in centers.iter().enumerate().skip(i + 1) {
            let gap = squared_distance(a, b).sqrt();
            gaps[i] = gaps[i].min(gap);
            gaps[j] = gaps[j].min(gap);
        }
    }
    gaps.iter_mut().for_each(|g| *g *= 0.5);
    gaps
}

/// Labels every feature with its nearest centre and records its squared distance, in parallel
/// (each feature independently, so the result does not depend on the thread count), searching
/// only where the [`LowerBounds`] leave the answer open.
fn assign(
    data: &FeatureMatrix,
    centers: &[Vec<f64>],
    labels: &mut [usize],
    distances: &mut [f64],
    bounds: &mut LowerBounds,
) -> Assignment {
    const CHUNK: usize = 512;
    let d = data.dim();
    let search = Search {
        centers,
        blocks: CentreBlocks::new(centers),
        half_gaps: half_gaps(centers),
        margin: bounds.margin,
    };
    #[cfg(target_arch = "x86_64")]
    let wide = crate::simd::has_avx2();
    data.as_slice()
        .par_chunks(CHUNK * d)
        .zip(labels.par_chunks_mut(CHUNK))
        .zip(distances.par_chunks_mut(CHUNK))
        .zip(bounds.lower.par_chunks_mut(CHUNK))
        .map(|(((rows, labels), distances), lower)| {
            let features = Features {
                rows,
                labels,
                distances,
                lower,
            };
            #[cfg(target_arch = "x86_64")]
            if wide {
                // SAFETY: `wide` is set only where the processor has AVX2.
                return unsafe { search.assign_avx2(features) };
            }
            search.assign(features)
        })
        .reduce(Assignment::default, |a, b| Assignment {
            changed: a.changed + b.changed,
            searched: a.searched + b.searched,
        })
}

/// What an assignment did.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Assignment {
    /// Features whose label changed.
    changed: usize,
    /// Features searched over every centre (the others were settled by their bounds).
    searched: usize,
}

/// What one Lloyd iteration's assignment reads: the centres as they are and in blocks, their half
/// gaps, the margin of a skip.
struct Search<'a> {
    centers: &'a [Vec<f64>],
    blocks: CentreBlocks,
    half_gaps: Vec<f64>,
    margin: f64,
}

/// A run of features (`rows`, row-major) with their labels, distances and lower bounds.
struct Features<'a> {
    rows: &'a [f64],
    labels: &'a mut [usize],
    distances: &'a mut [f64],
    lower: &'a mut [f64],
}

impl Search<'_> {
    /// [`assign`](Self::assign) compiled with AVX2: the same operations, four lanes at a time.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn assign_avx2(&self, features: Features) -> Assignment {
        self.assign(features)
    }

    /// [`assign`] for a run of features.
    #[inline(always)]
    fn assign(&self, features: Features) -> Assignment {
        let Features {
            rows,
            labels,
            distances,
            lower,
        } = features;
        let d = self.blocks.dim;
        let mut done = Assignment::default();
        for (((x, label), distance), lower) in rows
            .chunks_exact(d)
            .zip(labels.iter_mut())
            .zip(distances.iter_mut())
            .zip(lower.iter_mut())
        {
            if let Some(centre) = self.centers.get(*label) {
                let own = squared_distance(x, centre);
                let clear = self.half_gaps[*label].max(*lower) - self.margin;
                if own.sqrt() < clear {
                    *distance = own;
                    continue;
                }
            }
            let nearest = nearest_of(x, &self.blocks);
            done.changed += usize::from(*label != nearest.index);
            done.searched += 1;
            *label = nearest.index;
            *distance = nearest.distance;
            *lower = nearest.second.sqrt();
        }
        done
    }
}

/// Centres per block of [`CentreBlocks`]: two lanes of four.
const BLOCK: usize = 8;

/// The centres transposed in blocks of [`BLOCK`]: coordinate `a` of the block's centres side by
/// side, so one pass over a feature's coordinates measures its distance to a whole block, each
/// centre in its own lane. The last block is padded with NaN centres, whose distance is never
/// below another.
struct CentreBlocks {
    dim: usize,
    /// Block `b`, coordinate `a` at `b * dim + a`.
    values: Vec<[f64; BLOCK]>,
}

impl CentreBlocks {
    fn new(centers: &[Vec<f64>]) -> Self {
        let dim = centers.first().map_or(0, Vec::len);
        let mut values = vec![[f64::NAN; BLOCK]; centers.len().div_ceil(BLOCK) * dim];
        for (i, centre) in centers.iter().enumerate() {
            for (a, &v) in centre.iter().enumerate() {
                values[i / BLOCK * dim + a][i % BLOCK] = v;
            }
        }
        Self { dim, values }
    }
}

/// A feature's nearest centre (ties to the lower index), its squared distance, and the squared
/// distance of the next nearest (infinite for a lone centre).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Nearest {
    index: usize,
    distance: f64,
    second: f64,
}

/// The nearest centre of every feature, in parallel, in feature order: [`KMeans::nearest`]'s
/// answer (ties to the lower index) and [`squared_distance`]'s bits.
fn nearest_centres(data: &FeatureMatrix, blocks: &CentreBlocks) -> Vec<Nearest> {
    const CHUNK: usize = 512;
    let d = data.dim();
    let none = Nearest {
        index: 0,
        distance: f64::INFINITY,
        second: f64::INFINITY,
    };
    let mut nearest = vec![none; data.rows()];
    if d == 0 || blocks.dim != d {
        return nearest;
    }
    #[cfg(target_arch = "x86_64")]
    let wide = crate::simd::has_avx2();
    data.as_slice()
        .par_chunks(CHUNK * d)
        .zip(nearest.par_chunks_mut(CHUNK))
        .for_each(|(rows, out)| {
            #[cfg(target_arch = "x86_64")]
            if wide {
                // SAFETY: `wide` is set only where the processor has AVX2.
                return unsafe { nearest_of_rows_avx2(rows, blocks, out) };
            }
            nearest_of_rows(rows, blocks, out);
        });
    nearest
}

/// [`nearest_of_rows`] compiled with AVX2: the same operations, four lanes at a time.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn nearest_of_rows_avx2(rows: &[f64], blocks: &CentreBlocks, out: &mut [Nearest]) {
    nearest_of_rows(rows, blocks, out);
}

/// [`nearest_of`] each feature of `rows` (row-major), into `out`.
#[inline(always)]
fn nearest_of_rows(rows: &[f64], blocks: &CentreBlocks, out: &mut [Nearest]) {
    for (x, out) in rows.chunks_exact(blocks.dim).zip(out) {
        *out = nearest_of(x, blocks);
    }
}

/// The nearest centre of `x`. Each lane repeats [`squared_distance`] for its centre (the first
/// square, then the others added in coordinate order, each rounded as there) and keeps its first
/// strictly smaller distance, as the scan over the centres in order keeps it, and its next
/// smallest; of the lanes' bests the smallest distance wins, ties to the lower centre index, which
/// is the scan's answer.
#[inline(always)]
fn nearest_of(x: &[f64], blocks: &CentreBlocks) -> Nearest {
    let d = blocks.dim;
    let mut best = [f64::INFINITY; BLOCK];
    let mut second = [f64::INFINITY; BLOCK];
    let mut index = [0usize; BLOCK];
    for (b, block) in blocks.values.chunks_exact(d).enumerate() {
        let mut distance = [0.0; BLOCK];
        for (lane, &c) in distance.iter_mut().zip(&block[0]) {
            let t = x[0] - c;
            *lane = t * t;
        }
        for (&v, centres) in x.iter().zip(block).skip(1) {
            for (lane, &c) in distance.iter_mut().zip(centres) {
                let t = v - c;
                *lane += t * t;
            }
        }
        for (lane, &candidate) in distance.iter().enumerate() {
            let nearer = candidate < best[lane];
            second[lane] = if nearer {
                best[lane]
            } else if candidate < second[lane] {
                candidate
            } else {
                second[lane]
            };
            best[lane] = if nearer { candidate } else { best[lane] };
            index[lane] = if nearer { b * BLOCK + lane } else { index[lane] };
        }
    }
    let mut winner = 0;
    for lane in 1..BLOCK {
        if best[lane] < best[winner] || (best[lane] == best[winner] && index[lane] < index[winner]) {
            winner = lane;
        }
    }
    let others = (0..BLOCK).filter(|&lane| lane != winner).map(|lane| best[lane]);
    Nearest {
        index: index[winner],
        distance: best[winner],
        second: others.fold(second[winner], f64::min),
    }
}

/// Moves, into every empty cluster, the feature farthest from its current centre (ties to the
/// lower index), updating the running sums and counts.
fn reseed_empty(
    data: &FeatureMatrix,
    labels: &mut [usize],
    distances: &mut [f64],
    sums: &mut [Vec<f64>],
    counts: &mut [usize],
    bounds: &mut LowerBounds,
) {
    for empty in 0..counts.len() {
        if counts[empty] > 0 {
            continue;
        }
        let far =
            (0..labels.len())
                .filter(|&i| counts[labels[i]] > 1)
                .fold(None, |best: Option<usize>, i| match best {
                    Some(b) if distances[b] >= distances[i] => Some(b),
                    _ => Some(i),
                });
        let Some(i) = far else { continue };
        let from = labels[i];
        let x = data.row(i);
        sums[from].iter_mut().zip(x).for_each(|(s, v)| *s -= v);
        counts[from] -= 1;
        sums[empty].copy_from_slice(x);
        counts[empty] = 1;
        labels[i] = empty;
        distances[i] = 0.0;
        bounds.forget(i);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::stream;

    fn blobs() -> FeatureMatrix {
        let mut rng = stream(1, 0);
        let centers = [[0.0, 0.0], [100.0, 0.0], [0.0, 100.0]];
        let features: Vec<Vec<f64>> = (0..90)
            .map(|i| {
                let c = centers[i % 3];
                vec![c[0] + rng.random::<f64>() - 0.5, c[1] + rng.random::<f64>() - 0.5]
            })
            .collect();
        FeatureMatrix::from_features(&features, "blobs").unwrap()
    }

    /// The blocked search against the scan of [`KMeans::nearest`] and [`squared_distance`], bit for
    /// bit, in both builds: blocks whole and padded, one coordinate and many, and ties (repeated
    /// centres, features on a centre, features halfway between two).
    #[test]
    fn the_blocked_search_finds_the_scans_nearest_centre_and_distance() {
        let mut rng = stream(8, 0);
        for (dim, k) in [(1, 1), (1, 9), (2, 8), (3, 17), (7, 5), (10, 400), (13, 24)] {
            let mut centers: Vec<Vec<f64>> = (0..k)
                .map(|_| (0..dim).map(|_| rng.random_range(-1.0..1.0)).collect())
                .collect();
            if k > 3 {
                centers[k - 1] = centers[1].clone();
                centers[2] = centers[k - 2].clone();
            }
            let mut features: Vec<Vec<f64>> = (0..300)
                .map(|_| (0..dim).map(|_| rng.random_range(-1.5..1.5)).collect())
                .collect();
            features.extend(centers.iter().cloned());
            if k > 1 {
                features.push(
                    centers[0]
                        .iter()
                        .zip(&centers[1])
                        .map(|(a, b)| 0.5 * (a + b))
                        .collect(),
                );
            }
            let data = FeatureMatrix::from_features(&features, "search").unwrap();
            let model = KMeans::from_centers(centers).unwrap();
            let want: Vec<(usize, u64)> = features
                .iter()
                .map(|x| {
                    let i = model.nearest(x);
                    (i, squared_distance(x, &model.centers()[i]).to_bits())
                })
                .collect();
            let blocks = CentreBlocks::new(model.centers());
            let bits = |found: Vec<Nearest>| -> Vec<(usize, u64)> {
                found
                    .into_iter()
                    .map(|n| (n.index, n.distance.to_bits()))
                    .collect()
            };
            let none = Nearest {
                index: 0,
                distance: 0.0,
                second: 0.0,
            };
            let mut baseline = vec![none; features.len()];
            nearest_of_rows(data.as_slice(), &blocks, &mut baseline);
            assert_eq!(bits(baseline), want, "baseline, dim {dim}, k {k}");
            assert_eq!(bits(nearest_centres(&data, &blocks)), want, "dim {dim}, k {k}");
            #[cfg(target_arch = "x86_64")]
            if crate::simd::has_avx2() {
                let mut wide = vec![none; features.len()];
                // SAFETY: the processor has AVX2.
                unsafe { nearest_of_rows_avx2(data.as_slice(), &blocks, &mut wide) };
                assert_eq!(bits(wide), want, "AVX2, dim {dim}, k {k}");
            }
            assert_eq!(
                model.labels(&data),
                want.iter().map(|&(i, _)| i).collect::<Vec<_>>()
            );
        }
    }

    /// The assignment with Hamerly's bounds against the full search, bit for bit, over centres
    /// that move by steps from a thousandth to a third of the data's extent (so the bounds settle
    /// most features on small steps and must give way on large ones), a lone centre, and centres
    /// repeated (ties); the second nearest distance too.
    #[test]
    fn the_bounded_assignment_gives_the_full_searchs_labels_and_distances() {
        let mut rng = stream(9, 0);
        for (dim, k) in [(3, 20), (10, 64), (2, 1), (4, 9)] {
            let features: Vec<Vec<f64>> = (0..1500)
                .map(|i| {
                    let blob = (i % 7) as f64;
                    (0..dim)
                        .map(|a| blob * (a as f64 + 1.0) + rng.random_range(-1.0..1.0))
                        .collect()
                })
                .collect();
            let data = FeatureMatrix::from_features(&features, "bounded").unwrap();
            let mut centers: Vec<Vec<f64>> = (0..k).map(|i| features[i * 97 % 1500].clone()).collect();
            if k > 3 {
                centers[3] = centers[1].clone();
            }
            let mut labels = vec![usize::MAX; features.len()];
            let mut distances = vec![0.0; features.len()];
            let mut bounds = LowerBounds::new(&data);
            let mut skipped = 0;
            for step in 0..24 {
                let done = assign(&data, &centers, &mut labels, &mut distances, &mut bounds);
                skipped += features.len() - done.searched;
                let model = KMeans::from_centers(centers.clone()).unwrap();
                for (i, x) in features.iter().enumerate() {
                    let want = model.nearest(x);
                    assert_eq!(labels[i], want, "dim {dim}, k {k}, step {step}, feature {i}");
                    let distance = squared_distance(x, &centers[want]);
                    assert_eq!(
                        distances[i].to_bits(),
                        distance.to_bits(),
                        "step {step}, feature {i}"
                    );
                    let second = centers
                        .iter()
                        .enumerate()
                        .filter(|&(j, _)| j != want)
                        .map(|(_, c)| squared_distance(x, c))
                        .fold(f64::INFINITY, f64::min);
                    assert_eq!(nearest_of(x, &CentreBlocks::new(&centers)).second, second);
                }
                let step_size = [1e-3, 0.02, 0.3][step % 3] * 8.0 * dim as f64;
                let mut largest_move: f64 = 0.0;
                for centre in &mut centers {
                    let mut moved = 0.0;
                    for c in centre.iter_mut() {
                        let new = *c + rng.random_range(-step_size..step_size);
                        moved += (new - *c) * (new - *c);
                        *c = new;
                    }
                    largest_move = largest_move.max(f64::sqrt(moved));
                }
                bounds.centres_moved(largest_move);
            }
            assert!(skipped > 0, "dim {dim}, k {k}: the bounds settled no feature");
        }
    }

    #[test]
    fn separates_well_separated_blobs() {
        let data = blobs();
        let (km, fit) = KMeans::fit(&data, 3, &KMeansConfig::default(), &mut stream(5, 0)).unwrap();
        let labels = km.labels(&data);
        for i in 0..90 {
            assert_eq!(labels[i], labels[i % 3], "feature {i}");
        }
        assert!(labels[0] != labels[1] && labels[1] != labels[2] && labels[0] != labels[2]);
        // Each blob is uniform on a unit square: inertia ~ 90 * 2/12.
        assert!(fit.inertia < 90.0 * 0.25, "{}", fit.inertia);
    }

    #[test]
    fn plus_plus_spreads_seeds_over_distinct_blobs() {
        let data = blobs();
        for seed in 0..20 {
            let seeds = kmeans_plus_plus(&data, 3, &mut stream(seed, 0));
            let mut blobs: Vec<usize> = seeds.iter().map(|i| i % 3).collect();
            blobs.sort();
            blobs.dedup();
            // D^2 weighting makes a second seed in the same blob ~(0.5/100)^2 as likely as a new blob.
            assert_eq!(blobs.len(), 3, "seed {seed}: {seeds:?}");
        }
    }

    #[test]
    fn empty_clusters_are_reseeded() {
        // Two distinct points repeated, k = 3: one cluster must take a duplicate.
        let features: Vec<Vec<f64>> = (0..6).map(|i| vec![(i % 2) as f64]).collect();
        let data = FeatureMatrix::from_features(&features, "t").unwrap();
        let (km, _) = KMeans::fit(&data, 3, &KMeansConfig::default(), &mut stream(0, 0)).unwrap();
        assert!(km.centers().iter().flatten().all(|v| v.is_finite()));
        assert!(matches!(
            KMeans::fit(&data, 7, &KMeansConfig::default(), &mut stream(0, 0)),
            Err(RecognizeError::TooFewFeatures { k: 7, n: 6 })
        ));
    }
}
