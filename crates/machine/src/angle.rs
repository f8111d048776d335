//! Sine and cosine of an angle in degrees and the angle of a direction in
//! degrees: the two transcendental functions of the kinematics hot path,
//! written out because the library calls they replace (`sin_cos` of
//! `to_radians`, `atan2` then `to_degrees`) cost three to four times as much
//! and were a tenth of the posting time.
//!
//! The polynomials are those of fdlibm (FreeBSD msun `k_sin.c`, `k_cos.c`:
//! minimax on |x| ≤ π/4, error below 2^-58; `s_atan.c`: arctangent on
//! [0, 7/16] and its reduction by atan(1/2) and atan(1) with their low
//! parts). Angles are reduced in degrees, which is exact: the result is at
//! least as accurate as the library's through radians (within 2 ulp of it,
//! tested below against the library), and exact at multiples of 90°.
//!
//! The constants are written as fdlibm prints them, to more digits than a
//! double holds; they round to fdlibm's bits.
#![allow(clippy::excessive_precision)]

/// `(sin, cos)` of `deg` degrees.
#[inline]
pub fn sin_cos_deg(deg: f64) -> (f64, f64) {
    // Beyond 2^40 degrees (and for NaN and infinities) the library decides.
    if deg.is_nan() || deg.abs() > 1_099_511_627_776.0 {
        return deg.to_radians().sin_cos();
    }
    // k = the nearest quarter turn, by the 1.5·2^52 rounding trick (no
    // library `round` on baseline x86-64); r = deg − 90k is exact (Sterbenz:
    // deg lies within a factor 2 of 90k when k ≠ 0) and |r| ≤ 45 + ε.
    const ROUND: f64 = 6_755_399_441_055_744.0;
    let rounded = deg * (1.0 / 90.0) + ROUND;
    let k = rounded - ROUND;
    let r = deg - 90.0 * k;
    let x = r * (std::f64::consts::PI / 180.0);
    let (s, c) = (sin_kernel(x), cos_kernel(x));
    // The quadrant k mod 4 from the low bits of 1.5·2^52 + k (|k| < 2^51;
    // 2^51 is 0 mod 4): no float-to-integer conversion, which saturates.
    match rounded.to_bits() & 3 {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

/// [`sin_cos_deg`] of the last angle of each axis, remembered by its bits:
/// the value written for a rotary axis repeats from block to block while the
/// axis turns less than its last decimal, and its sine and cosine need not be
/// worked out again. Gives the bits [`sin_cos_deg`] gives.
#[derive(Debug, Clone)]
pub struct SinCosMemo {
    last: [(u64, (f64, f64)); crate::MAX_AXES],
}

impl Default for SinCosMemo {
    /// Every axis at 0° (whose sine and cosine are exact).
    fn default() -> Self {
        SinCosMemo {
            last: [(0f64.to_bits(), (0.0, 1.0)); crate::MAX_AXES],
        }
    }
}

impl SinCosMemo {
    /// `sin_cos_deg(deg)` for axis `axis` (below [`crate::MAX_AXES`]).
    #[inline(always)]
    pub fn sin_cos_deg(&mut self, axis: usize, deg: f64) -> (f64, f64) {
        let slot = &mut self.last[axis];
        if slot.0 != deg.to_bits() {
            *slot = (deg.to_bits(), sin_cos_deg(deg));
        }
        slot.1
    }
}

/// sin x for |x| ≤ π/4 (fdlibm `__kernel_sin` with no tail).
#[inline(always)]
fn sin_kernel(x: f64) -> f64 {
    const S1: f64 = -1.666_666_666_666_663_243_48e-1;
    const S2: f64 = 8.333_333_333_322_489_461_24e-3;
    const S3: f64 = -1.984_126_982_985_794_931_34e-4;
    const S4: f64 = 2.755_731_370_707_006_767_89e-6;
    const S5: f64 = -2.505_076_025_340_686_341_95e-8;
    const S6: f64 = 1.589_690_995_211_550_102_21e-10;
    let z = x * x;
    let w = z * z;
    let r = S2 + z * (S3 + z * S4) + z * w * (S5 + z * S6);
    x + z * x * (S1 + z * r)
}

/// cos x for |x| ≤ π/4 (fdlibm `__kernel_cos` with no tail: `1 − z/2`
/// split so that its rounding error is recovered).
#[inline(always)]
fn cos_kernel(x: f64) -> f64 {
    const C1: f64 = 4.166_666_666_666_660_190_37e-2;
    const C2: f64 = -1.388_888_888_887_410_957_49e-3;
    const C3: f64 = 2.480_158_728_947_672_941_78e-5;
    const C4: f64 = -2.755_731_435_139_066_330_35e-7;
    const C5: f64 = 2.087_572_321_298_174_827_90e-9;
    const C6: f64 = -1.135_964_755_778_819_482_65e-11;
    let z = x * x;
    let w = z * z;
    let r = z * (C1 + z * (C2 + z * C3)) + w * w * (C4 + z * (C5 + z * C6));
    let hz = 0.5 * z;
    let one_minus_hz = 1.0 - hz;
    one_minus_hz + (((1.0 - one_minus_hz) - hz) + z * r)
}

/// The angle of the direction `(x, y)` in degrees, in [−180, 180]: what
/// `f64::atan2(y, x).to_degrees()` gives, within 2 ulp.
#[inline]
pub fn atan2_deg(y: f64, x: f64) -> f64 {
    atan2_rad(y, x).to_degrees()
}

/// The angle between two unit vectors in radians, accurate for small
/// angles (`atan2` of the cross and dot products, as
/// `a.cross(b).norm().atan2(a.dot(b))` within 2 ulp, at about half the
/// cost of the library's `atan2`).
#[inline]
pub fn angle_between(a: &nalgebra::Vector3<f64>, b: &nalgebra::Vector3<f64>) -> f64 {
    atan2_rad(a.cross(b).norm(), a.dot(b))
}

/// The angle of the direction `(x, y)` in radians, in [−π, π]: what
/// `f64::atan2(y, x)` gives, within 2 ulp.
#[inline(always)]
pub fn atan2_rad(y: f64, x: f64) -> f64 {
    // π/2 and π as a rounded value and what it leaves out.
    const PI_2_HI: f64 = std::f64::consts::FRAC_PI_2;
    const PI_2_LO: f64 = 6.123_233_995_736_766_036e-17;
    const PI_HI: f64 = std::f64::consts::PI;
    const PI_LO: f64 = 1.224_646_799_147_353_207e-16;
    let (ax, ay) = (x.abs(), y.abs());
    // Zeros, infinities and NaN: the library's conventions.
    if !(ax.is_finite() && ay.is_finite()) || (ax == 0.0 && ay == 0.0) {
        return f64::atan2(y, x);
    }
    // The angle of (|x|, |y|) in [0, π/2], from an arctangent on [0, 1].
    let mut a = if ay <= ax {
        atan_01(ay / ax)
    } else {
        PI_2_HI - (atan_01(ax / ay) - PI_2_LO)
    };
    // (x = −0 counts as +0, as the library has it: atan2(±y, −0) = ±π/2
    // exactly, where π − (π/2 − lo) would be an ulp off.)
    if x < 0.0 {
        a = PI_HI - (a - PI_LO);
    }
    if y.is_sign_negative() {
        a = -a;
    }
    a
}

/// atan t for 0 ≤ t ≤ 1 (fdlibm `atan` on that range).
#[inline(always)]
fn atan_01(t: f64) -> f64 {
    const AT: [f64; 11] = [
        3.333_333_333_333_293_180_27e-1,
        -1.999_999_999_987_648_324_76e-1,
        1.428_571_427_250_346_637_11e-1,
        -1.111_111_040_546_235_578_80e-1,
        9.090_887_133_436_506_561_96e-2,
        -7.691_876_205_044_829_994_95e-2,
        6.661_073_137_387_531_206_69e-2,
        -5.833_570_133_790_573_486_45e-2,
        4.976_877_994_615_932_360_17e-2,
        -3.653_157_274_421_691_552_70e-2,
        1.628_582_011_536_578_236_23e-2,
    ];
    // atan(1/2) and atan(1), rounded, and what the rounding left out.
    const HI: [f64; 2] = [4.636_476_090_008_060_935_15e-1, std::f64::consts::FRAC_PI_4];
    const LO: [f64; 2] = [
        2.269_877_745_296_168_709_24e-17,
        3.061_616_997_868_383_017_93e-17,
    ];
    // Below 7/16 directly; above, atan t = atan c + atan((t − c)/(1 + c·t))
    // for c = 1/2 (up to 11/16) or 1.
    let (id, u) = if t < 0.4375 {
        (None, t)
    } else if t < 0.6875 {
        (Some(0), (2.0 * t - 1.0) / (2.0 + t))
    } else {
        (Some(1), (t - 1.0) / (t + 1.0))
    };
    let z = u * u;
    let w = z * z;
    let s1 = z * (AT[0] + w * (AT[2] + w * (AT[4] + w * (AT[6] + w * (AT[8] + w * AT[10])))));
    let s2 = w * (AT[1] + w * (AT[3] + w * (AT[5] + w * (AT[7] + w * AT[9]))));
    match id {
        None => u - u * (s1 + s2),
        Some(i) => HI[i] - ((u * (s1 + s2) - LO[i]) - u),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Distance in units in the last place (of the larger magnitude).
    fn ulps(a: f64, b: f64) -> f64 {
        if a == b {
            return 0.0;
        }
        let scale = a.abs().max(b.abs());
        (a - b).abs() / (scale * f64::EPSILON)
    }

    #[test]
    fn the_memo_gives_the_bits_of_the_function() {
        let bits = |(s, c): (f64, f64)| (s.to_bits(), c.to_bits());
        let mut memo = SinCosMemo::default();
        // Its initial entries (0°), then misses, hits and a -0.
        for (axis, deg) in [
            (0, 0.0),
            (3, 0.0),
            (3, 12.5),
            (3, 12.5),
            (3, -0.0),
            (8, 1e-300),
        ] {
            assert_eq!(
                bits(memo.sin_cos_deg(axis, deg)),
                bits(sin_cos_deg(deg)),
                "{deg}"
            );
        }
        let nan = memo.sin_cos_deg(1, f64::NAN);
        assert!(nan.0.is_nan() && nan.1.is_nan());
    }

    #[test]
    fn exact_at_quarter_turns() {
        for k in -12i32..=12 {
            let (s, c) = sin_cos_deg(90.0 * f64::from(k));
            let want = [(0.0, 1.0), (1.0, 0.0), (0.0, -1.0), (-1.0, 0.0)][k.rem_euclid(4) as usize];
            // (±0 compare equal.)
            assert!(s == want.0 && c == want.1, "{k}: {s}, {c}");
        }
        assert_eq!(atan2_deg(0.0, 1.0), 0.0);
        assert_eq!(atan2_deg(1.0, 0.0), 90.0);
        assert_eq!(atan2_deg(0.0, -1.0), 180.0);
        assert_eq!(atan2_deg(-1.0, 0.0), -90.0);
        assert_eq!(atan2_deg(1.0, 1.0), 45.0);
        // −0 is +0 for x (as in the library).
        assert_eq!(atan2_deg(1.0, -0.0), 90.0);
        assert_eq!(atan2_deg(-1.0, -0.0), -90.0);
        assert_eq!(atan2_rad(-2.0, -0.0), -std::f64::consts::FRAC_PI_2);
    }

    #[test]
    fn special_values_follow_the_library() {
        let values = [
            0.0,
            -0.0,
            1.0,
            -1.0,
            1e-310,
            -1e-310,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ];
        for &y in &values {
            for &x in &values {
                let (got, want) = (atan2_deg(y, x), f64::atan2(y, x).to_degrees());
                assert!(
                    got.to_bits() == want.to_bits()
                        || (got.is_nan() && want.is_nan())
                        || ulps(got, want) <= 2.0,
                    "atan2({y}, {x}): {got} vs {want}"
                );
            }
            let (s, c) = sin_cos_deg(y);
            let (ws, wc) = y.to_radians().sin_cos();
            assert!(
                s.is_nan() == ws.is_nan() && c.is_nan() == wc.is_nan(),
                "{y}"
            );
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(100_000))]

        /// Within 2 ulp of the library, over the whole circle and at every
        /// scale of the direction's length.
        #[test]
        fn atan2_matches_the_library(
            deg in -180.0..180.0f64,
            scale in prop_oneof![Just(1.0), 1e-300..1e-290f64, 1e-10..1e10f64, 1e290..1e300f64],
            xy in (-1e3..1e3f64, -1e3..1e3f64),
            pick in 0usize..3,
        ) {
            let (y, x) = match pick {
                0 => {
                    let (s, c) = deg.to_radians().sin_cos();
                    (s * scale, c * scale)
                }
                1 => (xy.1 * scale, xy.0 * scale),
                // Near the axes and the diagonals, where the reduction
                // switches.
                _ => (scale * (1.0 + deg * 1e-12), scale * [1.0, -1.0, 7.0 / 16.0, 11.0 / 16.0][(deg.abs() as usize) % 4]),
            };
            let (got, want) = (atan2_deg(y, x), f64::atan2(y, x).to_degrees());
            prop_assert!(ulps(got, want) <= 2.0, "atan2({}, {}): {} vs {} ({} ulp)", y, x, got, want, ulps(got, want));
            let (got, want) = (atan2_rad(y, x), f64::atan2(y, x));
            prop_assert!(ulps(got, want) <= 2.0, "atan2({}, {}): {} vs {} rad ({} ulp)", y, x, got, want, ulps(got, want));
        }

        /// The angle between two unit vectors, from the pole to the
        /// opposite direction, within 2 ulp of the library's `atan2`.
        #[test]
        fn angle_between_matches_the_library(
            t in prop_oneof![0.0..3.2f64, 0.0..1e-6f64, (std::f64::consts::PI - 1e-3)..std::f64::consts::PI],
            phi in -3.2..3.2f64,
            z in -1.0..1.0f64,
        ) {
            let r = (1.0 - z * z).sqrt();
            let a = nalgebra::Vector3::new(r * phi.cos(), r * phi.sin(), z);
            // b: a turned by t about an axis normal to a.
            let n = a.cross(&nalgebra::Vector3::new(0.3, -0.5, 0.8)).normalize();
            let b = a * t.cos() + n.cross(&a) * t.sin();
            let (got, want) = (angle_between(&a, &b), a.cross(&b).norm().atan2(a.dot(&b)));
            prop_assert!(ulps(got, want) <= 2.0, "{}: {} vs {}", t, got, want);
        }

        /// The kernels are within 2 ulp of the library on the reduced
        /// angle (the reduction in degrees is exact), and the whole is the
        /// library's through radians up to the rounding of the radians.
        #[test]
        fn sin_cos_match_the_library(
            deg in prop_oneof![-720.0..720.0f64, -1e9..1e9f64, -1e-6..1e-6f64, -45.0..45.0f64],
        ) {
            let (s, c) = sin_cos_deg(deg);
            let k = (deg / 90.0).round();
            let (ws, wc) = (deg - 90.0 * k).to_radians().sin_cos();
            let (ws, wc) = match (k as i64) & 3 {
                0 => (ws, wc),
                1 => (wc, -ws),
                2 => (-ws, -wc),
                _ => (-wc, ws),
            };
            prop_assert!(ulps(s, ws) <= 2.0, "sin {}: {} vs {}", deg, s, ws);
            prop_assert!(ulps(c, wc) <= 2.0, "cos {}: {} vs {}", deg, c, wc);
            if deg.abs() <= 720.0 {
                // (Up to the rounding of the radians, |rad|·2^-53.)
                let (ls, lc) = deg.to_radians().sin_cos();
                let tol = 5e-16 * (1.0 + deg.to_radians().abs());
                prop_assert!((s - ls).abs() <= tol && (c - lc).abs() <= tol, "{}", deg);
            }
            prop_assert!((s * s + c * c - 1.0).abs() <= 4.0 * f64::EPSILON);
        }
    }
}
