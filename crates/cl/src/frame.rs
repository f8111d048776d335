//! Coordinate frames of `MSYS/` and `CSYS/` statements.

use thiserror::Error;

use crate::Vec3;
use crate::vector::{add, cross, dot, norm, scale, sub};

/// How far the axes of a frame may be from unit length and from square
/// (the dot products) and its Z axis from `X × Y`. CAM systems write
/// direction cosines with 6 or 7 decimals, so a correct frame is within
/// about 1e-6; 1e-4 (0.006°) still accepts 4-decimal writers while any frame
/// that is really skewed, scaled or mirrored is refused: points posted in it
/// would be distorted.
pub const FRAME_TOLERANCE: f64 = 1e-4;

/// Why a frame is refused.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum FrameError {
    /// A number is not finite.
    #[error("the frame's numbers are not all finite")]
    NotFinite,
    /// An axis is not of unit length.
    #[error("the frame's {axis} axis has length {length:.7}, not 1 (tolerance {FRAME_TOLERANCE})")]
    NotUnit {
        /// `"X"`, `"Y"` or `"Z"`.
        axis: &'static str,
        /// Its length.
        length: f64,
    },
    /// Two axes are not perpendicular.
    #[error(
        "the frame's {first} and {second} axes are not perpendicular (cosine {cosine:.7}, tolerance {FRAME_TOLERANCE})"
    )]
    NotSquare {
        /// The first axis.
        first: &'static str,
        /// The second axis.
        second: &'static str,
        /// The cosine of the angle between them.
        cosine: f64,
    },
    /// The Z axis is `−(X × Y)`: a mirror image.
    #[error(
        "the frame is left-handed (Z is -(X x Y)): a mirrored frame would post the part mirrored"
    )]
    LeftHanded,
}

/// A right-handed orthonormal frame given in an outer frame: its origin and
/// the directions of its X, Y and Z axes. A point with coordinates `p` in
/// this frame is `origin + p.x · x + p.y · y + p.z · z` in the outer one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// Origin, in the outer frame (mm).
    pub origin: Vec3,
    /// Direction of the X axis (unit length within [`FRAME_TOLERANCE`]).
    pub x: Vec3,
    /// Direction of the Y axis.
    pub y: Vec3,
    /// Direction of the Z axis (`x × y`).
    pub z: Vec3,
}

impl Frame {
    /// The identity frame.
    pub const IDENTITY: Frame = Frame {
        origin: [0.0; 3],
        x: [1.0, 0.0, 0.0],
        y: [0.0, 1.0, 0.0],
        z: [0.0, 0.0, 1.0],
    };

    /// The frame with `origin` and X and Y axes `x`, `y` (checked unit and
    /// square); Z is `x × y`.
    pub fn from_axes(origin: Vec3, x: Vec3, y: Vec3) -> Result<Frame, FrameError> {
        let z = cross(x, y);
        Frame::checked(origin, x, y, z)
    }

    /// The frame of a 3 × 4 matrix written row by row, as `CSYS/` has it:
    /// `x1,x2,x3,o1, y1,y2,y3,o2, z1,z2,z3,o3`: each row is the direction
    /// of one axis followed by one coordinate of the origin. (SOLIDWORKS CAM
    /// writes part instances this way: the `GOTO`s that follow map onto
    /// those of the reference instance through this frame; see
    /// `docs/cl-statements.md`.)
    pub fn from_rows(m: [f64; 12]) -> Result<Frame, FrameError> {
        Frame::checked(
            [m[3], m[7], m[11]],
            [m[0], m[1], m[2]],
            [m[4], m[5], m[6]],
            [m[8], m[9], m[10]],
        )
    }

    fn checked(origin: Vec3, x: Vec3, y: Vec3, z: Vec3) -> Result<Frame, FrameError> {
        if !origin
            .iter()
            .chain(&x)
            .chain(&y)
            .chain(&z)
            .all(|v| v.is_finite())
        {
            return Err(FrameError::NotFinite);
        }
        // X and Y first: from `from_axes`, Z is their product, and a skew
        // of X and Y is the error to name.
        let unit = |axis, v| {
            let length = norm(v);
            if (length - 1.0).abs() > FRAME_TOLERANCE {
                return Err(FrameError::NotUnit { axis, length });
            }
            Ok(())
        };
        let square = |first, a, second, b| {
            let cosine = dot(a, b);
            if cosine.abs() > FRAME_TOLERANCE {
                return Err(FrameError::NotSquare {
                    first,
                    second,
                    cosine,
                });
            }
            Ok(())
        };
        unit("X", x)?;
        unit("Y", y)?;
        square("X", x, "Y", y)?;
        unit("Z", z)?;
        square("Y", y, "Z", z)?;
        square("Z", z, "X", x)?;
        if dot(cross(x, y), z) < 0.0 {
            return Err(FrameError::LeftHanded);
        }
        Ok(Frame { origin, x, y, z })
    }

    /// A point given in this frame, in the outer frame.
    pub fn to_outer(&self, p: Vec3) -> Vec3 {
        add(
            self.origin,
            add(
                add(scale(self.x, p[0]), scale(self.y, p[1])),
                scale(self.z, p[2]),
            ),
        )
    }

    /// A point given in the outer frame, in this frame (the transpose
    /// of the rotation: exact for an orthonormal frame).
    pub fn to_inner(&self, p: Vec3) -> Vec3 {
        let d = sub(p, self.origin);
        [dot(d, self.x), dot(d, self.y), dot(d, self.z)]
    }

    /// A direction given in this frame, in the outer frame.
    pub fn direction_to_outer(&self, v: Vec3) -> Vec3 {
        add(
            add(scale(self.x, v[0]), scale(self.y, v[1])),
            scale(self.z, v[2]),
        )
    }

    /// Whether this is the identity within `tolerance` (origin in mm, axes
    /// as direction cosines).
    pub fn is_identity(&self, tolerance: f64) -> bool {
        let id = Frame::IDENTITY;
        [
            (self.origin, id.origin),
            (self.x, id.x),
            (self.y, id.y),
            (self.z, id.z),
        ]
        .iter()
        .all(|&(a, b)| norm(sub(a, b)) <= tolerance)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Vec3, b: Vec3) -> bool {
        norm(sub(a, b)) < 1e-12
    }

    #[test]
    fn rows_are_axes_and_the_last_column_is_the_origin() {
        // A quarter turn about Z, origin (1, 2, 3).
        let f = Frame::from_rows([0., -1., 0., 1., 1., 0., 0., 2., 0., 0., 1., 3.]).unwrap();
        assert_eq!(f.origin, [1., 2., 3.]);
        assert_eq!(f.x, [0., -1., 0.]);
        assert_eq!(f.y, [1., 0., 0.]);
        assert_eq!(f.z, [0., 0., 1.]);
        // The local X unit point lies one unit along the frame's X axis.
        assert!(close(f.to_outer([1., 0., 0.]), [1., 1., 3.]));
        assert!(close(f.to_inner(f.to_outer([4., -5., 6.])), [4., -5., 6.]));
        assert!(close(f.direction_to_outer([0., 1., 0.]), [1., 0., 0.]));
    }

    #[test]
    fn from_axes_completes_z_and_checks_square_and_unit() {
        let f = Frame::from_axes([0.; 3], [0., 1., 0.], [-1., 0., 0.]).unwrap();
        assert_eq!(f.z, [0., 0., 1.]);
        // NX writes 7 decimals: fine.
        let c = 0.9975352;
        let s = 0.0701679;
        assert!(Frame::from_axes([0.; 3], [c, -s, 0.], [-s, -c, 0.]).is_ok());
        assert!(matches!(
            Frame::from_axes([0.; 3], [2., 0., 0.], [0., 1., 0.]),
            Err(FrameError::NotUnit { axis: "X", .. })
        ));
        assert!(matches!(
            Frame::from_axes([0.; 3], [1., 0., 0.], [0.1, 0.995, 0.]),
            Err(FrameError::NotSquare { .. })
        ));
        assert_eq!(
            Frame::from_axes([f64::NAN, 0., 0.], [1., 0., 0.], [0., 1., 0.]),
            Err(FrameError::NotFinite)
        );
    }

    #[test]
    fn mirrored_rows_are_refused() {
        assert_eq!(
            Frame::from_rows([1., 0., 0., 0., 0., 1., 0., 0., 0., 0., -1., 0.]),
            Err(FrameError::LeftHanded)
        );
    }

    #[test]
    fn identity_is_recognized_within_tolerance() {
        let f = Frame::from_rows([1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1., 0.]).unwrap();
        assert!(f.is_identity(1e-9));
        let g = Frame::from_rows([1., 0., 0., 0., 0., 1., 0., 219.065, 0., 0., 1., 0.]).unwrap();
        assert!(!g.is_identity(1e-9));
    }
}
