//! Poses and lengths as a user reads them in a message.

use std::fmt;

use crate::model::Pose;

/// A length or angle in a message: four decimals, or in exponent notation
/// where that would print hundreds of digits (`GOTO/1e300,…`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mm(pub f64);

impl fmt::Display for Mm {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.0.abs() < 1e12 || !self.0.is_finite() {
            write!(f, "{:.4}", self.0)
        } else {
            write!(f, "{:.4e}", self.0)
        }
    }
}

/// `point (x, y, z) axis (i, j, k)`: the tool point to four decimals, the
/// tool axis to seven (as NX writes it).
impl fmt::Display for Pose {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (p, a) = (self.point, self.axis);
        write!(
            f,
            "point ({}, {}, {}) axis ({:.7}, {:.7}, {:.7})",
            Mm(p.x),
            Mm(p.y),
            Mm(p.z),
            a.x,
            a.y,
            a.z
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    #[test]
    fn huge_lengths_are_written_with_an_exponent() {
        assert_eq!(Mm(12.345_67).to_string(), "12.3457");
        assert_eq!(Mm(-999_999_999_999.0).to_string(), "-999999999999.0000");
        assert_eq!(Mm(1e300).to_string(), "1.0000e300");
        assert_eq!(Mm(-1e12).to_string(), "-1.0000e12");
        assert_eq!(Mm(f64::NAN).to_string(), "NaN");
    }

    #[test]
    fn a_pose_reads_as_point_and_axis() {
        let pose = Pose {
            point: Vector3::new(1.0, -2.5, 1e13),
            axis: Vector3::new(0.0, 0.0, 1.0),
            reference: None,
        };
        assert_eq!(
            pose.to_string(),
            "point (1.0000, -2.5000, 1.0000e13) axis (0.0000000, 0.0000000, 1.0000000)"
        );
    }
}
