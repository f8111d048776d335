//! Solving a pose near a known configuration: for points the post makes
//! itself (linearization, retracts) and for points where a singular angle is
//! held.

use kinpost_machine::tolerance::HELD_SLACK_DEG;
use kinpost_machine::{Joints, Kinematics, Pose, Solution};
use nalgebra::{UnitQuaternion, Vector3};

/// A singular angle held at a value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hold {
    /// Index of the axis.
    pub axis: usize,
    /// Its value, degrees (unwrapped).
    pub value_deg: f64,
}

/// The pose at `t` between `a` and `b`: the point linearly, the tool axis
/// (and reference) by spherical interpolation (the tool axis turns in the
/// plane of the two axes at constant speed, as a CL segment means it).
pub fn interpolate(a: &Pose, b: &Pose, t: f64) -> Pose {
    Pose {
        point: a.point.lerp(&b.point, t),
        axis: slerp(&a.axis, &b.axis, t),
        reference: match (a.reference, b.reference) {
            (Some(ra), Some(rb)) => Some(slerp(&ra, &rb, t)),
            (r, _) => r,
        },
    }
}

/// Spherical interpolation of unit vectors; opposite vectors have no
/// plane, and keep `a`.
fn slerp(a: &Vector3<f64>, b: &Vector3<f64>, t: f64) -> Vector3<f64> {
    match UnitQuaternion::rotation_between(a, b) {
        Some(q) => {
            let part = UnitQuaternion::identity().slerp(&q, t);
            part * a
        }
        None => *a,
    }
}

/// Where to solve a pose near: a configuration, the singular angle held
/// there if any, and the branch to keep if any.
pub struct Near<'a> {
    /// The configuration to stay near.
    pub joints: &'a Joints,
    /// The singular angle to hold, if any.
    pub hold: Option<Hold>,
    /// Solutions of this branch come first (when there are any).
    pub branch: Option<u8>,
}

/// The valid solution of `pose` whose rotary axes are nearest `near`
/// (`rotary`: the free rotary axes), of its branch if it has valid ones,
/// with the singular angle held if `near` says so: the tool axis is then
/// the nearest one the machine points with that angle, and the pose solved
/// is returned with it.
pub fn solve_near(
    kin: &Kinematics,
    pose: &Pose,
    near: &Near,
    rotary: &[usize],
    scratch: &mut Vec<Solution>,
) -> Option<(Pose, Solution)> {
    let n = kin.axis_count();
    let mut hint = *near.joints;
    let mut pose = *pose;
    let hold = near.hold;
    if let Some(h) = hold {
        hint[h.axis] = h.value_deg;
        if let Some(axis) = kin.held_axis(&pose.axis, h.value_deg) {
            pose.axis = axis;
        }
    }
    kin.ik(&pose, Some(&hint[..n]), scratch).ok()?;
    let travel =
        |s: &Solution| -> f64 { rotary.iter().map(|&i| (s.joints[i] - hint[i]).abs()).sum() };
    let held =
        |s: &Solution| hold.is_none_or(|h| (s.joints[h.axis] - h.value_deg).abs() < HELD_SLACK_DEG);
    let other = |s: &Solution| near.branch.is_some_and(|b| b != s.branch);
    let best = scratch
        .iter()
        .filter(|s| s.is_valid() && held(s))
        .min_by(|a, b| {
            other(a)
                .cmp(&other(b))
                .then(travel(a).total_cmp(&travel(b)))
        })
        .copied()?;
    // An interpolated tool axis just beyond what the machine can point: the
    // block points the nearest one, and is checked against it.
    if best.nearest_axis {
        pose.axis = kin.axis_reach(&pose.axis).1;
    }
    Some((pose, best))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolation_turns_the_axis_in_its_plane() {
        let a = Pose {
            point: Vector3::new(0.0, 0.0, 0.0),
            axis: Vector3::z(),
            reference: None,
        };
        let b = Pose {
            point: Vector3::new(10.0, 0.0, 0.0),
            axis: Vector3::x(),
            reference: None,
        };
        let m = interpolate(&a, &b, 0.5);
        assert!((m.point - Vector3::new(5.0, 0.0, 0.0)).norm() < 1e-12);
        let h = std::f64::consts::FRAC_1_SQRT_2;
        assert!((m.axis - Vector3::new(h, 0.0, h)).norm() < 1e-12);
    }
}
