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
use crate::angle::atan2_rad;
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
}

impl Kinematics {
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
