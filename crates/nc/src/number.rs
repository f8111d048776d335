//! Allocation-free fixed-point number formatting for NC words.
//!
//! A value is quantized to an integer number of units of `10^-decimals`
//! (correctly rounded from the exact binary value, ties to even, exactly as
//! `format!("{:.d$}")` rounds), optionally reduced modulo a period, and then
//! printed from that integer. [`NumberFormat::quantize`] returns
//! `units as f64 / 10^decimals`, which is bit for bit the number that
//! `str::parse::<f64>()` gives for the printed text.

use serde::Deserialize;

/// Largest number of decimals a word may have.
pub const MAX_DECIMALS: u8 = 9;

/// Largest magnitude (in units of `10^-decimals`) that can be written: 2^53,
/// below which every integer is exactly representable as `f64`.
const UNIT_LIMIT: f64 = 9_007_199_254_740_992.0;

const POW10: [f64; 10] = [1.0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9];
const POW5: [u128; 10] = [1, 5, 25, 125, 625, 3125, 15625, 78125, 390625, 1953125];

/// How trailing zeros of the fraction are written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TrailingZeros {
    /// Always all decimals: `459.000`, `8.800`.
    Keep,
    /// Trailing zeros removed, the decimal point kept: `459.`, `8.8`.
    Point,
    /// Trailing zeros and a bare decimal point removed: `459`, `8.8`.
    Trim,
}

/// The number part of a word (without prefix and suffix).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NumberFormat {
    /// Digits after the decimal point (0..=9).
    pub decimals: u8,
    /// Trailing-zero style.
    pub trailing_zeros: TrailingZeros,
    /// `0.5` (true) or `.5` (false). A zero integer part is kept when no
    /// fraction digit follows (`0`, `0.`).
    pub leading_zero: bool,
    /// Write `+` before positive values and zero (Heidenhain `X+0.000`).
    pub plus_sign: bool,
    /// Write the value reduced to `[0, modulo)` (e.g. 360 for Sinumerik `DC`).
    pub modulo: Option<f64>,
}

impl Default for NumberFormat {
    fn default() -> Self {
        NumberFormat {
            decimals: 3,
            trailing_zeros: TrailingZeros::Keep,
            leading_zero: true,
            plus_sign: false,
            modulo: None,
        }
    }
}

/// Why a value cannot be written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NumberError {
    /// NaN or infinite.
    NotFinite,
    /// `|value| * 10^decimals >= 2^53`.
    OutOfRange,
}

impl std::fmt::Display for NumberError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            NumberError::NotFinite => "value is not finite",
            NumberError::OutOfRange => "value is too large to be written",
        })
    }
}

/// A [`NumberFormat`] prepared for the hot path.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Formatter {
    decimals: u32,
    scale: f64,
    /// Period in units, 0 when there is none.
    modulo_units: i64,
    trailing: TrailingZeros,
    leading_zero: bool,
    plus_sign: bool,
}

impl NumberFormat {
    /// Checks the format; the message names the offending setting.
    pub fn validate(&self) -> Result<(), String> {
        if self.decimals > MAX_DECIMALS {
            return Err(format!(
                "decimals must be between 0 and {MAX_DECIMALS}, not {}",
                self.decimals
            ));
        }
        if let Some(m) = self.modulo {
            let units = m * POW10[self.decimals as usize];
            if !(m > 0.0 && units < UNIT_LIMIT) {
                return Err(format!("`modulo` must be a positive number, not {m}"));
            }
            if (units - units.round()).abs() > 1e-6 * units.max(1.0) {
                return Err(format!(
                    "`modulo` {m} is not a whole number of units of 10^-{} (the axis decimals)",
                    self.decimals
                ));
            }
        }
        Ok(())
    }

    pub(crate) fn formatter(&self) -> Formatter {
        let decimals = u32::from(self.decimals.min(MAX_DECIMALS));
        let scale = POW10[decimals as usize];
        Formatter {
            decimals,
            scale,
            modulo_units: self.modulo.map_or(0, |m| (m * scale).round() as i64),
            trailing: self.trailing_zeros,
            leading_zero: self.leading_zero,
            plus_sign: self.plus_sign,
        }
    }

    /// The value exactly as it is written: rounded to `decimals`, reduced
    /// modulo `modulo`. Values that cannot be written (non-finite, too large)
    /// are returned unchanged.
    pub fn quantize(&self, value: f64) -> f64 {
        self.formatter().quantize(value)
    }

    /// Appends the formatted value to `out` (no allocation beyond growing `out`).
    pub fn write(&self, out: &mut Vec<u8>, value: f64) -> Result<(), NumberError> {
        self.formatter().write(out, value)
    }

    /// The value formatted as a new string (convenience, not for hot paths).
    pub fn format(&self, value: f64) -> Result<String, NumberError> {
        let mut v = Vec::with_capacity(24);
        self.write(&mut v, value)?;
        // Only ASCII digits, signs and points are written.
        Ok(String::from_utf8(v).unwrap_or_default())
    }
}

impl Formatter {
    /// The value in units of `10^-decimals`, modulo applied.
    #[inline]
    pub(crate) fn units(&self, value: f64) -> Result<i64, NumberError> {
        let p = value * self.scale;
        // NaN fails this test too.
        if p.abs() >= UNIT_LIMIT || p.is_nan() {
            return Err(if value.is_finite() {
                NumberError::OutOfRange
            } else {
                NumberError::NotFinite
            });
        }
        // Truncation is one instruction (`round` may be a libm call).
        let t = p as i64;
        // Exact: |p| < 2^53, `t` has the sign of `p` and |p - t| < 1.
        let frac = p - t as f64;
        // `p` is within half an ulp of the exact product; only when it lies
        // that close to a half does the rounding direction need the exact value.
        let mut n = if (frac.abs() - 0.5).abs() <= p.abs() * 4.5e-16 {
            exact_units(value, self.decimals)
        } else if frac > 0.5 {
            t + 1
        } else if frac < -0.5 {
            t - 1
        } else {
            t
        };
        if self.modulo_units > 0 {
            n = n.rem_euclid(self.modulo_units);
        }
        Ok(n)
    }

    /// `units / 10^decimals`: the value as it is written.
    #[inline]
    pub(crate) fn value_of_units(&self, n: i64) -> f64 {
        n as f64 / self.scale
    }

    #[inline]
    pub(crate) fn quantize(&self, value: f64) -> f64 {
        match self.units(value) {
            Ok(n) => self.value_of_units(n),
            Err(_) => value,
        }
    }

    #[inline]
    pub(crate) fn write(&self, out: &mut Vec<u8>, value: f64) -> Result<(), NumberError> {
        let n = self.units(value)?;
        self.write_units(out, n);
        Ok(())
    }

    /// Writes an integer number of units as a decimal number.
    #[inline]
    pub(crate) fn write_units(&self, out: &mut Vec<u8>, n: i64) {
        let start = out.len();
        out.resize(start + ENCODE_MAX, 0);
        let end = self.encode_into(n, out, start);
        out.truncate(end);
    }

    /// Writes the text of `n` units into `buf` at `at` and returns where it
    /// ends. Writes at most [`ENCODE_MAX`] bytes (so `buf` must have that
    /// room), each byte once and in place (no scratch copy).
    #[inline(always)]
    pub(crate) fn encode_into(&self, n: i64, buf: &mut [u8], at: usize) -> usize {
        let d = self.decimals as usize;
        let mut u = n.unsigned_abs();
        let digits = decimal_digits(u);
        let mut p = at;
        if n < 0 {
            buf[p] = b'-';
            p += 1;
        } else if self.plus_sign {
            buf[p] = b'+';
            p += 1;
        }
        let int_len = if digits > d {
            digits - d
        } else {
            // Integer part 0: written unless a fraction digit follows and
            // leading zeros are off.
            let frac_written = match self.trailing {
                TrailingZeros::Keep => d > 0,
                _ => u != 0,
            };
            usize::from(self.leading_zero || !frac_written)
        };
        let point = p + int_len;
        let full_end = if d > 0 { point + 1 + d } else { point };
        // Fraction digits, backwards, two at a time.
        let mut q = full_end;
        for _ in 0..d / 2 {
            let two = (u % 100) as usize * 2;
            u /= 100;
            q -= 2;
            buf[q..q + 2].copy_from_slice(&DIGITS2[two..two + 2]);
        }
        if d % 2 == 1 {
            q -= 1;
            buf[q] = b'0' + (u % 10) as u8;
            u /= 10;
        }
        // Integer digits, backwards, two at a time.
        let mut q = point;
        while u >= 100 {
            let two = (u % 100) as usize * 2;
            u /= 100;
            q -= 2;
            buf[q..q + 2].copy_from_slice(&DIGITS2[two..two + 2]);
        }
        if u >= 10 {
            let two = u as usize * 2;
            q -= 2;
            buf[q..q + 2].copy_from_slice(&DIGITS2[two..two + 2]);
        } else if q > p {
            q -= 1;
            buf[q] = b'0' + u as u8;
        }
        debug_assert_eq!(q, p);
        if d == 0 {
            if self.trailing == TrailingZeros::Point {
                buf[point] = b'.';
                return point + 1;
            }
            return point;
        }
        buf[point] = b'.';
        let mut end = full_end;
        if self.trailing != TrailingZeros::Keep {
            while end > point + 1 && buf[end - 1] == b'0' {
                end -= 1;
            }
            if end == point + 1 && self.trailing == TrailingZeros::Trim {
                end = point;
            }
        }
        end
    }
}

/// Longest text of a number: sign, 16 digits (|units| < 2^53), a leading
/// zero and the point, rounded up.
pub(crate) const ENCODE_MAX: usize = 24;

/// Correctly rounded (ties to even) `value * 10^decimals` as an integer,
/// computed from the exact binary value. Only called near ties.
#[cold]
fn exact_units(value: f64, decimals: u32) -> i64 {
    let bits = value.to_bits();
    let negative = bits >> 63 == 1;
    let exp_bits = ((bits >> 52) & 0x7ff) as i32;
    let fraction = bits & ((1u64 << 52) - 1);
    let (mantissa, exp) = if exp_bits == 0 {
        (fraction, -1074)
    } else {
        (fraction | (1u64 << 52), exp_bits - 1075)
    };
    // value * 10^d = mantissa * 5^d * 2^(exp + d)
    let m = u128::from(mantissa) * POW5[decimals as usize];
    let k = exp + decimals as i32;
    let magnitude: u128 = if k >= 0 {
        m << k.min(64)
    } else {
        let shift = (-k) as u32;
        if shift >= 127 {
            0
        } else {
            let q = m >> shift;
            let rem = m - (q << shift);
            let half = 1u128 << (shift - 1);
            if rem > half || (rem == half && q & 1 == 1) {
                q + 1
            } else {
                q
            }
        }
    };
    let magnitude = magnitude.min(i64::MAX as u128) as i64;
    if negative { -magnitude } else { magnitude }
}

const DIGITS2: &[u8; 200] = b"\
0001020304050607080910111213141516171819\
2021222324252627282930313233343536373839\
4041424344454647484950515253545556575859\
6061626364656667686970717273747576777879\
8081828384858687888990919293949596979899";

const POW10_U64: [u64; 20] = {
    let mut t = [1u64; 20];
    let mut i = 1;
    while i < 20 {
        t[i] = t[i - 1] * 10;
        i += 1;
    }
    t
};

/// Number of decimal digits of `u` (1 for 0), from the bit length.
#[inline]
fn decimal_digits(u: u64) -> usize {
    let bits = 64 - (u | 1).leading_zeros();
    // floor(log10(2^bits)) or one more.
    let t = ((bits * 1233) >> 12) as usize;
    (t + usize::from(u >= POW10_U64[t])).max(1)
}

/// Appends an unsigned integer in decimal, at least `min_digits` digits.
#[inline]
pub(crate) fn write_u64(out: &mut Vec<u8>, mut u: u64, min_digits: usize) {
    let mut tmp = [b'0'; 24];
    let mut pos = tmp.len();
    while u >= 10 {
        pos -= 1;
        tmp[pos] = b'0' + (u % 10) as u8;
        u /= 10;
    }
    pos -= 1;
    tmp[pos] = b'0' + u as u8;
    let start = pos.min(tmp.len() - min_digits.clamp(1, tmp.len()));
    out.extend_from_slice(&tmp[start..]);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn f(
        decimals: u8,
        trailing_zeros: TrailingZeros,
        leading_zero: bool,
        plus_sign: bool,
    ) -> NumberFormat {
        NumberFormat {
            decimals,
            trailing_zeros,
            leading_zero,
            plus_sign,
            modulo: None,
        }
    }

    #[test]
    fn styles() {
        use TrailingZeros::*;
        let keep = f(3, Keep, true, false);
        assert_eq!(keep.format(459.0).unwrap(), "459.000");
        assert_eq!(keep.format(8.80694).unwrap(), "8.807");
        assert_eq!(keep.format(-0.0001).unwrap(), "0.000");
        assert_eq!(keep.format(-0.0).unwrap(), "0.000");
        assert_eq!(keep.format(-1.5).unwrap(), "-1.500");
        assert_eq!(f(3, Point, true, false).format(459.0).unwrap(), "459.");
        assert_eq!(f(3, Point, true, false).format(640.0).unwrap(), "640.");
        assert_eq!(f(3, Trim, true, false).format(250.0).unwrap(), "250");
        assert_eq!(f(3, Trim, true, false).format(8.8).unwrap(), "8.8");
        assert_eq!(f(3, Trim, false, false).format(0.5).unwrap(), ".5");
        assert_eq!(f(3, Trim, false, false).format(-0.5).unwrap(), "-.5");
        assert_eq!(f(3, Trim, false, false).format(0.0).unwrap(), "0");
        assert_eq!(f(3, Point, false, false).format(0.0).unwrap(), "0.");
        assert_eq!(f(3, Keep, true, true).format(1.0).unwrap(), "+1.000");
        assert_eq!(f(3, Keep, true, true).format(0.0).unwrap(), "+0.000");
        assert_eq!(f(0, Keep, true, false).format(2.5).unwrap(), "2");
        assert_eq!(f(0, Point, true, false).format(3.5).unwrap(), "4.");
        assert_eq!(keep.format(0.0625).unwrap(), "0.062");
        assert_eq!(
            f(9, Keep, true, false).format(-123456.123456789).unwrap(),
            "-123456.123456789"
        );
        assert_eq!(keep.format(f64::NAN), Err(NumberError::NotFinite));
        assert_eq!(keep.format(1e300), Err(NumberError::OutOfRange));
    }

    #[test]
    fn modulo() {
        let m = NumberFormat {
            modulo: Some(360.0),
            ..NumberFormat::default()
        };
        assert_eq!(m.format(-90.0).unwrap(), "270.000");
        assert_eq!(m.format(359.9996).unwrap(), "0.000");
        assert_eq!(m.format(720.25).unwrap(), "0.250");
        assert_eq!(m.quantize(-0.0004), 0.0);
        assert_eq!(m.quantize(-90.00049), 270.0);
    }

    #[test]
    fn digit_counts() {
        for u in [0u64, 1, 9, 10, 99, 100, 999_999, 1_000_000, u64::MAX] {
            assert_eq!(decimal_digits(u), u.to_string().len(), "{u}");
        }
        for (k, &p) in POW10_U64.iter().enumerate().skip(1) {
            assert_eq!(decimal_digits(p - 1), k);
            assert_eq!(decimal_digits(p), k + 1);
        }
    }

    #[test]
    fn integers() {
        let mut v = Vec::new();
        write_u64(&mut v, 0, 0);
        write_u64(&mut v, 42, 4);
        write_u64(&mut v, 12345, 2);
        assert_eq!(v, b"0004212345");
    }
}
