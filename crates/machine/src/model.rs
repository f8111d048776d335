//! The machine model (docs/machine-files.md): a serial chain of linear and rotary axes
//! described at home (every NC value zero), all vectors in one fixed machine
//! frame, lengths in mm, angles in degrees.

use nalgebra::{Matrix3, Vector3};

/// Largest number of axes a machine may have (free and fixed together).
pub const MAX_AXES: usize = 9;

/// Whether an axis translates or rotates what it carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AxisKind {
    /// Translates, mm.
    Linear,
    /// Rotates, degrees.
    Rotary,
}

/// What an axis carries: the part (a table) or the tool (a head).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    /// Carries the part (a table).
    Workpiece,
    /// Carries the tool (a head).
    Tool,
}

/// One NC axis.
#[derive(Debug, Clone, PartialEq)]
pub struct Axis {
    /// The NC address, e.g. `X` or `A`.
    pub name: String,
    /// Linear or rotary.
    pub kind: AxisKind,
    /// What it carries.
    pub side: Side,
    /// Unit vector in the machine frame at home. A linear axis at value `q`
    /// moves what it carries by `q·direction`; a rotary axis turns it by `q`
    /// degrees about the line (`point`, `direction`), right-hand rule.
    pub direction: Vector3<f64>,
    /// A point on the rotation line (rotary axes; zero for linear ones).
    pub point: Vector3<f64>,
    /// Travel in NC values `[min, max]`, if the machine has any.
    pub limits: Option<[f64; 2]>,
    /// The value the axis is locked at, if it does not move in this mode.
    pub fixed: Option<f64>,
    /// A locked axis that becomes free for CL points that carry a reference
    /// direction (6-axis output, e.g. the C axis of the MTS1600).
    pub free_with_reference: bool,
    /// How a rotary axis counts its turns (see [`Wrap`]).
    pub wrap: Wrap,
    /// Which of equivalent values the planner prefers, if the user said so.
    pub prefer: Option<Prefer>,
    /// Largest speed of the axis, mm/min or degrees/min; feed moves that
    /// would need more are slowed down.
    pub max_velocity: Option<f64>,
    /// The machine file's `machine_offset`: machine coordinate = NC value +
    /// this (0 when the file gives none; [`Axis::limits`] are NC values).
    pub machine_offset: f64,
}

/// How a rotary axis counts its turns.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Wrap {
    /// The value is continuous (it may grow over several turns, inside the
    /// travel) and written as it is.
    #[default]
    None,
    /// A modulo axis: written as 0 ≤ value < 360 with shortest-path words
    /// (Sinumerik `DC`); the controller turns the short way, which is the
    /// way the planner moves it.
    Modulo,
    /// Continuous inside a cut; between segments (rapids, tool changes) the
    /// axis turns back to the equivalent nearest zero, so turns do not add
    /// up over a program.
    Unwind,
}

/// A preference among equivalent rotary values (`prefer` in the machine
/// file).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Prefer {
    /// The equivalent at or above zero.
    Positive,
    /// The equivalent at or below zero.
    Negative,
    /// The equivalent nearest zero.
    Zero,
}

impl Axis {
    /// Whether it rotates.
    pub fn is_rotary(&self) -> bool {
        self.kind == AxisKind::Rotary
    }

    /// Whether it moves in this mode (not locked).
    pub fn is_free(&self) -> bool {
        self.fixed.is_none()
    }

    /// A rotary axis written as a modulo axis, with shortest-path words
    /// (Sinumerik `DC`): `wrap = "modulo"`.
    pub fn is_endless(&self) -> bool {
        self.is_rotary() && self.wrap == Wrap::Modulo
    }

    /// The `wrap` of an axis whose machine file does not say: modulo for a
    /// rotary axis without limits, continuous otherwise. Limits a file gives
    /// are kept unless it asks for modulo: a head whose cables allow ±370°
    /// must not be turned without end.
    pub fn default_wrap(kind: AxisKind, limits: Option<[f64; 2]>) -> Wrap {
        if kind == AxisKind::Rotary && limits.is_none() {
            Wrap::Modulo
        } else {
            Wrap::None
        }
    }

    /// The travel the machine holds the axis to: its limits, except for a
    /// modulo axis, which reaches every angle (its limits bound the counter,
    /// not the machine).
    pub fn travel(&self) -> Option<[f64; 2]> {
        if self.is_endless() { None } else { self.limits }
    }

    /// Whether `value` lies inside the travel ([`Axis::travel`], with a
    /// tolerance of 1e-9 for values computed exactly at a limit).
    pub fn accepts(&self, value: f64) -> bool {
        match self.travel() {
            None => value.is_finite(),
            Some([lo, hi]) => value >= lo - 1e-9 && value <= hi + 1e-9,
        }
    }
}

/// The controlled tool frame at home.
#[derive(Debug, Clone, PartialEq)]
pub struct Tool {
    /// Tool tip or, for a grinding wheel, the contact point.
    pub point: Vector3<f64>,
    /// Unit vector from the contact point towards the tool (for a belt wheel,
    /// the surface normal at contact).
    pub axis: Vector3<f64>,
    /// Optional second direction for full 6-DOF orientation (e.g. the wheel's
    /// rotation axis or the feed direction); orthogonal to `axis`.
    pub reference: Option<Vector3<f64>>,
}

/// Settings for writing programs for this machine.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PostSettings {
    /// Name of the dialect used when the command line names none.
    pub dialect: Option<String>,
    /// Header template replacing the dialect's own.
    pub header: Option<String>,
    /// Footer template replacing the dialect's own.
    pub footer: Option<String>,
    /// Joint or tool-centre-point output when the command line names none.
    pub output: Option<OutputMode>,
    /// Safe distance along the tool axis for a retract-and-reconfigure, mm.
    pub retract: Option<f64>,
    /// Half-angle of the cone around a singular tool-axis direction inside
    /// which the free angle is held, degrees.
    pub singular_cone_deg: Option<f64>,
    /// The machine's home, NC values in machine order (`[post] home`):
    /// where `GOHOME` without a point goes.
    pub home: Option<Vec<f64>>,
}

/// What the linear axis words of a program mean.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum OutputMode {
    /// Machine axis values: the post does the kinematics.
    #[default]
    Joint,
    /// Tool-centre-point control: X, Y, Z are the tool point in the part
    /// frame, the rotary words are axis values, and the controller does the
    /// kinematics (Sinumerik TRAORI, Fanuc G43.4, Heidenhain TCPM, LinuxCNC
    /// TCP kinematics).
    Tcp,
}

/// A whole machine.
#[derive(Debug, Clone, PartialEq)]
pub struct Machine {
    /// Its name (`mts1600`).
    pub name: String,
    /// One line about it.
    pub description: String,
    /// Axes in chain order from the machine base outwards (per side).
    pub axes: Vec<Axis>,
    /// Part (program) frame at home: columns x, y, z of the part axes in the
    /// machine frame.
    pub workpiece_rotation: Matrix3<f64>,
    /// Part frame origin at home, machine frame.
    pub workpiece_origin: Vector3<f64>,
    /// The tool frame at home.
    pub tool: Tool,
    /// Settings for writing its programs (`[post]`).
    pub post: PostSettings,
    /// A process axis that moves the tool point (the grinding pressure H1),
    /// if the machine has one; see [`Machine::at_pressure`].
    pub pressure: Option<crate::PressureAxis>,
    /// The solids of the virtual machine (`[[solid]]`), in file order.
    pub solids: Vec<crate::Solid>,
    /// When solids are too close, and which pairs are not checked
    /// (`[collision]`).
    pub collision: crate::CollisionSettings,
}

/// A tool pose in the part frame: what one CL point asks for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// Tool (contact) point, mm.
    pub point: Vector3<f64>,
    /// Unit tool axis.
    pub axis: Vector3<f64>,
    /// Unit reference direction, when the CL gives one (6-axis output).
    pub reference: Option<Vector3<f64>>,
}

impl Machine {
    /// Index of the axis called `name` (case-insensitive).
    pub fn axis_index(&self, name: &str) -> Option<usize> {
        self.axes
            .iter()
            .position(|a| a.name.eq_ignore_ascii_case(name))
    }

    /// Indices of the free (not `fixed`) rotary axes, in file order.
    pub fn free_rotary_axes(&self) -> impl Iterator<Item = usize> + '_ {
        (0..self.axes.len()).filter(|&i| self.axes[i].is_rotary() && self.axes[i].is_free())
    }

    /// Indices of the free rotary axes with `wrap = "unwind"` (back to the
    /// turn nearest zero at the start of every segment).
    pub fn unwinding_axes(&self) -> impl Iterator<Item = usize> + '_ {
        self.free_rotary_axes()
            .filter(|&i| self.axes[i].wrap == Wrap::Unwind)
    }

    /// Number of free (not `fixed`) rotary axes.
    pub fn free_rotary_count(&self) -> usize {
        self.free_rotary_axes().count()
    }

    /// Whether some axis is locked only until the CL gives reference
    /// directions (see [`Axis::free_with_reference`]).
    pub fn unlocks_with_reference(&self) -> bool {
        self.axes.iter().any(|a| a.free_with_reference)
    }

    /// The machine for CL points with a reference direction: every axis
    /// marked `free_with_reference` is free.
    pub fn with_reference_axes_free(&self) -> Machine {
        let mut m = self.clone();
        for a in &mut m.axes {
            if a.free_with_reference {
                a.fixed = None;
            }
        }
        m
    }

    /// The joint vector with every axis at home, fixed axes at their value.
    pub fn home_joints(&self) -> Vec<f64> {
        self.axes.iter().map(|a| a.fixed.unwrap_or(0.0)).collect()
    }

    /// An upper bound of the lever through which an angle error moves the
    /// tool point: the largest distance between the home tool point and a
    /// rotary axis line, plus, for an axis with linear axes between it and
    /// the tool in the chain (a table axis, or a head axis the ram carries
    /// further), the diagonal of the linear travel box (1 m per linear axis
    /// where the travel is not given). The linear axes move the tool point
    /// away from a table axis; a head axis that no linear axis follows keeps
    /// its distance.
    pub fn largest_pivot_distance(&self) -> f64 {
        let travel: f64 = self
            .axes
            .iter()
            .filter(|a| !a.is_rotary())
            .map(|a| match a.limits {
                Some([lo, hi]) => (hi - lo).powi(2),
                None => 1000.0f64.powi(2),
            })
            .sum::<f64>()
            .sqrt();
        // Between axis `i` and the tool: on the tool side, the axes of that
        // side listed after it; on the workpiece side, those listed before
        // it (they carry it) and every axis of the tool side.
        let linear_inside = |i: usize| {
            let side = self.axes[i].side;
            self.axes.iter().enumerate().any(|(j, a)| {
                !a.is_rotary()
                    && match (side, a.side) {
                        (Side::Tool, Side::Tool) => j > i,
                        (Side::Tool, Side::Workpiece) => false,
                        (Side::Workpiece, Side::Workpiece) => j < i,
                        (Side::Workpiece, Side::Tool) => true,
                    }
            })
        };
        self.axes
            .iter()
            .enumerate()
            .filter(|(_, a)| a.is_rotary())
            .map(|(i, a)| {
                let home = (self.tool.point - a.point).cross(&a.direction).norm();
                if linear_inside(i) {
                    home + travel
                } else {
                    home
                }
            })
            .fold(0.0, f64::max)
    }
}
