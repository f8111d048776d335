//! Fast decimal number reading for the hot path.
//!
//! A number whose digits make an integer `m` ≤ 2^53, with at most 22
//! fraction digits, is `m / 10^k` with both `m` and `10^k` exact in `f64`; one IEEE division
//! rounds that correctly, so the result is bit for bit what
//! `str::parse::<f64>()` gives (and what the writer's
//! `NumberFormat::quantize` returns for the printed text). Other numbers
//! take `str::parse`.

const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// A number read from text.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Number {
    /// Its value.
    pub value: f64,
    /// Bytes it took (sign included).
    pub len: usize,
    /// It had a decimal point (Fanuc: no point = least input increments).
    pub has_point: bool,
}

/// Reads `[+-]digits[.digits]` (or `.digits`) at the start of `b`; spaces
/// between the sign and the digits are allowed (`X- 5` in rs274ngc). `None`
/// when there is no digit.
#[inline]
pub(crate) fn read_number(b: &[u8]) -> Option<Number> {
    let mut i = 0;
    let mut negative = false;
    if let Some(&c) = b.first()
        && (c == b'+' || c == b'-')
    {
        negative = c == b'-';
        i = 1;
        while i < b.len() && (b[i] == b' ' || b[i] == b'\t') {
            i += 1;
        }
    }
    let start = i;
    let mut mantissa: u64 = 0;
    while let Some(d) = b.get(i).map(|c| c.wrapping_sub(b'0')).filter(|d| *d < 10) {
        mantissa = mantissa.wrapping_mul(10).wrapping_add(u64::from(d));
        i += 1;
    }
    let int_digits = i - start;
    let mut has_point = false;
    let mut fraction = 0usize;
    if b.get(i) == Some(&b'.') {
        has_point = true;
        i += 1;
        let f = i;
        while let Some(d) = b.get(i).map(|c| c.wrapping_sub(b'0')).filter(|d| *d < 10) {
            mantissa = mantissa.wrapping_mul(10).wrapping_add(u64::from(d));
            i += 1;
        }
        fraction = i - f;
    }
    if int_digits + fraction == 0 {
        return None;
    }
    // At most 19 digits cannot overflow; below 2^53 the mantissa is exact.
    let magnitude = if int_digits + fraction <= 19 && mantissa <= EXACT && fraction <= 22 {
        mantissa as f64 / POW10[fraction]
    } else {
        slow(&b[start..i])?
    };
    Some(Number {
        value: if negative { -magnitude } else { magnitude },
        len: i,
        has_point,
    })
}

/// 2^53: every integer up to it is exact in `f64`.
const EXACT: u64 = 1 << 53;

#[cold]
fn slow(digits: &[u8]) -> Option<f64> {
    let s = std::str::from_utf8(digits).ok()?;
    let s = s.strip_suffix('.').unwrap_or(s);
    let v: f64 = if let Some(rest) = s.strip_prefix('.') {
        format!("0.{rest}").parse().ok()?
    } else {
        s.parse().ok()?
    };
    v.is_finite().then_some(v)
}

/// Reads an unsigned integer (block numbers, labels); `None` on overflow or
/// no digit.
#[inline]
pub(crate) fn read_uint(b: &[u8]) -> Option<(u64, usize)> {
    let mut n: u64 = 0;
    let mut i = 0;
    while i < b.len() && b[i].is_ascii_digit() {
        n = n.checked_mul(10)?.checked_add(u64::from(b[i] - b'0'))?;
        i += 1;
    }
    (i > 0).then_some((n, i))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_bits_as_std() {
        for s in [
            "0",
            "-0.5",
            "459.000",
            "8.807",
            "-93.25",
            "1200",
            "0.5",
            "5.0",
            "+3.25",
            "0.000001",
            "123456789.123456789",
            "-0.0000000000000000000001234",
        ] {
            let n = read_number(s.as_bytes()).unwrap();
            let want: f64 = s.parse().unwrap();
            assert_eq!(n.value.to_bits(), want.to_bits(), "{s}");
            assert_eq!(n.len, s.len(), "{s}");
        }
        assert_eq!(read_number(b".5").unwrap().value, 0.5);
        assert_eq!(read_number(b"5.").unwrap().value, 5.0);
        assert_eq!(read_number(b"1e5").unwrap().len, 1);
        assert_eq!(read_number(b"- 5").unwrap().value, -5.0);
        assert!(read_number(b"-").is_none());
        assert!(read_number(b".").is_none());
        assert!(!read_number(b"12").unwrap().has_point);
        assert!(read_number(b"12.").unwrap().has_point);
    }

    #[test]
    fn every_fixed_point_value_reads_as_std() {
        for k in -20000i64..20000 {
            for d in 0..7 {
                let s = format!("{:.*}", d, k as f64 / 7.0);
                let n = read_number(s.as_bytes()).unwrap();
                assert_eq!(
                    n.value.to_bits(),
                    s.parse::<f64>().unwrap().to_bits(),
                    "{s}"
                );
            }
        }
    }
}
