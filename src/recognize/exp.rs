//! `e^x` with the bits of `f64::exp`, at less cost per call: the Gaussian mixture's E-step takes
//! two exponentials per feature and component, the posterior's tempering one per object, trial
//! prefix and candidate (`calibration`), hundreds of millions per codebook fit.
//!
//! Two shortcuts, neither of which changes a bit:
//! - Below [`EXP_UNDERFLOW`] `e^x` is exactly 0, answered without a call (the exponential's
//!   underflow path is its slowest; with many components most responsibilities underflow).
//! - On glibc, `exp` is a wrapper: it calls the implementation through the dynamic linker's table
//!   and afterwards sets `errno` on overflow and underflow, as POSIX asks, returning the
//!   implementation's value unchanged. That wrapper was a quarter of the time spent in
//!   exponentials (perf, the 52 letters' Polar-Fourier codebooks). glibc exports the
//!   implementation itself as `__exp_finite` (symbol version `GLIBC_2.15`, kept for binaries
//!   built against older headers); it is looked up once and called directly. Nothing here reads
//!   `errno`. Where it is missing (another C library) `f64::exp` is called.

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

    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    #[test]
    fn on_glibc_the_implementation_is_called_without_its_wrapper() {
        assert!(unwrapped().is_some(), "glibc exports __exp_finite@GLIBC_2.15");
    }
}
