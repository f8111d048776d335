//! Tool axes just beyond what a machine can point.
//!
//! A CAM system writes tool axes rounded: NX CLSF gives 7 decimals, which
//! move a unit vector by up to 9e-8 rad. Where a path runs along the edge of
//! the directions a machine can point (a tool lying flat on a 45° nutating
//! head, the one axis a head locked at 15° gives a 4-axis table, the rim of
//! the hole a C axis out of square leaves around its pole), that rounding
//! puts some of its axes just outside. Such an axis, up to
//! [`AXIS_ROUNDING_RAD`] outside, is solved at the nearest direction the
//! machine can point, and the closed-loop check counts the distance between
//! the two as the CL's own error. Farther out, the axis is unreachable.

use nalgebra::Vector3;

use super::{Folds, IkError, Kinematics, any_perpendicular};
use crate::angle::angle_between;

/// How far outside the directions a machine can point a requested tool axis
/// may lie and still be solved, at the nearest one it can point, radians:
/// the rounding of tool axes written with 6 decimals or more (half a unit of
/// the sixth decimal on each component moves a unit vector by up to 8.7e-7
/// rad).
pub const AXIS_ROUNDING_RAD: f64 = 1e-6;

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

    /// An inverse-kinematics failure in words; for a tool axis `axis` no
    /// setting of the rotary axes gives, how far beyond what the machine can
    /// point it lies.
    pub fn ik_error_text(&self, e: IkError, axis: &Vector3<f64>) -> String {
        let gap = self.axis_reach(axis).0;
        if e != IkError::OrientationUnreachable || gap == 0.0 {
            return e.to_string();
        }
        format!(
            "{e}: it lies {:.7}° ({gap:.1e} rad) beyond the directions the machine can point (an axis up to {AXIS_ROUNDING_RAD:.0e} rad beyond, CL rounding, is taken at the nearest)",
            gap.to_degrees()
        )
    }
}

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

    fn unit(x: f64, y: f64, z: f64) -> Vector3<f64> {
        Vector3::new(x, y, z).normalize()
    }

    fn solve(m: &Machine, axis: Vector3<f64>) -> Result<Vec<crate::Solution>, crate::IkError> {
        let kin = Kinematics::new(m);
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
    fn assert_nearest(m: &Machine, axis: Vector3<f64>, gap: f64) {
        let kin = Kinematics::new(m);
        let (got_gap, nearest) = kin.axis_reach(&axis);
        assert!((got_gap - gap).abs() < 1e-12, "gap {got_gap} vs {gap}");
        assert!((angle_between(&nearest, &axis) - gap).abs() < 1e-12);
        let sols = solve(m, axis).unwrap();
        assert!(!sols.is_empty());
        for s in &sols {
            let pose = kin.fk(&s.joints[..m.axes.len()]);
            assert!((pose.point - Vector3::new(10.0, 20.0, 30.0)).norm() < 1e-9);
            assert!(angle_between(&pose.axis, &nearest) < 1e-9, "{s:?}");
        }
    }

    #[test]
    fn a_flat_tool_rounded_below_the_horizontal_is_solved_flat() {
        // (0, -1, -0.0000001) as a CL writes it: 1e-7 rad below the fold.
        assert_nearest(&nutating(), unit(0.0, -1.0, -0.0000001), 1e-7);
        // Exactly flat and above it: inside.
        assert_eq!(
            Kinematics::new(&nutating())
                .axis_reach(&unit(0.0, -1.0, 0.0))
                .0,
            0.0
        );
        // 2e-6 rad below: beyond CL rounding, unreachable.
        assert_eq!(
            solve(&nutating(), unit(0.0, -1.0, -2e-6)).unwrap_err(),
            crate::IkError::OrientationUnreachable
        );
    }

    #[test]
    fn fifteen_degrees_rounded_to_seven_decimals_is_solved_at_fifteen() {
        let axis = unit(-0.2588190, 0.0, 0.9659258);
        let gap = 15f64.to_radians() - angle_between(&Vector3::z(), &axis);
        assert!(gap > 1e-8 && gap < 1e-7, "{gap}");
        assert_nearest(&locked_head(), axis, gap);
        assert_eq!(
            solve(&locked_head(), unit(-0.2588, 0.0, 0.9659)).unwrap_err(),
            crate::IkError::OrientationUnreachable
        );
    }

    #[test]
    fn one_free_axis_takes_the_nearest_direction_on_its_cone() {
        // The locked head above with A locked too: C turns the 15° axis.
        let m = machine(&format!("{B_LOCKED_AT_15}{C_TABLE}"));
        let axis = unit(0.0, 0.2588195, 0.9659258);
        let gap = (15f64.to_radians() - angle_between(&Vector3::z(), &axis)).abs();
        assert!(gap > 1e-8 && gap < 1e-6, "{gap}");
        assert_nearest(&m, axis, gap);
        assert!(solve(&m, unit(0.0, 0.26, 0.9659258)).is_err());
    }

    #[test]
    fn no_free_axis_takes_its_one_direction_within_rounding() {
        let m = machine(B_LOCKED_AT_15);
        let axis = unit(0.2588190, 0.0, 0.9659258);
        let gap = (15f64.to_radians() - angle_between(&Vector3::z(), &axis)).abs();
        assert_nearest(&m, axis, gap);
        assert!(solve(&m, unit(0.2588, 0.0, 0.9659)).is_err());
    }
}
