//! Small 3-vector helpers (pure, for the geometry of arcs, curves and frames).

use crate::Vec3;

pub(crate) fn add(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

pub(crate) fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub(crate) fn scale(a: Vec3, s: f64) -> Vec3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

pub(crate) fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub(crate) fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub(crate) fn norm(a: Vec3) -> f64 {
    dot(a, a).sqrt()
}

/// `v` scaled to unit length; `None` if it is (nearly) zero or not finite.
pub(crate) fn normalize(v: Vec3) -> Option<Vec3> {
    let n2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    if n2 == 1.0 {
        return Some(v); // already unit length, e.g. 0,0,1
    }
    // The usual case: no overflow or underflow in the squares (also false
    // for NaN and infinity); one square root, three correctly rounded
    // divisions.
    if n2 > 1e-200 && n2 < 1e200 {
        let n = n2.sqrt();
        return Some([v[0] / n, v[1] / n, v[2] / n]);
    }
    // Scale first so that huge or tiny components neither overflow nor vanish.
    let m = v[0].abs().max(v[1].abs()).max(v[2].abs());
    if !(m.is_finite() && m > 1e-300) {
        return None;
    }
    let s = [v[0] / m, v[1] / m, v[2] / m];
    let n = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
    Some([s[0] / n, s[1] / n, s[2] / n])
}
