//! How far a solid can move between two poses: the bound of conservative
//! advancement.
//!
//! A solid is carried by the axes `1..k` of its side (base outwards), each
//! moving by `G_i(q_i)`, so a point `x` of it is at
//! `G_1(q_1) ⋯ G_k(q_k) x`. Along a path on which every axis moves
//! monotonically from `q_a` to `q_b` (a joint-linear move, or any profile
//! that never turns an axis back), the path length of every point of a
//! ball of centre `c` and radius `ρ` (at home) is at most `D_1`, where,
//! from the innermost axis outwards (`D_{k+1} = 0`),
//!
//! ```text
//! linear i:  D_i = D_{i+1} + |Δq_i|
//! rotary i:  D_i = D_{i+1} + |Δθ_i| · (r_i + ρ + D_{i+1})
//! ```
//!
//! with `r_i` the distance from `y_i = G_{i+1}(q_a) ⋯ G_k(q_a) c` to the
//! home line of axis `i`. Proof: the velocity of the point is the sum of
//! one term per axis; axis `i` contributes `|q̇_i|` (linear) or `|θ̇_i|`
//! times the distance from the point, as the axes inside `i` hold it, to
//! the line of `i` (rigid motions outside `i` keep lengths). That distance
//! is at most `r_i + ρ` at `q_a` and grows by no more than the path the
//! axes inside `i` give the point, `D_{i+1}`. Integrating over the path,
//! `∫|q̇_i| = |Δq_i|` for a monotone axis. A locked rotary axis does not
//! move (`Δθ = 0`, as the kinematics reads it).
//!
//! Two solids whose distance at `q_a` exceeds the sum of their bounds
//! cannot touch anywhere on the path: the sum is how much nearer they can
//! get.

use kinpost_machine::{AxisKind, Body, Machine};
use nalgebra::{Unit, UnitQuaternion, Vector3};

/// One axis of a solid's chain, in the machine frame at home.
#[derive(Debug, Clone, Copy)]
struct ChainAxis {
    index: usize,
    rotary: bool,
    direction: Unit<Vector3<f64>>,
    point: Vector3<f64>,
    locked: bool,
    locked_at: f64,
}

/// The motion bound of one solid: its chain and bounding ball at home.
#[derive(Debug, Clone)]
pub struct MotionBound {
    /// Base outwards.
    chain: Vec<ChainAxis>,
    /// Centre of the ball at home, machine frame.
    centre: Vector3<f64>,
    /// Its radius, mm.
    radius: f64,
}

impl MotionBound {
    /// The bound of a solid on `body` inside the ball (`centre`, `radius`)
    /// at home.
    pub fn new(machine: &Machine, body: Body, centre: Vector3<f64>, radius: f64) -> MotionBound {
        let chain = machine
            .chain_of(body)
            .into_iter()
            .map(|i| {
                let a = &machine.axes[i];
                let rotary = a.kind == AxisKind::Rotary;
                ChainAxis {
                    index: i,
                    rotary,
                    direction: Unit::new_normalize(a.direction),
                    point: a.point,
                    locked: rotary && a.fixed.is_some(),
                    locked_at: a.fixed.unwrap_or(0.0),
                }
            })
            .collect();
        MotionBound {
            chain,
            centre,
            radius,
        }
    }

    /// The longest path any point of the solid can travel while every axis
    /// moves monotonically from `from` to `to` (NC values, machine-file
    /// order), mm.
    pub fn path_bound_mm(&self, from: &[f64], to: &[f64]) -> f64 {
        let mut y = self.centre;
        let mut d = 0.0;
        for a in self.chain.iter().rev() {
            let qa = from.get(a.index).copied().unwrap_or(0.0);
            let qb = to.get(a.index).copied().unwrap_or(0.0);
            if !a.rotary {
                d += (qb - qa).abs();
                y += a.direction.into_inner() * qa;
                continue;
            }
            if a.locked {
                y = turn(a, a.locked_at, &y);
                continue;
            }
            let off = y - a.point;
            let r = (off - a.direction.into_inner() * off.dot(&a.direction)).norm();
            d += (qb - qa).abs().to_radians() * (r + self.radius + d);
            y = turn(a, qa, &y);
        }
        d
    }
}

/// `y` turned by `deg` about the axis line.
fn turn(a: &ChainAxis, deg: f64, y: &Vector3<f64>) -> Vector3<f64> {
    let r = UnitQuaternion::from_axis_angle(&a.direction, deg.to_radians());
    a.point + r * (y - a.point)
}

#[cfg(test)]
mod tests {
    use super::*;
    use kinpost_machine::builtin;

    /// On one linear axis the bound is the travel; on one rotary axis the
    /// arc of the farthest point of the ball: (distance of the centre from
    /// the line + radius) × angle.
    #[test]
    fn single_axes_give_their_closed_forms() {
        let m = builtin::load("mts1600").unwrap().unwrap();
        let x = m.axis_index("X").unwrap();
        let a = m.axis_index("A").unwrap();
        let mut from = m.home_joints();
        let mut to = from.clone();
        to[x] = 30.0;
        let on_x = MotionBound::new(&m, Body::Axis(x), Vector3::new(5.0, 6.0, 7.0), 9.0);
        assert_eq!(on_x.path_bound_mm(&from, &to), 30.0);
        // The ball 100 mm from the A line, radius 10, turned 90°: the
        // farthest point travels a quarter circle of radius 110.
        let on_a = MotionBound::new(&m, Body::Axis(a), Vector3::new(-300.0, 60.0, 80.0), 10.0);
        to[x] = 0.0;
        to[a] = 90.0;
        let want = 110.0 * std::f64::consts::FRAC_PI_2;
        assert!((on_a.path_bound_mm(&from, &to) - want).abs() < 1e-9);
        // With X moving as well, the X travel adds to it (X carries A).
        to[x] = -40.0;
        assert!((on_a.path_bound_mm(&from, &to) - (want + 40.0)).abs() < 1e-9);
        // The base never moves; the tool side does not move with X and A.
        let base = MotionBound::new(&m, Body::Base, Vector3::zeros(), 1e3);
        assert_eq!(base.path_bound_mm(&from, &to), 0.0);
        let tool = MotionBound::new(&m, Body::Tool, Vector3::zeros(), 1e3);
        assert_eq!(tool.path_bound_mm(&from, &to), 0.0);
        // A locked axis (C of the 5-axis mts1600) adds nothing.
        let c = m.axis_index("C").unwrap();
        from[c] = 0.0;
        to[c] = 50.0;
        assert_eq!(tool.path_bound_mm(&from, &to), 0.0);
    }
}
