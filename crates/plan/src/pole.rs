//! The distance of a tool axis from the machine's singular direction, for
//! the planner's tests against the singular cone: most are settled by a
//! lower bound, without an `atan2`.

use kinpost_machine::Singularity;
use kinpost_machine::angle::atan2_rad;
use kinpost_machine::tolerance::POLE_BOUND_SLACK;
use nalgebra::Vector3;

/// The angle between a tool axis and the singular direction, kept as its
/// sine and cosine terms ([`Singularity::sin_cos`]): most decisions are
/// settled by a lower bound, without the `atan2` of
/// [`Singularity::distance`], which is exact (the same bits) where the
/// bound does not settle them.
///
/// The sine term is kept squared: far from the pole, the tests are settled
/// without its square root ([`Pole::surely_beyond`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Pole {
    /// `|d × a|²` (the square of [`Singularity::sin_cos`]'s first term).
    sin2: f64,
    /// `|d · a|`.
    cos: f64,
}

impl Pole {
    pub(crate) fn new(s: &Singularity, axis: &Vector3<f64>) -> Pole {
        Pole {
            sin2: s.direction.cross(axis).norm_squared(),
            cos: s.direction.dot(axis).abs(),
        }
    }

    /// The sine term, `|d × a|` (the same bits as [`Singularity::sin_cos`]).
    pub(crate) fn sin(self) -> f64 {
        self.sin2.sqrt()
    }

    /// The angle, radians (as [`Singularity::distance`]).
    pub(crate) fn exact_rad(self) -> f64 {
        atan2_rad(self.sin(), self.cos)
    }

    /// A lower bound of the angle, radians: its sine `s / √(s² + c²)` is at
    /// least `s / max(s² + c², 1)`, and an angle of [0, π/2] is at least its
    /// sine.
    pub(crate) fn lower_rad(self) -> f64 {
        let (s, c) = (self.sin(), self.cos);
        s / (s * s + c * c).max(1.0) * (1.0 - POLE_BOUND_SLACK)
    }

    /// The lower bound is surely above `rad`, without a square root: with
    /// `s² + c² ≤ 1.0001` (a unit tool axis) the bound is at least
    /// `0.99989·s`, and `s² · 0.9996 > rad²` makes `s` above `rad / 0.9998`.
    /// (`false` says nothing.)
    pub(crate) fn surely_beyond(self, rad: f64) -> bool {
        self.sin2 + self.cos * self.cos <= 1.0001 && self.sin2 * 0.9996 > rad * rad
    }

    /// Whether the angle is below `cone_rad`.
    pub(crate) fn within(self, cone_rad: f64) -> bool {
        !self.surely_beyond(cone_rad) && self.lower_rad() < cone_rad && self.exact_rad() < cone_rad
    }

    /// Whether the two angles, in degrees, add up to at most `limit`.
    pub(crate) fn sum_within(a: Pole, b: Pole, limit: f64) -> bool {
        let limit_rad = limit.to_radians();
        !a.surely_beyond(limit_rad)
            && !b.surely_beyond(limit_rad)
            && (a.lower_rad() + b.lower_rad()).to_degrees() <= limit
            && a.exact_rad().to_degrees() + b.exact_rad().to_degrees() <= limit
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    fn unit(v: [f64; 3]) -> Vector3<f64> {
        Vector3::from(v).normalize()
    }

    proptest::proptest! {
        /// The pole tests decide as the exact angles of
        /// `Singularity::distance` do, also at their limits (the cone and
        /// the sum set to the exact values, or an ulp off them).
        #[test]
        fn pole_tests_agree_with_the_exact_angles(
            d in proptest::array::uniform3(-1.0f64..1.0),
            a in proptest::array::uniform3(-1.0f64..1.0),
            b in proptest::array::uniform3(-1.0f64..1.0),
            near in 0.0f64..1e-3,
            ulps in -2i64..=2,
        ) {
            proptest::prop_assume!(Vector3::from(d).norm() > 1e-3);
            let s = Singularity { axis: 0, direction: unit(d) };
            // Tool axes anywhere, or within `near` of the pole.
            let a = unit(a);
            let b = (s.direction + near * unit(b)).normalize();
            let nudge = |x: f64| f64::from_bits((x.to_bits() as i64 + ulps) as u64);
            let (pa, pb) = (Pole::new(&s, &a), Pole::new(&s, &b));
            proptest::prop_assert_eq!(pa.sin().to_bits(), s.sin_cos(&a).0.to_bits());
            for (pole, axis) in [(pa, &a), (pb, &b)] {
                let exact = s.distance(axis);
                proptest::prop_assert_eq!(pole.exact_rad().to_bits(), exact.to_bits());
                for cone in [nudge(exact), 1e-3, 0.0, exact * 2.0] {
                    proptest::prop_assert_eq!(pole.within(cone), exact < cone);
                }
            }
            let sum = s.distance(&a).to_degrees() + s.distance(&b).to_degrees();
            for limit in [nudge(sum), sum * 0.5, 0.0, f64::INFINITY] {
                proptest::prop_assert_eq!(Pole::sum_within(pa, pb, limit), sum <= limit);
            }
        }
    }
}
