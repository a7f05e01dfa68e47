//! `e^x` with the bits of `f64::exp`, at less cost per call: the Gaussian mixture's E-step takes
//! two exponentials per feature and component, the posterior's tempering one per object, trial
//! prefix and candidate (`calibration`), hundreds of millions per codebook fit.
//!
//! Three shortcuts, none of which changes a bit:
//! - Below [`EXP_UNDERFLOW`] `e^x` is exactly 0, answered without a call (the exponential's
//!   underflow path is its slowest; with many components most responsibilities underflow).
//! - On glibc, `exp` is a wrapper: it calls the implementation through the dynamic linker's table
//!   and afterwards sets `errno` on overflow and underflow, as POSIX asks, returning the
//!   implementation's value unchanged. That wrapper was a quarter of the time spent in
//!   exponentials (perf, the 52 letters' Polar-Fourier codebooks). glibc exports the
//!   implementation itself as `__exp_finite` (symbol version `GLIBC_2.15`, kept for binaries
//!   built against older headers); it is looked up once and called directly. Nothing here reads
//!   `errno`. Where it is missing (another C library) `f64::exp` is called.
//! - Rows of exponentials (the E-step's log-sum-exps and responsibilities, a posterior's
//!   log-sum-exp, the tempering's four prefixes side by side: [`add_exp_of_differences`],
//!   [`exp_of_differences_in_place`], [`sum_exp_of_differences`], [`Lanes`]) go four at a time
//!   where the processor has AVX2 and FMA (`four_lanes`): glibc's algorithm (since 2.28, the one
//!   of Arm's optimized-routines: `e^x = 2^(k/128) e^r` with `|r| <= ln 2 / 256`, a table of
//!   `2^(i/128)` and a polynomial of degree five, a rescaled path for subnormal results), in the
//!   operations glibc's FMA build does, lane by lane: which products it fuses decides the last
//!   bit. Four lanes that all underflow give zeros without the rest. Whether the lanes give the C
//!   library's bits is checked once per process on probes across the whole range (every table
//!   entry, both paths, the bounds between them); where they do not (another C library or
//!   version), every value is one call.

/// Below this `f64::exp` returns exactly 0: the smallest subnormal is `e^-744.4`, and anything
/// under half of it (`e^-745.1`) rounds to zero.
pub(crate) const EXP_UNDERFLOW: f64 = -746.0;

/// `e^x`, the same bits as `x.exp()` for every `x`.
#[inline]
pub(crate) fn exp(x: f64) -> f64 {
    if x < EXP_UNDERFLOW {
        0.0
    } else {
        (implementation())(x)
    }
}

type Exp = extern "C" fn(f64) -> f64;

extern "C" fn platform_exp(x: f64) -> f64 {
    x.exp()
}

/// The C library's exponential without its `errno` wrapper where it has one, else `f64::exp`.
fn implementation() -> Exp {
    static IMPLEMENTATION: std::sync::OnceLock<Exp> = std::sync::OnceLock::new();
    *IMPLEMENTATION.get_or_init(|| unwrapped().unwrap_or(platform_exp))
}

#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn unwrapped() -> Option<Exp> {
    // SAFETY: both names are NUL-terminated; `dlvsym` only reads them. A non-null result is the
    // address of glibc's `double __exp_finite(double)`, whose C ABI `Exp` declares.
    unsafe {
        let symbol = libc::dlvsym(
            libc::RTLD_DEFAULT,
            c"__exp_finite".as_ptr(),
            c"GLIBC_2.15".as_ptr(),
        );
        (!symbol.is_null()).then(|| std::mem::transmute::<*mut libc::c_void, Exp>(symbol))
    }
}

#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
fn unwrapped() -> Option<Exp> {
    None
}

/// What each row's exponent is taken from: `values[r] - shift`.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Shift<'a> {
    /// One shift per row (the log-sum-exp of each feature's row of components).
    Rows(&'a [f64]),
    /// One shift for every row.
    All(f64),
}

impl Shift<'_> {
    fn of(self, r: usize) -> f64 {
        match self {
            Shift::Rows(shift) => shift[r],
            Shift::All(shift) => shift,
        }
    }

    /// How many rows it has a shift for (every row for [`Shift::All`]).
    fn rows(self) -> usize {
        match self {
            Shift::Rows(shift) => shift.len(),
            Shift::All(_) => usize::MAX,
        }
    }
}

/// `sum[r] += e^(values[r] - shift_r)` for every row `r`, each exponential [`exp`]'s bits: the
/// sums of a log-sum-exp, one column of terms at a time.
pub(crate) fn add_exp_of_differences(sum: &mut [f64], values: &[f64], shift: Shift) {
    let n = sum.len().min(values.len()).min(shift.rows());
    let mut first = 0;
    #[cfg(target_arch = "x86_64")]
    if four_lanes::agree() {
        // SAFETY: `agree` is true only where the processor has AVX2 and FMA.
        first = unsafe { four_lanes::add_exp_of_differences(&mut sum[..n], &values[..n], shift) };
    }
    for (r, (s, &v)) in sum[..n].iter_mut().zip(&values[..n]).enumerate().skip(first) {
        *s += exp(v - shift.of(r));
    }
}

/// `values[r] = e^(values[r] - shift_r)` for every row `r`, each exponential [`exp`]'s bits: the
/// responsibilities from their logarithms and their normalisers.
pub(crate) fn exp_of_differences_in_place(values: &mut [f64], shift: Shift) {
    let n = values.len().min(shift.rows());
    let mut first = 0;
    #[cfg(target_arch = "x86_64")]
    if four_lanes::agree() {
        // SAFETY: `agree` is true only where the processor has AVX2 and FMA.
        first = unsafe { four_lanes::exp_of_differences_in_place(&mut values[..n], shift) };
    }
    for (r, v) in values[..n].iter_mut().enumerate().skip(first) {
        *v = exp(*v - shift.of(r));
    }
}

/// `sum_r e^(values[r] - shift)`, each exponential [`exp`]'s bits, added in row order from -0 as
/// `f64`'s `Sum` adds them.
pub(crate) fn sum_exp_of_differences(values: &[f64], shift: f64) -> f64 {
    let mut sum = -0.0;
    let mut r = 0;
    #[cfg(target_arch = "x86_64")]
    if four_lanes::agree() {
        // SAFETY: `agree` is true only where the processor has AVX2 and FMA.
        (sum, r) = unsafe { four_lanes::sum_exp_of_differences(values, shift) };
    }
    values[r..].iter().fold(sum, |sum, &v| sum + exp(v - shift))
}

/// Rows of four values side by side, none of them NaN: the operand of four log-sum-exps at once
/// ([`Lanes::scaled_max_and_exp_sum`]). Without NaN, `maxpd` and `f64::max` take the same maximum
/// (for equal values they may differ in a zero's sign, which neither `v - max` nor `max + ln sum`
/// shows).
#[derive(Debug, Clone, Default)]
pub(crate) struct Lanes(Vec<[f64; 4]>);

impl Lanes {
    /// `None` if a value is NaN.
    pub(crate) fn new(rows: Vec<[f64; 4]>) -> Option<Self> {
        (!rows.iter().flatten().any(|v| v.is_nan())).then_some(Self(rows))
    }

    #[cfg(test)]
    pub(crate) fn len(&self) -> usize {
        self.0.len()
    }

    /// Four log-sum-exps side by side, each of `weight[l] * v[j][l]` over the rows `v[j]` of
    /// `rows`: per lane `(max, sum)`, the largest weighted value and `sum_j e^(weight v_j - max)`
    /// added in row order from -0, the bits [`crate::recognize::gmm::log_sum_exp`] forms them with
    /// (its result is `max + ln sum` where `max` is finite). `None` where the lanes would not give
    /// those bits (no AVX2 and FMA, another C library) or `rows` is out of range: the caller then
    /// takes them one at a time.
    pub(crate) fn scaled_max_and_exp_sum(
        &self,
        rows: std::ops::Range<usize>,
        weight: [f64; 4],
    ) -> Option<([f64; 4], [f64; 4])> {
        let values = self.0.get(rows)?;
        #[cfg(target_arch = "x86_64")]
        if four_lanes::agree() {
            // SAFETY: `agree` is true only where the processor has AVX2 and FMA.
            return Some(unsafe { four_lanes::scaled_max_and_exp_sum4(values, weight) });
        }
        let _ = (values, weight);
        None
    }
}

/// glibc's exponential four lanes wide (`sysdeps/ieee754/dbl-64/e_exp.c`, as its FMA build
/// compiles it: which products are fused decides the last bit).
#[cfg(target_arch = "x86_64")]
mod four_lanes {
    use std::arch::x86_64::{
        __m256d, __m256i, _CMP_LT_OQ, _mm256_add_epi64, _mm256_add_pd, _mm256_and_si256, _mm256_andnot_si256,
        _mm256_blendv_pd, _mm256_castpd_si256, _mm256_castsi256_pd, _mm256_cmp_pd, _mm256_cmpeq_epi64,
        _mm256_cmpgt_epi64, _mm256_fmadd_pd, _mm256_i64gather_epi64, _mm256_i64gather_pd, _mm256_loadu_pd,
        _mm256_max_pd, _mm256_movemask_pd, _mm256_mul_pd, _mm256_or_si256, _mm256_set1_epi64x,
        _mm256_set1_pd, _mm256_slli_epi64, _mm256_srli_epi64, _mm256_storeu_pd, _mm256_sub_pd,
    };

    use super::{EXP_UNDERFLOW, Shift, exp};

    /// `N / ln 2` with `N = 128` table entries per octave.
    const INV_LN2_N: f64 = f64::from_bits(0x40671547652b82fe);
    /// `-ln 2 / N` in two parts: the high one has trailing zeros, so `k * hi` is exact.
    const NEG_LN2_HI_N: f64 = f64::from_bits(0xbf762e42fefa0000);
    const NEG_LN2_LO_N: f64 = f64::from_bits(0xbd0cf79abc9e3b3a);
    /// `1.5 * 2^52`: added and subtracted, it rounds `x N / ln 2` to the integer `k`, whose low
    /// bits are then the sum's.
    const SHIFT: f64 = f64::from_bits(0x4338000000000000);
    /// The polynomial's coefficients of `r^2` to `r^5` (those of 1 and `r` are 1).
    const C2: f64 = f64::from_bits(0x3fdffffffffffdbd);
    const C3: f64 = f64::from_bits(0x3fc555555555543c);
    const C4: f64 = f64::from_bits(0x3fa55555cf172b91);
    const C5: f64 = f64::from_bits(0x3f81111167a4d017);
    /// `2^-1022`, the scale of the subnormal path.
    const TWO_POW_M1022: f64 = f64::from_bits(0x0010000000000000);
    /// The biased exponents bounding the main path: `2^-54 <= |x| < 512`.
    const MAIN_FIRST_EXPONENT: i64 = 0x3c9;
    const MAIN_END_EXPONENT: i64 = 0x408;

    /// Per entry `i`: the rounding error of `2^(i/N)` relative to it, then the bits of `2^(i/N)`
    /// rounded, less `i << 45` (where `k`'s shifted bits are added back). Both words follow from
    /// `2^(i/128)` computed to 80 digits; they equal glibc's `__exp_data.tab`.
    static TABLE: [u64; 256] = [
        0x0000000000000000,
        0x3ff0000000000000,
        0x3c9b3b4f1a88bf6e,
        0x3feff63da9fb3335,
        0xbc7160139cd8dc5d,
        0x3fefec9a3e778061,
        0xbc905e7a108766d1,
        0x3fefe315e86e7f85,
        0x3c8cd2523567f613,
        0x3fefd9b0d3158574,
        0xbc8bce8023f98efa,
        0x3fefd06b29ddf6de,
        0x3c60f74e61e6c861,
        0x3fefc74518759bc8,
        0x3c90a3e45b33d399,
        0x3fefbe3ecac6f383,
        0x3c979aa65d837b6d,
        0x3fefb5586cf9890f,
        0x3c8eb51a92fdeffc,
        0x3fefac922b7247f7,
        0x3c3ebe3d702f9cd1,
        0x3fefa3ec32d3d1a2,
        0xbc6a033489906e0b,
        0x3fef9b66affed31b,
        0xbc9556522a2fbd0e,
        0x3fef9301d0125b51,
        0xbc5080ef8c4eea55,
        0x3fef8abdc06c31cc,
        0xbc91c923b9d5f416,
        0x3fef829aaea92de0,
        0x3c80d3e3e95c55af,
        0x3fef7a98c8a58e51,
        0xbc801b15eaa59348,
        0x3fef72b83c7d517b,
        0xbc8f1ff055de323d,
        0x3fef6af9388c8dea,
        0x3c8b898c3f1353bf,
        0x3fef635beb6fcb75,
        0xbc96d99c7611eb26,
        0x3fef5be084045cd4,
        0x3c9aecf73e3a2f60,
        0x3fef54873168b9aa,
        0xbc8fe782cb86389d,
        0x3fef4d5022fcd91d,
        0x3c8a6f4144a6c38d,
        0x3fef463b88628cd6,
        0x3c807a05b0e4047d,
        0x3fef3f49917ddc96,
        0x3c968efde3a8a894,
        0x3fef387a6e756238,
        0x3c875e18f274487d,
        0x3fef31ce4fb2a63f,
        0x3c80472b981fe7f2,
        0x3fef2b4565e27cdd,
        0xbc96b87b3f71085e,
        0x3fef24dfe1f56381,
        0x3c82f7e16d09ab31,
        0x3fef1e9df51fdee1,
        0xbc3d219b1a6fbffa,
        0x3fef187fd0dad990,
        0x3c8b3782720c0ab4,
        0x3fef1285a6e4030b,
        0x3c6e149289cecb8f,
        0x3fef0cafa93e2f56,
        0x3c834d754db0abb6,
        0x3fef06fe0a31b715,
        0x3c864201e2ac744c,
        0x3fef0170fc4cd831,
        0x3c8fdd395dd3f84a,
        0x3feefc08b26416ff,
        0xbc86a3803b8e5b04,
        0x3feef6c55f929ff1,
        0xbc924aedcc4b5068,
        0x3feef1a7373aa9cb,
        0xbc9907f81b512d8e,
        0x3feeecae6d05d866,
        0xbc71d1e83e9436d2,
        0x3feee7db34e59ff7,
        0xbc991919b3ce1b15,
        0x3feee32dc313a8e5,
        0x3c859f48a72a4c6d,
        0x3feedea64c123422,
        0xbc9312607a28698a,
        0x3feeda4504ac801c,
        0xbc58a78f4817895b,
        0x3feed60a21f72e2a,
        0xbc7c2c9b67499a1b,
        0x3feed1f5d950a897,
        0x3c4363ed60c2ac11,
        0x3feece086061892d,
        0x3c9666093b0664ef,
        0x3feeca41ed1d0057,
        0x3c6ecce1daa10379,
        0x3feec6a2b5c13cd0,
        0x3c93ff8e3f0f1230,
        0x3feec32af0d7d3de,
        0x3c7690cebb7aafb0,
        0x3feebfdad5362a27,
        0x3c931dbdeb54e077,
        0x3feebcb299fddd0d,
        0xbc8f94340071a38e,
        0x3feeb9b2769d2ca7,
        0xbc87deccdc93a349,
        0x3feeb6daa2cf6642,
        0xbc78dec6bd0f385f,
        0x3feeb42b569d4f82,
        0xbc861246ec7b5cf6,
        0x3feeb1a4ca5d920f,
        0x3c93350518fdd78e,
        0x3feeaf4736b527da,
        0x3c7b98b72f8a9b05,
        0x3feead12d497c7fd,
        0x3c9063e1e21c5409,
        0x3feeab07dd485429,
        0x3c34c7855019c6ea,
        0x3feea9268a5946b7,
        0x3c9432e62b64c035,
        0x3feea76f15ad2148,
        0xbc8ce44a6199769f,
        0x3feea5e1b976dc09,
        0xbc8c33c53bef4da8,
        0x3feea47eb03a5585,
        0xbc845378892be9ae,
        0x3feea34634ccc320,
        0xbc93cedd78565858,
        0x3feea23882552225,
        0x3c5710aa807e1964,
        0x3feea155d44ca973,
        0xbc93b3efbf5e2228,
        0x3feea09e667f3bcd,
        0xbc6a12ad8734b982,
        0x3feea012750bdabf,
        0xbc6367efb86da9ee,
        0x3fee9fb23c651a2f,
        0xbc80dc3d54e08851,
        0x3fee9f7df9519484,
        0xbc781f647e5a3ecf,
        0x3fee9f75e8ec5f74,
        0xbc86ee4ac08b7db0,
        0x3fee9f9a48a58174,
        0xbc8619321e55e68a,
        0x3fee9feb564267c9,
        0x3c909ccb5e09d4d3,
        0x3feea0694fde5d3f,
        0xbc7b32dcb94da51d,
        0x3feea11473eb0187,
        0x3c94ecfd5467c06b,
        0x3feea1ed0130c132,
        0x3c65ebe1abd66c55,
        0x3feea2f336cf4e62,
        0xbc88a1c52fb3cf42,
        0x3feea427543e1a12,
        0xbc9369b6f13b3734,
        0x3feea589994cce13,
        0xbc805e843a19ff1e,
        0x3feea71a4623c7ad,
        0xbc94d450d872576e,
        0x3feea8d99b4492ed,
        0x3c90ad675b0e8a00,
        0x3feeaac7d98a6699,
        0x3c8db72fc1f0eab4,
        0x3feeace5422aa0db,
        0xbc65b6609cc5e7ff,
        0x3feeaf3216b5448c,
        0x3c7bf68359f35f44,
        0x3feeb1ae99157736,
        0xbc93091fa71e3d83,
        0x3feeb45b0b91ffc6,
        0xbc5da9b88b6c1e29,
        0x3feeb737b0cdc5e5,
        0xbc6c23f97c90b959,
        0x3feeba44cbc8520f,
        0xbc92434322f4f9aa,
        0x3feebd829fde4e50,
        0xbc85ca6cd7668e4b,
        0x3feec0f170ca07ba,
        0x3c71affc2b91ce27,
        0x3feec49182a3f090,
        0x3c6dd235e10a73bb,
        0x3feec86319e32323,
        0xbc87c50422622263,
        0x3feecc667b5de565,
        0x3c8b1c86e3e231d5,
        0x3feed09bec4a2d33,
        0xbc91bbd1d3bcbb15,
        0x3feed503b23e255d,
        0x3c90cc319cee31d2,
        0x3feed99e1330b358,
        0x3c8469846e735ab3,
        0x3feede6b5579fdbf,
        0xbc82dfcd978e9db4,
        0x3feee36bbfd3f37a,
        0x3c8c1a7792cb3387,
        0x3feee89f995ad3ad,
        0xbc907b8f4ad1d9fa,
        0x3feeee07298db666,
        0xbc55c3d956dcaeba,
        0x3feef3a2b84f15fb,
        0xbc90a40e3da6f640,
        0x3feef9728de5593a,
        0xbc68d6f438ad9334,
        0x3feeff76f2fb5e47,
        0xbc91eee26b588a35,
        0x3fef05b030a1064a,
        0x3c74ffd70a5fddcd,
        0x3fef0c1e904bc1d2,
        0xbc91bdfbfa9298ac,
        0x3fef12c25bd71e09,
        0x3c736eae30af0cb3,
        0x3fef199bdd85529c,
        0x3c8ee3325c9ffd94,
        0x3fef20ab5fffd07a,
        0x3c84e08fd10959ac,
        0x3fef27f12e57d14b,
        0x3c63cdaf384e1a67,
        0x3fef2f6d9406e7b5,
        0x3c676b2c6c921968,
        0x3fef3720dcef9069,
        0xbc808a1883ccb5d2,
        0x3fef3f0b555dc3fa,
        0xbc8fad5d3ffffa6f,
        0x3fef472d4a07897c,
        0xbc900dae3875a949,
        0x3fef4f87080d89f2,
        0x3c74a385a63d07a7,
        0x3fef5818dcfba487,
        0xbc82919e2040220f,
        0x3fef60e316c98398,
        0x3c8e5a50d5c192ac,
        0x3fef69e603db3285,
        0x3c843a59ac016b4b,
        0x3fef7321f301b460,
        0xbc82d52107b43e1f,
        0x3fef7c97337b9b5f,
        0xbc892ab93b470dc9,
        0x3fef864614f5a129,
        0x3c74b604603a88d3,
        0x3fef902ee78b3ff6,
        0x3c83c5ec519d7271,
        0x3fef9a51fbc74c83,
        0xbc8ff7128fd391f0,
        0x3fefa4afa2a490da,
        0xbc8dae98e223747d,
        0x3fefaf482d8e67f1,
        0x3c8ec3bc41aa2008,
        0x3fefba1bee615a27,
        0x3c842b94c3a9eb32,
        0x3fefc52b376bba97,
        0x3c8a64a931d185ee,
        0x3fefd0765b6e4540,
        0xbc8e37bae43be3ed,
        0x3fefdbfdad9cbe14,
        0x3c77893b4d91cd9d,
        0x3fefe7c1819e90d8,
        0x3c5305c14160cc89,
        0x3feff3c22b8f71f1,
    ];

    /// Whether the four lanes give the C library's bits: AVX2 and FMA present, and every probe the
    /// same as one call. Checked once.
    pub(super) fn agree() -> bool {
        static AGREE: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
        *AGREE.get_or_init(|| {
            // SAFETY: `exp4` runs only after the processor has shown AVX2 and FMA.
            crate::simd::has_avx2_fma()
                && probes().chunks_exact(4).all(|x| {
                    let lanes = unsafe { exp4_of(x) };
                    lanes.iter().zip(x).all(|(e, &x)| e.to_bits() == exp(x).to_bits())
                })
        })
    }

    /// Arguments exercising every path and table entry: a ramp over every table index across the
    /// E-step's range, the bounds between the paths and the values beyond them.
    pub(super) fn probes() -> Vec<f64> {
        let ramp = (0..4096).map(|i| -760.0 + f64::from(i) * (775.0 / 4096.0));
        let entries = (0..128).map(|i| f64::from(i) * std::f64::consts::LN_2 / 128.0 - 3.0);
        let bounds = [
            -1024.0,
            -512.0,
            512.0,
            709.7,
            -745.1,
            -745.2,
            -708.4,
            -708.3,
            1e-17,
            -1e-17,
            6e-17,
            -6e-17,
            0.0,
            -0.0,
            1.0,
            -1.0,
            EXP_UNDERFLOW,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        let mut probes: Vec<f64> = ramp.chain(entries).chain(bounds).collect();
        probes.resize(probes.len().next_multiple_of(4), 0.5);
        probes
    }

    /// [`exp4`] of four values.
    #[target_feature(enable = "avx2,fma")]
    pub(super) unsafe fn exp4_of(x: &[f64]) -> [f64; 4] {
        let mut out = [0.0; 4];
        // SAFETY: both slices hold four values; unaligned loads and stores.
        unsafe { _mm256_storeu_pd(out.as_mut_ptr(), exp4(_mm256_loadu_pd(x[..4].as_ptr()))) };
        out
    }

    /// `e^(values[r..r + 4] - shift)`.
    ///
    /// # Safety
    /// `r + 4` rows of `values` (and of `shift`'s rows) exist.
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    unsafe fn exp4_at(values: &[f64], shift: Shift, r: usize) -> __m256d {
        // SAFETY: the caller keeps `r + 4` within both; unaligned loads.
        unsafe {
            let shift = match shift {
                Shift::Rows(shift) => _mm256_loadu_pd(shift.as_ptr().add(r)),
                Shift::All(shift) => _mm256_set1_pd(shift),
            };
            exp4(_mm256_sub_pd(_mm256_loadu_pd(values.as_ptr().add(r)), shift))
        }
    }

    /// The whole groups of four rows of [`super::add_exp_of_differences`]; returns the first row
    /// left. `sum` and `values` have the same length, `shift` at least as many rows.
    #[target_feature(enable = "avx2,fma")]
    pub(super) unsafe fn add_exp_of_differences(sum: &mut [f64], values: &[f64], shift: Shift) -> usize {
        let whole = sum.len() - sum.len() % 4;
        for r in (0..whole).step_by(4) {
            // SAFETY: `r + 4 <= whole`, within all three.
            unsafe {
                let s = _mm256_add_pd(_mm256_loadu_pd(sum.as_ptr().add(r)), exp4_at(values, shift, r));
                _mm256_storeu_pd(sum.as_mut_ptr().add(r), s);
            }
        }
        whole
    }

    /// The whole groups of four rows of [`super::exp_of_differences_in_place`]; returns the first
    /// row left. `shift` has at least as many rows as `values`.
    #[target_feature(enable = "avx2,fma")]
    pub(super) unsafe fn exp_of_differences_in_place(values: &mut [f64], shift: Shift) -> usize {
        let whole = values.len() - values.len() % 4;
        for r in (0..whole).step_by(4) {
            // SAFETY: `r + 4 <= whole`, within both.
            unsafe {
                let e = exp4_at(values, shift, r);
                _mm256_storeu_pd(values.as_mut_ptr().add(r), e);
            }
        }
        whole
    }

    /// The sum of [`super::sum_exp_of_differences`] over the whole groups of four rows, added in
    /// row order, and the first row left.
    #[target_feature(enable = "avx2,fma")]
    pub(super) unsafe fn sum_exp_of_differences(values: &[f64], shift: f64) -> (f64, usize) {
        let whole = values.len() - values.len() % 4;
        let mut sum = -0.0;
        let mut lanes = [0.0; 4];
        for r in (0..whole).step_by(4) {
            // SAFETY: `r + 4 <= whole`; a four-value array.
            unsafe { _mm256_storeu_pd(lanes.as_mut_ptr(), exp4_at(values, Shift::All(shift), r)) };
            sum = lanes.iter().fold(sum, |sum, e| sum + e);
        }
        (sum, whole)
    }

    /// [`super::Lanes::scaled_max_and_exp_sum`] of NaN-free rows.
    #[target_feature(enable = "avx2,fma")]
    pub(super) unsafe fn scaled_max_and_exp_sum4(
        values: &[[f64; 4]],
        weight: [f64; 4],
    ) -> ([f64; 4], [f64; 4]) {
        // SAFETY: four-value arrays; unaligned loads and stores.
        unsafe {
            let weight = _mm256_loadu_pd(weight.as_ptr());
            let scaled = |row: &[f64; 4]| _mm256_mul_pd(weight, _mm256_loadu_pd(row.as_ptr()));
            let max = values.iter().fold(_mm256_set1_pd(f64::NEG_INFINITY), |max, row| {
                _mm256_max_pd(max, scaled(row))
            });
            let sum = values.iter().fold(_mm256_set1_pd(-0.0), |sum, row| {
                _mm256_add_pd(sum, exp4(_mm256_sub_pd(scaled(row), max)))
            });
            let (mut max_lanes, mut sum_lanes) = ([0.0; 4], [0.0; 4]);
            _mm256_storeu_pd(max_lanes.as_mut_ptr(), max);
            _mm256_storeu_pd(sum_lanes.as_mut_ptr(), sum);
            (max_lanes, sum_lanes)
        }
    }

    /// `e^x` per lane. The main path (`2^-54 <= |x| < 512`) and the subnormal path (`-1024 < x
    /// <= -512`, glibc's `specialcase` for negative `k`) are computed for every lane and blended;
    /// `|x| < 2^-54` gives `1 + x`, `x` below [`EXP_UNDERFLOW`] 0; a lane beyond all of them
    /// (`x >= 512`, NaN) is one call.
    #[target_feature(enable = "avx2,fma")]
    unsafe fn exp4(x: __m256d) -> __m256d {
        let splat = _mm256_set1_pd;
        let splat_int = _mm256_set1_epi64x;
        let is_zero = _mm256_cmp_pd::<_CMP_LT_OQ>(x, splat(EXP_UNDERFLOW));
        if _mm256_movemask_pd(is_zero) == 0b1111 {
            // With hundreds of components most responsibilities underflow, often four in a row.
            return splat(0.0);
        }
        let one = splat(1.0);
        // k = round(x N / ln 2) and r = x - k ln 2 / N.
        let z = _mm256_fmadd_pd(x, splat(INV_LN2_N), splat(SHIFT));
        let ki = _mm256_castpd_si256(z);
        let kd = _mm256_sub_pd(z, splat(SHIFT));
        let r = _mm256_fmadd_pd(kd, splat(NEG_LN2_HI_N), x);
        let r = _mm256_fmadd_pd(kd, splat(NEG_LN2_LO_N), r);
        // 2^(k/N) = 2^(top) 2^(i/N), i = k mod N: the table's pair at 2i.
        let index = _mm256_slli_epi64::<1>(_mm256_and_si256(ki, splat_int(127)));
        let top = _mm256_slli_epi64::<45>(ki);
        // SAFETY: `index` is at most 254, so both gathers read within the table.
        let (tail, sbits) = unsafe {
            let base = TABLE.as_ptr();
            (
                _mm256_i64gather_pd::<8>(base.cast::<f64>(), index),
                _mm256_add_epi64(_mm256_i64gather_epi64::<8>(base.add(1).cast::<i64>(), index), top),
            )
        };
        // tail + r + r^2 (C2 + r C3) + r^4 (C4 + r C5), fused as glibc's FMA build fuses it.
        let r2 = _mm256_mul_pd(r, r);
        let low = _mm256_fmadd_pd(r, splat(C3), splat(C2));
        let high = _mm256_fmadd_pd(r, splat(C5), splat(C4));
        let tmp = _mm256_fmadd_pd(low, r2, _mm256_add_pd(r, tail));
        let tmp = _mm256_fmadd_pd(_mm256_mul_pd(r2, r2), high, tmp);
        let scale = _mm256_castsi256_pd(sbits);
        let main = _mm256_fmadd_pd(scale, tmp, scale);
        let subnormal = subnormal_path(sbits, tmp, one);

        let exponent = _mm256_and_si256(_mm256_srli_epi64::<52>(_mm256_castpd_si256(x)), splat_int(0x7ff));
        let is_tiny = _mm256_cmpgt_epi64(splat_int(MAIN_FIRST_EXPONENT), exponent);
        let is_large = _mm256_cmpgt_epi64(exponent, splat_int(MAIN_END_EXPONENT - 1));
        let is_subnormal_path = _mm256_and_si256(
            _mm256_cmpeq_epi64(exponent, splat_int(MAIN_END_EXPONENT)),
            _mm256_cmpgt_epi64(splat_int(0), _mm256_slli_epi64::<32>(ki)),
        );
        let is_zero = _mm256_castpd_si256(is_zero);
        let y = _mm256_blendv_pd(main, _mm256_add_pd(one, x), _mm256_castsi256_pd(is_tiny));
        let y = _mm256_blendv_pd(y, subnormal, _mm256_castsi256_pd(is_subnormal_path));
        let y = _mm256_blendv_pd(y, splat(0.0), _mm256_castsi256_pd(is_zero));
        // Large lanes neither on the subnormal path nor zero: x >= 512, infinities, NaN.
        let handled = _mm256_or_si256(is_subnormal_path, is_zero);
        let others = _mm256_movemask_pd(_mm256_castsi256_pd(_mm256_andnot_si256(handled, is_large)));
        if others == 0 {
            return y;
        }
        let mut lanes = [0.0; 4];
        let mut args = [0.0; 4];
        // SAFETY: four-value arrays; unaligned stores and load.
        unsafe {
            _mm256_storeu_pd(lanes.as_mut_ptr(), y);
            _mm256_storeu_pd(args.as_mut_ptr(), x);
        }
        for (lane, (out, &arg)) in lanes.iter_mut().zip(&args).enumerate() {
            if others & (1 << lane) != 0 {
                *out = exp(arg);
            }
        }
        // SAFETY: a four-value array.
        unsafe { _mm256_loadu_pd(lanes.as_ptr()) }
    }

    /// glibc's `specialcase` for `k < 0`: the result scaled up by `2^1022` into the normal range,
    /// then, where it is below 1, summed again in two parts so that the final scaling down rounds
    /// once. Not fused: glibc's build reuses `scale * tmp`.
    #[target_feature(enable = "avx2,fma")]
    fn subnormal_path(sbits: __m256i, tmp: __m256d, one: __m256d) -> __m256d {
        let scale = _mm256_castsi256_pd(_mm256_add_epi64(sbits, _mm256_set1_epi64x(1022 << 52)));
        let scaled_tmp = _mm256_mul_pd(tmp, scale);
        let y = _mm256_add_pd(scale, scaled_tmp);
        let lo = _mm256_add_pd(_mm256_sub_pd(scale, y), scaled_tmp);
        let hi = _mm256_add_pd(y, one);
        let lo = _mm256_add_pd(_mm256_add_pd(_mm256_sub_pd(one, hi), y), lo);
        let resummed = _mm256_sub_pd(_mm256_add_pd(lo, hi), one);
        let y = _mm256_blendv_pd(y, resummed, _mm256_cmp_pd::<_CMP_LT_OQ>(y, one));
        _mm256_mul_pd(y, _mm256_set1_pd(TWO_POW_M1022))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_argument_gets_the_bits_of_f64_exp() {
        use rand::RngExt;
        let mut rng = crate::rng::rng(59);
        // Across the underflow threshold (every thousandth near it), through the subnormal range
        // and far below, the range the E-step and the tempering use, and the special values.
        let near = (-4000..4000).map(|i| EXP_UNDERFLOW + f64::from(i) * 1e-3);
        let wide = (0..2000).map(|i| -f64::from(i) * 0.75);
        let random: Vec<f64> = (0..200_000).map(|_| rng.random_range(-800.0..710.0)).collect();
        let small: Vec<f64> = (0..20_000).map(|_| rng.random_range(-1e-6..1e-6)).collect();
        let special = [
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NAN,
            -1e300,
            1e300,
            0.0,
            -0.0,
            709.0,
            710.0,
            f64::MIN_POSITIVE,
            -f64::MIN_POSITIVE,
        ];
        let mut zeros = 0;
        for x in near.chain(wide).chain(random).chain(small).chain(special) {
            assert_eq!(exp(x).to_bits(), x.exp().to_bits(), "exp({x})");
            zeros += usize::from(x < EXP_UNDERFLOW);
        }
        // Not vacuous: the shortcut answered many of them.
        assert!(zeros > 3000, "{zeros}");
        // The threshold is not too low to matter: the last subnormals are just above it.
        assert!((EXP_UNDERFLOW + 2.0).exp() > 0.0);
    }

    /// Arguments for the four lanes: the whole range at random, dense runs through the subnormal
    /// path and across the bounds between paths, and the probes.
    fn lane_arguments() -> Vec<f64> {
        use rand::RngExt;
        let mut rng = crate::rng::rng(61);
        let mut x: Vec<f64> = (0..400_000).map(|_| rng.random_range(-800.0..710.0)).collect();
        x.extend((0..200_000).map(|_| rng.random_range(-746.0..-700.0)));
        x.extend((0..100_000).map(|_| rng.random_range(-30.0..1.0)));
        for bound in [-1024.0f64, -512.0, 512.0, -745.133, 6e-17, -6e-17, 5.55e-17] {
            x.extend((-500..500).map(|i| bound + f64::from(i) * bound.abs() * 1e-13));
            let bits = bound.to_bits();
            x.extend((0..200).map(|i| f64::from_bits(bits - 100 + i)));
        }
        x.extend((0..1000).map(|_| rng.random_range(-1e-15..1e-15)));
        x.extend(four_lanes::probes());
        x
    }

    #[cfg(target_arch = "x86_64")]
    #[test]
    fn four_lanes_give_the_bits_of_f64_exp() {
        if !crate::simd::has_avx2_fma() {
            return;
        }
        let x = lane_arguments();
        let mut subnormal = 0;
        for chunk in x.chunks_exact(4) {
            // SAFETY: the processor has AVX2 and FMA (checked above).
            let lanes = unsafe { four_lanes::exp4_of(chunk) };
            for (e, &x) in lanes.iter().zip(chunk) {
                assert_eq!(
                    e.to_bits(),
                    x.exp().to_bits(),
                    "exp({x:e}) = {e:e}, not {:e}",
                    x.exp()
                );
                subnormal += usize::from(*e > 0.0 && *e < f64::MIN_POSITIVE);
            }
        }
        // Not vacuous: the subnormal path was taken many times.
        assert!(subnormal > 50_000, "{subnormal}");
    }

    #[cfg(all(target_arch = "x86_64", target_os = "linux", target_env = "gnu"))]
    #[test]
    fn on_glibc_with_avx2_and_fma_the_rows_go_four_at_a_time() {
        // Without this the rows would fall back to one call each and the test above could pass
        // while nothing used the lanes.
        assert_eq!(four_lanes::agree(), crate::simd::has_avx2_fma());
    }

    #[test]
    fn every_row_gets_the_bits_of_f64_exp() {
        let x = lane_arguments();
        // Lengths not a multiple of four: the last rows go one at a time.
        let x = &x[..x.len() - x.len() % 4 - 3];
        let shift: Vec<f64> = (0..x.len()).map(|r| (r % 7) as f64 - 3.0).collect();
        let values: Vec<f64> = x.iter().zip(&shift).map(|(x, s)| x + s).collect();
        let mut in_place = values.clone();
        exp_of_differences_in_place(&mut in_place, Shift::Rows(&shift));
        let mut sums = vec![0.5; x.len()];
        add_exp_of_differences(&mut sums, &values, Shift::Rows(&shift));
        let mut all = values.clone();
        exp_of_differences_in_place(&mut all, Shift::All(2.5));
        for (r, (&v, &s)) in values.iter().zip(&shift).enumerate() {
            let e = (v - s).exp();
            assert_eq!(in_place[r].to_bits(), e.to_bits(), "row {r}: exp({:e})", v - s);
            assert_eq!(
                sums[r].to_bits(),
                (0.5 + e).to_bits(),
                "row {r}: 0.5 + exp({:e})",
                v - s
            );
            assert_eq!(
                all[r].to_bits(),
                (v - 2.5).exp().to_bits(),
                "row {r}: exp({:e})",
                v - 2.5
            );
        }
    }

    #[test]
    fn a_sum_of_exponentials_is_the_in_order_sum_of_f64_exp() {
        let x = lane_arguments();
        for (length, shift) in [(0, 0.0), (1, 3.0), (3, -2.0), (4, 0.0), (401, 1.5), (4099, -7.0)] {
            for values in x.chunks_exact(length.max(1)).take(40) {
                let values = &values[..length];
                let expected = values.iter().map(|v| (v - shift).exp()).sum::<f64>();
                let sum = sum_exp_of_differences(values, shift);
                assert_eq!(
                    sum.to_bits(),
                    expected.to_bits(),
                    "{length} values, shift {shift}"
                );
            }
        }
    }

    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    #[test]
    fn on_glibc_the_implementation_is_called_without_its_wrapper() {
        assert!(unwrapped().is_some(), "glibc exports __exp_finite@GLIBC_2.15");
    }
}
