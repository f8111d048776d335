//! Decimal numbers as the text of NC and CL words: allocation-free
//! fixed-point formatting, shared by the NC writers and the CL writer.
//!
//! A value is quantized to an integer number of units of `10^-decimals`
//! (correctly rounded from the exact binary value, ties to even, exactly as
//! `format!("{:.d$}")` rounds), optionally reduced modulo a period, and then
//! printed from that integer. [`NumberFormat::quantize`] returns
//! `units as f64 / 10^decimals`, which is bit for bit the number that
//! `str::parse::<f64>()` gives for the printed text.

#![deny(missing_docs)]

use serde::Deserialize;

/// Largest number of decimals a word may have.
pub const MAX_DECIMALS: u8 = 9;

/// Largest magnitude (in units of `10^-decimals`) that can be written: 2^53,
/// below which every integer is exactly representable as `f64`.
const UNIT_LIMIT: f64 = 9_007_199_254_740_992.0;

/// Below this magnitude `p + ROUND_MAGIC` rounds `p` to an integer that
/// the low bits of the sum hold (ulp 1, `p + ROUND_MAGIC` in [2^52, 2^53)).
const ROUND_LIMIT: f64 = 2_251_799_813_685_248.0; // 2^51
/// 1.5 * 2^52.
const ROUND_MAGIC: f64 = 6_755_399_441_055_744.0;

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

/// Why a [`NumberFormat`] cannot be used.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FormatError {
    /// More decimals than [`MAX_DECIMALS`].
    Decimals(u8),
    /// A period that is not a positive number small enough to write.
    ModuloNotPositive(f64),
    /// A period that is not a whole number of units of the last decimal.
    ModuloNotWhole {
        /// The period.
        modulo: f64,
        /// The decimals.
        decimals: u8,
    },
}

impl std::fmt::Display for FormatError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            FormatError::Decimals(d) => {
                write!(f, "decimals must be between 0 and {MAX_DECIMALS}, not {d}")
            }
            FormatError::ModuloNotPositive(m) => {
                write!(f, "`modulo` must be a positive number, not {m}")
            }
            FormatError::ModuloNotWhole { modulo, decimals } => write!(
                f,
                "`modulo` {modulo} is not a whole number of units of 10^-{decimals} (the axis decimals)"
            ),
        }
    }
}

impl std::error::Error for FormatError {}

/// A [`NumberFormat`] prepared for the hot path.
#[derive(Debug, Clone, Copy)]
pub struct Formatter {
    decimals: u32,
    scale: f64,
    /// Period in units, 0 when there is none.
    modulo_units: i64,
    trailing: TrailingZeros,
    leading_zero: bool,
    plus_sign: bool,
    /// 1..=7 decimals: [`Formatter::encode_into`] takes the word-at-a-time
    /// path ([`Formatter::encode_fast`]).
    fast: bool,
    /// Fast path: most leading zeros of eight digits that are left out,
    /// `8 - decimals - leading_zero`.
    max_skip: u32,
    /// Fast path: integer digits among eight, `8 - decimals`.
    int_digits: usize,
    /// Fast path: `8 * (8 - decimals)`, the shift that leaves the fraction
    /// digits of eight.
    fraction_shift: u32,
}

impl NumberFormat {
    /// Checks the format; the error names the offending setting.
    pub fn validate(&self) -> Result<(), FormatError> {
        if self.decimals > MAX_DECIMALS {
            return Err(FormatError::Decimals(self.decimals));
        }
        if let Some(m) = self.modulo {
            let units = m * POW10[self.decimals as usize];
            if !(m > 0.0 && units < UNIT_LIMIT) {
                return Err(FormatError::ModuloNotPositive(m));
            }
            if (units - units.round()).abs() > 1e-6 * units.max(1.0) {
                return Err(FormatError::ModuloNotWhole {
                    modulo: m,
                    decimals: self.decimals,
                });
            }
        }
        Ok(())
    }

    /// The format prepared for writing many values.
    pub fn formatter(&self) -> Formatter {
        let decimals = u32::from(self.decimals.min(MAX_DECIMALS));
        let scale = POW10[decimals as usize];
        Formatter {
            decimals,
            scale,
            modulo_units: self.modulo.map_or(0, |m| (m * scale).round() as i64),
            trailing: self.trailing_zeros,
            leading_zero: self.leading_zero,
            plus_sign: self.plus_sign,
            fast: (1..=7).contains(&decimals),
            max_skip: 8u32.saturating_sub(decimals + u32::from(self.leading_zero)),
            int_digits: 8usize.saturating_sub(decimals as usize),
            fraction_shift: 8 * 8u32.saturating_sub(decimals),
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
    /// The value of `units` (units of `10^-decimals`, as
    /// [`Formatter::units`] gives them).
    #[inline]
    pub fn value(&self, units: i64) -> f64 {
        units as f64 / self.scale
    }

    /// The value in units of `10^-decimals`, modulo applied.
    #[inline]
    pub fn units(&self, value: f64) -> Result<i64, NumberError> {
        let p = value * self.scale;
        // Below 2^51, adding 1.5 * 2^52 rounds `p` to an integer (to
        // nearest) that the low bits of the sum hold; NaN and larger values
        // take the slow path.
        // One unordered comparison: NaN fails it too.
        #[allow(clippy::neg_cmp_op_on_partial_ord)]
        if !(p.abs() < ROUND_LIMIT) {
            return self.units_slow(value);
        }
        let sum = p + ROUND_MAGIC;
        let mut n = sum.to_bits() as i64 - ROUND_MAGIC.to_bits() as i64;
        // Exact: `sum - ROUND_MAGIC` is the integer `n`, and `p - n` is
        // exact (|p - n| <= 0.5 and `n` is within a factor 2 of `p`, or 0).
        let off = p - (sum - ROUND_MAGIC);
        // `p` is within half an ulp of the exact product; only when it lies
        // that close to a half does the rounding direction need the exact value.
        if 0.5 - off.abs() <= p.abs() * 4.5e-16 {
            n = exact_units(value, self.decimals);
        }
        Ok(self.reduce(n))
    }

    /// [`Formatter::units`] for values that are not finite or whose units
    /// are at least 2^51 in magnitude.
    #[cold]
    #[inline(never)]
    fn units_slow(&self, value: f64) -> Result<i64, NumberError> {
        let p = value * self.scale;
        // NaN fails this test too.
        if p.abs() >= UNIT_LIMIT || p.is_nan() {
            return Err(if value.is_finite() {
                NumberError::OutOfRange
            } else {
                NumberError::NotFinite
            });
        }
        let t = p as i64;
        // Exact: |p| < 2^53, `t` has the sign of `p` and |p - t| < 1.
        let frac = p - t as f64;
        let n = if (frac.abs() - 0.5).abs() <= p.abs() * 4.5e-16 {
            exact_units(value, self.decimals)
        } else if frac > 0.5 {
            t + 1
        } else if frac < -0.5 {
            t - 1
        } else {
            t
        };
        Ok(self.reduce(n))
    }

    /// `n` reduced modulo the period, if there is one.
    #[inline(always)]
    fn reduce(&self, n: i64) -> i64 {
        // Values already in [0, period) need no division.
        if self.modulo_units > 0 && !(n >= 0 && n < self.modulo_units) {
            n.rem_euclid(self.modulo_units)
        } else {
            n
        }
    }

    /// `units / 10^decimals`: the value as it is written.
    #[inline]
    pub fn value_of_units(&self, n: i64) -> f64 {
        n as f64 / self.scale
    }

    /// The value as it is written (unchanged when it cannot be).
    #[inline]
    pub fn quantize(&self, value: f64) -> f64 {
        match self.units(value) {
            Ok(n) => self.value_of_units(n),
            Err(_) => value,
        }
    }

    /// Appends the value's text to `out`.
    #[inline]
    pub fn write(&self, out: &mut Vec<u8>, value: f64) -> Result<(), NumberError> {
        let n = self.units(value)?;
        self.write_units(out, n);
        Ok(())
    }

    /// Writes an integer number of units as a decimal number.
    #[inline]
    pub fn write_units(&self, out: &mut Vec<u8>, n: i64) {
        let start = out.len();
        out.resize(start + ENCODE_MAX, 0);
        let end = self.encode_into(n, out, start);
        out.truncate(end);
    }

    /// Writes the text of `n` units into `buf` at `at` and returns where it
    /// ends. Writes at most [`ENCODE_MAX`] bytes (so `buf` must have that
    /// room; bytes past the returned end may be overwritten too).
    #[inline(always)]
    pub fn encode_into(&self, n: i64, buf: &mut [u8], at: usize) -> usize {
        if self.fast {
            self.encode_fast(n, buf, at)
        } else {
            self.encode_general(n, buf, at)
        }
    }

    /// [`Formatter::encode_into`] for 1..=7 decimals, eight digits at a
    /// time: the digits of `|n|` (of its last eight digits, when it has
    /// more) are made in one `u64` and stored twice, the integer part with
    /// the fraction after it, then the point and the fraction over that
    /// fraction.
    #[inline(always)]
    fn encode_fast(&self, n: i64, buf: &mut [u8], at: usize) -> usize {
        let d = self.decimals as usize;
        debug_assert!((1..=7).contains(&d));
        let u = n.unsigned_abs();
        // The sign byte is always stored ('+' or, two higher, '-'), and kept
        // when it is wanted.
        let negative = (n as u64 >> 63) as u8;
        buf[at] = b'+' + 2 * negative;
        let mut p = at + usize::from(negative | u8::from(self.plus_sign));
        // `digits`: eight digits of `u` (the last eight when it has more),
        // `skip`: how many of them, from the first, are not written.
        let (digits, skip) = if u < 100_000_000 {
            let raw = digit_values8(u as u32);
            // Leading zero digits (0..=7: the last digit always counts).
            let zeros = (raw | 1 << 56).trailing_zeros() / 8;
            (raw | ASCII_ZEROS, zeros.min(self.max_skip))
        } else {
            // The digits before the last eight: `u < 2^53`, so at most eight.
            let high = u / 100_000_000;
            let raw = digit_values8(high as u32);
            let zeros = raw.trailing_zeros() / 8;
            store8(buf, p, (raw | ASCII_ZEROS) >> (8 * zeros));
            p += 8 - zeros as usize;
            (ascii8((u % 100_000_000) as u32), 0)
        };
        store8(buf, p, digits >> (8 * skip));
        let point = p + self.int_digits - skip as usize;
        let fraction = digits >> self.fraction_shift;
        store8(buf, point, (fraction << 8) | u64::from(b'.'));
        if self.trailing == TrailingZeros::Keep {
            return point + 1 + d;
        }
        // Fraction digits that are not '0', as non-zero bytes.
        let nonzero = fraction ^ (ASCII_ZEROS >> self.fraction_shift);
        if nonzero != 0 {
            return point + 1 + (71 - nonzero.leading_zeros() as usize) / 8;
        }
        // No fraction digit: the integer part is written even without
        // leading zeros (`0`, `0.`).
        if point == p {
            buf[point] = b'0';
            buf[point + 1] = b'.';
            point + 1 + usize::from(self.trailing == TrailingZeros::Point)
        } else {
            point + usize::from(self.trailing == TrailingZeros::Point)
        }
    }

    /// [`Formatter::encode_into`] for any number of decimals, digit pair by
    /// digit pair.
    #[inline(always)]
    pub fn encode_general(&self, n: i64, buf: &mut [u8], at: usize) -> usize {
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
pub const ENCODE_MAX: usize = 24;

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

/// Eight ASCII `'0'`.
const ASCII_ZEROS: u64 = 0x3030_3030_3030_3030;

/// The eight decimal digits of `x < 10^8` as ASCII, most significant first
/// in memory order (little-endian), leading zeros included: the integer
/// is split into four pairs of digits in 16-bit lanes, then each pair into
/// two digits, all lanes at once (multiplications by reciprocals that are
/// exact in these ranges).
#[inline(always)]
fn ascii8(x: u32) -> u64 {
    digit_values8(x) | ASCII_ZEROS
}

/// [`ascii8`] without the ASCII: digit values 0..=9 in the bytes.
#[inline(always)]
fn digit_values8(x: u32) -> u64 {
    debug_assert!(x < 100_000_000);
    // Two lanes of 32 bits: the upper four digits, the lower four.
    let merged = u64::from(x / 10_000) | (u64::from(x % 10_000) << 32);
    // Per lane / 100 (10486 / 2^20, exact below 10^4).
    let hundreds = ((merged * 10486) >> 20) & ((0x7f << 32) | 0x7f);
    let pairs = ((merged - 100 * hundreds) << 16) | hundreds;
    // Four lanes of 16 bits, each / 10 (103 / 2^10, exact below 100).
    let tens = ((pairs * 103) >> 10) & 0x000f_000f_000f_000f;
    tens | ((pairs - 10 * tens) << 8)
}

/// Stores `v` little-endian at `at`.
#[inline(always)]
fn store8(buf: &mut [u8], at: usize, v: u64) {
    buf[at..at + 8].copy_from_slice(&v.to_le_bytes());
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

/// Writes `u` in decimal at `at` and returns where it ends; writes up to
/// 20 bytes (`buf` must have that room).
#[inline]
pub fn encode_u64(buf: &mut [u8], at: usize, u: u64) -> usize {
    if u < 100_000_000 {
        let raw = digit_values8(u as u32);
        // Leading zero digits (the last digit always counts).
        let zeros = (raw | 1 << 56).trailing_zeros() / 8;
        store8(buf, at, (raw | ASCII_ZEROS) >> (8 * zeros));
        at + 8 - zeros as usize
    } else {
        let mut digits = [0u8; 20];
        let mut first = digits.len();
        let mut u = u;
        while u > 0 {
            first -= 1;
            digits[first] = b'0' + (u % 10) as u8;
            u /= 10;
        }
        let len = digits.len() - first;
        buf[at..at + len].copy_from_slice(&digits[first..]);
        at + len
    }
}

/// Appends an unsigned integer in decimal, at least `min_digits` digits.
#[inline]
pub fn write_u64(out: &mut Vec<u8>, mut u: u64, min_digits: usize) {
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
    use proptest::prelude::*;

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
    fn ascii8_digits() {
        let check = |x: u32| assert_eq!(ascii8(x).to_le_bytes(), *format!("{x:08}").as_bytes());
        (0..200_000).for_each(check);
        (0..100_000_000).step_by(9_973).for_each(check);
        (99_800_000..100_000_000).for_each(check);
        for k in 0..8 {
            let p = 10u32.pow(k);
            [p - 1, p, p + 1, 99_999_999 / p * p]
                .into_iter()
                .for_each(check);
        }
    }

    /// Units near the powers of ten and the ends of the range.
    fn units_strategy() -> impl Strategy<Value = i64> {
        prop_oneof![
            -2_000_000i64..2_000_000,
            -(1i64 << 53) + 1..1i64 << 53,
            -1_000_000_000_000i64..1_000_000_000_000,
            (0u32..16, -3i64..=3, any::<bool>()).prop_map(|(k, off, neg)| {
                let n = 10i64.pow(k) + off;
                if neg { -n } else { n }
            }),
            Just((1i64 << 53) - 1),
            Just(-(1i64 << 53) + 1),
            Just(0),
        ]
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(20_000))]

        /// The word-at-a-time path writes the same bytes as the general one,
        /// for every style.
        #[test]
        fn fast_encoding_matches_general(
            n in units_strategy(),
            decimals in 0u8..=9,
            trailing in 0usize..3,
            leading_zero: bool,
            plus_sign: bool,
            at in 0usize..3,
        ) {
            let format = NumberFormat {
                decimals,
                trailing_zeros: [TrailingZeros::Keep, TrailingZeros::Point, TrailingZeros::Trim][trailing],
                leading_zero,
                plus_sign,
                modulo: None,
            };
            let f = format.formatter();
            let mut fast = vec![0xAAu8; at + ENCODE_MAX];
            let mut general = vec![0x55u8; at + ENCODE_MAX];
            let end_fast = f.encode_into(n, &mut fast, at);
            let end_general = f.encode_general(n, &mut general, at);
            prop_assert_eq!(
                &fast[at..end_fast],
                &general[at..end_general],
                "{} units, {:?}", n, format
            );
        }

        /// The rounding with the magic constant gives the units of the
        /// original truncating rounding, ties and modulo included.
        #[test]
        fn units_match_slow_path(
            v in prop_oneof![
                -1e6..1e6f64,
                -1e-3..1e-3f64,
                -1e16..1e16f64,
                (-10_000_000i64..10_000_000, 0u32..10).prop_map(|(k, d)| (k as f64 + 0.5) / 10f64.powi(d as i32)),
                (-10_000_000i64..10_000_000, 0u32..10, -2i64..=2).prop_map(|(k, d, ulps)| {
                    let x = (k as f64 + 0.5) / 10f64.powi(d as i32);
                    f64::from_bits((x.to_bits() as i64 + ulps) as u64)
                }),
                Just(f64::NAN),
                Just(f64::INFINITY),
            ],
            decimals in 0u8..=9,
            modulo in proptest::option::of(prop_oneof![
                Just(360.0), Just(1.0), Just(0.001)
            ]),
        ) {
            let format = NumberFormat { decimals, modulo, ..NumberFormat::default() };
            if format.validate().is_ok() {
                let f = format.formatter();
                prop_assert_eq!(f.units(v), f.units_slow(v), "{:e} {:?}", v, format);
            }
        }
    }

    #[test]
    fn encoded_integers() {
        let mut buf = [0xAAu8; 24];
        for u in (0..2000u64)
            .chain([99_999_999, 100_000_000, 123_456_789_012, u64::MAX])
            .chain((0..64).map(|k| 1u64 << k))
        {
            let end = encode_u64(&mut buf, 2, u);
            assert_eq!(&buf[2..end], u.to_string().as_bytes());
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
