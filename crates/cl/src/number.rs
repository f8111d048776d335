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

const ONES: u64 = 0x0101_0101_0101_0101;
const HIGH_BITS: u64 = 0x8080_8080_8080_8080;

/// `word` with each ASCII digit turned into its value, and a mask whose
/// lowest set bit is the high bit of the first byte (from the low end) that
/// is not a digit; 0 if all eight are digits.
#[inline(always)]
fn digit_values(word: u64) -> (u64, u64) {
    let v = word ^ (ONES * u64::from(b'0'));
    // A byte is a digit iff it becomes 0..=9: then adding 0x76 leaves its
    // high bit clear and carries nothing into the next byte. A byte that is
    // not a digit gets its high bit set (by the sum, or by `| v` for bytes
    // from 0x80 up); its carry may garble the bytes above it, but not the
    // lowest flagged byte, the only one looked at.
    let stop = (v.wrapping_add(ONES * 0x76) | v) & HIGH_BITS;
    (v, stop)
}

/// The number written by the digit values in `d` (each byte 0..=9), most
/// significant in the lowest byte; leading digits may be zero bytes (the
/// classic SWAR conversion of eight digits, without its first mask: the
/// bytes are already values).
#[inline(always)]
fn eight_digits(d: u64) -> u64 {
    let d = d.wrapping_mul(2561) >> 8;
    let d = (d & 0x00FF_00FF_00FF_00FF).wrapping_mul(6_553_601) >> 16;
    (d & 0x0000_FFFF_0000_FFFF).wrapping_mul(42_949_672_960_001) >> 32
}

/// -1 for a first byte `-`, else 1: the sign of a plain number, looked up
/// by its first byte (a table, as the optimizer turns a comparison into a
/// branch).
const SIGN: [f64; 256] = {
    let mut sign = [1.0; 256];
    sign[b'-' as usize] = -1.0;
    sign
};

/// The length of the chunk [`plain_number`] reads: a sign, eight digits,
/// a point and the byte after the number.
pub(crate) const PLAIN_CHUNK: usize = 11;

/// [`scan_number`] for the shape CL files are made of: `[-+]?d*[.d*]` with
/// at most 7 digits before the point and at most 8 digits in all, read a
/// word at a time from a fixed-size chunk (so that no load needs a bounds
/// check). Returns the number and its length, which is at most 10:
/// `chunk[len]` is the byte after it. The caller must check that this byte
/// is a separator, neither a digit (more digits), nor `.`, `e` or `E`: then
/// the number is what [`scan_number`] gives. `None` for any other shape.
///
/// The number is the quotient of its signed digits and a power of ten,
/// correctly rounded (Clinger's fast path, exact operands).
#[inline(always)]
pub(crate) fn plain_number(chunk: &[u8; PLAIN_CHUNK]) -> Option<(f64, usize)> {
    let sign = chunk[0];
    let s = usize::from(sign == b'-' || sign == b'+');
    let word = load_word(chunk, s);
    let (values, stop) = digit_values(word);
    if stop == 0 {
        return None; // eight digits or more before the point
    }
    // The digits before the point (0..=7), times 8, then the point, if any.
    let whole_bits = stop.trailing_zeros() & 0x38;
    let whole = (whole_bits / 8) as usize;
    let (values, n, len) = if (word >> whole_bits) as u8 == b'.' {
        // The whole digits, then those after the point moved down over it.
        let low = (1u64 << whole_bits) - 1;
        let digits = (word & low) | (load_word(chunk, s + 1) & !low);
        let (values, stop) = digit_values(digits);
        // `trailing_zeros` is 64 if all eight are digits.
        let n = (stop.trailing_zeros() / 8) as usize;
        (values, n, s + n + 1)
    } else {
        (values, whole, s + whole)
    };
    if n == 0 {
        return None;
    }
    // The n digits up to the top byte (the most significant at byte 8 - n),
    // what follows them shifted out.
    let mantissa = eight_digits(values << (64 - 8 * n));
    // At most 8 digits: the mantissa is exact, and so is the power of ten
    // (Clinger's fast path; `scan_number` computes the very same quotient).
    // Through i64, which converts in one instruction, unlike u64. The index
    // is at most 8 (n >= whole when there is a point); the mask only spares
    // a bounds check.
    // The sign on the digits (`-m / d` is `-(m / d)` exactly, and -0 for 0
    // as `str::parse` has it), without a branch on it, which is
    // unpredictable.
    let m = (mantissa as i64) as f64 * SIGN[usize::from(sign)];
    Some((m / POW10[(n - whole) & 15], len))
}

/// The eight bytes at `chunk[i..]` (`i` is 0, 1 or 2), little-endian.
#[inline(always)]
fn load_word(chunk: &[u8; PLAIN_CHUNK], i: usize) -> u64 {
    let mut word = [0; 8];
    word.copy_from_slice(&chunk[i..i + 8]);
    u64::from_le_bytes(word)
}

/// [`plain_number`] on `b[start..]`: the value and the index just after the
/// number. `None` also if `b` has fewer than [`PLAIN_CHUNK`] bytes from
/// `start` (pad the buffer).
#[cfg(test)]
fn scan_plain_number(b: &[u8], start: usize) -> Option<(f64, usize)> {
    let (v, len) = plain_number(b.get(start..)?.first_chunk()?)?;
    Some((v, start + len))
}

#[cfg(test)]
mod tests {
    use super::{parse_number, scan_number, scan_plain_number};

    #[test]
    fn plain_numbers_match_the_general_scanner() {
        let mut texts: Vec<String> = [
            "0",
            "-0",
            "+0",
            "-0.0",
            "25.",
            ".5",
            "-.5",
            "+.5",
            "-3.",
            "1234567.1",
            "1.1234567",
            ".12345678",
            "0000000.0",
            "9999999.9",
            "99999999",
            "-391.2345",
            "0.9922222",
            "-0.0123456",
            ".",
            "-",
            "+",
            "",
            "1e5",
            "1.5E3",
            "1.5e",
            "5.e2",
            "12345678",
            "1.12345678",
            "1.2.3",
            "1,2",
            "-+1",
            "--1",
            "1 ",
            " 1",
            "a",
            "1a",
            "0x10",
            "7.",
            "..5",
            "1..",
            "-.",
            "+.",
            "1-2",
            "1.-2",
            "\u{e9}1",
            "1.\u{e9}",
            "12345678.1",
        ]
        .iter()
        .map(|t| t.to_string())
        .collect();
        for k in 0..5000u64 {
            let x = k.wrapping_mul(0x9E37_79B9_7F4A_7C15);
            let whole = x % 100_000_000 / 10u64.pow((x >> 40) as u32 % 9);
            let decimals = ((x >> 48) % 9) as usize;
            let fraction = (x >> 20) % 10u64.pow(decimals as u32);
            let sign = ["", "-", "+"][(x >> 60) as usize % 3];
            texts.push(match (x >> 56) % 4 {
                0 => format!("{sign}{whole}"),
                1 => format!("{sign}{whole}."),
                2 if decimals > 0 => format!("{sign}.{fraction:0decimals$}"),
                _ => format!("{sign}{whole}.{fraction:0decimals$}"),
            });
        }
        for text in &texts {
            for after in [",", "\n", "\r\n", ",1.5,2\n", " ", "e5", ".5", "5", ""] {
                let b = format!("{text}{after}\0\0\0\0\0\0\0\0\0\0\0");
                let Some((v, end)) = scan_plain_number(b.as_bytes(), 0) else {
                    continue;
                };
                if matches!(b.as_bytes()[end], b'0'..=b'9' | b'.' | b'e' | b'E') {
                    continue; // the caller falls back
                }
                let (w, e) = scan_number(b.as_bytes(), 0).expect(text);
                assert_eq!((v.to_bits(), end), (w.to_bits(), e), "{text:?}{after:?}");
            }
            // Every plain number up to 7 + 8 digits (8 in all) is taken.
            let sign = usize::from(text.starts_with(['-', '+']));
            let parts: Vec<&str> = text[sign..].split('.').collect();
            let digits: usize = parts.iter().map(|p| p.len()).sum();
            let plain = parts.len() <= 2
                && parts.iter().all(|p| p.bytes().all(|c| c.is_ascii_digit()))
                && parts[0].len() < 8
                && (1..=8).contains(&digits);
            let b = format!("{text},\0\0\0\0\0\0\0\0\0\0\0");
            assert_eq!(
                scan_plain_number(b.as_bytes(), 0).is_some_and(|(_, end)| end == text.len()),
                plain,
                "{text:?}"
            );
        }
    }

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

    /// A decimal text as CAM systems write it: a sign or none, digits with
    /// leading and trailing zeros, with or without a point, up to 17
    /// significant digits, maybe an exponent (which the reader accepts).
    fn cam_number() -> impl proptest::strategy::Strategy<Value = String> {
        use proptest::prelude::*;
        (
            prop::sample::select(vec!["", "-", "+"]),
            "0{0,2}[0-9]{0,8}",
            prop::sample::select(vec!["", "."]),
            "[0-9]{0,9}0{0,2}",
            prop::option::weighted(0.2, ("[eE]", "[-+]?", "[0-9]{1,2}")),
        )
            .prop_filter("at least one digit", |(_, whole, _, fraction, _)| {
                !whole.is_empty() || !fraction.is_empty()
            })
            .prop_map(|(sign, whole, point, fraction, exponent)| {
                // Without a point, the fraction digits are more whole digits.
                let mut text = format!("{sign}{whole}{point}{fraction}");
                if let Some((e, exponent_sign, digits)) = exponent {
                    text = format!("{text}{e}{exponent_sign}{digits}");
                }
                text
            })
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(20_000))]

        /// Both fast paths give the very bits of `str::parse::<f64>`; the
        /// plain one takes every plain number of up to 8 digits.
        #[test]
        fn fast_paths_are_bit_identical_to_std(text in cam_number()) {
            let std: f64 = text.parse().unwrap();
            let general = parse_number(&text).map(f64::to_bits);
            proptest::prop_assert_eq!(general, Some(std.to_bits()), "{}", text);
            for after in [",", "\n", "\r\n"] {
                let b = format!("{text}{after}\0\0\0\0\0\0\0\0\0\0\0");
                // As the reader uses it: followed by a separator.
                let plain = scan_plain_number(b.as_bytes(), 0)
                    .filter(|&(_, end)| !matches!(b.as_bytes()[end], b'0'..=b'9' | b'.' | b'e' | b'E'));
                if let Some((v, end)) = plain {
                    proptest::prop_assert_eq!((v.to_bits(), end), (std.to_bits(), text.len()), "{}", text);
                }
                let unsigned = text.trim_start_matches(['-', '+']);
                let digits = unsigned.bytes().filter(u8::is_ascii_digit).count();
                let whole = unsigned.split('.').next().unwrap().len();
                let simple = !unsigned.contains(['e', 'E']) && digits <= 8 && whole <= 7;
                proptest::prop_assert_eq!(plain.is_some(), simple, "{}", text);
            }
        }
    }
}
