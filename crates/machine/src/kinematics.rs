//! Forward and inverse kinematics of a [`Machine`] by the product of
//! exponentials over the home configuration (Lynch & Park 2017, §4.1).
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
//!
//! Evaluation: the tool pose in the part frame is one chain of rigid motions,
//!
//! ```text
//! W(q)⁻¹ · T(q) = W0⁻¹ · G_wk⁻¹ ⋯ G_w1⁻¹ · G_t1 ⋯ G_tm · T0,
//! ```
//!
//! and every constant motion in it (the part frame, rotary axes locked at a
//! value) is carried inwards to the tool at construction: a constant `C` in
//! front of an axis motion `G(u, p)` equals `G(R_C u, C p) · C`. (A locked
//! linear axis stays in the chain and moves by the value it is given, like
//! the free ones.) What is left is
//! the product of exponentials in the part frame at home (Murray, Li,
//! Sastry §3.2): the free axes with their lines moved into the part frame,
//! then the constant tool point and directions. [`Kinematics::fk`] applies
//! that chain to three vectors with hand-written 3×3 products; the inverse
//! kinematics solves the linear axes in the frame just inside the outermost
//! of them, where their columns are constant on most machines (precomputed
//! Cramer rows).

use nalgebra::{Matrix3, Vector3};

use crate::angle::{atan2_deg, sin_cos_deg};

mod bodies;
mod chord;
mod reach;
mod singular;
pub use bodies::BodyPoses;
pub use chord::{lever_over, midpoint_bound};
pub use reach::{AXIS_ROUNDING_RAD, IkFailure, MAX_AXIS_ROUNDING_RAD};
pub use singular::{Excursion, Folds, Singularity};

use crate::model::{AxisKind, MAX_AXES, Machine, Pose, Side};
use crate::subproblems::{FREE_EPS, Sp2, coordinate_axis, rotation, rotation_cs, sp1_xy, unit_xy};

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
    /// The requested tool axis lies just beyond the directions the machine
    /// can point (CL rounding, within [`Kinematics::axis_rounding`]): this solution
    /// points the nearest one it can ([`Kinematics::axis_reach`]).
    pub nearest_axis: bool,
    /// The first axis outside its travel, for a branch that has no
    /// equivalent inside the limits.
    pub violation: Option<Violation>,
}

impl Solution {
    /// Whether it lies inside the travel.
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

type V3 = Vector3<f64>;

/// A 3×3 matrix by rows, multiplied out by hand: the hot path needs only
/// matrix × vector, which nalgebra's generic products do not inline as well.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Rot([[f64; 3]; 3]);

impl Rot {
    fn from_matrix(m: &Matrix3<f64>) -> Rot {
        Rot(std::array::from_fn(|i| std::array::from_fn(|j| m[(i, j)])))
    }

    fn matrix(&self) -> Matrix3<f64> {
        Matrix3::from_fn(|i, j| self.0[i][j])
    }

    /// `self · v`.
    #[inline(always)]
    fn apply(&self, v: &V3) -> V3 {
        let r = &self.0;
        V3::new(
            r[0][0] * v.x + r[0][1] * v.y + r[0][2] * v.z,
            r[1][0] * v.x + r[1][1] * v.y + r[1][2] * v.z,
            r[2][0] * v.x + r[2][1] * v.y + r[2][2] * v.z,
        )
    }

    /// `selfᵀ · v`.
    #[inline(always)]
    fn apply_t(&self, v: &V3) -> V3 {
        let r = &self.0;
        V3::new(
            r[0][0] * v.x + r[1][0] * v.y + r[2][0] * v.z,
            r[0][1] * v.x + r[1][1] * v.y + r[2][1] * v.z,
            r[0][2] * v.x + r[1][2] * v.y + r[2][2] * v.z,
        )
    }
}

/// The line of a free rotary axis in the part frame at home, with what
/// Rodrigues' formula needs of its direction.
#[derive(Debug, Clone, Copy)]
struct Turn {
    /// Machine-file index of the axis.
    axis: usize,
    /// Position among the free rotary axes (effective-chain order).
    slot: usize,
    /// Unit direction (negated for a workpiece axis: the chain holds its
    /// inverse) and a point of the line.
    dir: V3,
    point: V3,
    /// xx, xy, xz, yy, yz, zz of `dir`.
    dir2: [f64; 6],
    /// `Some(k)` when `dir` is ±e_k exactly (most machines): the rotation
    /// then turns two coordinates only.
    aligned: Option<usize>,
}

impl Turn {
    fn new(axis: usize, slot: usize, dir: V3, point: V3) -> Turn {
        let (x, y, z) = (dir.x, dir.y, dir.z);
        let aligned = coordinate_axis(&dir).map(|(k, _)| k);
        Turn {
            axis,
            slot,
            dir,
            point,
            dir2: [x * x, x * y, x * z, y * y, y * z, z * z],
            aligned,
        }
    }

    /// The rotation about `dir` by the angle with cosine `c` and sine `s`
    /// (Rodrigues: `c·I + s·[w]× + (1 − c)·w wᵀ`, as
    /// [`rotation_cs`](crate::subproblems::rotation_cs)).
    #[inline(always)]
    fn rotation(&self, c: f64, s: f64) -> Turned {
        let v = 1.0 - c;
        if let Some(k) = self.aligned {
            // Rodrigues' terms for w = ±e_k: `c + 1·v` on the diagonal at k
            // (not exactly 1), `c` at the other two, `∓s` off the diagonal
            // (`w_k·s` below), zeros elsewhere.
            return Turned::Axis {
                k,
                c,
                s: self.dir[k] * s,
                d: c + v,
            };
        }
        let (x, y, z) = (self.dir.x * s, self.dir.y * s, self.dir.z * s);
        let [xx, xy, xz, yy, yz, zz] = self.dir2;
        Turned::Matrix(Rot([
            [c + xx * v, xy * v - z, xz * v + y],
            [xy * v + z, c + yy * v, yz * v - x],
            [xz * v - y, yz * v + x, c + zz * v],
        ]))
    }

    /// `m·(x − point) + point`: the point `x` turned about the line.
    #[inline(always)]
    fn move_point(&self, m: &Turned, x: &V3) -> V3 {
        m.apply(&(x - self.point)) + self.point
    }

    /// The inverse of [`Turn::move_point`].
    #[inline(always)]
    fn unmove_point(&self, m: &Turned, x: &V3) -> V3 {
        m.apply_t(&(x - self.point)) + self.point
    }
}

/// The rotation of a [`Turn`] for some angle.
#[derive(Debug, Clone, Copy)]
enum Turned {
    /// About the coordinate axis `k`: cosine, sine (signed by the
    /// direction) and the diagonal term `d = c + (1 − c)` at `k`. The
    /// products are those of the full matrix without its zero terms: the
    /// same values, up to the sign of a zero result.
    Axis {
        k: usize,
        c: f64,
        s: f64,
        d: f64,
    },
    Matrix(Rot),
}

impl Turned {
    /// `self · v`.
    #[inline(always)]
    fn apply(&self, v: &V3) -> V3 {
        match *self {
            Turned::Axis { k, c, s, d } => about_axis(k, c, s, d, v),
            Turned::Matrix(ref m) => m.apply(v),
        }
    }

    /// `selfᵀ · v`: the turn back, by `−s`.
    #[inline(always)]
    fn apply_t(&self, v: &V3) -> V3 {
        match *self {
            Turned::Axis { k, c, s, d } => about_axis(k, c, -s, d, v),
            Turned::Matrix(ref m) => m.apply_t(v),
        }
    }
}

/// `v` turned about the coordinate axis `k` (cosine `c`, sine `s`, diagonal
/// term `d`): the rows of [`Turn::rotation`] with their zero terms left out,
/// each sum in the same order.
#[inline(always)]
fn about_axis(k: usize, c: f64, s: f64, d: f64, v: &V3) -> V3 {
    match k {
        0 => V3::new(d * v.x, c * v.y - s * v.z, s * v.y + c * v.z),
        1 => V3::new(c * v.x + s * v.z, d * v.y, c * v.z - s * v.x),
        _ => V3::new(c * v.x - s * v.y, s * v.x + c * v.y, d * v.z),
    }
}

/// One motion of the chain from the part frame (outermost) to the tool.
#[derive(Debug, Clone, Copy)]
enum Step {
    /// `x ↦ x + q·dir`, `q` the value of axis `axis`; `column`: position
    /// among the free linear axes (`None` for a locked axis, which moves by
    /// the value it is given like the others).
    Linear {
        axis: usize,
        column: Option<usize>,
        dir: V3,
    },
    /// A free rotary axis.
    Rotary(Turn),
}

/// How the free linear axes are solved once the angles are known.
#[derive(Debug, Clone, Copy)]
enum LinearSolve {
    /// Three free linear axes with no free rotary axis between them: their
    /// columns are constant inside the outermost of them, and so are the
    /// rows of Cramer's rule (`(c_j × c_k) / det`, cyclic), by column;
    /// `axes`: the machine-file index of each column's axis, `bounds` its
    /// travel (as `Kinematics::free_lin_bounds`).
    Constant {
        rows: [V3; 3],
        axes: [usize; 3],
        bounds: [[f64; 2]; 3],
    },
    /// Columns that depend on the angles, or fewer than three axes.
    General,
}

/// A machine compiled for fast kinematics.
#[derive(Debug, Clone)]
pub struct Kinematics {
    n: usize,
    /// The chain in the part frame at home, outermost first.
    steps: Vec<Step>,
    /// The number of steps outside the outermost free linear axis (all of
    /// them if there is none): the linear axes are solved inside them.
    split: usize,
    linear_solve: LinearSolve,
    /// The tool point, axis and reference at home in the part frame, with
    /// every constant of the chain applied.
    tip: V3,
    tip_axis: V3,
    tip_reference: V3,
    rw0: Matrix3<f64>,
    a0: Vector3<f64>,
    r0: Option<Vector3<f64>>,
    fixed: Joints,
    /// The free linear axes with their travel widened by the 1e-9 slack of
    /// [`Axis::accepts`](crate::Axis::accepts) (infinite without limits:
    /// the values tested are finite).
    free_lin_bounds: Vec<(usize, [f64; 2])>,
    /// Free rotary axes in effective-chain order: (axis index, signed direction).
    free_rot: Vec<(usize, Vector3<f64>)>,
    /// The free rotary axes by slot.
    slots: [Slot; 3],
    /// The steps inside the outermost free linear axis other than free
    /// linear axes: what moves the tool point when those are at zero.
    inner_fixed: Vec<Step>,
    /// `C0ᵀ·R_W0`: the CL tool axis as subproblem 2 of two free rotary
    /// axes takes it.
    axis_to_sp2: Rot,
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
    sp2: Sp2,
    c0t: Matrix3<f64>,
    /// How far outside the directions the machine can point a CL tool axis
    /// may lie and still be solved at the nearest one (see
    /// [`Kinematics::set_axis_rounding`]).
    axis_rounding: f64,
    /// The axes in the machine frame, for [`Kinematics::body_poses`].
    body_axes: Vec<bodies::BodyAxis>,
    /// The part frame at home, machine frame.
    w0: nalgebra::Isometry3<f64>,
}

#[inline]
fn rad(deg: f64) -> f64 {
    deg.to_radians()
}

/// A rigid motion `x ↦ rot·x + shift`.
#[derive(Clone, Copy)]
struct Rigid {
    rot: Rot,
    shift: V3,
}

impl Rigid {
    /// `self · other`.
    fn then_inner(&self, other: &Rigid) -> Rigid {
        Rigid {
            rot: Rot::from_matrix(&(self.rot.matrix() * other.rot.matrix())),
            shift: self.rot.apply(&other.shift) + self.shift,
        }
    }

    /// The rotation by `deg` about the line (`point`, `dir`).
    fn about(dir: &V3, point: &V3, deg: f64) -> Rigid {
        let rot = Rot::from_matrix(&rotation(dir, rad(deg)));
        Rigid {
            rot,
            shift: point - rot.apply(point),
        }
    }
}

/// The effective orientation chain (directions only) of `chain` (axis
/// and sign, outermost first): the free rotary axes with their directions,
/// and the constant rotations before, between and after them.
fn orientation_chain(
    machine: &Machine,
    chain: &[(usize, f64)],
) -> (Vec<(usize, V3)>, Vec<Matrix3<f64>>) {
    let mut free_rot = Vec::new();
    let mut between = vec![Matrix3::identity()];
    for &(i, sign) in chain {
        let a = &machine.axes[i];
        if !a.is_rotary() {
            continue;
        }
        let w = a.direction * sign;
        match a.fixed {
            Some(v) => {
                let last = between.last_mut().expect("never empty");
                *last *= rotation(&w, rad(v));
            }
            None => {
                free_rot.push((i, w));
                between.push(Matrix3::identity());
            }
        }
    }
    (free_rot, between)
}

/// The chain's motions in the part frame, the constants of locked rotary
/// axes carried inwards, and the product of those constants (which moves
/// the tool frame).
fn motion_steps(
    machine: &Machine,
    chain: &[(usize, f64)],
    free_lin: &[usize],
    free_rot: &[(usize, V3)],
) -> (Vec<Step>, Rigid) {
    let rw0t = machine.workpiece_rotation.transpose();
    let mut carried = Rigid {
        rot: Rot::from_matrix(&rw0t),
        shift: -(rw0t * machine.workpiece_origin),
    };
    let mut steps = Vec::new();
    for &(i, sign) in chain {
        let a = &machine.axes[i];
        let dir = a.direction * sign;
        match (a.kind, a.fixed) {
            (AxisKind::Linear, _) => steps.push(Step::Linear {
                axis: i,
                column: free_lin.iter().position(|&j| j == i),
                dir: carried.rot.apply(&dir),
            }),
            (AxisKind::Rotary, Some(v)) => {
                carried = carried.then_inner(&Rigid::about(&dir, &a.point, v));
            }
            (AxisKind::Rotary, None) => {
                let slot = free_rot.iter().position(|&(j, _)| j == i).expect("free");
                steps.push(Step::Rotary(Turn::new(
                    i,
                    slot,
                    carried.rot.apply(&dir),
                    carried.rot.apply(&a.point) + carried.shift,
                )));
            }
        }
    }
    (steps, carried)
}

/// The slots of the free rotary axes: their travel, and the arc of it
/// where it is less than a full turn and a degree.
fn rotary_slots(steps: &[Step], limits: &[Option<[f64; 2]>; MAX_AXES]) -> [Slot; 3] {
    let mut slots = [Slot::default(); 3];
    for step in steps {
        if let Step::Rotary(t) = step {
            let limits = limits[t.axis];
            slots[t.slot] = Slot {
                axis: t.axis,
                limits,
                // A travel of a full turn and a degree has an equivalent of
                // every angle, with margin over the rounding of
                // `turn_range`.
                arc: match limits {
                    Some([lo, hi]) if hi - lo < 361.0 => Some(Arc::new(lo, hi)),
                    _ => None,
                },
            };
        }
    }
    slots
}

/// The linear axes of a chain as the inverse kinematics solves them.
struct LinearPart {
    /// The first step that is a free linear axis.
    split: usize,
    /// The steps after it that are not free linear axes.
    inner_fixed: Vec<Step>,
    /// The travel of each free linear axis, with a slack for rounding.
    bounds: Vec<(usize, [f64; 2])>,
    solve: LinearSolve,
}

impl LinearPart {
    fn of(steps: &[Step], free_lin: &[usize], limits: &[Option<[f64; 2]>; MAX_AXES]) -> LinearPart {
        let is_free_linear = |s: &Step| {
            matches!(
                s,
                Step::Linear {
                    column: Some(_),
                    ..
                }
            )
        };
        let split = steps.iter().position(is_free_linear).unwrap_or(steps.len());
        let last_linear = steps.iter().rposition(is_free_linear).unwrap_or(split);
        let turns_between = steps[split..last_linear.max(split)]
            .iter()
            .any(|s| matches!(s, Step::Rotary(_)));
        let inner_fixed = steps[split..]
            .iter()
            .filter(|s| !is_free_linear(s))
            .copied()
            .collect();
        let mut columns = [V3::zeros(); 3];
        for s in steps {
            if let Step::Linear {
                column: Some(k),
                dir,
                ..
            } = s
            {
                columns[*k] = *dir;
            }
        }
        let bounds: Vec<(usize, [f64; 2])> = free_lin
            .iter()
            .map(|&i| {
                let b = match limits[i] {
                    Some([lo, hi]) => [lo - 1e-9, hi + 1e-9],
                    None => [f64::NEG_INFINITY, f64::INFINITY],
                };
                (i, b)
            })
            .collect();
        let solve = match cramer_rows(&columns) {
            Some(rows) if free_lin.len() == 3 && !turns_between => LinearSolve::Constant {
                rows,
                axes: [free_lin[0], free_lin[1], free_lin[2]],
                bounds: std::array::from_fn(|k| bounds[k].1),
            },
            _ => LinearSolve::General,
        };
        LinearPart {
            split,
            inner_fixed,
            bounds,
            solve,
        }
    }
}

impl Kinematics {
    /// Compiles a validated machine.
    pub fn new(machine: &Machine) -> Kinematics {
        let n = machine.axes.len();
        let mut fixed = [0.0; MAX_AXES];
        let mut is_fixed = [false; MAX_AXES];
        let mut limits = [None; MAX_AXES];
        let mut rotary = [false; MAX_AXES];
        for (i, a) in machine.axes.iter().enumerate() {
            fixed[i] = a.fixed.unwrap_or(0.0);
            is_fixed[i] = a.fixed.is_some();
            limits[i] = a.travel();
            rotary[i] = a.is_rotary();
        }
        // The chain outermost first: W0⁻¹, the workpiece axes inverted from
        // the part outwards, then the tool axes from the base. An axis
        // locked at zero is the identity motion (the C axis of the 5-axis
        // mts1600).
        let (work, tool): (Vec<usize>, Vec<usize>) =
            (0..n).partition(|&i| machine.axes[i].side == Side::Workpiece);
        let chain: Vec<(usize, f64)> = work
            .iter()
            .rev()
            .map(|&i| (i, -1.0))
            .chain(tool.iter().map(|&i| (i, 1.0)))
            .filter(|&(i, _)| machine.axes[i].fixed != Some(0.0))
            .collect();
        let free_lin: Vec<usize> = (0..n).filter(|&i| !rotary[i] && !is_fixed[i]).collect();

        let (free_rot, between) = orientation_chain(machine, &chain);
        let (steps, carried) = motion_steps(machine, &chain, &free_lin, &free_rot);
        let tool = &machine.tool;
        let tip = carried.rot.apply(&tool.point) + carried.shift;
        let tip_axis = carried.rot.apply(&tool.axis);
        let tip_reference = carried.rot.apply(&tool.reference.unwrap_or_else(V3::zeros));
        let slots = rotary_slots(&steps, &limits);
        let linear = LinearPart::of(&steps, &free_lin, &limits);
        let (split, inner_fixed, free_lin_bounds, linear_solve) = (
            linear.split,
            linear.inner_fixed,
            linear.bounds,
            linear.solve,
        );

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
        let w1 = free_rot.first().map_or_else(V3::zeros, |r| r.1);
        let sp2 = Sp2::new(&w1, &sp2_w2, &sp2_p);
        let axis_to_sp2 = Rot::from_matrix(&(c0t * machine.workpiece_rotation));
        Kinematics {
            n,
            steps,
            split,
            slots,
            inner_fixed,
            axis_to_sp2,
            linear_solve,
            tip,
            tip_axis,
            tip_reference,
            sp2_w2,
            sp2_p,
            sp2,
            c0t,
            rw0: machine.workpiece_rotation,
            a0: machine.tool.axis,
            r0: machine.tool.reference,
            fixed,
            free_lin_bounds,
            free_rot,
            between,
            free_lin,
            axis_rounding: AXIS_ROUNDING_RAD,
            body_axes: bodies::BodyAxis::of(machine),
            w0: nalgebra::Isometry3::from_parts(
                machine.workpiece_origin.into(),
                nalgebra::UnitQuaternion::from_rotation_matrix(
                    &nalgebra::Rotation3::from_matrix_unchecked(machine.workpiece_rotation),
                ),
            ),
        }
    }

    /// Number of axes.
    pub fn axis_count(&self) -> usize {
        self.n
    }

    /// Forward kinematics: the tool pose in the part frame for NC values `q`
    /// (machine-file order; every axis, fixed ones included).
    pub fn fk(&self, q: &[f64]) -> Pose {
        self.chain::<false>(q, true, |_, deg| sin_cos_deg(deg)).0
    }

    /// The forward kinematics, and with `LEVER` the largest distance from
    /// the tool point to the point of a free rotary axis line (see
    /// [`Kinematics::fk_lever`]). `sin_cos(axis, degrees)` gives the sine
    /// and cosine of an axis value.
    #[inline(always)]
    fn chain<const LEVER: bool>(
        &self,
        q: &[f64],
        with_reference: bool,
        mut sin_cos: impl FnMut(usize, f64) -> (f64, f64),
    ) -> (Pose, f64) {
        let mut point = self.tip;
        let mut axis = self.tip_axis;
        let mut reference = self.tip_reference;
        let mut lever2: f64 = 0.0;
        // (A machine without a reference direction returns none: not
        // turned.)
        let with_reference = with_reference && self.r0.is_some();
        for step in self.steps.iter().rev() {
            match step {
                Step::Linear { axis: i, dir, .. } => point += dir * q[*i],
                Step::Rotary(t) => {
                    if LEVER {
                        // A turn about the line keeps the distance to its
                        // point.
                        lever2 = lever2.max((point - t.point).norm_squared());
                    }
                    let (s, c) = sin_cos(t.axis, q[t.axis]);
                    let m = t.rotation(c, s);
                    point = t.move_point(&m, &point);
                    axis = m.apply(&axis);
                    if with_reference {
                        reference = m.apply(&reference);
                    }
                }
            }
        }
        let pose = Pose {
            point,
            axis,
            reference: with_reference.then_some(reference),
        };
        (pose, if LEVER { lever2.sqrt() } else { 0.0 })
    }

    /// Inverse kinematics: every solution branch of `pose` and its 360°
    /// equivalents inside the rotary limits, appended to `out` (cleared
    /// first). A branch whose linear values are outside their travel appears
    /// once with its `violation` set; so does a branch with no equivalent
    /// inside the rotary limits, when no branch is inside every limit (see
    /// [`Kinematics::ik_all_branches`]).
    ///
    /// `hint` (e.g. the previous block) gives the value of an angle that is
    /// free at a singular pose, and the turns of rotary axes without limits:
    /// those within 210° of the hint (one, or two for an angle about half a
    /// turn from it).
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
        match self.free_rot.len() {
            0 => self.solve_n::<0>(pose, hint, out, all_branches),
            1 => self.solve_n::<1>(pose, hint, out, all_branches),
            2 => self.solve_n::<2>(pose, hint, out, all_branches),
            _ => self.solve_n::<3>(pose, hint, out, all_branches),
        }
    }

    /// [`Kinematics::solve`] for `N` free rotary axes: one piece of code,
    /// its loops over the rotary slots unrolled for each `N` (each its own
    /// function: a frame of its own size).
    #[inline(never)]
    fn solve_n<const N: usize>(
        &self,
        pose: &Pose,
        hint: Option<&[f64]>,
        out: &mut Vec<Solution>,
        all_branches: bool,
    ) -> Result<(), IkError> {
        out.clear();
        let mut branches = [Branch::<N>::default(); 2];
        let two = if N == 2 {
            self.orient_two(pose, &mut branches)
        } else {
            None
        };
        let count = match two {
            Some(count) => count,
            None => self.orient_any(pose, hint, &mut branches)?,
        };
        // Branches whose rotary angles fit the travel first; the others are
        // only needed to say why nothing fits. An angle (its `atan2`) is
        // found only when it is needed: for the slots with less than a full
        // turn of travel to decide whether a branch fits, for the others
        // when the branch is solved.
        // (Written out for the one or two branches: as loops, the compiler
        // hoists the setup of every slot out of them, which costs more than
        // the loops save.)
        let [b0, b1] = &mut branches;
        let second = count > 1;
        let fits0 = self.fits::<N>(b0);
        if fits0 {
            self.solve_branch::<N>(b0, 0, &pose.point, hint, out);
        }
        let fits1 = second && self.fits::<N>(b1);
        if fits1 {
            self.solve_branch::<N>(b1, 1, &pose.point, hint, out);
        }
        if all_branches || !out.iter().any(Solution::is_valid) {
            if !fits0 {
                self.solve_branch::<N>(b0, 0, &pose.point, hint, out);
            }
            if second && !fits1 {
                self.solve_branch::<N>(b1, 1, &pose.point, hint, out);
            }
        }
        if out.is_empty() {
            return Err(IkError::PositionUnreachable);
        }
        Ok(())
    }

    /// The orientation of two free rotary axes when subproblem 2 has
    /// solutions and no angle is free (the usual pose): the number of
    /// branches. `None` otherwise, for [`Kinematics::orient`] to decide
    /// (from the very same subproblem).
    /// (Generic only to fit [`Kinematics::solve_n`]: called with `N = 2`.)
    #[inline(always)]
    fn orient_two<const N: usize>(
        &self,
        pose: &Pose,
        branches: &mut [Branch<N>; 2],
    ) -> Option<usize> {
        let q = self.axis_to_sp2.apply(&pose.axis);
        let (sols, n) = self.sp2.solve_xy(&q, 0.0);
        let lengths = self.sp2.xy_lengths(&q);
        for (b, s) in branches.iter_mut().zip(&sols[..n]) {
            let ((x1, y1), (x2, y2)) = (s.theta1?, s.theta2?);
            match lengths {
                Some([r1, r2]) => {
                    b.angles[0] = SlotAngle::from_xy_length(x1, y1, r1);
                    b.angles[1] = SlotAngle::from_xy_length(x2, y2, r2);
                }
                None => {
                    b.angles[0] = SlotAngle::from_xy(x1, y1);
                    b.angles[1] = SlotAngle::from_xy(x2, y2);
                }
            }
        }
        (n > 0).then_some(n)
    }

    /// [`Kinematics::orient`] for `N` slots.
    #[cold]
    #[inline(never)]
    fn orient_any<const N: usize>(
        &self,
        pose: &Pose,
        hint: Option<&[f64]>,
        branches: &mut [Branch<N>; 2],
    ) -> Result<usize, IkError> {
        let mut all = [Branch::default(); 2];
        let count = self.orient(pose, hint, &mut all)?;
        for (b, a) in branches.iter_mut().zip(&all) {
            b.angles.copy_from_slice(&a.angles[..N]);
            b.singular = a.singular;
            b.nearest_axis = a.nearest_axis;
        }
        Ok(count)
    }

    /// The orientation branches of `pose`, for any number of free rotary
    /// axes and singular poses: the number of branches.
    #[cold]
    #[inline(never)]
    fn orient(
        &self,
        pose: &Pose,
        hint: Option<&[f64]>,
        branches: &mut [Branch<3>; 2],
    ) -> Result<usize, IkError> {
        let hint_of = |i: usize| hint.map_or(0.0, |h| h[i]);
        let target = self.rw0 * pose.axis;
        let count;
        match self.free_rot.len() {
            0 => {
                if (self.between[0] * self.a0 - target).norm() > 1e-9 {
                    if self.axis_reach(&pose.axis).0 > self.axis_rounding {
                        return Err(IkError::OrientationUnreachable);
                    }
                    branches[0].nearest_axis = true;
                }
                count = 1;
            }
            1 => {
                let (i, w) = self.free_rot[0];
                let u = self.between[1] * self.a0;
                let v = self.between[0].transpose() * target;
                // (Subproblem 1 by projection turns `u` to the nearest
                // direction of its cone.)
                let b = &mut branches[0];
                if (w.dot(&u) - w.dot(&v)).abs() > 1e-9 {
                    if self.axis_reach(&pose.axis).0 > self.axis_rounding {
                        return Err(IkError::OrientationUnreachable);
                    }
                    b.nearest_axis = true;
                }
                b.angles[0] = match sp1_xy(&w, &u, &v) {
                    Some((x, y)) => SlotAngle::from_xy(x, y),
                    None => {
                        b.singular = true;
                        SlotAngle::from_degrees(hint_of(i))
                    }
                };
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
                    (self.sp2_p, self.axis_to_sp2.apply(&pose.axis), None)
                };
                let (mut sols, mut n) = self.sp2.solve_xy(&q, 0.0);
                let mut nearest_axis = false;
                if n == 0 && full.is_none() {
                    // Just beyond a fold (CL rounding): the nearest axis on
                    // it, where the two branches meet. (On it, by the
                    // measure of `axis_reach`, subproblem 2's own rounding
                    // missed it: the axis itself.)
                    let (gap, nearest) = self.axis_reach(&pose.axis);
                    nearest_axis = gap > 0.0;
                    if gap <= self.axis_rounding {
                        (sols, n) = self
                            .sp2
                            .solve_xy(&self.axis_to_sp2.apply(&nearest), f64::INFINITY);
                        // Both branches, as the path on either side has it.
                        if n == 1 {
                            (sols[1], n) = (sols[0], 2);
                        }
                    }
                }
                if n == 0 {
                    return Err(IkError::OrientationUnreachable);
                }
                for (k, s) in sols[..n].iter().enumerate() {
                    let b = &mut branches[k];
                    b.nearest_axis = nearest_axis;
                    let (a1, a2) = match (s.theta1, s.theta2) {
                        (Some((x1, y1)), Some((x2, y2))) => {
                            (SlotAngle::from_xy(x1, y1), SlotAngle::from_xy(x2, y2))
                        }
                        // One angle is free (the tool axis lies on a rotary
                        // axis): keep the hinted value and solve the other
                        // one for it so that the tool axis is exact.
                        (None, a2) => {
                            b.singular = true;
                            let a1 = SlotAngle::from_degrees(hint_of(i1));
                            let v = a1.rotation(&w1).transpose() * q;
                            let a2 = match sp1_xy(&w2e, &p, &v).or(a2) {
                                Some((x, y)) => SlotAngle::from_xy(x, y),
                                None => SlotAngle::from_degrees(hint_of(i2)),
                            };
                            (a1, a2)
                        }
                        (Some((x1, y1)), None) => {
                            b.singular = true;
                            let a2 = SlotAngle::from_degrees(hint_of(i2));
                            let u = a2.rotation(&w2e) * p;
                            let (x, y) = sp1_xy(&w1, &u, &q).unwrap_or((x1, y1));
                            (SlotAngle::from_xy(x, y), a2)
                        }
                    };
                    b.angles[0] = a1;
                    b.angles[1] = a2;
                    if let Some(target_rot) = full {
                        let (i3, w3) = self.free_rot[2];
                        let r12 = c[0] * a1.rotation(&w1) * c[1] * a2.rotation(&w2) * c[2];
                        let f3 = r12.transpose() * target_rot * c[3].transpose();
                        // Any vector off the axis shows the angle of F3.
                        let x = any_perpendicular(&w3);
                        b.angles[2] = match sp1_xy(&w3, &x, &(f3 * x)) {
                            Some((x, y)) => SlotAngle::from_xy(x, y),
                            None => {
                                b.singular = true;
                                SlotAngle::from_degrees(hint_of(i3))
                            }
                        };
                    }
                }
                count = n;
            }
        }

        Ok(count)
    }

    /// Whether every rotary angle of the branch has an equivalent inside its
    /// travel (asked once per branch). An angle not yet known in degrees
    /// is first tried with the arc test, which leaves out its `atan2` when
    /// the answer is no.
    #[inline(always)]
    fn fits<const N: usize>(&self, b: &mut Branch<N>) -> bool {
        for (slot, a) in self.slots[..N].iter().zip(&mut b.angles) {
            let Some(arc) = &slot.arc else {
                continue;
            };
            let inside = match arc.contains(a.cos, a.sin) {
                Some(inside) if !a.has_degrees() => inside,
                _ => slot.range(a.in_degrees(), None).has_equivalent(),
            };
            if !inside {
                return false;
            }
        }
        true
    }

    /// The linear axes of one orientation branch, and its solutions.
    #[inline(always)]
    fn solve_branch<const N: usize>(
        &self,
        b: &mut Branch<N>,
        branch: u8,
        point: &V3,
        hint: Option<&[f64]>,
        out: &mut Vec<Solution>,
    ) {
        let mut joints = self.fixed;
        // Arrays of the slots there are: no setup of unused ones. (The
        // rotary values go into the joints only as a solution is pushed:
        // the linear solve reads the angles' cosines and sines, and the
        // joints written in pieces just before being read whole stall the
        // processor.)
        let mut ranges = [SlotRange::default(); N];
        for ((slot, a), r) in self.slots.iter().zip(&mut b.angles).zip(&mut ranges) {
            *r = slot.range(a.in_degrees(), hint);
        }
        if self.solve_linear(&mut joints, &b.angles, point) {
            self.push_equivalents::<N>(&joints, &ranges, branch, (b.singular, b.nearest_axis), out);
        }
    }

    /// `to` with the free linear values of `from`, copied one by one: they
    /// were just written one by one, and a wider load of them (a copy of the
    /// whole array) would wait for those stores to retire.
    #[inline(always)]
    fn copy_linear(&self, from: &Joints, to: &mut Joints) {
        match &self.linear_solve {
            LinearSolve::Constant { axes, .. } => {
                for &i in axes {
                    to[i] = from[i];
                }
            }
            LinearSolve::General => {
                for &i in &self.free_lin {
                    to[i] = from[i];
                }
            }
        }
    }

    /// With the cosines and sines of the rotary angles in `angles` (by
    /// slot), solves the free linear axes so that the tool point lands on
    /// `target` (part frame), into `q` (no copies of the joints in and
    /// out; its other values are those of `self.fixed`); `false` when they
    /// cannot.
    ///
    /// (Inlined for the precomputed solve of most machines, the general one
    /// out of line.)
    #[inline(always)]
    fn solve_linear(&self, q: &mut Joints, angles: &[SlotAngle], target: &V3) -> bool {
        // Bring the target inside the steps outside the linear axes. (The
        // values of locked axes are read from `self.fixed`, which `q`
        // starts as: `q` was just written, and reading it back in other
        // pieces than it was written in stalls the processor.)
        // One rotary axis outside (a table) is read from `target` itself: a
        // copy of it, stored in other pieces than the turn reads, stalls the
        // processor.
        let y = match &self.steps[..self.split] {
            [] => *target,
            [Step::Rotary(t)] => t.unmove_point(&turned(angles, t), target),
            steps => {
                let mut y = *target;
                for step in steps {
                    match step {
                        // Locked linear axes only: the split is at the first
                        // free one.
                        Step::Linear { axis, dir, .. } => y -= dir * self.fixed[*axis],
                        Step::Rotary(t) => y = t.unmove_point(&turned(angles, t), &y),
                    }
                }
                y
            }
        };
        let LinearSolve::Constant { rows, axes, .. } = &self.linear_solve else {
            return self.solve_linear_general(q, angles, &y);
        };
        // The tool point with the free linear axes at zero.
        let mut point = self.tip;
        for step in self.inner_fixed.iter().rev() {
            match step {
                Step::Linear { axis, dir, .. } => point += dir * self.fixed[*axis],
                Step::Rotary(t) => point = t.move_point(&turned(angles, t), &point),
            }
        }
        let rhs = y - point;
        // Three axes, known here: no loops over `free_lin`.
        let values = rows.map(|r| r.dot(&rhs));
        for (&i, v) in axes.iter().zip(values) {
            q[i] = v;
        }
        values.iter().all(|v| v.is_finite())
    }

    /// [`Kinematics::solve_linear`] inside the steps outside the linear
    /// axes (`y`: the target there) when the columns depend on the angles
    /// or there are fewer than three linear axes.
    #[inline(never)]
    fn solve_linear_general(&self, q: &mut Joints, angles: &[SlotAngle], y: &V3) -> bool {
        let y = *y;
        let inner = &self.steps[self.split..];
        let m = self.free_lin.len();

        // The tool point with the free linear axes at zero, and the column
        // of each free linear axis (how the point moves per unit of it).
        let mut point = self.tip;
        let mut c = [V3::zeros(); 3];
        for step in inner.iter().rev() {
            match step {
                Step::Linear {
                    column: Some(k),
                    dir,
                    ..
                } => c[*k] = *dir,
                Step::Linear { axis, dir, .. } => point += dir * self.fixed[*axis],
                Step::Rotary(t) => {
                    let r = &turned(angles, t);
                    point = t.move_point(r, &point);
                    for col in &mut c[..m] {
                        *col = r.apply(col);
                    }
                }
            }
        }
        let rhs = y - point;
        let values: [f64; 3] = match m {
            3 => {
                // Cramer's rule with triple products.
                let c12 = c[1].cross(&c[2]);
                let det = c[0].dot(&c12);
                if det.abs() < 1e-12 {
                    return false;
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
                let Ok(x) = j.svd(true, true).solve(&b, 1e-12) else {
                    return false;
                };
                let mut out = [0.0; 3];
                out[..m].copy_from_slice(x.as_slice());
                out
            }
        };
        let mut moved = V3::zeros();
        for (k, &i) in self.free_lin.iter().enumerate() {
            q[i] = values[k];
            moved += c[k] * values[k];
        }
        if m < 3 && (moved - rhs).norm() > 1e-9 * (1.0 + rhs.norm()) {
            return false;
        }
        values.iter().all(|v| v.is_finite())
    }

    /// Appends the solution `joints` with every 360° equivalent of its
    /// rotary angles inside their travel (`ranges`, by slot; the first free
    /// rotary axis varies slowest).
    #[inline(always)]
    fn push_equivalents<const N: usize>(
        &self,
        joints: &Joints,
        ranges: &[SlotRange; N],
        branch: u8,
        (singular, nearest_axis): (bool, bool),
        out: &mut Vec<Solution>,
    ) {
        // Each solution is pushed with the locked values (`self.fixed`,
        // written long ago), then its linear and rotary values are written
        // in place (see `copy_linear`).
        if let Some(slot) = ranges.iter().position(|r| !r.has_equivalent()) {
            // No equivalent inside the limits: report the principal value.
            out.push(Solution {
                joints: self.fixed,
                branch,
                singular,
                nearest_axis,
                violation: Some(Violation {
                    axis: self.slots[slot].axis,
                    value: ranges[slot].principal,
                }),
            });
            let pushed = &mut out.last_mut().expect("just pushed").joints;
            self.copy_linear(joints, pushed);
            for (s, r) in self.slots.iter().zip(ranges) {
                pushed[s.axis] = r.raw;
            }
            return;
        }
        // Linear axes: their values do not change between equivalents. A
        // branch outside the linear travel is given once.
        let violation = self.linear_violation(joints);
        let mut turn: [f64; N] = ranges.map(|r| r.first);
        loop {
            out.push(Solution {
                joints: self.fixed,
                branch,
                singular,
                nearest_axis,
                violation,
            });
            let pushed = &mut out.last_mut().expect("just pushed").joints;
            self.copy_linear(joints, pushed);
            for k in 0..N {
                pushed[self.slots[k].axis] = ranges[k].principal + 360.0 * turn[k];
            }
            if violation.is_some() {
                return;
            }
            // The next combination, the last slot fastest.
            let mut slot = N;
            loop {
                if slot == 0 {
                    return;
                }
                slot -= 1;
                if turn[slot] < ranges[slot].last {
                    turn[slot] += 1.0;
                    break;
                }
                turn[slot] = ranges[slot].first;
            }
        }
    }
}

/// The rotation of the free rotary axis `t` for its angle in `angles`
/// (each free rotary axis is one step of the chain: its rotation is made
/// where it is used).
#[inline(always)]
fn turned(angles: &[SlotAngle], t: &Turn) -> Turned {
    let a = &angles[t.slot];
    t.rotation(a.cos, a.sin)
}

impl Kinematics {
    /// The first free linear axis of `q` outside its travel, in
    /// machine-file order (`Axis::accepts` with the bounds worked out once;
    /// the solved values are finite, see `solve_linear`).
    #[inline(always)]
    fn linear_violation(&self, q: &Joints) -> Option<Violation> {
        let outside = |&(i, [lo, hi]): &(usize, [f64; 2])| !(q[i] >= lo && q[i] <= hi);
        let axis = match &self.linear_solve {
            // Three axes, known here: the first outside, tested without
            // a loop over a `Vec`.
            LinearSolve::Constant { axes, bounds, .. } => {
                let out: [bool; 3] = std::array::from_fn(|k| outside(&(axes[k], bounds[k])));
                out.iter().position(|&o| o).map(|k| axes[k])
            }
            LinearSolve::General => self
                .free_lin_bounds
                .iter()
                .find(|b| outside(b))
                .map(|b| b.0),
        };
        axis.map(|i| Violation {
            axis: i,
            value: q[i],
        })
    }
}

/// The rows of Cramer's rule for the columns `c`: `x_k = rows[k]·rhs` solves
/// `Σ x_k c_k = rhs`. `None` for a (nearly) singular matrix.
fn cramer_rows(c: &[V3; 3]) -> Option<[V3; 3]> {
    let n = [c[1].cross(&c[2]), c[2].cross(&c[0]), c[0].cross(&c[1])];
    let det = c[0].dot(&n[0]);
    // A margin above the singularity test of the general path, which then
    // decides (identically) for nearly singular machines.
    if det.abs() < 1e-9 {
        return None;
    }
    Some(n.map(|v| v / det))
}

/// One solved orientation branch: the angle of every free rotary slot
/// (`N` of them), known as cosine and sine first, in degrees once needed.
#[derive(Clone, Copy)]
struct Branch<const N: usize> {
    angles: [SlotAngle; N],
    singular: bool,
    nearest_axis: bool,
}

impl<const N: usize> Branch<N> {
    fn new(angles: [SlotAngle; N]) -> Self {
        Branch {
            angles,
            singular: false,
            nearest_axis: false,
        }
    }
}

impl<const N: usize> Default for Branch<N> {
    fn default() -> Self {
        Branch::new([SlotAngle::default(); N])
    }
}

/// The angle of one free rotary slot.
#[derive(Clone, Copy)]
struct SlotAngle {
    cos: f64,
    sin: f64,
    /// `(x, y)` from subproblem 1, whose `atan2` is the angle; unused when
    /// `degrees` is known from the start.
    x: f64,
    y: f64,
    /// NaN until known: a plain number, where an `Option` would add a tag
    /// and its padding to every copy of a branch. (A NaN hint gives a NaN
    /// `atan2`: taking it again changes nothing.)
    degrees: f64,
}

impl Default for SlotAngle {
    /// A placeholder, all zeros (cheap to write): every slot of a branch
    /// that is solved is set by the orientation first.
    fn default() -> Self {
        SlotAngle {
            cos: 0.0,
            sin: 0.0,
            x: 0.0,
            y: 0.0,
            degrees: 0.0,
        }
    }
}

impl SlotAngle {
    #[inline]
    fn from_xy(x: f64, y: f64) -> SlotAngle {
        let (cos, sin) = unit_xy(x, y);
        SlotAngle {
            cos,
            sin,
            x,
            y,
            degrees: f64::NAN,
        }
    }

    /// [`SlotAngle::from_xy`] with the length of `(x, y)` known.
    #[inline]
    fn from_xy_length(x: f64, y: f64, length: f64) -> SlotAngle {
        SlotAngle {
            cos: x / length,
            sin: y / length,
            x,
            y,
            degrees: f64::NAN,
        }
    }

    /// An angle given in degrees (a hint), through radians as the solver
    /// has it.
    fn from_degrees(deg: f64) -> SlotAngle {
        let rad = deg.to_radians();
        let (sin, cos) = rad.sin_cos();
        SlotAngle {
            cos,
            sin,
            x: cos,
            y: sin,
            degrees: rad.to_degrees(),
        }
    }

    /// The angle in degrees (its `atan2` taken once).
    #[inline]
    fn in_degrees(&mut self) -> f64 {
        if !self.has_degrees() {
            self.degrees = xy_degrees(self.x, self.y);
        }
        self.degrees
    }

    #[inline]
    fn has_degrees(&self) -> bool {
        !self.degrees.is_nan()
    }

    fn rotation(&self, w: &V3) -> Matrix3<f64> {
        rotation_cs(w, self.cos, self.sin)
    }
}

/// The angle of `(x, y)` in degrees, out of line: inlined, its code
/// crowds the registers of the solver around it.
#[inline(never)]
fn xy_degrees(x: f64, y: f64) -> f64 {
    atan2_deg(y, x)
}

/// The travel `[lo, hi]` of a rotary axis (less than a full turn and a
/// degree), tested on the cosine and sine of an angle: the angle has an
/// equivalent inside iff `cos(θ − mid) ≥ cos(half)`, `mid` and `half` the
/// middle and half width of the travel with the 1e-9° slack of
/// [`turn_range`].
#[derive(Debug, Clone, Copy)]
struct Arc {
    cos_mid: f64,
    sin_mid: f64,
    cos_half: f64,
}

impl Arc {
    fn new(lo: f64, hi: f64) -> Arc {
        let (sin_mid, cos_mid) = rad(0.5 * (lo + hi)).sin_cos();
        Arc {
            cos_mid,
            sin_mid,
            cos_half: rad(0.5 * (hi - lo) + 1e-9).cos(),
        }
    }

    /// Whether the angle with cosine `c` and sine `s` has an equivalent
    /// inside the travel; `None` within 1e-9 of the edge, where the
    /// rounding of either test could decide, and the angle in degrees
    /// must (exactly as [`turn_range`] has it).
    #[inline]
    fn contains(&self, c: f64, s: f64) -> Option<bool> {
        let d = c * self.cos_mid + s * self.sin_mid - self.cos_half;
        if d > 1e-9 {
            Some(true)
        } else if d < -1e-9 {
            Some(false)
        } else {
            None
        }
    }
}

/// A free rotary axis, by its slot.
#[derive(Debug, Clone, Copy, Default)]
struct Slot {
    /// Machine-file index of the axis.
    axis: usize,
    limits: Option<[f64; 2]>,
    /// The arc test of a travel of less than a full turn and a degree.
    arc: Option<Arc>,
}

impl Slot {
    /// The angle `raw` (degrees, as solved), its principal value and the
    /// whole turns that keep it inside the travel; for an axis without
    /// limits, the turns within [`ENDLESS_REACH_DEG`] of the hint.
    #[inline(always)]
    fn range(&self, raw: f64, hint: Option<&[f64]>) -> SlotRange {
        let principal = wrap180(raw);
        let (first, last) = match self.limits {
            None => {
                // The nearest turn lies within half a turn of the hint;
                // the one beyond it too when that is within the reach.
                // (A product, not a division: the hint comes from the
                // planner's last point, and this is on the path from one
                // point to the next. A quotient an ulp off can move `t` by
                // one only where `d` is ±180°, and the turns chosen below
                // are the same either way.)
                let h = hint.map_or(0.0, |h| h[self.axis]);
                let t = turns_nearest((h - principal) * (1.0 / 360.0));
                let d = principal + 360.0 * t - h;
                let below = d - 360.0 >= -ENDLESS_REACH_DEG;
                let above = d + 360.0 <= ENDLESS_REACH_DEG;
                (
                    t - f64::from(u8::from(below)),
                    t + f64::from(u8::from(above)),
                )
            }
            Some([lo, hi]) => turn_range(lo, hi, principal),
        };
        SlotRange {
            raw,
            principal,
            first,
            last,
        }
    }
}

/// How far from the hint the equivalents of an axis without limits go:
/// half a turn, and a margin. Of two configurations half a turn apart on
/// the hint (the other branch of an A/C trunnion), both turns are
/// candidates, so that a sequence on either branch stays continuous while
/// the best one is the hint (nearest the hint alone, its turn would follow
/// the rounding).
const ENDLESS_REACH_DEG: f64 = 180.0 + 30.0;

/// A slot angle in degrees as solved (`raw`), wrapped to (−180°, 180°], and
/// the whole turns `first..=last` that keep it inside the travel.
#[derive(Clone, Copy, Default)]
struct SlotRange {
    raw: f64,
    principal: f64,
    first: f64,
    last: f64,
}

impl SlotRange {
    fn has_equivalent(&self) -> bool {
        self.first <= self.last
    }
}

// Rounding in floating point: `floor`, `ceil` and `round` are library
// calls on baseline x86-64, and conversions to integers saturate (several
// instructions each); both showed up in the posting profile.

/// ⌊x⌋: below 2^51 by rounding to the nearest whole number with the
/// 1.5·2^52 trick (adding it leaves no fraction bits) and stepping down if
/// that rounded up; larger numbers are whole or nearly, for the library.
#[inline(always)]
fn floor_f(x: f64) -> f64 {
    const ROUND: f64 = 6_755_399_441_055_744.0;
    if x.abs() < 2_251_799_813_685_248.0 {
        let r = (x + ROUND) - ROUND;
        if r > x { r - 1.0 } else { r }
    } else {
        x.floor()
    }
}

/// The nearest whole number to x (halves up).
#[inline(always)]
fn turns_nearest(x: f64) -> f64 {
    floor_f(x + 0.5)
}

/// The whole turns k with lo ≤ principal + 360k ≤ hi (1e-9° slack), as
/// the first and last k.
#[inline(always)]
fn turn_range(lo: f64, hi: f64, principal: f64) -> (f64, f64) {
    (
        -floor_f(-(lo - 1e-9 - principal) / 360.0),
        floor_f((hi + 1e-9 - principal) / 360.0),
    )
}

/// Angle in degrees wrapped to (−180, 180].
#[inline]
pub fn wrap180(deg: f64) -> f64 {
    // Inside (−180, 180) the formula below gives `deg` back to the bit
    // (no turn, or one turn down and back up, both exact): skip it.
    if deg.abs() < 180.0 {
        return deg;
    }
    wrap180_by_turns(deg)
}

/// [`wrap180`] by the nearest whole turn.
#[inline]
fn wrap180_by_turns(deg: f64) -> f64 {
    let w = deg - 360.0 * turns_nearest(deg / 360.0);
    if w <= -180.0 {
        w + 360.0
    } else if w > 180.0 {
        w - 360.0
    } else {
        w
    }
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
            assert_eq!(floor_f(x), x.floor(), "{x}");
            assert_eq!(floor_f(-x), (-x).floor(), "{x}");
            let w = wrap180(x);
            assert!(w > -180.0 && w <= 180.0, "{x} -> {w}");
            assert!(
                ((x - w) / 360.0 - ((x - w) / 360.0).round()).abs() < 1e-12,
                "{x} -> {w}"
            );
        }
        assert_eq!(wrap180(-180.0), 180.0);
        assert_eq!(turn_range(-360.0, 360.0, 10.0), (-1.0, 0.0));
        assert_eq!(turn_range(-45.2, 45.2, 10.0), (0.0, 0.0));
        assert_eq!(turn_range(-45.2, 45.2, 50.0), (0.0, -1.0));
        assert_eq!(turn_range(0.0, 720.0, -90.0), (1.0, 2.0));
        for x in [0.5, 1.5, 2.5, -0.5, -1.5, 4503599627370495.5, 1e300, -1e300] {
            assert_eq!(floor_f(x), x.floor(), "{x}");
        }
        assert!(floor_f(f64::NAN).is_nan());
    }
}

#[cfg(test)]
#[path = "kinematics_props.rs"]
mod props;
