//! Tool axes just beyond what a machine can point.
//!
//! A CAM system writes tool axes rounded: NX CLSF gives 7 decimals, which
//! move a unit vector by up to 9e-8 rad. Where a path runs along the edge of
//! the directions a machine can point (a tool lying flat on a 45° nutating
//! head, the one axis a head locked at 15° gives a 4-axis table, the rim of
//! the hole a C axis out of square leaves around its pole), that rounding
//! puts some of its axes just outside. Such an axis, up to
//! [`Kinematics::axis_rounding`] outside ([`AXIS_ROUNDING_RAD`] unless set
//! for a CL that rounds more coarsely), is solved at the nearest direction
//! the machine can point, and the closed-loop check counts the distance
//! between the two as the CL's own error. Farther out, the axis is
//! unreachable.

use nalgebra::Vector3;

use super::{Folds, IkError, Kinematics, any_perpendicular};
use crate::angle::angle_between;

/// How far outside the directions a machine can point a requested tool axis
/// may lie and still be solved, at the nearest one it can point, radians:
/// the rounding of tool axes written with 6 decimals or more (half a unit of
/// the sixth decimal on each component moves a unit vector by up to 8.7e-7
/// rad).
pub const AXIS_ROUNDING_RAD: f64 = 1e-6;

/// The largest axis rounding [`Kinematics::set_axis_rounding`] takes,
/// radians: the rounding of tool axes written with 3 decimals (8.7e-4 rad).
/// Farther out, a tool axis is not the rounding of one the machine can point.
pub const MAX_AXIS_ROUNDING_RAD: f64 = 1e-3;

/// `a` (unit) turned in its plane with `d` (unit) to make the angle `t`
/// with `d`; for `a` along `±d`, any such direction.
fn at_angle_from(d: &Vector3<f64>, a: &Vector3<f64>, t: f64) -> Vector3<f64> {
    let off = a - d * d.dot(a);
    let norm = off.norm();
    let off = if norm > 1e-12 {
        off / norm
    } else {
        any_perpendicular(d)
    };
    d * t.cos() + off * t.sin()
}

impl Folds {
    /// How far tool axis `axis` (unit) lies outside the band of directions
    /// the machine can point, radians (0 inside), and the nearest direction
    /// in the band (`axis` itself inside).
    pub fn nearest(&self, axis: &Vector3<f64>) -> (f64, Vector3<f64>) {
        let t = angle_between(&self.direction, axis);
        let [lower, upper] = self.edges;
        // An edge that is a pole (NaN) bounds nothing: both tests fail.
        let edge = if t < lower {
            lower
        } else if t > upper {
            upper
        } else {
            return (0.0, *axis);
        };
        ((t - edge).abs(), at_angle_from(&self.direction, axis, edge))
    }
}

impl Kinematics {
    /// How far tool axis `axis` (part frame, unit) lies outside the
    /// directions the free rotary axes can point (their travel aside),
    /// radians, and the nearest of those directions: `(0, axis)` for a
    /// direction they can point. With three free rotary axes every
    /// direction is counted as reachable (the reference direction decides).
    pub fn axis_reach(&self, axis: &Vector3<f64>) -> (f64, Vector3<f64>) {
        let to_part = |v: Vector3<f64>| self.rw0.transpose() * (self.between[0] * v);
        match self.free_rot.len() {
            // The one direction the locked axes give.
            0 => {
                let only = to_part(self.a0);
                (angle_between(&only, axis), only)
            }
            // A cone about the free axis `w`, through the carried tool axis `u`.
            1 => {
                let (_, w) = self.free_rot[0];
                let u = self.between[1] * self.a0;
                let v = self.between[0].transpose() * (self.rw0 * axis);
                let (want, t) = (angle_between(&w, &u), angle_between(&w, &v));
                if t == want {
                    return (0.0, *axis);
                }
                ((t - want).abs(), to_part(at_angle_from(&w, &v, want)))
            }
            2 => self.folds().map_or((0.0, *axis), |f| f.nearest(axis)),
            _ => (0.0, *axis),
        }
    }

    /// How far outside the directions the machine can point a tool axis may
    /// lie and still be solved, at the nearest one it can point, radians:
    /// the rounding of the CL's tool axes ([`AXIS_ROUNDING_RAD`] unless set).
    pub fn axis_rounding(&self) -> f64 {
        self.axis_rounding
    }

    /// Sets [`Kinematics::axis_rounding`] for a CL that writes its tool axes
    /// with fewer decimals (half a unit of the last decimal on each component
    /// moves a unit vector by up to `0.87·10^-d` rad: 8.7e-5 rad for 4
    /// decimals). Clamped to `0..=`[`MAX_AXIS_ROUNDING_RAD`] (NaN: the
    /// default).
    pub fn set_axis_rounding(&mut self, rad: f64) {
        self.axis_rounding = if rad.is_nan() {
            AXIS_ROUNDING_RAD
        } else {
            rad.clamp(0.0, MAX_AXIS_ROUNDING_RAD)
        };
    }

    /// Why `ik` failed for a pose with tool axis `axis`, with how far that
    /// axis lies beyond the directions the machine can point (its text says
    /// which `--axis-rounding` would take it, where one would).
    pub fn ik_failure(&self, error: IkError, axis: &Vector3<f64>) -> IkFailure {
        IkFailure {
            error,
            beyond_rad: self.axis_reach(axis).0,
            rounding_rad: self.axis_rounding,
        }
    }
}

/// An [`IkError`] with what its message tells the user: how far the tool
/// axis lies beyond the directions the machine can point, radians (0 when
/// it does not), and the axis rounding in force.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IkFailure {
    /// What failed.
    pub error: IkError,
    /// How far the tool axis lies beyond reach, radians.
    pub beyond_rad: f64,
    /// The axis rounding in force ([`Kinematics::axis_rounding`]), radians.
    pub rounding_rad: f64,
}

impl std::fmt::Display for IkFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (e, gap, rounding) = (self.error, self.beyond_rad, self.rounding_rad);
        if e != IkError::OrientationUnreachable || gap == 0.0 {
            return write!(f, "{e}");
        }
        write!(
            f,
            "{e}: it lies {:.7}° ({gap:.1e} rad) beyond the directions the machine can point (an axis up to {rounding:.1e} rad beyond, CL rounding, is taken at the nearest",
            gap.to_degrees()
        )?;
        if gap <= MAX_AXIS_ROUNDING_RAD {
            // Two significant digits, rounded up: that value takes it.
            let scale = 10f64.powi(gap.log10().floor() as i32 - 1);
            let suggest = ((gap / scale).ceil() * scale).min(MAX_AXIS_ROUNDING_RAD);
            write!(
                f,
                "; if the CL rounds its tool axes that coarsely, --axis-rounding {suggest:.1e} takes it at the nearest"
            )?;
        }
        f.write_str(")")
    }
}

impl std::error::Error for IkFailure {}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::machine_from_toml;
    use crate::{Pose, model::Machine};

    fn machine(rotary: &str) -> Machine {
        let text = format!(
            r#"
name = "reach"
[[axis]]
name = "X"
kind = "linear"
side = "tool"
direction = [1, 0, 0]
[[axis]]
name = "Y"
kind = "linear"
side = "tool"
direction = [0, 1, 0]
[[axis]]
name = "Z"
kind = "linear"
side = "tool"
direction = [0, 0, 1]
{rotary}
[tool]
point = [0, 0, 0]
axis = [0, 0, 1]
"#
        );
        machine_from_toml(&text, "reach.toml").unwrap()
    }

    /// The test machine with a 45° nutating head (B about (1, 0, 1)/√2, C
    /// table): it points every direction from Z down to the horizontal
    /// (the upper fold).
    fn nutating() -> Machine {
        machine_from_toml(
            include_str!("../../tests/machines/nutating-45.toml"),
            "nutating-45.toml",
        )
        .unwrap()
    }

    const B_LOCKED_AT_15: &str = r#"
[[axis]]
name = "B"
kind = "rotary"
side = "tool"
direction = [0, 1, 0]
point = [0, 0, 150]
fixed = 15
"#;
    const A_TABLE: &str = r#"
[[axis]]
name = "A"
kind = "rotary"
side = "workpiece"
direction = [1, 0, 0]
point = [0, 0, -50]
"#;
    const C_TABLE: &str = r#"
[[axis]]
name = "C"
kind = "rotary"
side = "workpiece"
direction = [0, 0, 1]
point = [0, 0, 0]
"#;

    /// Head B locked at 15°, table A (X) and C (Z) free: the tool axis makes
    /// at least 15° with the part's Z (the lower fold), A = 0 on it.
    fn locked_head() -> Machine {
        machine(&format!("{B_LOCKED_AT_15}{A_TABLE}{C_TABLE}"))
    }

    /// How far short of 15° from Z the direction `axis` lies, radians (the
    /// tilt of the head locked at 15°).
    fn off_15_degrees(axis: &Vector3<f64>) -> f64 {
        15f64.to_radians() - angle_between(&Vector3::z(), axis)
    }

    fn unit(x: f64, y: f64, z: f64) -> Vector3<f64> {
        Vector3::new(x, y, z).normalize()
    }

    fn solve(kin: &Kinematics, axis: Vector3<f64>) -> Result<Vec<crate::Solution>, crate::IkError> {
        let mut out = Vec::new();
        let pose = Pose {
            point: Vector3::new(10.0, 20.0, 30.0),
            axis,
            reference: None,
        };
        kin.ik_all_branches(&pose, None, &mut out).map(|()| out)
    }

    /// Every solution reaches the point exactly and the nearest axis the
    /// machine can point, which lies `gap` from `axis`.
    fn assert_nearest(kin: &Kinematics, axis: Vector3<f64>, gap: f64) {
        let (got_gap, nearest) = kin.axis_reach(&axis);
        assert!((got_gap - gap).abs() < 1e-12, "gap {got_gap} vs {gap}");
        assert!((angle_between(&nearest, &axis) - gap).abs() < 1e-12);
        let sols = solve(kin, axis).unwrap();
        assert!(!sols.is_empty());
        for s in &sols {
            let pose = kin.fk(&s.joints[..kin.axis_count()]);
            assert!((pose.point - Vector3::new(10.0, 20.0, 30.0)).norm() < 1e-9);
            assert!(angle_between(&pose.axis, &nearest) < 1e-9, "{s:?}");
        }
    }

    #[test]
    fn a_flat_tool_rounded_below_the_horizontal_is_solved_flat() {
        // (0, -1, -0.0000001) as a CL writes it: 1e-7 rad below the fold.
        assert_nearest(
            &Kinematics::new(&nutating()),
            unit(0.0, -1.0, -0.0000001),
            1e-7,
        );
        // Exactly flat and above it: inside.
        assert_eq!(
            Kinematics::new(&nutating())
                .axis_reach(&unit(0.0, -1.0, 0.0))
                .0,
            0.0
        );
        // 2e-6 rad below: beyond CL rounding, unreachable.
        assert_eq!(
            solve(&Kinematics::new(&nutating()), unit(0.0, -1.0, -2e-6)).unwrap_err(),
            crate::IkError::OrientationUnreachable
        );
    }

    #[test]
    fn fifteen_degrees_rounded_to_seven_decimals_is_solved_at_fifteen() {
        let axis = unit(-0.2588190, 0.0, 0.9659258);
        let gap = off_15_degrees(&axis);
        assert!(gap > 1e-8 && gap < 1e-7, "{gap}");
        assert_nearest(&Kinematics::new(&locked_head()), axis, gap);
        assert_eq!(
            solve(&Kinematics::new(&locked_head()), unit(-0.2588, 0.0, 0.9659)).unwrap_err(),
            crate::IkError::OrientationUnreachable
        );
    }

    #[test]
    fn four_decimals_need_their_axis_rounding() {
        // 15° written with 4 decimals lies 1.17e-5 rad inside the fold
        // (15° − atan2(0.2588, 0.9659) = 0.000671°).
        let axis = unit(-0.2588, 0.0, 0.9659);
        let gap = off_15_degrees(&axis);
        assert!(gap > 1e-5 && gap < 2e-5, "{gap}");
        let mut kin = Kinematics::new(&locked_head());
        assert_eq!(kin.axis_rounding(), AXIS_ROUNDING_RAD);
        let e = solve(&kin, axis).unwrap_err();
        assert_eq!(
            kin.ik_failure(e, &axis).to_string(),
            "no setting of the rotary axes gives this tool axis: it lies 0.0006711° (1.2e-5 rad) beyond the directions the machine can point (an axis up to 1.0e-6 rad beyond, CL rounding, is taken at the nearest; if the CL rounds its tool axes that coarsely, --axis-rounding 1.2e-5 takes it at the nearest)"
        );
        kin.set_axis_rounding(1.2e-5);
        assert_nearest(&kin, axis, gap);
        // Clamped to what rounding can be; NaN is the default.
        kin.set_axis_rounding(1.0);
        assert_eq!(kin.axis_rounding(), MAX_AXIS_ROUNDING_RAD);
        kin.set_axis_rounding(f64::NAN);
        assert_eq!(kin.axis_rounding(), AXIS_ROUNDING_RAD);
        // Beyond what any rounding can be: no hint.
        let far = unit(-0.2, 0.0, 0.98);
        let text = kin
            .ik_failure(solve(&kin, far).unwrap_err(), &far)
            .to_string();
        assert!(!text.contains("--axis-rounding"), "{text}");
    }

    #[test]
    fn an_axis_on_the_rim_of_the_hole_is_not_beyond_it() {
        // A C table out of square by 0.01° in XZ on an A table: it cannot
        // point within 0.01° of its own direction, and Z lies on that rim
        // (at A = 0, C = 0). Subproblem 2 misses it by rounding; the axis
        // is solved as it is, not flagged as taken at a nearest one.
        let tilt = 0.01f64.to_radians();
        let m = machine(&format!(
            "{A_TABLE}[[axis]]\nname = \"C\"\nkind = \"rotary\"\nside = \"workpiece\"\n\
             direction = [{}, 0, {}]\npoint = [0, 0, 0]\n",
            tilt.sin(),
            tilt.cos()
        ));
        let kin = Kinematics::new(&m);
        assert_eq!(kin.axis_reach(&Vector3::z()).0, 0.0);
        let sols = solve(&kin, Vector3::z()).unwrap();
        assert!(!sols.is_empty());
        for s in &sols {
            assert!(!s.nearest_axis, "{s:?}");
            let pose = kin.fk(&s.joints[..kin.axis_count()]);
            assert!(angle_between(&pose.axis, &Vector3::z()) < 1e-12, "{s:?}");
        }
    }

    #[test]
    fn one_free_axis_takes_the_nearest_direction_on_its_cone() {
        // The locked head above with A locked too: C turns the 15° axis.
        let m = machine(&format!("{B_LOCKED_AT_15}{C_TABLE}"));
        let axis = unit(0.0, 0.2588195, 0.9659258);
        let gap = off_15_degrees(&axis).abs();
        assert!(gap > 1e-8 && gap < 1e-6, "{gap}");
        assert_nearest(&Kinematics::new(&m), axis, gap);
        assert!(solve(&Kinematics::new(&m), unit(0.0, 0.26, 0.9659258)).is_err());
    }

    #[test]
    fn no_free_axis_takes_its_one_direction_within_rounding() {
        let m = machine(B_LOCKED_AT_15);
        let axis = unit(0.2588190, 0.0, 0.9659258);
        let gap = off_15_degrees(&axis).abs();
        assert_nearest(&Kinematics::new(&m), axis, gap);
        assert!(solve(&Kinematics::new(&m), unit(0.2588, 0.0, 0.9659)).is_err());
    }
}
