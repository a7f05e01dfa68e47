//! Numbers for people: lengths and plain values with four significant digits, so that a message
//! says `covering 1.2 mm` rather than the shortest round-trip form `0.0012000000000000001 m`
//! (files keep the round-trip form, [`round_trip`]).

/// `v` in shortest round-trip form, for files: plain decimals for ordinary magnitudes, exponent
/// form for tiny or huge ones (where plain decimals would run to hundreds of digits).
pub fn round_trip(v: f64) -> String {
    let mut text = String::new();
    push_round_trip(&mut text, v);
    text
}

/// Appends [`round_trip`]`(v)` to `out` without a string of its own: MJCF writes a scanned mesh's
/// million coordinates this way (issue 39).
pub fn push_round_trip(out: &mut String, v: f64) {
    use std::fmt::Write;
    let a = v.abs();
    let _ = if a == 0.0 || (1e-5..1e16).contains(&a) {
        write!(out, "{v}")
    } else {
        write!(out, "{v:e}")
    };
}

/// `v` with at most four significant digits, trailing zeros dropped: `1.2`, `0.576`, `12`, and
/// exponent form outside [1e-4, 1e6): `3e30`.
pub fn significant(v: f64) -> String {
    if !v.is_finite() {
        return v.to_string();
    }
    if v == 0.0 {
        return "0".to_string();
    }
    let magnitude = v.abs().log10().floor() as i32;
    if !(-4..6).contains(&magnitude) {
        let text = format!("{v:.3e}");
        return match text.split_once('e') {
            Some((mantissa, exponent)) => format!("{}e{exponent}", trim_zeros(mantissa)),
            None => text,
        };
    }
    let decimals = (3 - magnitude).max(0) as usize;
    trim_zeros(&format!("{v:.decimals$}"))
}

fn trim_zeros(text: &str) -> String {
    let trimmed = if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.')
    } else {
        text
    };
    if trimmed == "-0" {
        "0".to_string()
    } else {
        trimmed.to_string()
    }
}

/// A length given in metres, in millimetres below one metre (`1.2 mm`, `120 mm`) and in metres
/// from there on (`1.5 m`, `3e30 m`).
pub fn length(m: f64) -> String {
    if m != 0.0 && m.abs() < 1.0 {
        format!("{} mm", significant(m * 1e3))
    } else {
        format!("{} m", significant(m))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lengths_read_as_a_person_writes_them() {
        assert_eq!(length(0.1 * 0.012), "1.2 mm");
        assert_eq!(length(0.012), "12 mm");
        assert_eq!(length(0.12), "120 mm");
        assert_eq!(length(0.48 * 0.0012), "0.576 mm");
        assert_eq!(length(1.5), "1.5 m");
        assert_eq!(length(3e30), "3e30 m");
        assert_eq!(length(0.0), "0 m");
        assert_eq!(significant(-0.00001234567), "-1.235e-5");
        assert_eq!(significant(9.99996), "10");
        assert_eq!(significant(f64::INFINITY), "inf");
    }
}
