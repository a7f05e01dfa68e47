//! The Gaussian mixture's two heavy sums (Sec. V-B1, Eq. 9-10), each on the triangle that
//! matters, four lanes at a time.
//!
//! Every EM iteration does, per component, two matrix products over all `n` training features:
//! the E-step's whitened residuals `X P_i` (`P_i` upper triangular, so half of a general product
//! multiplies structural zeros) and the M-step's weighted scatter `(D^T diag(r)) D` (symmetric, so
//! half of a general product is thrown away when the covariance is symmetrised). Both also wrote
//! `n x d` intermediates per component. Here each is computed on its triangle only, from blocks
//! small enough to stay in the cache.
//!
//! They replace the general products exactly. nalgebra multiplies these sizes with
//! `matrixmultiply`, whose kernel on a processor with AVX2 and FMA forms every output value as a
//! chain of fused multiply-adds starting from zero over the summed index, in blocks of [`KC`]
//! terms whose chains are added in order. The functions here form each value by the same chain,
//! lane by lane. A chain never holds -0 (it starts at +0, and a sum that cancels exactly rounds to
//! +0), so a fused multiply-add by a structural zero leaves it unchanged and skipping those terms
//! changes no bit; the tests in `gmm` compare with nalgebra's product bit for bit. Where
//! `matrixmultiply` would sum another way (a processor without FMA runs its plain AVX kernel;
//! `d` beyond one block) the functions return `None` and the mixture keeps the general product, so
//! a fit gives the same bits as before on every machine.
//!
//! A product with a dimension of at most [`NALGEBRA_SMALL_DIM`] (the Polar-Fourier features of the
//! letters keep 4 components) nalgebra forms without `matrixmultiply`: column by column, each
//! value a chain of separately rounded products and sums in the order of the summed index,
//! starting from its first term. Those chains are repeated here on every machine, without the
//! `n x d` intermediates, and the scatter again skips the features of zero responsibility: each
//! adds a signed zero, which changes a chain only while it is zero and only in the sign of that
//! zero, so an entry that ends at zero is summed again over every feature.
//!
//! The mean `sum_r p_r x_r` is nalgebra's dot product of each column with the responsibilities:
//! eight chains over the rows by their index modulo eight, while eight remain, added pairwise in a
//! fixed order, then the rest in order. [`weighted_column_sums`] forms the same chains, skipping
//! the groups of eight features whose responsibilities are all zero (a chain starts at +0 and so
//! never holds -0: a zero term leaves it unchanged).

use nalgebra::DMatrix;

use crate::simd::has_avx2_fma;

/// The block of the summed index in `matrixmultiply`'s `f64` product (its `D_KC`): each output
/// value is the in-order sum of one chain per block.
pub(super) const KC: usize = 256;

/// nalgebra hands a product to `matrixmultiply` only when the dimensions exceed this (its
/// `SMALL_DIM`).
const NALGEBRA_SMALL_DIM: usize = 5;

/// Columns `j` of `P` per pass of the E-step.
const COLS: usize = 4;
/// Feature rows per pass of the E-step: two lanes of four.
const ROWS: usize = 8;
/// Rows `a` of the scatter per tile (broadcast).
const TILE_A: usize = 4;
/// Rows of the last tiles where at most two rows remain after the groups of [`TILE_A`].
const SHORT_TILE_A: usize = 2;
/// Columns `b` of the scatter per tile: two lanes of four.
const TILE_B: usize = 8;
/// Columns of the last tile of a row group where the triangle ends within one lane of four.
const NARROW_TILE_B: usize = 4;
/// Features per pass of the scatter, so that the pass's residuals stay in the first-level cache.
const PASS: usize = 64;

/// Whether the triangular sums repeat nalgebra's products for `n` features of `d` values on this
/// processor.
fn repeats_the_general_product(n: usize, d: usize) -> bool {
    has_avx2_fma() && !is_small_product(n, d) && d <= KC
}

/// Whether nalgebra forms the products of `n` features of `d` values by its own chains (a
/// dimension of at most [`NALGEBRA_SMALL_DIM`]) rather than with `matrixmultiply`.
fn is_small_product(n: usize, d: usize) -> bool {
    n <= NALGEBRA_SMALL_DIM || d <= NALGEBRA_SMALL_DIM
}

/// `q_r = sum_j ((X P)_rj - shift_j)^2` for every row `r` of `x` (`n x d`, column-major), the
/// squared Mahalanobis distance of the E-step with `shift = P^T mu`: the squares added in column
/// order, each `(X P)_rj` the chain over `i <= j` of the general product. `p` is the upper
/// triangular precision factor. `None` where the general product would sum another way.
pub(super) fn whitened_distances(x: &DMatrix<f64>, p: &DMatrix<f64>, shift: &[f64]) -> Option<Vec<f64>> {
    let (n, d) = x.shape();
    if p.nrows() != d {
        return None;
    }
    let distances = WhitenedDistances::new(n, p, shift)?;
    let mut q = vec![0.0; n];
    distances.of_rows(x.as_slice(), n, 0, &mut q);
    Some(q)
}

/// One component's [`whitened_distances`], ready for any rows of the data: the E-step takes a
/// block of rows' distances to every component while the block is in the cache. Each row's
/// distance is the same bits whichever rows it is computed with.
pub(super) struct WhitenedDistances {
    factor: Factor,
    shift: Vec<f64>,
}

/// How [`WhitenedDistances`] repeats the general product's sums.
enum Factor {
    /// nalgebra's own chains ([`is_small_product`]): the factor as it is.
    Small(DMatrix<f64>),
    /// `matrixmultiply`'s FMA chains on the triangle.
    Triangle(PaddedRows),
}

impl WhitenedDistances {
    /// The distances of `n` features to the component of upper triangular precision factor `p`,
    /// `shift = P^T mu`; `None` where the general product would sum another way (or the shapes
    /// disagree).
    pub(super) fn new(n: usize, p: &DMatrix<f64>, shift: &[f64]) -> Option<Self> {
        let d = p.nrows();
        if d == 0 || p.ncols() != d || shift.len() != d {
            return None;
        }
        let factor = if is_small_product(n, d) {
            Factor::Small(p.clone())
        } else if repeats_the_general_product(n, d) {
            Factor::Triangle(PaddedRows::upper(p))
        } else {
            return None;
        };
        Some(Self {
            factor,
            shift: shift.to_vec(),
        })
    }

    /// `q` of rows `first..first + q.len()` of `x` (`n x d`, column-major), into `q`.
    pub(super) fn of_rows(&self, x: &[f64], n: usize, first: usize, q: &mut [f64]) {
        match &self.factor {
            Factor::Small(p) => small_distances(x, n, p, &self.shift, first, q),
            // SAFETY: a triangle is made only where `repeats_the_general_product` found AVX2 and
            // FMA.
            Factor::Triangle(rows) => unsafe { distances_fma(x, n, rows, &self.shift, first, q) },
        }
    }
}

/// The rows of an upper-triangular `d x d` matrix, row-major, each padded with zeros to a whole
/// number of [`COLS`]-wide groups (the E-step reads `P_ij` for `j` in one group at once).
struct PaddedRows {
    d: usize,
    stride: usize,
    values: Vec<f64>,
}

impl PaddedRows {
    fn upper(p: &DMatrix<f64>) -> Self {
        let d = p.nrows();
        let stride = d.next_multiple_of(COLS);
        let mut values = vec![0.0; d * stride];
        for i in 0..d {
            for j in i..d {
                values[i * stride + j] = p[(i, j)];
            }
        }
        Self { d, stride, values }
    }
}

/// The E-step's distances, compiled with AVX2 and FMA where they exist (callers check the
/// processor first; elsewhere nothing calls it).
#[cfg_attr(target_arch = "x86_64", target_feature(enable = "avx2,fma"))]
unsafe fn distances_fma(x: &[f64], n: usize, p: &PaddedRows, shift: &[f64], first: usize, q: &mut [f64]) {
    let whole = q.len() - q.len() % ROWS;
    for (group, out) in q[..whole].chunks_exact_mut(ROWS).enumerate() {
        out.copy_from_slice(&distances_of_rows::<ROWS>(x, n, first + group * ROWS, p, shift));
    }
    for (r, out) in q.iter_mut().enumerate().skip(whole) {
        *out = distances_of_rows::<1>(x, n, first + r, p, shift)[0];
    }
}

/// [`whitened_distances`] of the `R` rows from `first`: per group of [`COLS`] columns `j`, the
/// chains over `i` up to the group's last column (beyond a column's own `j` the factor is a
/// structural zero, which leaves a chain unchanged), then the squares added in column order.
#[inline(always)]
fn distances_of_rows<const R: usize>(
    x: &[f64],
    n: usize,
    first: usize,
    p: &PaddedRows,
    shift: &[f64],
) -> [f64; R] {
    let mut sum = [0.0; R];
    for j0 in (0..p.d).step_by(COLS) {
        let end = (j0 + COLS).min(p.d);
        let mut chain = [[0.0; R]; COLS];
        for i in 0..end {
            let xi = &x[i * n + first..][..R];
            let pi = &p.values[i * p.stride + j0..][..COLS];
            for (chain, &pij) in chain.iter_mut().zip(pi) {
                for (c, &v) in chain.iter_mut().zip(xi) {
                    *c = v.mul_add(pij, *c);
                }
            }
        }
        for (chain, &s) in chain.iter().zip(&shift[j0..end]) {
            for (sum, &c) in sum.iter_mut().zip(chain) {
                let t = c - s;
                *sum += t * t;
            }
        }
    }
    sum
}

/// The lower triangle of the M-step's weighted scatter `S = sum_r resp_r (x_r - mean)(x_r -
/// mean)^T`, row-major `d x d` (`S_ab` for `a >= b`; the entries above the diagonal are not
/// written), from `x_rows` (`n x d`, row-major): `S_ab` is the general product's
/// `sum_r ((x_ra - mean_a) resp_r) (x_rb - mean_b)`, chained over the features in blocks of [`KC`].
/// `None` where the general product would sum another way.
pub(super) fn weighted_scatter(x_rows: &[f64], mean: &[f64], resp: &[f64]) -> Option<Vec<f64>> {
    let (n, d) = (resp.len(), mean.len());
    if n == 0 || d == 0 || x_rows.len() != n * d {
        return None;
    }
    if is_small_product(n, d) {
        return Some(small_scatter(x_rows, mean, resp));
    }
    if !repeats_the_general_product(n, d) {
        return None;
    }
    let mut lower = vec![0.0; d * d];
    // SAFETY: `repeats_the_general_product` checked that the processor has AVX2 and FMA.
    unsafe { scatter_fma(x_rows, mean, resp, &mut lower) };
    Some(lower)
}

/// [`whitened_distances`] for a small product: `(X P)_rj` as nalgebra's chain over `i` (every
/// term, the structural zeros too), then the squares added in column order.
fn small_distances(x: &[f64], n: usize, p: &DMatrix<f64>, shift: &[f64], first: usize, q: &mut [f64]) {
    let d = p.nrows();
    for (r, q) in (first..).zip(q.iter_mut()) {
        let mut sum = 0.0;
        for (column, &s) in p.as_slice().chunks_exact(d).zip(shift) {
            let mut y = x[r] * column[0];
            for (i, &pij) in column.iter().enumerate().skip(1) {
                y += x[i * n + r] * pij;
            }
            let t = y - s;
            sum += t * t;
        }
        *q = sum;
    }
}

/// [`weighted_scatter`] for a small product: `S_ab` as nalgebra's chain over the features of
/// `((x_ra - mean_a) resp_r) (x_rb - mean_b)`, from the features of non-zero responsibility; an
/// entry that ends at zero is chained again over every feature, for the sign of its zero.
fn small_scatter(x_rows: &[f64], mean: &[f64], resp: &[f64]) -> Vec<f64> {
    let d = mean.len();
    let mut lower = vec![0.0; d * d];
    let mut residual = vec![0.0; d];
    let mut weighted = vec![0.0; d];
    let mut started = false;
    for (x, &weight) in x_rows.chunks_exact(d).zip(resp) {
        if weight == 0.0 {
            continue;
        }
        residual_into(x, mean, weight, &mut residual, &mut weighted);
        for (a, row) in lower.chunks_exact_mut(d).enumerate() {
            for (s, &rb) in row[..=a].iter_mut().zip(&residual) {
                let term = weighted[a] * rb;
                *s = if started { term + *s } else { term };
            }
        }
        started = true;
    }
    for a in 0..d {
        for b in 0..=a {
            if lower[a * d + b] == 0.0 {
                lower[a * d + b] = small_scatter_entry(x_rows, mean, resp, a, b);
            }
        }
    }
    lower
}

/// A feature's residual `x - mean` and its weighted residual `(x - mean) weight`, the two factors of
/// its term in the scatter.
#[inline(always)]
fn residual_into(x: &[f64], mean: &[f64], weight: f64, residual: &mut [f64], weighted: &mut [f64]) {
    for (((res, w), &v), &m) in residual.iter_mut().zip(weighted).zip(x).zip(mean) {
        *res = v - m;
        *w = *res * weight;
    }
}

/// One entry of [`small_scatter`] chained over every feature, as nalgebra chains it.
fn small_scatter_entry(x_rows: &[f64], mean: &[f64], resp: &[f64], a: usize, b: usize) -> f64 {
    let d = mean.len();
    let term = |(x, &weight): (&[f64], &f64)| ((x[a] - mean[a]) * weight) * (x[b] - mean[b]);
    let mut features = x_rows.chunks_exact(d).zip(resp);
    let first = features.next().map_or(0.0, term);
    features.fold(first, |s, feature| term(feature) + s)
}

/// `sum_r resp_r x_r` for every column of `x` (`n x d`, column-major): nalgebra's `x^T resp`
/// ([`Matrix::tr_mul`](nalgebra::Matrix::tr_mul)) to the bit, skipping the groups of eight
/// features (one term of each chain) whose responsibilities are all zero; and `sum_r resp_r`
/// added in feature order from +0 (nalgebra's `sum`), which skips the same groups: a zero added
/// to a sum from +0 changes no bit. With hundreds of components most groups are zero.
pub(super) fn weighted_column_sums(x: &DMatrix<f64>, resp: &[f64]) -> (Vec<f64>, f64) {
    /// nalgebra's dot product keeps this many chains.
    const CHAINS: usize = 8;
    let (n, d) = x.shape();
    if n == 0 {
        return (vec![0.0; d], 0.0);
    }
    let chained = n - n % CHAINS;
    let groups: Vec<usize> = (0..chained)
        .step_by(CHAINS)
        .filter(|&g| resp[g..g + CHAINS].iter().any(|&r| r != 0.0))
        .collect();
    let total = groups
        .iter()
        .flat_map(|&g| &resp[g..g + CHAINS])
        .chain(&resp[chained..])
        .fold(0.0, |sum, &r| sum + r);
    let sums = x
        .as_slice()
        .chunks_exact(n)
        .map(|column| {
            let mut chain = [0.0; CHAINS];
            for &g in &groups {
                let terms = column[g..g + CHAINS].iter().zip(&resp[g..g + CHAINS]);
                for (c, (v, r)) in chain.iter_mut().zip(terms) {
                    *c += v * r;
                }
            }
            let mut sum = 0.0;
            for (low, high) in chain[..CHAINS / 2].iter().zip(&chain[CHAINS / 2..]) {
                sum += low + high;
            }
            for (v, r) in column[chained..].iter().zip(&resp[chained..]) {
                sum += v * r;
            }
            sum
        })
        .collect();
    (sums, total)
}

/// The M-step's scatter, compiled with AVX2 and FMA where they exist (callers check the
/// processor first; elsewhere nothing calls it).
#[cfg_attr(target_arch = "x86_64", target_feature(enable = "avx2,fma"))]
unsafe fn scatter_fma(x_rows: &[f64], mean: &[f64], resp: &[f64], lower: &mut [f64]) {
    Scatter::new(mean.len()).sum(x_rows, mean, resp, lower);
}

/// The shape of one tile of the scatter: rows `a` x columns `b`.
#[derive(Debug, Clone, Copy, PartialEq)]
enum TileShape {
    /// [`TILE_A`] x [`TILE_B`].
    Full,
    /// [`TILE_A`] x [`NARROW_TILE_B`]: the triangle's last columns of a row group.
    Narrow,
    /// [`SHORT_TILE_A`] x [`TILE_B`]: the last rows of a `d` that leaves two (or one) after the
    /// groups of four.
    Short,
    /// [`SHORT_TILE_A`] x [`NARROW_TILE_B`].
    ShortNarrow,
}

impl TileShape {
    /// Rows and columns.
    #[cfg(test)]
    fn size(self) -> (usize, usize) {
        match self {
            Self::Full => (TILE_A, TILE_B),
            Self::Narrow => (TILE_A, NARROW_TILE_B),
            Self::Short => (SHORT_TILE_A, TILE_B),
            Self::ShortNarrow => (SHORT_TILE_A, NARROW_TILE_B),
        }
    }
}

/// One tile of the scatter: its first row `a0`, first column `b0` and shape.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Tile {
    a0: usize,
    b0: usize,
    shape: TileShape,
}

/// The tiles that cover the lower triangle of a `d x d` scatter: per group of rows, tiles of eight
/// columns up to the group's last row, the last of them four wide where four columns suffice; the
/// last group two rows tall where at most two rows remain. Each entry's chain is the same whatever
/// tile computes it, so the tiling only decides how little of the padding is summed (at `d = 10`,
/// 18 vectors of four per feature instead of 32 in tiles of 4 x 8).
fn lower_tiles(d: usize) -> Vec<Tile> {
    let mut tiles = Vec::new();
    for a0 in (0..d).step_by(TILE_A) {
        let short = d - a0 <= SHORT_TILE_A;
        let columns = d.min(a0 + TILE_A);
        for b0 in (0..columns).step_by(TILE_B) {
            let narrow = columns - b0 <= NARROW_TILE_B;
            let shape = match (short, narrow) {
                (false, false) => TileShape::Full,
                (false, true) => TileShape::Narrow,
                (true, false) => TileShape::Short,
                (true, true) => TileShape::ShortNarrow,
            };
            tiles.push(Tile { a0, b0, shape });
        }
    }
    tiles
}

/// The scatter's working set: one pass of residuals `D` and weighted residuals `W` (row-major,
/// padded with zeros to whole tiles), the current [`KC`] block's chains and the blocks' total, and
/// the tiles that cover the lower triangle ([`lower_tiles`]).
struct Scatter {
    d: usize,
    stride: usize,
    residuals: Vec<f64>,
    weighted: Vec<f64>,
    block: Vec<f64>,
    total: Vec<f64>,
    tiles: Vec<Tile>,
}

impl Scatter {
    fn new(d: usize) -> Self {
        let stride = d.next_multiple_of(TILE_B);
        let tiles = lower_tiles(d);
        let square = d.next_multiple_of(TILE_A) * stride;
        Self {
            d,
            stride,
            residuals: vec![0.0; PASS * stride],
            weighted: vec![0.0; PASS * stride],
            block: vec![0.0; square],
            total: vec![0.0; square],
            tiles,
        }
    }

    #[inline(always)]
    fn sum(mut self, x_rows: &[f64], mean: &[f64], resp: &[f64], lower: &mut [f64]) {
        let n = resp.len();
        for k0 in (0..n).step_by(KC) {
            let k_end = (k0 + KC).min(n);
            // A feature of zero responsibility adds an exact zero to every chain, which leaves it
            // unchanged (a chain never holds -0): such features are skipped. With hundreds of
            // components most of a component's responsibilities underflow to zero.
            let mut count = 0;
            for r in (k0..k_end).filter(|&r| resp[r] != 0.0) {
                self.residual_of(x_rows, mean, resp[r], r, count);
                count += 1;
                if count == PASS {
                    self.chain(count);
                    count = 0;
                }
            }
            if count > 0 {
                self.chain(count);
            }
            // `matrixmultiply` adds each block's chain to the value so far (`c = ab + c`).
            for (t, b) in self.total.iter_mut().zip(&mut self.block) {
                *t += *b;
                *b = 0.0;
            }
        }
        for (a, row) in lower.chunks_exact_mut(self.d).enumerate() {
            row[..=a].copy_from_slice(&self.total[a * self.stride..][..=a]);
        }
    }

    /// Fills row `t` of the pass's `D` and `W` with feature `r`, of responsibility `weight`.
    #[inline(always)]
    fn residual_of(&mut self, x_rows: &[f64], mean: &[f64], weight: f64, r: usize, t: usize) {
        let (d, stride) = (self.d, self.stride);
        let x = &x_rows[r * d..][..d];
        let residual = &mut self.residuals[t * stride..][..d];
        let weighted = &mut self.weighted[t * stride..][..d];
        residual_into(x, mean, weight, residual, weighted);
    }

    /// Continues every tile's chains over the pass's `count` features.
    #[inline(always)]
    fn chain(&mut self, count: usize) {
        for i in 0..self.tiles.len() {
            let Tile { a0, b0, shape } = self.tiles[i];
            match shape {
                TileShape::Full => self.chain_tile::<TILE_A, TILE_B>(a0, b0, count),
                TileShape::Narrow => self.chain_tile::<TILE_A, NARROW_TILE_B>(a0, b0, count),
                TileShape::Short => self.chain_tile::<SHORT_TILE_A, TILE_B>(a0, b0, count),
                TileShape::ShortNarrow => self.chain_tile::<SHORT_TILE_A, NARROW_TILE_B>(a0, b0, count),
            }
        }
    }

    /// Continues the chains of the `A x B` tile at `(a0, b0)` over the pass's `count` features.
    #[inline(always)]
    fn chain_tile<const A: usize, const B: usize>(&mut self, a0: usize, b0: usize, count: usize) {
        let stride = self.stride;
        let mut chain = [[0.0; B]; A];
        for (a, c) in chain.iter_mut().enumerate() {
            c.copy_from_slice(&self.block[(a0 + a) * stride + b0..][..B]);
        }
        for t in 0..count {
            let w = &self.weighted[t * stride + a0..][..A];
            let res = &self.residuals[t * stride + b0..][..B];
            for (c, &wa) in chain.iter_mut().zip(w) {
                for (c, &rb) in c.iter_mut().zip(res) {
                    *c = wa.mul_add(rb, *c);
                }
            }
        }
        for (a, c) in chain.iter().enumerate() {
            self.block[(a0 + a) * stride + b0..][..B].copy_from_slice(c);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_tiles_cover_the_lower_triangle_once_within_the_padding() {
        for d in 1usize..=40 {
            let stride = d.next_multiple_of(TILE_B);
            let rows = d.next_multiple_of(TILE_A);
            let mut covered = vec![0; rows * stride];
            for Tile { a0, b0, shape } in lower_tiles(d) {
                let (height, width) = shape.size();
                assert!(
                    a0 + height <= rows && b0 + width <= stride,
                    "d {d}: tile at ({a0}, {b0}) leaves the padding"
                );
                for a in a0..a0 + height {
                    for b in b0..b0 + width {
                        covered[a * stride + b] += 1;
                    }
                }
            }
            for a in 0..d {
                for b in 0..=a {
                    assert_eq!(covered[a * stride + b], 1, "d {d}: entry ({a}, {b})");
                }
            }
        }
        // The padding summed at d = 10 (the letters' MNTI and Moment-Normalized features): 18
        // vectors of four per feature.
        let lanes: usize = lower_tiles(10)
            .iter()
            .map(|t| {
                let (height, width) = t.shape.size();
                height * width
            })
            .sum();
        assert_eq!(lanes / 4, 18);
    }

    #[test]
    fn sizes_the_general_product_sums_another_way_are_left_to_it() {
        // Beyond one block of the summed index `matrixmultiply` adds its chains another way.
        let d = KC + 1;
        let x = DMatrix::from_element(6, d, 1.0);
        assert!(whitened_distances(&x, &DMatrix::identity(d, d), &vec![0.0; d]).is_none());
        assert!(weighted_scatter(&vec![1.0; 6 * d], &vec![0.0; d], &[1.0; 6]).is_none());
        // nalgebra's own chains (a dimension of at most 5) are repeated on every machine.
        let x = DMatrix::from_element(100, 5, 1.0);
        assert!(whitened_distances(&x, &DMatrix::identity(5, 5), &[0.0; 5]).is_some());
        assert!(weighted_scatter(&[1.0; 500], &[0.0; 5], &[1.0; 100]).is_some());
    }
}
