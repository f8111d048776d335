//! Forward and inverse kinematics of a [`Machine`] by the product of
//! exponentials over the home configuration (DESIGN.md §2).
//!
//! Conventions: `G_i(q)` is the rigid motion of axis `i` at NC value `q` in the
//! home frame (translation `q·u` or rotation by `q` degrees about the line
//! through `p` along `u`). With the axes of each side in chain order,
//!
//! ```text
//! W(q) = Π_workpiece G_i(q_i) · W0      pose of the part frame in the machine
//! T(q) = Π_tool      G_i(q_i) · T0      pose of the tool frame in the machine
//! tool pose in the part frame = W(q)⁻¹ · T(q)
//! ```
//!
//! Inverse kinematics: orientation depends only on the rotary axes. Writing
//! `R_W(q)ᵀ R_T(q) a0 = R_W0 a` as one chain of rotations
//! `E = R_wkᵀ ⋯ R_w1ᵀ · R_t1 ⋯ R_tm` (workpiece axes outermost first, each
//! turning by `−q` about its direction), two free rotary axes are Paden–Kahan
//! subproblem 2 and a third one, when the pose carries a reference direction,
//! subproblem 1. With every angle known the tool point is affine in the
//! linear axis values: a 3×3 linear solve.

use nalgebra::{Matrix3, Vector3};

mod singular;
pub use singular::Singularity;

use crate::model::{AxisKind, MAX_AXES, Machine, Pose, Side};
use crate::subproblems::{Angle, FREE_EPS, rotation, sp1_cs, sp2};

/// Joint values of one configuration, in machine-file axis order.
pub type Joints = [f64; MAX_AXES];

/// Why a solution cannot be used as it is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Violation {
    /// Index of the axis outside its travel.
    pub axis: usize,
    /// The value it would need.
    pub value: f64,
}

/// One inverse-kinematics solution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Solution {
    /// NC values of every axis (fixed axes at their value); only the first
    /// `Machine::axes.len()` entries are used.
    pub joints: Joints,
    /// Which orientation branch of the closed form this is (0 or 1).
    pub branch: u8,
    /// A rotary angle was free (tool axis on a rotary axis line) and was
    /// taken from the hint.
    pub singular: bool,
    /// The first axis outside its travel, for a branch that has no
    /// equivalent inside the limits.
    pub violation: Option<Violation>,
}

impl Solution {
    pub fn is_valid(&self) -> bool {
        self.violation.is_none()
    }
}

/// Inverse kinematics failures that no branch escapes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IkError {
    /// No setting of the rotary axes gives this tool axis.
    OrientationUnreachable,
    /// Three free rotary axes and a pose without a reference direction.
    NeedsReference,
    /// The linear axes cannot reach the point with these angles (fewer than
    /// three linear axes, or a degenerate chain).
    PositionUnreachable,
}

impl std::fmt::Display for IkError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            IkError::OrientationUnreachable => "no setting of the rotary axes gives this tool axis",
            IkError::NeedsReference => {
                "the machine has three free rotary axes: the CL must give a reference direction (GOTO with 9 values)"
            }
            IkError::PositionUnreachable => "the linear axes cannot reach this point",
        })
    }
}

impl std::error::Error for IkError {}

#[derive(Debug, Clone, Copy)]
struct Link {
    kind: AxisKind,
    dir: Vector3<f64>,
    point: Vector3<f64>,
    /// Machine-file index of the axis.
    index: usize,
    /// Position among the free linear axes (the column of the linear solve).
    free_lin: Option<usize>,
    /// Position among the free rotary axes (effective-chain order).
    slot: Option<usize>,
    /// Rotation of a rotary axis locked by `fixed`.
    fixed_rot: Matrix3<f64>,
}

/// Rotation matrices of the free rotary axes, by slot.
type Rots = [Matrix3<f64>; 3];

/// A machine compiled for fast kinematics.
#[derive(Debug, Clone)]
pub struct Kinematics {
    n: usize,
    tool_chain: Vec<Link>,
    work_chain: Vec<Link>,
    rw0: Matrix3<f64>,
    ow0: Vector3<f64>,
    t0: Vector3<f64>,
    a0: Vector3<f64>,
    r0: Option<Vector3<f64>>,
    fixed: Joints,
    is_fixed: [bool; MAX_AXES],
    limits: [Option<[f64; 2]>; MAX_AXES],
    rotary: [bool; MAX_AXES],
    /// Free rotary axes in effective-chain order: (axis index, signed direction).
    free_rot: Vec<(usize, Vector3<f64>)>,
    /// Constant rotations between the free rotary axes in the effective chain:
    /// `E = C[0]·F1·C[1]·F2·C[2]…`.
    between: Vec<Matrix3<f64>>,
    /// Free linear axes, machine-file indices.
    free_lin: Vec<usize>,
    /// Constant inputs of subproblem 2 (two or more free rotary axes): the
    /// second axis as seen by the first, `C1·w2`, the home vector it turns,
    /// `C1·C2·a0` (two free axes) or `C1·C2·w3` (three), and `C0ᵀ`.
    sp2_w2: Vector3<f64>,
    sp2_p: Vector3<f64>,
    c0t: Matrix3<f64>,
    /// Axis index and own direction of each free rotary slot.
    slot_axis: Vec<usize>,
    slot_dir: Vec<Vector3<f64>>,
}

#[inline]
fn rad(deg: f64) -> f64 {
    deg.to_radians()
}

/// The tool pose in the part frame for some joint values, and how the tool
/// point moves per unit of each free linear axis.
struct Eval {
    point: Vector3<f64>,
    axis: Vector3<f64>,
    reference: Option<Vector3<f64>>,
    cols: [Vector3<f64>; 3],
}

impl Kinematics {
    /// Compiles a validated machine.
    pub fn new(machine: &Machine) -> Kinematics {
        let n = machine.axes.len();
        let mut fixed = [0.0; MAX_AXES];
        let mut is_fixed = [false; MAX_AXES];
        let mut limits = [None; MAX_AXES];
        let mut rotary = [false; MAX_AXES];
        let (mut tool_chain, mut work_chain): (Vec<Link>, Vec<Link>) = (Vec::new(), Vec::new());
        for (i, a) in machine.axes.iter().enumerate() {
            fixed[i] = a.fixed.unwrap_or(0.0);
            is_fixed[i] = a.fixed.is_some();
            limits[i] = a.limits;
            rotary[i] = a.is_rotary();
            let free_lin = (!a.is_rotary() && a.fixed.is_none()).then(|| {
                machine.axes[..i]
                    .iter()
                    .filter(|b| !b.is_rotary() && b.fixed.is_none())
                    .count()
            });
            let link = Link {
                kind: a.kind,
                dir: a.direction,
                point: a.point,
                index: i,
                free_lin,
                slot: None,
                fixed_rot: Matrix3::identity(),
            };
            // An axis locked at zero is the identity motion: leave it out of
            // the chains (the C axis of the 5-axis mts1600).
            if a.fixed == Some(0.0) {
                continue;
            }
            match a.side {
                Side::Tool => tool_chain.push(link),
                Side::Workpiece => work_chain.push(link),
            }
        }
        // Effective orientation chain: workpiece rotaries outermost first,
        // direction negated (R(u, q)ᵀ = R(−u, q)), then tool rotaries.
        let effective: Vec<(usize, Vector3<f64>)> = work_chain
            .iter()
            .rev()
            .filter(|l| l.kind == AxisKind::Rotary)
            .map(|l| (l.index, -l.dir))
            .chain(
                tool_chain
                    .iter()
                    .filter(|l| l.kind == AxisKind::Rotary)
                    .map(|l| (l.index, l.dir)),
            )
            .collect();
        let mut free_rot = Vec::new();
        let mut between = vec![Matrix3::identity()];
        for (i, w) in effective {
            if is_fixed[i] {
                let last = between.last_mut().expect("never empty");
                *last *= rotation(&w, rad(fixed[i]));
            } else {
                free_rot.push((i, w));
                between.push(Matrix3::identity());
            }
        }
        let free_lin = (0..n).filter(|&i| !rotary[i] && !is_fixed[i]).collect();
        // Slots of the free rotary axes and cached rotations of fixed ones.
        let slot_axis: Vec<usize> = free_rot.iter().map(|&(i, _)| i).collect();
        let slot_dir = slot_axis
            .iter()
            .map(|&i| machine.axes[i].direction)
            .collect();
        for l in tool_chain.iter_mut().chain(work_chain.iter_mut()) {
            l.slot = free_rot.iter().position(|&(i, _)| i == l.index);
            if l.kind == AxisKind::Rotary && is_fixed[l.index] {
                l.fixed_rot = rotation(&l.dir, rad(fixed[l.index]));
            }
        }
        let (sp2_w2, sp2_p) = match free_rot.len() {
            2 => (
                between[1] * free_rot[1].1,
                between[1] * between[2] * machine.tool.axis,
            ),
            3 => (
                between[1] * free_rot[1].1,
                between[1] * between[2] * free_rot[2].1,
            ),
            _ => (Vector3::zeros(), Vector3::zeros()),
        };
        let c0t = between[0].transpose();
        Kinematics {
            n,
            sp2_w2,
            sp2_p,
            c0t,
            tool_chain,
            work_chain,
            rw0: machine.workpiece_rotation,
            ow0: machine.workpiece_origin,
            t0: machine.tool.point,
            a0: machine.tool.axis,
            r0: machine.tool.reference,
            fixed,
            is_fixed,
            limits,
            rotary,
            free_rot,
            between,
            free_lin,
            slot_axis,
            slot_dir,
        }
    }

    /// Number of axes.
    pub fn axis_count(&self) -> usize {
        self.n
    }

    /// Forward kinematics: the tool pose in the part frame for NC values `q`
    /// (machine-file order; every axis, fixed ones included).
    pub fn fk(&self, q: &[f64]) -> Pose {
        let mut rots = [Matrix3::identity(); 3];
        for (k, &i) in self.slot_axis.iter().enumerate() {
            rots[k] = rotation(&self.slot_dir[k], rad(q[i]));
        }
        let e = self.eval(q, &rots);
        Pose {
            point: e.point,
            axis: e.axis,
            reference: e.reference,
        }
    }

    /// The rotation of link `l` (cached for fixed axes).
    #[inline]
    fn rot<'a>(l: &'a Link, rots: &'a Rots) -> &'a Matrix3<f64> {
        match l.slot {
            Some(k) => &rots[k],
            None => &l.fixed_rot,
        }
    }

    /// One pass over both chains: the tool pose in the part frame at `q`, and
    /// the column of each free linear axis (the pose is affine in them).
    #[inline]
    fn eval(&self, q: &[f64], rots: &Rots) -> Eval {
        // Tool chain, base outwards: T = G_t1 ⋯ G_tm, G x = g (x − p) + p.
        let mut r = Matrix3::identity();
        let mut t = Vector3::zeros();
        let mut tool_cols = [Vector3::zeros(); 3];
        for l in &self.tool_chain {
            match l.kind {
                AxisKind::Linear => {
                    let d = r * l.dir;
                    if let Some(k) = l.free_lin {
                        tool_cols[k] = d;
                    }
                    t += d * q[l.index];
                }
                AxisKind::Rotary => {
                    let g = Self::rot(l, rots);
                    t += r * (l.point - g * l.point);
                    r *= g;
                }
            }
        }
        let x = r * self.t0 + t;
        // Workpiece chain, outermost first: S_j = G_w(j+1) ⋯ G_wk · W0 ends
        // as W. A linear axis j moves the part point by −S_jᵀ u_j per unit.
        let mut sr = self.rw0;
        let mut st = self.ow0;
        let mut cols = [Vector3::zeros(); 3];
        for l in self.work_chain.iter().rev() {
            match l.kind {
                AxisKind::Linear => {
                    if let Some(k) = l.free_lin {
                        cols[k] = -(sr.tr_mul(&l.dir));
                    }
                    st += l.dir * q[l.index];
                }
                AxisKind::Rotary => {
                    let g = Self::rot(l, rots);
                    sr = g * sr;
                    st = g * st + (l.point - g * l.point);
                }
            }
        }
        for l in &self.tool_chain {
            if let Some(k) = l.free_lin {
                cols[k] = sr.tr_mul(&tool_cols[k]);
            }
        }
        Eval {
            point: sr.tr_mul(&(x - st)),
            axis: sr.tr_mul(&(r * self.a0)),
            reference: self.r0.map(|v| sr.tr_mul(&(r * v))),
            cols,
        }
    }

    /// Inverse kinematics: every solution branch of `pose` and its 360°
    /// equivalents inside the rotary limits, appended to `out` (cleared
    /// first). A branch whose linear values are outside their travel appears
    /// once with its `violation` set; so does a branch with no equivalent
    /// inside the rotary limits, when no branch is inside every limit (see
    /// [`Kinematics::ik_all_branches`]).
    ///
    /// `hint` (e.g. the previous block) gives the value of an angle that is
    /// free at a singular pose, and the turn of rotary axes without limits.
    pub fn ik(
        &self,
        pose: &Pose,
        hint: Option<&[f64]>,
        out: &mut Vec<Solution>,
    ) -> Result<(), IkError> {
        self.solve(pose, hint, out, false)
    }

    /// Like [`Kinematics::ik`], but every branch is solved in full, also those
    /// with no equivalent inside the rotary limits while another branch has
    /// one (which [`Kinematics::ik`] leaves out to save time).
    pub fn ik_all_branches(
        &self,
        pose: &Pose,
        hint: Option<&[f64]>,
        out: &mut Vec<Solution>,
    ) -> Result<(), IkError> {
        self.solve(pose, hint, out, true)
    }

    fn solve(
        &self,
        pose: &Pose,
        hint: Option<&[f64]>,
        out: &mut Vec<Solution>,
        all_branches: bool,
    ) -> Result<(), IkError> {
        out.clear();
        let hint_of = |i: usize| hint.map_or(0.0, |h| h[i]);
        let target = self.rw0 * pose.axis;
        let mut orientations = [Orientation {
            joints: self.fixed,
            singular: false,
            angles: [ZERO_ANGLE; 3],
        }; 2];
        let count;
        match self.free_rot.len() {
            0 => {
                if (self.between[0] * self.a0 - target).norm() > 1e-9 {
                    return Err(IkError::OrientationUnreachable);
                }
                count = 1;
            }
            1 => {
                let (i, w) = self.free_rot[0];
                let u = self.between[1] * self.a0;
                let v = self.between[0].transpose() * target;
                if (w.dot(&u) - w.dot(&v)).abs() > 1e-9 {
                    return Err(IkError::OrientationUnreachable);
                }
                let o = &mut orientations[0];
                let angle = sp1_cs(&w, &u, &v).unwrap_or_else(|| {
                    o.singular = true;
                    degrees(hint_of(i))
                });
                o.set(0, i, angle);
                count = 1;
            }
            nfree => {
                let (i1, w1) = self.free_rot[0];
                let (i2, w2) = self.free_rot[1];
                let c = &self.between;
                let w2e = self.sp2_w2;
                // With a third free axis, the vector it leaves unchanged (its
                // own direction) must be carried to where the full target
                // rotation puts it; otherwise the tool axis.
                let (p, q, full) = if nfree == 3 {
                    let Some(reference) = pose.reference else {
                        return Err(IkError::NeedsReference);
                    };
                    let (_, w3) = self.free_rot[2];
                    let r0 = self.r0.ok_or(IkError::NeedsReference)?;
                    let target_rot =
                        frame(&target, &(self.rw0 * reference)) * frame(&self.a0, &r0).transpose();
                    let q = self.c0t * target_rot * c[3].transpose() * w3;
                    (self.sp2_p, q, Some(target_rot))
                } else {
                    (self.sp2_p, self.c0t * target, None)
                };
                let (sols, n) = sp2(&w1, &w2e, &p, &q, 1e-10);
                if n == 0 {
                    return Err(IkError::OrientationUnreachable);
                }
                for (k, s) in sols[..n].iter().enumerate() {
                    let o = &mut orientations[k];
                    let (a1, a2) = match (s.theta1, s.theta2) {
                        (Some(a1), Some(a2)) => (a1, a2),
                        // One angle is free (the tool axis lies on a rotary
                        // axis): keep the hinted value and solve the other
                        // one for it so that the tool axis is exact.
                        (None, a2) => {
                            o.singular = true;
                            let a1 = degrees(hint_of(i1));
                            let v = a1.rotation(&w1).transpose() * q;
                            let a2 = sp1_cs(&w2e, &p, &v).or(a2).unwrap_or(degrees(hint_of(i2)));
                            (a1, a2)
                        }
                        (Some(a1), None) => {
                            o.singular = true;
                            let a2 = degrees(hint_of(i2));
                            let u = a2.rotation(&w2e) * p;
                            (sp1_cs(&w1, &u, &q).unwrap_or(a1), a2)
                        }
                    };
                    o.set(0, i1, a1);
                    o.set(1, i2, a2);
                    if let Some(target_rot) = full {
                        let (i3, w3) = self.free_rot[2];
                        let r12 = c[0] * a1.rotation(&w1) * c[1] * a2.rotation(&w2) * c[2];
                        let f3 = r12.transpose() * target_rot * c[3].transpose();
                        // Any vector off the axis shows the angle of F3.
                        let x = any_perpendicular(&w3);
                        let a3 = sp1_cs(&w3, &x, &(f3 * x)).unwrap_or_else(|| {
                            o.singular = true;
                            degrees(hint_of(i3))
                        });
                        o.set(2, i3, a3);
                    }
                }
                count = n;
            }
        }

        // Branches whose rotary angles fit the travel first; the others are
        // only needed to say why nothing fits.
        let fits = |j: &Joints| {
            self.free_rot
                .iter()
                .all(|&(i, _)| has_equivalent(self.limits[i], wrap180(j[i])))
        };
        for pass in [true, false] {
            if !pass && !all_branches && out.iter().any(Solution::is_valid) {
                break;
            }
            for (k, o) in orientations[..count].iter().enumerate() {
                if fits(&o.joints) != pass {
                    continue;
                }
                let mut rots = [Matrix3::identity(); 3];
                for (slot, a) in o.angles[..self.free_rot.len()].iter().enumerate() {
                    rots[slot] = a.rotation(&self.slot_dir[slot]);
                }
                let Some(joints) = self.solve_linear(&o.joints, &rots, &pose.point) else {
                    continue;
                };
                self.push_equivalents(joints, k as u8, o.singular, hint, out);
            }
        }
        if out.is_empty() {
            return Err(IkError::PositionUnreachable);
        }
        Ok(())
    }

    /// With every rotary angle set in `joints`, solves the free linear axes so
    /// that the tool point lands on `target` (part frame).
    fn solve_linear(&self, joints: &Joints, rots: &Rots, target: &Vector3<f64>) -> Option<Joints> {
        let mut q = *joints;
        for &i in &self.free_lin {
            q[i] = 0.0;
        }
        let e = self.eval(&q, rots);
        let rhs = target - e.point;
        let c = &e.cols;
        let m = self.free_lin.len();
        let values: [f64; 3] = match m {
            3 => {
                // Cramer's rule with triple products.
                let c12 = c[1].cross(&c[2]);
                let det = c[0].dot(&c12);
                if det.abs() < 1e-12 {
                    return None;
                }
                [
                    rhs.dot(&c12) / det,
                    c[0].dot(&rhs.cross(&c[2])) / det,
                    c[0].dot(&c[1].cross(&rhs)) / det,
                ]
            }
            0 => [0.0; 3],
            _ => {
                // Least squares over the available axes; the residual then
                // tells whether the point is reachable at all.
                let j = nalgebra::DMatrix::from_fn(3, m, |r, k| c[k][r]);
                let b = nalgebra::DVector::from_column_slice(rhs.as_slice());
                let x = j.svd(true, true).solve(&b, 1e-12).ok()?;
                let mut out = [0.0; 3];
                out[..m].copy_from_slice(x.as_slice());
                out
            }
        };
        let mut moved = Vector3::zeros();
        for (k, &i) in self.free_lin.iter().enumerate() {
            q[i] = values[k];
            moved += c[k] * values[k];
        }
        if m < 3 && (moved - rhs).norm() > 1e-9 * (1.0 + rhs.norm()) {
            return None;
        }
        if !values.iter().all(|v| v.is_finite()) {
            return None;
        }
        Some(q)
    }

    fn push_equivalents(
        &self,
        joints: Joints,
        branch: u8,
        singular: bool,
        hint: Option<&[f64]>,
        out: &mut Vec<Solution>,
    ) {
        // Linear axes first: their values do not change between equivalents.
        let linear_violation = (0..self.n)
            .filter(|&i| !self.rotary[i] && !self.is_fixed[i])
            .find(|&i| !accepts(self.limits[i], joints[i]))
            .map(|i| Violation {
                axis: i,
                value: joints[i],
            });
        let start = out.len();
        let mut stack = joints;
        self.expand(0, &mut stack, branch, singular, hint, out);
        if out.len() == start {
            // No equivalent inside the limits: report the principal value.
            let (i, v) = self
                .free_rot
                .iter()
                .map(|&(i, _)| (i, wrap180(joints[i])))
                .find(|&(i, v)| !has_equivalent(self.limits[i], v))
                .unwrap_or((0, joints[0]));
            out.push(Solution {
                joints,
                branch,
                singular,
                violation: Some(Violation { axis: i, value: v }),
            });
        } else if let Some(v) = linear_violation {
            for s in &mut out[start..] {
                s.violation = Some(v);
            }
            out.truncate(start + 1);
        }
    }

    fn expand(
        &self,
        k: usize,
        joints: &mut Joints,
        branch: u8,
        singular: bool,
        hint: Option<&[f64]>,
        out: &mut Vec<Solution>,
    ) {
        let Some(&(i, _)) = self.free_rot.get(k) else {
            out.push(Solution {
                joints: *joints,
                branch,
                singular,
                violation: None,
            });
            return;
        };
        let principal = wrap180(joints[i]);
        match self.limits[i] {
            None => {
                // Unlimited: the turn nearest the hint (continuous output).
                let h = hint.map_or(0.0, |h| h[i]);
                joints[i] = principal + 360.0 * turns_nearest((h - principal) / 360.0) as f64;
                self.expand(k + 1, joints, branch, singular, hint, out);
            }
            Some([lo, hi]) => {
                let (first, last) = turn_range(lo, hi, principal);
                for turn in first..=last {
                    joints[i] = principal + 360.0 * turn as f64;
                    self.expand(k + 1, joints, branch, singular, hint, out);
                }
            }
        }
    }
}

fn accepts(limits: Option<[f64; 2]>, v: f64) -> bool {
    match limits {
        None => v.is_finite(),
        Some([lo, hi]) => v >= lo - 1e-9 && v <= hi + 1e-9,
    }
}

fn has_equivalent(limits: Option<[f64; 2]>, principal: f64) -> bool {
    match limits {
        None => true,
        Some([lo, hi]) => {
            let (first, last) = turn_range(lo, hi, principal);
            first <= last
        }
    }
}

// Rounding by integer conversion: `floor`, `ceil`, `round` and `fmod` are
// library calls on baseline x86-64 and showed up in the posting profile.
// Angles here are far below 2^53 turns.

/// ⌊x⌋ as an integer.
#[inline]
fn floor_i(x: f64) -> i64 {
    let t = x as i64;
    if (t as f64) > x { t - 1 } else { t }
}

/// The nearest integer to x (halves away from zero or not: callers do not care).
#[inline]
fn turns_nearest(x: f64) -> i64 {
    floor_i(x + 0.5)
}

/// The whole turns k with lo ≤ principal + 360k ≤ hi (1e-9° slack).
#[inline]
fn turn_range(lo: f64, hi: f64, principal: f64) -> (i64, i64) {
    (
        -floor_i(-(lo - 1e-9 - principal) / 360.0),
        floor_i((hi + 1e-9 - principal) / 360.0),
    )
}

/// Angle in degrees wrapped to (−180, 180].
#[inline]
pub fn wrap180(deg: f64) -> f64 {
    let w = deg - 360.0 * turns_nearest(deg / 360.0) as f64;
    if w <= -180.0 {
        w + 360.0
    } else if w > 180.0 {
        w - 360.0
    } else {
        w
    }
}

/// The solved orientation of one branch.
#[derive(Clone, Copy)]
struct Orientation {
    joints: Joints,
    singular: bool,
    /// Angles of the free rotary slots.
    angles: [Angle; 3],
}

impl Orientation {
    fn set(&mut self, slot: usize, axis: usize, angle: Angle) {
        self.joints[axis] = angle.rad.to_degrees();
        self.angles[slot] = angle;
    }
}

const ZERO_ANGLE: Angle = Angle {
    rad: 0.0,
    cos: 1.0,
    sin: 0.0,
};

/// An angle given in degrees.
fn degrees(deg: f64) -> Angle {
    let rad = deg.to_radians();
    let (sin, cos) = rad.sin_cos();
    Angle { rad, cos, sin }
}

/// Orthonormal frame (columns a, b', a×b') from a direction and a second,
/// not parallel one (Gram–Schmidt).
fn frame(a: &Vector3<f64>, b: &Vector3<f64>) -> Matrix3<f64> {
    let b = (b - a * a.dot(b)).normalize();
    Matrix3::from_columns(&[*a, b, a.cross(&b)])
}

fn any_perpendicular(w: &Vector3<f64>) -> Vector3<f64> {
    let seed = if w.x.abs() < 0.6 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let p = seed - w * w.dot(&seed);
    debug_assert!(p.norm() > FREE_EPS);
    p.normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rounding_helpers_match_the_library() {
        for x in [
            -721.5,
            -360.0,
            -180.0,
            -179.999,
            -0.5,
            -1e-12,
            0.0,
            1e-12,
            0.49,
            180.0,
            359.9,
            540.0,
            1e6 + 0.25,
        ] {
            assert_eq!(floor_i(x), x.floor() as i64, "{x}");
            let w = wrap180(x);
            assert!(w > -180.0 && w <= 180.0, "{x} -> {w}");
            assert!(
                ((x - w) / 360.0 - ((x - w) / 360.0).round()).abs() < 1e-12,
                "{x} -> {w}"
            );
        }
        assert_eq!(wrap180(-180.0), 180.0);
        assert_eq!(turn_range(-360.0, 360.0, 10.0), (-1, 0));
        assert_eq!(turn_range(-45.2, 45.2, 10.0), (0, 0));
        assert_eq!(turn_range(-45.2, 45.2, 50.0), (0, -1));
        assert_eq!(turn_range(0.0, 720.0, -90.0), (1, 2));
    }
}
