//! Paden–Kahan subproblems for rotations about lines through the origin
//! (directions only: orientation does not depend on where a rotary axis is).
//!
//! Reference: R. M. Murray, Z. Li, S. S. Sastry, *A Mathematical Introduction
//! to Robotic Manipulation* (1994), §3.3.2, subproblems 1 and 2. All angles
//! come from `atan2`, never `acos`, so accuracy holds near singular poses.

use nalgebra::{Matrix3, Vector3};

/// Below this length a projection onto the plane normal to a rotation axis is
/// taken as zero: the vector lies on the axis and the angle is free.
pub const FREE_EPS: f64 = 1e-12;

/// Rotation matrix about unit `w` by `theta` radians (Rodrigues' formula).
#[inline]
pub fn rotation(w: &Vector3<f64>, theta: f64) -> Matrix3<f64> {
    let (s, c) = theta.sin_cos();
    rotation_cs(w, c, s)
}

/// Rotation matrix about unit `w` by the angle whose cosine and sine are
/// `c` and `s` (no trigonometry: for angles that come out of [`sp1_cs`]).
#[inline]
pub fn rotation_cs(w: &Vector3<f64>, c: f64, s: f64) -> Matrix3<f64> {
    let v = 1.0 - c;
    let (x, y, z) = (w.x, w.y, w.z);
    Matrix3::new(
        c + x * x * v,
        x * y * v - z * s,
        x * z * v + y * s,
        y * x * v + z * s,
        c + y * y * v,
        y * z * v - x * s,
        z * x * v - y * s,
        z * y * v + x * s,
        c + z * z * v,
    )
}

/// An angle with its cosine and sine, as subproblem 1 finds them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Angle {
    /// Radians, in (−π, π].
    pub rad: f64,
    pub cos: f64,
    pub sin: f64,
}

impl Angle {
    /// The rotation about unit `w` by this angle.
    #[inline]
    pub fn rotation(&self, w: &Vector3<f64>) -> Matrix3<f64> {
        rotation_cs(w, self.cos, self.sin)
    }
}

/// Subproblem 1 with the cosine and sine of the solution (see [`sp1`]).
#[inline]
pub fn sp1_cs(w: &Vector3<f64>, u: &Vector3<f64>, v: &Vector3<f64>) -> Option<Angle> {
    let up = u - w * w.dot(u);
    let vp = v - w * w.dot(v);
    if up.norm_squared() < FREE_EPS * FREE_EPS || vp.norm_squared() < FREE_EPS * FREE_EPS {
        return None;
    }
    let y = w.dot(&up.cross(&vp));
    let x = up.dot(&vp);
    // Both are products of unit-length-scale vectors: no overflow to fear.
    let r = (x * x + y * y).sqrt();
    Some(Angle {
        rad: f64::atan2(y, x),
        cos: x / r,
        sin: y / r,
    })
}

/// Subproblem 1: the angle `θ` with `rot(w, θ)·u = v`, assuming `w·u = w·v`
/// and `|u| = |v|`. `None` when `u` (or `v`) lies on the axis: every angle
/// is a solution (a singular configuration).
#[inline]
pub fn sp1(w: &Vector3<f64>, u: &Vector3<f64>, v: &Vector3<f64>) -> Option<f64> {
    sp1_cs(w, u, v).map(|a| a.rad)
}

/// One solution of subproblem 2.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sp2Solution {
    /// Angle about the first axis; `None` if free (singular).
    pub theta1: Option<Angle>,
    /// Angle about the second axis; `None` if free (singular).
    pub theta2: Option<Angle>,
}

/// Subproblem 2: angles with `rot(w1, θ1)·rot(w2, θ2)·p = q` for unit vectors
/// `p`, `q` and non-parallel unit axes `w1`, `w2`. Returns 0, 1 or 2
/// solutions. `slack` is how far below zero the squared height of the
/// intersection point may be before the orientation counts as unreachable
/// (round-off at the edge of the reachable cone).
pub fn sp2(
    w1: &Vector3<f64>,
    w2: &Vector3<f64>,
    p: &Vector3<f64>,
    q: &Vector3<f64>,
    slack: f64,
) -> ([Sp2Solution; 2], usize) {
    let none = Sp2Solution {
        theta1: None,
        theta2: None,
    };
    let w12 = w1.dot(w2);
    let cross = w1.cross(w2);
    let cross2 = cross.norm_squared();
    if cross2 < 1e-24 {
        return ([none; 2], 0);
    }
    let denom = w12 * w12 - 1.0;
    let a = (w12 * w2.dot(p) - w1.dot(q)) / denom;
    let b = (w12 * w1.dot(q) - w2.dot(p)) / denom;
    let g2 = (p.norm_squared() - a * a - b * b - 2.0 * a * b * w12) / cross2;
    if g2 < -slack {
        return ([none; 2], 0);
    }
    let g = g2.max(0.0).sqrt();
    let solve = |g: f64| {
        let z = w1 * a + w2 * b + cross * g;
        Sp2Solution {
            theta1: sp1_cs(w1, &z, q),
            theta2: sp1_cs(w2, p, &z),
        }
    };
    if g == 0.0 {
        ([solve(0.0), none], 1)
    } else {
        ([solve(g), solve(-g)], 2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn unit() -> impl Strategy<Value = Vector3<f64>> {
        (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64)
            .prop_filter("non-zero", |(x, y, z)| x * x + y * y + z * z > 0.01)
            .prop_map(|(x, y, z)| Vector3::new(x, y, z).normalize())
    }

    #[test]
    fn rotation_is_right_handed() {
        let r = rotation(&Vector3::z(), std::f64::consts::FRAC_PI_2);
        assert!((r * Vector3::x() - Vector3::y()).norm() < 1e-15);
    }

    proptest! {
        #[test]
        fn sp1_recovers_the_angle(w in unit(), u in unit(), t in -3.1..3.1f64) {
            prop_assume!(w.cross(&u).norm() > 1e-3);
            let v = rotation(&w, t) * u;
            let got = sp1(&w, &u, &v).unwrap();
            prop_assert!((got - t).abs() < 1e-12);
        }

        #[test]
        fn sp2_solutions_satisfy_the_equation_and_contain_the_truth(
            w1 in unit(), w2 in unit(), p in unit(), t1 in -3.1..3.1f64, t2 in -3.1..3.1f64
        ) {
            prop_assume!(w1.cross(&w2).norm() > 1e-3);
            prop_assume!(w2.cross(&p).norm() > 1e-3);
            let q = rotation(&w1, t1) * rotation(&w2, t2) * p;
            prop_assume!(w1.cross(&q).norm() > 1e-3);
            let (sols, n) = sp2(&w1, &w2, &p, &q, 1e-12);
            prop_assert!(n >= 1);
            let mut found = false;
            for s in &sols[..n] {
                let (a, b) = (s.theta1.unwrap().rad, s.theta2.unwrap().rad);
                let m = s.theta1.unwrap().rotation(&w1) * s.theta2.unwrap().rotation(&w2) * p;
                prop_assert!((m - q).norm() < 1e-9, "cos/sin rotation {m} vs {q}");
                let got = rotation(&w1, a) * rotation(&w2, b) * p;
                prop_assert!((got - q).norm() < 1e-9, "{got} vs {q}");
                let d = |x: f64, y: f64| (x - y + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
                if d(a, t1).abs() < 1e-6 && d(b, t2).abs() < 1e-6 { found = true; }
            }
            prop_assert!(found);
        }
    }
}
