//! Singular tool-axis directions and the pose a machine reaches when the
//! angle that becomes free there is held (pole handling for the planner).
//!
//! With two free rotary axes the orientation is subproblem 2,
//! `R(w1, θ1)·R(w2, θ2)·p = q` (see the module above). When `q` lies on `w1`
//! the first angle `θ1` is free: a tool axis along `± R_W0ᵀ·C0·w1` in the part
//! frame. Near that direction `θ1` swings fast with small changes of the tool
//! axis; holding it and turning `θ2` to the reachable axis nearest the wanted
//! one (subproblem 1 by projection) keeps the machine still at the price of
//! an orientation error no larger than the distance to the pole.

use nalgebra::Vector3;

use super::Kinematics;
use crate::angle::{angle_between, atan2_rad};
use crate::subproblems::{rotation, sp1_cs};

/// The tool-axis direction at which one rotary angle becomes free.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Singularity {
    /// Index of the axis whose angle is free there.
    pub axis: usize,
    /// Unit direction in the part frame; its opposite is singular as well.
    pub direction: Vector3<f64>,
}

impl Singularity {
    /// Angle between `axis` (unit) and the nearer of ±direction, radians
    /// (`atan2` of the cross and the absolute dot product, within 2 ulp of
    /// the library's).
    pub fn distance(&self, axis: &Vector3<f64>) -> f64 {
        let (s, c) = self.sin_cos(axis);
        atan2_rad(s, c)
    }

    /// The sine and cosine terms of [`Singularity::distance`] (`|d × a|`
    /// and `|d · a|`), for a caller that can often decide without the angle:
    /// the angle is at least `s / max(s² + c², 1)` (its sine, for unit
    /// vectors), and `atan2_rad(s, c)` is the distance exactly.
    #[inline]
    pub fn sin_cos(&self, axis: &Vector3<f64>) -> (f64, f64) {
        (
            self.direction.cross(axis).norm(),
            self.direction.dot(axis).abs(),
        )
    }

    /// The least [`Singularity::distance`] along the shorter great-circle
    /// arc from tool axis `a` to `b` (unit; the path a linearization
    /// interpolates), radians.
    pub fn arc_distance(&self, a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
        let (lo, hi) = arc_angles(&self.direction, a, b);
        lo.min(std::f64::consts::PI - hi)
    }
}

/// The tool-axis directions at which the two branches of a machine with two
/// free rotary axes meet without an angle becoming free (a fold): the edges
/// of the band of directions such a machine reaches when its axes are not
/// at the angle the tool axis makes with the inner one.
///
/// The tool axis `p` turned about the inner axis `w2` sweeps a cone of
/// half-angle `β = ∠(p, w2)` around it, and `w2` makes the angle
/// `γ = ∠(w1, w2)` with the outer axis, about which the cone turns: the
/// reachable axes make an angle between `|γ − β|` and `γ + β` with `w1`
/// (`360° − γ − β` when that is less). An edge at 0 or 180° is the pole of
/// [`Singularity`]; the others are folds, where subproblem 2 has a double
/// root: near one, both angles move like the square root of the distance
/// to it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Folds {
    /// Unit direction in the part frame (that of [`Singularity`]).
    pub direction: Vector3<f64>,
    /// Angles from `direction` of the lower and the upper fold, radians
    /// (NaN where that edge of the band is a pole).
    pub edges: [f64; 2],
}

impl Folds {
    /// Angle between `axis` (unit) and the nearest fold, radians.
    pub fn distance(&self, axis: &Vector3<f64>) -> f64 {
        let t = angle_between(&self.direction, axis);
        self.edges
            .iter()
            .filter(|e| !e.is_nan())
            .map(|e| (t - e).abs())
            .fold(f64::INFINITY, f64::min)
    }

    /// Whether the shorter great-circle arc from tool axis `a` to `b` (unit;
    /// the path a linearization interpolates) reaches a fold, within
    /// `slack` radians.
    pub fn reached(&self, a: &Vector3<f64>, b: &Vector3<f64>, slack: f64) -> bool {
        let (lo, hi) = arc_angles(&self.direction, a, b);
        self.edges
            .iter()
            .any(|&e| e >= lo - slack && e <= hi + slack)
    }

    /// Where the shorter great-circle arc from tool axis `a` to `b` (unit;
    /// the path a linearization interpolates) goes deepest outside the band
    /// of directions the machine can point: into the cone inside the lower
    /// fold (around `direction`) or beyond the upper one (around its
    /// opposite). `None` when it stays inside the band.
    pub fn arc_outside(&self, a: &Vector3<f64>, b: &Vector3<f64>) -> Option<Excursion> {
        use std::f64::consts::PI;
        let (lo, hi) = arc_angles(&self.direction, a, b);
        let [lower, upper] = self.edges;
        // An edge that is a pole (NaN) bounds nothing.
        let below = Excursion {
            cone_axis: self.direction,
            half_angle: lower,
            depth: lower - lo,
        };
        let above = Excursion {
            cone_axis: -self.direction,
            half_angle: PI - upper,
            depth: hi - upper,
        };
        [below, above]
            .into_iter()
            .filter(|e| e.depth > 0.0)
            .max_by(|x, y| x.depth.total_cmp(&y.depth))
    }
}

/// How far an arc of tool axes enters a cone of directions the machine
/// cannot point ([`Folds::arc_outside`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Excursion {
    /// The cone's axis (unit, part frame).
    pub cone_axis: Vector3<f64>,
    /// The cone's half-angle, radians (the angle of a fold from its axis).
    pub half_angle: f64,
    /// How far inside the cone the arc comes, radians.
    pub depth: f64,
}

/// The least and the largest angle from `d` (unit) along the shorter
/// great-circle arc from `a` to `b` (unit; the tool axis a linearization
/// interpolates between two points), radians. The angle takes every value
/// between them along the arc; they lie at the ends or where the arc is
/// nearest and farthest from `d`.
fn arc_angles(d: &Vector3<f64>, a: &Vector3<f64>, b: &Vector3<f64>) -> (f64, f64) {
    let (mut lo, mut hi) = {
        let (ta, tb) = (angle_between(d, a), angle_between(d, b));
        (ta.min(tb), ta.max(tb))
    };
    // The arc: x(φ) = cos φ·a + sin φ·u for φ in [0, θ], u the unit vector
    // normal to a towards b; d·x(φ) = p·cos φ + q·sin φ is largest at
    // φ* = atan2(q, p) and least half a turn on.
    let theta = angle_between(a, b);
    let u = b - a * a.dot(b);
    let norm = u.norm();
    if theta > 0.0 && norm > 0.0 {
        let u = u / norm;
        let (p, q) = (d.dot(a), d.dot(&u));
        let nearest = atan2_rad(q, p);
        let farthest = if nearest > 0.0 {
            nearest - std::f64::consts::PI
        } else {
            nearest + std::f64::consts::PI
        };
        for phi in [nearest, farthest] {
            if phi > 0.0 && phi < theta {
                let x = a * phi.cos() + u * phi.sin();
                let t = angle_between(d, &x);
                lo = lo.min(t);
                hi = hi.max(t);
            }
        }
    }
    (lo, hi)
}

impl Kinematics {
    /// The folds of a machine with exactly two free rotary axes, if it has
    /// any (see [`Folds`]): none when both edges are poles (`γ = β = 90°`:
    /// the axes at right angles, the tool axis normal to the inner one).
    pub fn folds(&self) -> Option<Folds> {
        use std::f64::consts::{PI, TAU};
        const POLE: f64 = 1e-9;
        let s = self.singularity()?;
        let (_, w1) = self.free_rot[0];
        let gamma = angle_between(&w1, &self.sp2_w2);
        let beta = angle_between(&self.sp2_p, &self.sp2_w2);
        let lower = (gamma - beta).abs();
        let upper = (gamma + beta).min(TAU - gamma - beta);
        let edges = [
            if lower > POLE { lower } else { f64::NAN },
            if upper < PI - POLE { upper } else { f64::NAN },
        ];
        (!edges.iter().all(|e| e.is_nan())).then_some(Folds {
            direction: s.direction,
            edges,
        })
    }

    /// The singular direction of a machine with exactly two free rotary axes
    /// (with three, the reference direction decides and none is reported).
    pub fn singularity(&self) -> Option<Singularity> {
        if self.free_rot.len() != 2 {
            return None;
        }
        let (axis, w1) = self.free_rot[0];
        // q = C0ᵀ·R_W0·a is on w1  ⇔  a = R_W0ᵀ·C0·w1.
        let direction = self.rw0.transpose() * (self.between[0] * w1);
        Some(Singularity { axis, direction })
    }

    /// The tool axis nearest `axis` (part frame, unit) that the machine can
    /// point with the singular angle (see [`Kinematics::singularity`]) held
    /// at `held_deg`; `None` without a singularity or when no second angle
    /// turns the axis at all.
    pub fn held_axis(&self, axis: &Vector3<f64>, held_deg: f64) -> Option<Vector3<f64>> {
        if self.free_rot.len() != 2 {
            return None;
        }
        let (_, w1) = self.free_rot[0];
        let q = self.c0t * (self.rw0 * axis);
        let r1 = rotation(&w1, held_deg.to_radians());
        let v = r1.transpose() * q;
        let w2 = self.sp2_w2;
        let p = self.sp2_p;
        // The angle about w2 that brings p nearest v: both projected on the
        // plane normal to w2 (subproblem 1 by projection).
        let a2 = sp1_cs(&w2, &p, &v)?;
        let reached = r1 * (a2.rotation(&w2) * p);
        Some(self.rw0.transpose() * (self.between[0] * reached))
    }
}
