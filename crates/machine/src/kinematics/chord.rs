//! How far the tool point can stray from the chord when the axes move
//! linearly in joint space between two configurations (what a controller
//! does between two joint-output blocks): a bound from the second derivative
//! of the chain, cheap enough to settle most segments of a fine CL path
//! without a forward kinematics at their midpoint.
//!
//! The chain is a product of exponentials, `p(t) = E_1 ∘ … ∘ E_k (tip)` with
//! `E_i = exp(ξ_i θ_i(t))` and every `θ_i` linear in `t` (rate `Δ_i`). Its
//! velocity is `p' = Σ_rot Δ_i ω_i × (p − c_i) + Σ_lin Δ_i d_i`, with `ω_i`,
//! `c_i`, `d_i` the current direction, reference point and direction of each
//! axis (moved by the axes outside it). Differentiating once more,
//! `ω_i' = Σ_{j<i} Δ_j ω_j × ω_i`, `c_i' = Σ_{j<i} Δ_j ζ_j·c_i` and
//! `d_i' = Σ_{j<i} Δ_j ω_j × d_i`; with unit directions,
//! `|c_i − c_j| ≤ |p − c_i| + |p − c_j|` and every cross product bounded by
//! the product of the lengths:
//!
//! ```text
//! |p''| ≤ 4·W²·ρ + 3·V·W
//! ```
//!
//! `W = Σ|Δθ|` over the free rotary axes (radians), `V = Σ|Δq|` over the free
//! linear axes (mm) and `ρ` the largest distance from the tool point to the
//! reference point of a free rotary axis during the motion (the *lever*). The
//! lever changes at most at the rate `|p'| + |c_i'| ≤ 3·W·ρ + 2·V`, so over
//! the motion `ρ ≤ (ρ(0) + 2V) / (1 − 3W)` (for `3W < 1`). The midpoint of
//! the motion is within `max|p''| / 8` of the midpoint of the chord.

use super::Kinematics;
use crate::angle::SinCosMemo;
use crate::model::Pose;

/// Upper bound of the lever over a straight joint motion of rotary travel
/// `w` (radians, summed over the axes) and linear travel `v` (mm) that starts
/// with lever `lever` (see the module documentation); infinite when the
/// motion turns too far (`3w ≥ 1`) for the bound to hold.
pub fn lever_over(lever: f64, w: f64, v: f64) -> f64 {
    let shrink = 1.0 - 3.0 * w;
    if shrink > 0.0 {
        (lever + 2.0 * v) / shrink
    } else {
        f64::INFINITY
    }
}

/// Upper bound of the distance between the tool point at the midpoint of a
/// straight joint motion and the midpoint of the chord between its ends:
/// `(4·W²·ρ + 3·V·W) / 8` with `ρ` from [`lever_over`].
pub fn midpoint_bound(lever: f64, w: f64, v: f64) -> f64 {
    let rho = lever_over(lever, w, v);
    (4.0 * w * w * rho + 3.0 * v * w) / 8.0
}

impl Kinematics {
    /// Forward kinematics of `q` (as [`Kinematics::fk`], bit for bit) and
    /// its lever: the largest distance from the tool point to the reference
    /// point of a free rotary axis (0 without one). `memo` keeps the sines
    /// and cosines of the rotary values for the next call (a sequence of
    /// blocks whose rotary values often repeat). The reference direction
    /// only `with_reference` (else `None`: a 5-axis check has no use for it).
    pub fn fk_lever(&self, q: &[f64], memo: &mut SinCosMemo, with_reference: bool) -> (Pose, f64) {
        self.chain::<true>(q, with_reference, |axis, deg| memo.sin_cos_deg(axis, deg))
    }

    /// The travel of the straight joint motion from `a` to `b`: summed over
    /// the free rotary axes in radians, and over the free linear axes in mm.
    #[inline]
    pub fn joint_travel(&self, a: &[f64], b: &[f64]) -> (f64, f64) {
        let mut w = 0.0;
        for &(i, _) in &self.free_rot {
            w += (b[i] - a[i]).abs();
        }
        let mut v = 0.0;
        for &i in &self.free_lin {
            v += (b[i] - a[i]).abs();
        }
        (w.to_radians(), v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::builtin;

    #[test]
    fn a_pure_turn_is_bounded_by_four_sagittas() {
        // One turn of w about a line at distance ρ: the sagitta is
        // ρ(1 − cos(w/2)) ≈ ρw²/8; the bound is ρw²/2.
        let rho = 300.0;
        let w: f64 = 0.01;
        let sagitta = rho * (1.0 - (w / 2.0).cos());
        let bound = midpoint_bound(rho, w, 0.0);
        assert!(bound >= sagitta);
        assert!(bound <= 4.2 * sagitta);
        assert_eq!(midpoint_bound(rho, 0.0, 25.0), 0.0);
        assert_eq!(lever_over(rho, 0.4, 0.0), f64::INFINITY);
    }

    #[test]
    fn the_lever_comes_with_the_forward_kinematics() {
        let m = builtin::load("mts1600").unwrap().unwrap();
        let kin = Kinematics::new(&m);
        let q = [459.0, 12.0, 8.8, 361.4, -17.0, 0.0];
        let mut memo = SinCosMemo::default();
        for q in [q, q, [459.0, 12.0, 8.8, 361.4, -17.5, 0.0], q] {
            let (pose, lever) = kin.fk_lever(&q, &mut memo, true);
            let want = kin.fk(&q);
            let bits = |v: &nalgebra::Vector3<f64>| v.map(f64::to_bits);
            assert_eq!(bits(&pose.point), bits(&want.point));
            assert_eq!(bits(&pose.axis), bits(&want.axis));
            assert!(lever > 0.0 && lever.is_finite());
        }
    }
}
