//! The closed-loop check: every block, with its values exactly as written, is
//! run back through the forward kinematics and compared with the CL pose it
//! was made from.

pub use kinpost_machine::angle_between;
use kinpost_machine::{Kinematics, Machine, Pose};

/// How far a block may put the tool from its CL pose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerance {
    /// Largest distance between the tool point of a block and its CL point, mm.
    pub position_mm: f64,
    /// Largest angle between the tool axis of a block and its CL axis, rad.
    pub axis_rad: f64,
}

impl Tolerance {
    /// The error that rounding to the output decimals can cause: half a unit
    /// of the last decimal on every free linear axis, plus half a unit on
    /// every free rotary axis times the machine's largest pivot distance
    /// ([`Machine::largest_pivot_distance`]). `resolution(i)` is the value of
    /// one unit in the last written decimal of axis `i` (0.001 for 3
    /// decimals).
    pub fn from_resolution(machine: &Machine, resolution: impl Fn(usize) -> f64) -> Tolerance {
        let lever = machine.largest_pivot_distance();
        Self::with_levers(machine, resolution, |_| lever)
    }

    /// The rounding error of tool-centre-point output: the tool point is
    /// written directly (half a unit per linear word), the tool axis through
    /// the rotary words.
    pub fn for_tcp(machine: &Machine, resolution: impl Fn(usize) -> f64) -> Tolerance {
        Self::with_levers(machine, resolution, |_| 0.0)
    }

    /// The rounding error bound of one block at joint values `q`, with the
    /// actual lever of every rotary axis (how far the tool point moves per
    /// radian of that axis, by central differences through `kin`). Used where
    /// a block lies beyond the machine-wide bound, e.g. on a machine without
    /// travel limits whose linear axes run far out; 1.5 times the first-order
    /// bound covers the second-order terms of half a unit.
    pub fn at_block(
        machine: &Machine,
        kin: &Kinematics,
        q: &[f64],
        resolution: impl Fn(usize) -> f64,
    ) -> Tolerance {
        let mut probe = q.to_vec();
        let h = 1e-3; // degrees
        let t = Self::with_levers(machine, resolution, |i| {
            probe[i] = q[i] + h;
            let plus = kin.fk(&probe).point;
            probe[i] = q[i] - h;
            let minus = kin.fk(&probe).point;
            probe[i] = q[i];
            (plus - minus).norm() / (2.0 * h).to_radians()
        });
        Tolerance {
            position_mm: 1.5 * t.position_mm,
            axis_rad: t.axis_rad,
        }
    }

    fn with_levers(
        machine: &Machine,
        resolution: impl Fn(usize) -> f64,
        mut lever: impl FnMut(usize) -> f64,
    ) -> Tolerance {
        let mut position = 0.0;
        let mut axis = 0.0;
        for (i, a) in machine.axes.iter().enumerate() {
            if !a.is_free() {
                continue;
            }
            let half = 0.5 * resolution(i);
            if a.is_rotary() {
                let rad = half.to_radians();
                axis += rad;
                position += rad * lever(i);
            } else {
                position += half;
            }
        }
        // Slack for the arithmetic itself (1e-9 mm / rad).
        Tolerance {
            position_mm: position + 1e-9,
            axis_rad: axis + 1e-9,
        }
    }
}

/// Position and orientation error of `got` against `want`: the angle
/// between the tool axes, or between the reference directions if that is
/// larger (both poses with one: 6-axis output).
pub fn pose_error(want: &Pose, got: &Pose) -> (f64, f64) {
    (
        (want.point - got.point).norm(),
        angle_between(&want.axis, &got.axis).max(reference_error(want, got)),
    )
}

/// The angle between the reference directions of `want` and `got`, each
/// taken normal to its tool axis (the part of a CL reference along the tool
/// axis says nothing: the inverse kinematics leaves it out too); 0 unless
/// both have one.
pub fn reference_error(want: &Pose, got: &Pose) -> f64 {
    let (Some(a), Some(b)) = (&want.reference, &got.reference) else {
        return 0.0;
    };
    let normal = |r: &nalgebra::Vector3<f64>, axis: &nalgebra::Vector3<f64>| r - axis * r.dot(axis);
    let (a, b) = (normal(a, &want.axis), normal(b, &got.axis));
    match (a.try_normalize(1e-12), b.try_normalize(1e-12)) {
        (Some(a), Some(b)) => angle_between(&a, &b),
        // A reference along the tool axis gives no direction to compare.
        _ => 0.0,
    }
}

/// Running maxima of the check.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CheckStats {
    pub max_position_error_mm: f64,
    pub max_axis_error_rad: f64,
    /// CL line of the block with the largest position error.
    pub worst_line: Option<usize>,
    /// sin of `max_axis_error_rad`, to skip the `atan2` of smaller errors.
    sin_max_axis: f64,
}

impl CheckStats {
    /// Records one block; returns whether it is within `tolerance`. Only
    /// errors that may be new maxima or failures are measured exactly (one
    /// `sqrt`/`atan2` saved per block on the hot path).
    pub fn record(&mut self, want: &Pose, got: &Pose, line: usize, tolerance: &Tolerance) -> bool {
        let d2 = (want.point - got.point).norm_squared();
        let max = self.max_position_error_mm;
        if d2 > max * max {
            self.max_position_error_mm = d2.sqrt();
            self.worst_line = Some(line);
        }
        let sin = want.axis.cross(&got.axis).norm();
        let cos = want.axis.dot(&got.axis);
        if cos <= 0.0 || sin > self.sin_max_axis || want.reference.is_some() {
            let a = sin.atan2(cos).max(reference_error(want, got));
            if a > self.max_axis_error_rad {
                self.max_axis_error_rad = a;
                self.sin_max_axis = if a < std::f64::consts::FRAC_PI_2 {
                    a.sin()
                } else {
                    1.0
                };
            }
        }
        self.max_position_error_mm <= tolerance.position_mm
            && self.max_axis_error_rad <= tolerance.axis_rad
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    #[test]
    fn tolerance_of_mts1600_at_3_decimals() {
        let m = kinpost_machine::builtin::load("mts1600").unwrap().unwrap();
        let t = Tolerance::from_resolution(&m, |_| 0.001);
        // 3 linear axes × 0.0005 mm + 2 free rotaries × 0.0005° × lever.
        let lever = m.largest_pivot_distance();
        let want = 3.0 * 0.0005 + 2.0 * 0.0005f64.to_radians() * lever + 1e-9;
        assert!((t.position_mm - want).abs() < 1e-15);
        // The A line (the X axis) is farthest from the home contact point
        // (43, 79.2, −350); the travel box is 1750.5 × 501 × 501.3 mm.
        let want_lever = (79.2f64.powi(2) + 350.0f64.powi(2)).sqrt()
            + (1750.5f64.powi(2) + 501.0f64.powi(2) + 501.3f64.powi(2)).sqrt();
        assert!((lever - want_lever).abs() < 1e-9, "{lever} vs {want_lever}");
        assert!((t.axis_rad - (2.0 * 0.0005f64.to_radians() + 1e-9)).abs() < 1e-15);
    }

    #[test]
    fn a_head_no_linear_axis_follows_keeps_its_pivot_as_lever() {
        // head-head-bc: X Y Z carry the C fork, which carries the B spindle
        // with its line 250 mm above the tool tip; the linear travel does
        // not move the tool tip away from either line.
        let m = kinpost_machine::builtin::load("head-head-bc")
            .unwrap()
            .unwrap();
        assert!((m.largest_pivot_distance() - 250.0).abs() < 1e-9);
        let t = Tolerance::from_resolution(&m, |_| 0.001);
        let want = 3.0 * 0.0005 + 2.0 * 0.0005f64.to_radians() * 250.0 + 1e-9;
        assert!((t.position_mm - want).abs() < 1e-15, "{}", t.position_mm);
    }

    #[test]
    fn stats_keep_exact_maxima() {
        let pose = |x: f64, ax: f64| Pose {
            point: Vector3::new(x, 0.0, 0.0),
            axis: Vector3::new(ax.sin(), 0.0, ax.cos()),
            reference: None,
        };
        let tol = Tolerance {
            position_mm: 0.5,
            axis_rad: 0.25,
        };
        let mut s = CheckStats::default();
        assert!(s.record(&pose(0.0, 0.0), &pose(0.3, 0.2), 7, &tol));
        assert!(s.record(&pose(0.0, 0.0), &pose(0.1, 0.1), 8, &tol));
        assert!((s.max_position_error_mm - 0.3).abs() < 1e-15);
        assert!((s.max_axis_error_rad - 0.2).abs() < 1e-15);
        assert_eq!(s.worst_line, Some(7));
        assert!(!s.record(&pose(0.0, 0.0), &pose(0.0, 2.5), 9, &tol));
        assert!((s.max_axis_error_rad - 2.5).abs() < 1e-12);
    }

    #[test]
    fn six_axis_blocks_are_checked_on_their_reference_too() {
        // The same point and tool axis, the reference turned 0.1 rad about
        // the axis: an orientation error of 0.1 rad.
        let pose = |r: Vector3<f64>| Pose {
            point: Vector3::zeros(),
            axis: Vector3::z(),
            reference: Some(r),
        };
        let tol = Tolerance {
            position_mm: 0.01,
            axis_rad: 1e-3,
        };
        let turned = Vector3::new(0.1f64.cos(), 0.1f64.sin(), 0.0);
        let mut s = CheckStats::default();
        assert!(!s.record(&pose(Vector3::x()), &pose(turned), 3, &tol));
        assert!((s.max_axis_error_rad - 0.1).abs() < 1e-12);
        assert!((pose_error(&pose(Vector3::x()), &pose(turned)).1 - 0.1).abs() < 1e-12);
        // A CL reference with a part along the tool axis points the same
        // way once that part is left out, as the inverse kinematics has it.
        let mut s = CheckStats::default();
        let leaning = Vector3::new(1.0, 0.0, 0.3).normalize();
        assert!(s.record(&pose(leaning), &pose(Vector3::x()), 4, &tol));
        assert_eq!(s.max_axis_error_rad, 0.0);
        // Without a reference on both sides there is nothing to compare.
        let mut none = pose(Vector3::x());
        none.reference = None;
        assert_eq!(reference_error(&pose(turned), &none), 0.0);
    }

    #[test]
    fn small_angles_are_accurate() {
        let a = Vector3::z();
        let b = Vector3::new(1e-10, 0.0, 1.0).normalize();
        assert!((angle_between(&a, &b) - 1e-10).abs() < 1e-20);
    }
}
