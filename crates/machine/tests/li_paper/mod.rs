//! Li (B-spline grinding) (Li), section 5, written from the printed formulas,
//! independently of kinpost's chain: the transformation chain eq. 17-25,
//! the normal transform eq. 26 and the angles of eq. 30. Shared by
//! `li_eq30.rs` (the `ac-grinder`'s inverse kinematics) and by
//! `crates/kinpost/tests/all/li_grinding_path.rs` (a posted grinding path), which
//! includes this file with `#[path]`.
//!
//! The installation offsets L_x, L_y, L_z, the wheel radius r_s1 and the
//! angle φ of the grinding point (eq. 27) are the assumed values stated in
//! `machines/ac-grinder.toml`.
#![allow(dead_code)]

use nalgebra::{Matrix3, Matrix4, Vector3};

pub const L_X: f64 = 12.0;
pub const L_Y: f64 = 40.0;
pub const L_Z: f64 = 120.0;
pub const R_S1: f64 = 50.0;
pub const PHI: f64 = 0.0;

pub fn translation(x: f64, y: f64, z: f64) -> Matrix4<f64> {
    Matrix4::new(
        1.0, 0.0, 0.0, x, //
        0.0, 1.0, 0.0, y, //
        0.0, 0.0, 1.0, z, //
        0.0, 0.0, 0.0, 1.0,
    )
}

/// Eq. 18 (T2) and eq. 23 (T7): the matrix printed as
/// [cos t, sin t; −sin t, cos t] in the xy block.
pub fn about_z_printed(t: f64) -> Matrix4<f64> {
    let (s, c) = t.sin_cos();
    Matrix4::new(
        c, s, 0.0, 0.0, //
        -s, c, 0.0, 0.0, //
        0.0, 0.0, 1.0, 0.0, //
        0.0, 0.0, 0.0, 1.0,
    )
}

/// Eq. 24 (T8): [cos t, −sin t; sin t, cos t] in the xy block.
pub fn t8(t: f64) -> Matrix4<f64> {
    let (s, c) = t.sin_cos();
    Matrix4::new(
        c, -s, 0.0, 0.0, //
        s, c, 0.0, 0.0, //
        0.0, 0.0, 1.0, 0.0, //
        0.0, 0.0, 0.0, 1.0,
    )
}

/// Eq. 22 (T6) with the angle π/2 as printed.
pub fn t6() -> Matrix4<f64> {
    let (s, c) = std::f64::consts::FRAC_PI_2.sin_cos();
    Matrix4::new(
        c, 0.0, s, 0.0, //
        0.0, 1.0, 0.0, 0.0, //
        -s, 0.0, c, 0.0, //
        0.0, 0.0, 0.0, 1.0,
    )
}

/// Eq. 25: the transformation from the part frame S_g to the wheel frame S_s
/// for axis motions l_x, l_y, l_z and angles θa, θc (radians).
pub fn eq25(lx: f64, ly: f64, lz: f64, ta: f64, tc: f64) -> Matrix4<f64> {
    let t1 = translation(0.0, -L_Y, 0.0); // eq. 17
    let t2 = about_z_printed(tc); // eq. 18
    let t3 = translation(0.0, 0.0, -(L_Z + lz)); // eq. 19
    let t4 = translation(L_X, 0.0, 0.0); // eq. 20
    let t5 = translation(lx, L_Y + ly, 0.0); // eq. 21
    let t7 = about_z_printed(std::f64::consts::PI); // eq. 23
    t1 * t2 * t3 * t4 * t5 * t6() * t7 * t8(ta)
}

/// Eq. 26: the normal of the part in wheel coordinates.
pub fn eq26(n: &Vector3<f64>, ta: f64, tc: f64) -> Vector3<f64> {
    let m = about_z_printed(tc) * t6() * about_z_printed(std::f64::consts::PI) * t8(ta);
    let r: Matrix3<f64> = m.fixed_view::<3, 3>(0, 0).into();
    r * n
}

/// Eq. 30, solved as printed: θa = arctan(n_x/n_y), and θc from the second
/// line, tan θc = n_z / (n_x sin θa + n_y cos θa). Principal values,
/// radians.
pub fn eq30(n: &Vector3<f64>) -> (f64, f64) {
    let ta = (n.x / n.y).atan();
    let tc = (n.z / (n.x * ta.sin() + n.y * ta.cos())).atan();
    (ta, tc)
}

/// The left side of eq. 30's second line.
pub fn eq30_residual(n: &Vector3<f64>, ta: f64, tc: f64) -> f64 {
    -n.x * ta.sin() * tc.sin() - n.y * ta.cos() * tc.sin() + n.z * tc.cos()
}

/// Eq. 30's own angles in degrees, (θa, θc) with θc or θc + 180°, whichever
/// gives C0 > 0 (both solve the second line), and the other orientation
/// branch (θa + 180°, 180° − θc).
pub fn eq30_angles_deg(n: &Vector3<f64>) -> [(f64, f64); 2] {
    let (ta, tc) = eq30(n);
    let tc = if eq26(n, ta, tc).y < 0.0 {
        tc
    } else {
        tc + std::f64::consts::PI
    };
    let (ta, tc) = (ta.to_degrees(), tc.to_degrees());
    [(ta, tc), (ta + 180.0, 180.0 - tc)]
}

/// Whether two angles in degrees differ by a whole number of `period`s
/// (within `tol` degrees).
pub fn same_angle_within(a: f64, b: f64, period: f64, tol: f64) -> bool {
    let d = (a - b) / period;
    (d - d.round()).abs() * period < tol
}

/// [`same_angle_within`] at 1e-9°.
pub fn same_angle(a: f64, b: f64, period: f64) -> bool {
    same_angle_within(a, b, period, 1e-9)
}
