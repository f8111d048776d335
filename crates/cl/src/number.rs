//! APT number syntax and a fast, correctly rounded parser for it.

/// Powers of ten that are exact in an `f64`.
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// Parses an APT number: an optional sign, digits with an optional decimal
/// point (at least one digit; `.9625`, `25.`, `-3.` are fine) and an optional
/// exponent (`1E-3`, `2e+5`). No surrounding whitespace, no `inf`/`nan`.
///
/// Returns `None` for anything else and for numbers too large to be finite.
/// The result is correctly rounded (as [`str::parse::<f64>`]); short decimals
/// take a fast exact path.
///
/// ```
/// use kinpost_cl::parse_number;
/// assert_eq!(parse_number(".9625"), Some(0.9625));
/// assert_eq!(parse_number("-3."), Some(-3.0));
/// assert_eq!(parse_number("1E-3"), Some(0.001));
/// assert_eq!(parse_number("1.2.3"), None);
/// assert_eq!(parse_number("inf"), None);
/// ```
pub fn parse_number(s: &str) -> Option<f64> {
    match scan_number(s.as_bytes(), 0) {
        Some((v, end)) if end == s.len() => Some(v),
        _ => None,
    }
}

/// Parses the APT number that starts at `b[start]` and returns it with the
/// index just after it. `None` if no number starts there (or an exponent has
/// no digits, or the number is too large to be finite). What follows the
/// number is not looked at: the caller checks for a separator.
#[inline(always)]
pub(crate) fn scan_number(b: &[u8], start: usize) -> Option<(f64, usize)> {
    let mut i = start;
    let negative = match b.get(i) {
        Some(b'-') => {
            i += 1;
            true
        }
        Some(b'+') => {
            i += 1;
            false
        }
        _ => false,
    };
    // All mantissa digits, leading zeros included; with at most 19 of them
    // the mantissa is exact in a u64 (wrapping arithmetic otherwise, and the
    // slow path). A plain loop beats eight-digits-at-a-time (SWAR) tricks on
    // CL numbers, which have only 5 to 9 digits.
    let mut mantissa: u64 = 0;
    let digits_start = i;
    while let Some(&c) = b.get(i) {
        let d = c.wrapping_sub(b'0');
        if d >= 10 {
            break;
        }
        mantissa = mantissa.wrapping_mul(10).wrapping_add(u64::from(d));
        i += 1;
    }
    let mut digits = i - digits_start;
    let mut exponent: i64 = 0;
    if b.get(i) == Some(&b'.') {
        i += 1;
        let fraction_start = i;
        while let Some(&c) = b.get(i) {
            let d = c.wrapping_sub(b'0');
            if d >= 10 {
                break;
            }
            mantissa = mantissa.wrapping_mul(10).wrapping_add(u64::from(d));
            i += 1;
        }
        digits += i - fraction_start;
        exponent = -((i - fraction_start) as i64);
    }
    if digits == 0 {
        return None;
    }
    if let Some(&c) = b.get(i)
        && (c | 0x20) == b'e'
    {
        i += 1;
        let exp_negative = match b.get(i) {
            Some(b'-') => {
                i += 1;
                true
            }
            Some(b'+') => {
                i += 1;
                false
            }
            _ => false,
        };
        let exp_start = i;
        let mut e: i64 = 0;
        while let Some(&c) = b.get(i) {
            let d = c.wrapping_sub(b'0');
            if d >= 10 {
                break;
            }
            e = (e * 10 + i64::from(d)).min(1_000_000);
            i += 1;
        }
        if i == exp_start {
            return None;
        }
        exponent += if exp_negative { -e } else { e };
    }
    if digits <= 19 && mantissa <= 1 << 53 && (-22..=22).contains(&exponent) {
        // Clinger's fast path: both operands exact, one rounding.
        let m = mantissa as f64;
        let v = if exponent < 0 {
            m / POW10[(-exponent) as usize]
        } else {
            m * POW10[exponent as usize]
        };
        return Some((if negative { -v } else { v }, i));
    }
    // Valid APT syntax is a subset of Rust's float syntax.
    let text = std::str::from_utf8(&b[start..i]).ok()?;
    let v: f64 = text.parse().ok()?;
    v.is_finite().then_some((v, i))
}

#[cfg(test)]
mod tests {
    use super::parse_number;

    #[test]
    fn apt_forms() {
        for (text, value) in [
            ("0", 0.0),
            ("25.", 25.0),
            (".9625", 0.9625),
            ("-3.", -3.0),
            ("+2", 2.0),
            ("1E-3", 1e-3),
            ("1e+3", 1e3),
            ("5.e2", 500.0),
            (".5E1", 5.0),
            ("-416.0000", -416.0),
            ("70.3931", 70.3931),
            ("0.0000000", 0.0),
            ("-0.0", -0.0),
        ] {
            assert_eq!(parse_number(text), Some(value), "{text}");
        }
        assert!(parse_number("-0.0").unwrap().is_sign_negative());
    }

    #[test]
    fn rejects_non_numbers() {
        for text in [
            "", "-", "+", ".", "-.", "1.2.3", "abc", "1e", "1e+", "e5", "inf", "NaN", "1 2", " 1",
            "1 ", "1,2", "0x10", "1e999", "--1", "1d3",
        ] {
            assert_eq!(parse_number(text), None, "{text:?}");
        }
    }

    #[test]
    fn agrees_with_std_on_long_and_extreme_numbers() {
        for text in [
            "123456789012345678901234567890",
            "0.000000000000000000000000000001234",
            "9007199254740993",
            "9007199254740992.5",
            "1e-320",
            "2.2250738585072014e-308",
            "1.7976931348623157e308",
            "123.456e-30",
            "0.1",
            "0.30000000000000004",
            "1e22",
            "1e23",
            "00000000000000000000000000000000001.5",
        ] {
            assert_eq!(parse_number(text), text.parse::<f64>().ok(), "{text}");
        }
    }
}
