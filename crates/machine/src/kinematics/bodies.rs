//! Where every body of the chain is at joint values `q`: the rigid motions
//! of the virtual machine (what moves its solids), in the machine frame.
//!
//! With the axes of a side in machine-file order and `G_i(q_i)` the motion
//! of axis `i` (module doc of `kinematics`), the body of axis `i` is moved
//! by `B_i(q) = Π_{j ≤ i, same side} G_j(q_j)` from its place at home; the
//! tool body is the last tool-side axis's, the workpiece body the last
//! workpiece-side axis's. The forward kinematics is then
//! `fk(q) = (B_workpiece · W0)⁻¹ · B_tool` applied to the tool at home
//! (tested in `kinematics_props`).
//!
//! The values are read as [`Kinematics::fk`] reads them: a rotary axis
//! locked with `fixed` stands at its fixed value whatever `q` says, every
//! other axis (a locked linear axis too) at `q`.

use nalgebra::{Isometry3, Translation3, Unit, UnitQuaternion, Vector3};

use super::Kinematics;
use crate::model::{AxisKind, MAX_AXES, Machine, Side};
use crate::solid::Body;

/// One axis as the bodies need it: its motion in the machine frame.
#[derive(Debug, Clone, Copy)]
pub(super) struct BodyAxis {
    side: Side,
    kind: AxisKind,
    direction: Unit<Vector3<f64>>,
    point: Vector3<f64>,
    /// The value of a locked rotary axis.
    locked_at: Option<f64>,
}

impl BodyAxis {
    /// The axes of a machine.
    pub(super) fn of(machine: &Machine) -> Vec<BodyAxis> {
        machine
            .axes
            .iter()
            .map(|a| BodyAxis {
                side: a.side,
                kind: a.kind,
                direction: Unit::new_normalize(a.direction),
                point: a.point,
                locked_at: if a.is_rotary() { a.fixed } else { None },
            })
            .collect()
    }

    /// `G(q)`: the motion of this axis at NC value `q` (mm or degrees).
    fn motion(&self, q: f64) -> Isometry3<f64> {
        let q = self.locked_at.unwrap_or(q);
        match self.kind {
            AxisKind::Linear => Isometry3::from_parts(
                Translation3::from(self.direction.into_inner() * q),
                UnitQuaternion::identity(),
            ),
            AxisKind::Rotary => {
                let r = UnitQuaternion::from_axis_angle(&self.direction, q.to_radians());
                // About the line through `point`: x ↦ p + R (x − p).
                Isometry3::from_parts(Translation3::from(self.point - r * self.point), r)
            }
        }
    }
}

/// The rigid motion of every body of the chain from its place at home, at
/// one set of joint values (see [`Kinematics::body_poses`]). A point `x` of
/// a body at home (machine frame) is at `pose * x`.
#[derive(Debug, Clone, PartialEq)]
pub struct BodyPoses {
    /// The body of each axis, machine-file order (the first
    /// [`Kinematics::axis_count`] entries are used).
    pub axes: [Isometry3<f64>; MAX_AXES],
    /// The tool body.
    pub tool: Isometry3<f64>,
    /// The workpiece body (the part frame is `workpiece · W0`, see
    /// [`BodyPoses::part_frame`]).
    pub workpiece: Isometry3<f64>,
    /// The part frame at home, machine frame.
    w0: Isometry3<f64>,
}

impl BodyPoses {
    /// The motion of `body` (the identity for the base). An axis index
    /// beyond the machine's axes is the identity.
    pub fn of(&self, body: Body) -> &Isometry3<f64> {
        use std::sync::LazyLock;
        static IDENTITY: LazyLock<Isometry3<f64>> = LazyLock::new(Isometry3::identity);
        match body {
            Body::Base => &IDENTITY,
            Body::Axis(i) => self.axes.get(i).unwrap_or(&IDENTITY),
            Body::Tool => &self.tool,
            Body::Workpiece => &self.workpiece,
        }
    }

    /// The part (program) frame in the machine frame: `workpiece · W0`.
    pub fn part_frame(&self) -> Isometry3<f64> {
        self.workpiece * self.w0
    }
}

impl Kinematics {
    /// The rigid motion of every body of the chain at joint values `q`
    /// (machine-file order, every axis): what moves the solids of the
    /// virtual machine. Consistent with [`Kinematics::fk`]: the tool point
    /// and axis at home moved by `tool`, seen from the part frame
    /// [`BodyPoses::part_frame`], are `fk(q)`.
    pub fn body_poses(&self, q: &[f64]) -> BodyPoses {
        let mut axes = [Isometry3::identity(); MAX_AXES];
        let mut tool = Isometry3::identity();
        let mut workpiece = Isometry3::identity();
        for (i, a) in self.body_axes.iter().enumerate() {
            let value = q.get(i).copied().unwrap_or(0.0);
            let carried = match a.side {
                Side::Tool => &mut tool,
                Side::Workpiece => &mut workpiece,
            };
            *carried *= a.motion(value);
            axes[i] = *carried;
        }
        BodyPoses {
            axes,
            tool,
            workpiece,
            w0: self.w0,
        }
    }
}
