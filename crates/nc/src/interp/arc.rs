//! Arc geometry: centre from a radius, sweep, full turns, the radius check,
//! arcs through an intermediate point.

use super::machine::Tolerances;
use super::{Arc, ArcPlane};

/// How the centre of an arc is given.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Centre {
    /// Absolute centre in the plane (first, second coordinate).
    At([f64; 2]),
    /// Radius; negative for more than half a circle (`R-5`, `CR=-5`).
    Radius(f64),
}

/// Why an arc cannot be made.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum ArcError {
    /// R form with the end at the start.
    RadiusFullCircle,
    /// R form: the radius is shorter than half the chord.
    RadiusTooSmall { radius: f64, half_chord: f64 },
    /// Centre form: the end is not on the circle.
    RadiusMismatch { start: f64, end: f64 },
    /// Zero radius.
    ZeroRadius,
}

impl std::fmt::Display for ArcError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ArcError::RadiusFullCircle => f.write_str(
                "an arc given by its radius cannot end where it starts (a full circle needs its centre)",
            ),
            ArcError::RadiusTooSmall { radius, half_chord } => write!(
                f,
                "arc radius {radius:.4} mm is too small to reach the end point (half the chord is {half_chord:.4} mm)"
            ),
            ArcError::RadiusMismatch { start, end } => write!(
                f,
                "the end of the arc is not on its circle: radius {start:.4} mm at the start, {end:.4} mm at the end"
            ),
            ArcError::ZeroRadius => f.write_str("arc of zero radius (the centre is the start point)"),
        }
    }
}

/// An arc from `start` to `end` (X, Y, Z, mm) in `plane`, with `turns`
/// extra full turns.
pub(crate) fn arc(
    plane: ArcPlane,
    clockwise: bool,
    start: [f64; 3],
    end: [f64; 3],
    centre: Centre,
    turns: u32,
    tol: &Tolerances,
) -> Result<Arc, ArcError> {
    let [a, b, n] = plane.axes();
    let (sa, sb, ea, eb) = (start[a], start[b], end[a], end[b]);
    let c = match centre {
        Centre::At(c) => c,
        Centre::Radius(r) => centre_from_radius(clockwise, [sa, sb], [ea, eb], r, tol)?,
    };
    let r0 = (sa - c[0]).hypot(sb - c[1]);
    let r1 = (ea - c[0]).hypot(eb - c[1]);
    if r0 == 0.0 {
        return Err(ArcError::ZeroRadius);
    }
    if (r1 - r0).abs() > tol.arc_radius_mm.max(tol.arc_radius_rel * r0) {
        return Err(ArcError::RadiusMismatch { start: r0, end: r1 });
    }
    let t0 = (sb - c[1]).atan2(sa - c[0]);
    let t1 = (eb - c[1]).atan2(ea - c[0]);
    let full = std::f64::consts::TAU;
    let mut sweep = if clockwise { t0 - t1 } else { t1 - t0 };
    sweep = sweep.rem_euclid(full);
    // End on the start: a full circle.
    if sweep <= 1e-12 || full - sweep <= 1e-12 && (ea - sa).hypot(eb - sb) <= 1e-9 {
        sweep = full;
    }
    sweep += f64::from(turns) * full;
    let mut centre_mm = [0.0; 3];
    centre_mm[a] = c[0];
    centre_mm[b] = c[1];
    centre_mm[n] = start[n];
    Ok(Arc {
        plane,
        clockwise,
        centre_mm,
        start_mm: start,
        radius_mm: r0,
        turns,
        sweep_deg: sweep.to_degrees(),
        helix_mm: end[n] - start[n],
    })
}

/// The centre of an arc of radius `r` (negative: the long way) from `s` to
/// `e` in the plane.
fn centre_from_radius(
    clockwise: bool,
    s: [f64; 2],
    e: [f64; 2],
    r: f64,
    tol: &Tolerances,
) -> Result<[f64; 2], ArcError> {
    let (dx, dy) = (e[0] - s[0], e[1] - s[1]);
    let chord = dx.hypot(dy);
    if chord == 0.0 {
        return Err(ArcError::RadiusFullCircle);
    }
    let half = chord / 2.0;
    let radius = r.abs();
    // A radius a hair short of half the chord (rounded output) is a half circle.
    let h2 = radius * radius - half * half;
    if h2 < 0.0 && half - radius > tol.arc_radius_mm {
        return Err(ArcError::RadiusTooSmall {
            radius,
            half_chord: half,
        });
    }
    let h = h2.max(0.0).sqrt();
    // The centre of the short arc lies left of the chord for a
    // counter-clockwise arc, right for a clockwise one; R < 0 swaps.
    let left = clockwise == (r < 0.0);
    let sign = if left { 1.0 } else { -1.0 };
    let (ux, uy) = (-dy / chord, dx / chord);
    Ok([
        s[0] + dx / 2.0 + sign * h * ux,
        s[1] + dy / 2.0 + sign * h * uy,
    ])
}

/// The circle through three points of a plane (Sinumerik `CIP`): its
/// centre, or `None` when they lie on a line. Also whether the arc from
/// `s` through `m` to `e` turns clockwise.
pub(crate) fn circle_through(s: [f64; 2], m: [f64; 2], e: [f64; 2]) -> Option<([f64; 2], bool)> {
    let (ax, ay) = (m[0] - s[0], m[1] - s[1]);
    let (bx, by) = (e[0] - s[0], e[1] - s[1]);
    let d = 2.0 * (ax * by - ay * bx);
    let scale = (ax.hypot(ay) * bx.hypot(by)).max(1e-300);
    if d.abs() <= 1e-12 * scale {
        return None;
    }
    let a2 = ax * ax + ay * ay;
    let b2 = bx * bx + by * by;
    let cx = (by * a2 - ay * b2) / d;
    let cy = (ax * b2 - bx * a2) / d;
    // s → m → e turning left (cross > 0) is counter-clockwise.
    Some(([s[0] + cx, s[1] + cy], d < 0.0))
}

/// The last path element, kept so that `CT` can find its end tangent
/// (worked out only when a `CT` asks: X Y Z before and after, the arc).
pub(crate) type LastElement = ([f64; 3], [f64; 3], Option<Arc>);

/// The unit direction of the path at the end of an element (a line from
/// `before` to `after`, or an arc ending at `after`); `None` for a line of
/// no length.
pub(crate) fn end_tangent((before, after, arc): LastElement) -> Option<[f64; 3]> {
    let t = match arc {
        None => [
            after[0] - before[0],
            after[1] - before[1],
            after[2] - before[2],
        ],
        Some(a) => {
            let [pa, pb, _] = a.plane.axes();
            let (ra, rb) = (after[pa] - a.centre_mm[pa], after[pb] - a.centre_mm[pb]);
            let mut t = [0.0; 3];
            // Perpendicular to the radius, in the sense of turning.
            if a.clockwise {
                t[pa] = rb;
                t[pb] = -ra;
            } else {
                t[pa] = -rb;
                t[pb] = ra;
            }
            t
        }
    };
    let n = (t[0] * t[0] + t[1] * t[1] + t[2] * t[2]).sqrt();
    (n > 1e-12).then(|| [t[0] / n, t[1] / n, t[2] / n])
}

/// The centre of the circle that leaves `s` along the direction `t` and
/// reaches `e` (Sinumerik `CT`), and whether it turns clockwise; `None`
/// when `e` lies on the tangent.
pub(crate) fn tangent_centre(s: [f64; 2], t: [f64; 2], e: [f64; 2]) -> Option<([f64; 2], bool)> {
    let (dx, dy) = (e[0] - s[0], e[1] - s[1]);
    let tn = t[0].hypot(t[1]);
    if tn == 0.0 {
        return None;
    }
    // Left of the tangent.
    let (nx, ny) = (-t[1] / tn, t[0] / tn);
    let dn = dx * nx + dy * ny;
    let d2 = dx * dx + dy * dy;
    if dn.abs() <= 1e-12 * d2.sqrt().max(1e-300) {
        return None;
    }
    // |c - s| = |c - e| with c = s + λ n: λ = |d|² / (2 d·n).
    let lambda = d2 / (2.0 * dn);
    Some(([s[0] + lambda * nx, s[1] + lambda * ny], lambda < 0.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tol() -> Tolerances {
        Tolerances::default()
    }

    /// Quarter circles by hand: centre (0, 0), from (1, 0) to (0, 1).
    #[test]
    fn quarter_circles() {
        let s = [1.0, 0.0, 0.0];
        let e = [0.0, 1.0, 0.0];
        let ccw = arc(ArcPlane::Xy, false, s, e, Centre::Radius(1.0), 0, &tol()).unwrap();
        assert!((ccw.centre_mm[0]).abs() < 1e-12 && ccw.centre_mm[1].abs() < 1e-12);
        assert!((ccw.sweep_deg - 90.0).abs() < 1e-9);
        // Clockwise the short way: centre (1, 1), 90°.
        let cw = arc(ArcPlane::Xy, true, s, e, Centre::Radius(1.0), 0, &tol()).unwrap();
        assert!((cw.centre_mm[0] - 1.0).abs() < 1e-12 && (cw.centre_mm[1] - 1.0).abs() < 1e-12);
        assert!((cw.sweep_deg - 90.0).abs() < 1e-9);
        // R < 0: the long way round, 270°, centre (1, 1) for CCW.
        let long = arc(ArcPlane::Xy, false, s, e, Centre::Radius(-1.0), 0, &tol()).unwrap();
        assert!((long.centre_mm[0] - 1.0).abs() < 1e-12);
        assert!((long.sweep_deg - 270.0).abs() < 1e-9);
        // Full circle by centre, two extra turns.
        let full = arc(ArcPlane::Xy, true, s, s, Centre::At([0.0, 0.0]), 2, &tol()).unwrap();
        assert!((full.sweep_deg - 3.0 * 360.0).abs() < 1e-9);
        assert!(arc(ArcPlane::Xy, true, s, s, Centre::Radius(1.0), 0, &tol()).is_err());
        assert!(
            arc(
                ArcPlane::Xy,
                true,
                s,
                [5.0, 0.0, 0.0],
                Centre::Radius(1.0),
                0,
                &tol()
            )
            .is_err()
        );
        assert!(
            arc(
                ArcPlane::Xy,
                true,
                s,
                [0.0, 2.0, 0.0],
                Centre::At([0.0, 0.0]),
                0,
                &tol()
            )
            .is_err()
        );
    }

    /// Leaving (0, 0) along +X towards (1, 1): the quarter circle about
    /// (0, 1), counter-clockwise.
    #[test]
    fn tangent_circle() {
        let (c, cw) = tangent_centre([0.0, 0.0], [1.0, 0.0], [1.0, 1.0]).unwrap();
        assert!((c[0]).abs() < 1e-12 && (c[1] - 1.0).abs() < 1e-12 && !cw);
        let (c, cw) = tangent_centre([0.0, 0.0], [1.0, 0.0], [1.0, -1.0]).unwrap();
        assert!((c[1] + 1.0).abs() < 1e-12 && cw);
        assert!(tangent_centre([0.0, 0.0], [1.0, 0.0], [5.0, 0.0]).is_none());
    }

    #[test]
    fn circle_through_three_points() {
        let (c, cw) = circle_through([1.0, 0.0], [0.0, 1.0], [-1.0, 0.0]).unwrap();
        assert!(c[0].abs() < 1e-12 && c[1].abs() < 1e-12 && !cw);
        let (_, cw) = circle_through([1.0, 0.0], [0.0, -1.0], [-1.0, 0.0]).unwrap();
        assert!(cw);
        assert!(circle_through([0.0, 0.0], [1.0, 1.0], [2.0, 2.0]).is_none());
    }
}
