//! Numbers for people: the human-readable lines print a computed value without its binary
//! representation noise (`τ = 0.15 s`, not `τ = 0.15000000000000002 s`). JSON and CSV
//! outputs keep the full `f64`.

/// Significant digits [`num`] keeps.
pub const DIGITS: usize = 6;

/// `x` with up to [`DIGITS`] significant digits, trailing zeros trimmed: `0.15`, `300.25`,
/// `2500`, `1e-4`, `1.23457e7`. Exponent notation below 1e-4 and from 1e6 on (in magnitude);
/// `NaN`, `inf` and `-inf` as such; `-0` as `0`.
pub fn num(x: f64) -> String {
    sig(x, DIGITS)
}

/// `x` with up to `digits` significant digits (at least 1), trailing zeros trimmed; the
/// notation as in [`num`].
pub fn sig(x: f64, digits: usize) -> String {
    if x.is_nan() {
        return "NaN".into();
    }
    if x.is_infinite() {
        return if x > 0.0 { "inf" } else { "-inf" }.into();
    }
    if x == 0.0 {
        return "0".into();
    }
    let digits = digits.max(1);
    // rounded to `digits` significant digits first: the exponent is the rounded value's
    let scientific = format!("{:.*e}", digits - 1, x);
    let (mantissa, exponent) = scientific
        .split_once('e')
        .expect("`{:e}` writes an exponent");
    let exponent: i32 = exponent.parse().expect("`{:e}` writes an integer exponent");
    if (-4..6).contains(&exponent) {
        let decimals = (digits as i32 - 1 - exponent).max(0) as usize;
        trim_zeros(format!("{x:.decimals$}"))
    } else {
        format!("{}e{exponent}", trim_zeros(mantissa.to_string()))
    }
}

/// Seconds with their unit: `0.15 s`.
pub fn seconds(x: f64) -> String {
    format!("{} s", num(x))
}

/// Kelvin with their unit: `300.25 K`.
pub fn kelvin(x: f64) -> String {
    format!("{} K", num(x))
}

/// Trailing zeros after a decimal point removed, and the point if nothing follows it; `-0`
/// as `0`. A number without a point (or in exponent notation) is left as it is.
pub fn trim_zeros(mut s: String) -> String {
    if s.contains('.') {
        let kept = s.trim_end_matches('0').trim_end_matches('.').len();
        s.truncate(kept);
    }
    if s == "-0" {
        s = "0".into();
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn representation_noise_is_gone() {
        assert_eq!(num(0.075 * 2.0), "0.15");
        assert_eq!(num(0.1 + 0.2), "0.3");
        assert_eq!(seconds(0.15000000000000002), "0.15 s");
        assert_eq!(kelvin(300.25), "300.25 K");
    }

    #[test]
    fn magnitudes_and_special_values() {
        assert_eq!(num(2500.0), "2500");
        assert_eq!(num(1e-4), "0.0001");
        assert_eq!(num(5e-5), "5e-5");
        assert_eq!(num(1.5e-5), "1.5e-5");
        assert_eq!(num(123456.7), "123457");
        assert_eq!(num(999999.7), "1e6");
        assert_eq!(num(12345678.0), "1.23457e7");
        assert_eq!(num(-0.30000000000000004), "-0.3");
        assert_eq!(num(-0.0), "0");
        assert_eq!(num(-1e-9), "-1e-9");
        assert_eq!(num(f64::NAN), "NaN");
        assert_eq!(num(f64::NEG_INFINITY), "-inf");
        assert_eq!(sig(1500.0000002, 9), "1500");
        assert_eq!(sig(1500.3, 9), "1500.3");
        assert_eq!(sig(2.0 / 3.0, 3), "0.667");
        assert_eq!(sig(0.99996, 4), "1");
    }
}
