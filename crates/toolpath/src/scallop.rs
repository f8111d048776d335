//! What a wheel leaves between two passes.
//!
//! The wheel at a contact point P with tool-side unit normal n and feed
//! direction t is a cylinder of radius R and width W: axis direction
//! a = t × n, centre C = P + R·n. A surface point X with d = X − C lies
//! within the wheel's width when |d·a| ≤ W/2; its clearance is
//! |d − (d·a)·a| − R: positive, the wheel passed that far above X (material
//! left); negative, the wheel reached under the design surface at X.
//!
//! The wheel rolls along its pass, so for X the position that matters is
//! the foot point of X on the pass (where X − P(s) is normal to the pass
//! tangent), found by Newton's method.

use kinpost_surface::Surface;
use nalgebra::Vector3;

/// A contact wheel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WheelShape {
    /// Radius, mm.
    pub radius: f64,
    /// Width, mm.
    pub width: f64,
}

/// A pass as the scallop computation sees it: an iso-parametric curve.
#[derive(Debug, Clone, Copy)]
pub struct PassCurve {
    /// Along u (fixed v = `cross`) or along v (fixed u = `cross`).
    pub along_u: bool,
    /// The fixed parameter.
    pub cross: f64,
    /// The pass parameter range.
    pub s0: f64,
    /// See `s0`.
    pub s1: f64,
    /// +1 or −1: the side of the surface the wheel is on.
    pub side: f64,
}

impl PassCurve {
    /// (u, v) of pass parameter `s`.
    pub fn uv(&self, s: f64) -> (f64, f64) {
        if self.along_u {
            (s, self.cross)
        } else {
            (self.cross, s)
        }
    }

    /// Point, first and second derivative along the pass, and the
    /// tool-side unit normal at `s`.
    pub fn frame(&self, surface: &Surface, s: f64) -> Option<PassFrame> {
        let (u, v) = self.uv(s);
        let d = surface.derivatives(u, v);
        let cross = d.du.cross(&d.dv);
        let len = cross.norm();
        if !(len > 1e-300) {
            return None;
        }
        let (ds, dss) = if self.along_u {
            (d.du, d.duu)
        } else {
            (d.dv, d.dvv)
        };
        if !(ds.norm() > 1e-300) {
            return None;
        }
        Some(PassFrame {
            point: d.point,
            ds,
            dss,
            normal: cross / len * self.side,
        })
    }
}

/// The surface along a pass at one parameter.
#[derive(Debug, Clone, Copy)]
pub struct PassFrame {
    /// The point.
    pub point: Vector3<f64>,
    /// First derivative along the pass.
    pub ds: Vector3<f64>,
    /// Second derivative along the pass.
    pub dss: Vector3<f64>,
    /// Tool-side unit normal.
    pub normal: Vector3<f64>,
}

impl PassFrame {
    /// Unit feed direction (increasing pass parameter).
    pub fn tangent(&self) -> Vector3<f64> {
        self.ds.normalize()
    }
}

/// Clearance of the surface point `x` (tool-side unit normal `n`) to the
/// wheel at a contact frame, measured along `n` (the usual definition of a
/// scallop height): the distance from `x` along `n` to the wheel's
/// cylindrical surface, negative when `x` lies inside the wheel (then the
/// distance back out along −n). `None` where that line misses the wheel or
/// meets it outside its width.
pub fn clearance(
    wheel: WheelShape,
    at: &PassFrame,
    x: &Vector3<f64>,
    n: &Vector3<f64>,
) -> Option<f64> {
    let a = at.tangent().cross(&at.normal);
    let an = a.norm();
    if !(an > 1e-12) {
        return None;
    }
    let a = a / an;
    let centre = at.point + at.normal * wheel.radius;
    let d = x - centre;
    let dp = d - a * d.dot(&a);
    let np = n - a * n.dot(&a);
    // |dp + t·np|² = R²
    let qa = np.dot(&np);
    let qb = dp.dot(&np);
    let qc = dp.dot(&dp) - wheel.radius * wheel.radius;
    let disc = qb * qb - qa * qc;
    if !(qa > 1e-300) || disc < 0.0 {
        return None;
    }
    let root = disc.sqrt();
    // Outside the wheel (qc > 0): the first hit along n; inside: the exit
    // backwards along −n (the root of smaller magnitude).
    let t = if qc > 0.0 {
        let t = (-qb - root) / qa;
        if t < 0.0 {
            return None;
        }
        t
    } else {
        (-qb - root) / qa
    };
    let hit = d + n * t;
    if hit.dot(&a).abs() > wheel.width / 2.0 {
        return None;
    }
    Some(t)
}

/// The foot point of `x` on the pass: the parameter where x − P(s) is
/// normal to the pass, from the start value `s`, kept inside the pass.
pub fn foot_point(
    surface: &Surface,
    pass: &PassCurve,
    x: &Vector3<f64>,
    mut s: f64,
) -> Option<PassFrame> {
    let mut frame = pass.frame(surface, s)?;
    for _ in 0..12 {
        let r = x - frame.point;
        let f = r.dot(&frame.ds);
        let df = -frame.ds.dot(&frame.ds) + r.dot(&frame.dss);
        if df >= 0.0 {
            // Not a minimum of the distance along this Newton step.
            break;
        }
        let next = (s - f / df).clamp(pass.s0, pass.s1);
        let done = (next - s).abs() < 1e-13 * (pass.s1 - pass.s0).abs().max(1e-300);
        s = next;
        frame = pass.frame(surface, s)?;
        if done {
            break;
        }
    }
    Some(frame)
}

/// Scallop and wheel-edge interference between two passes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gap {
    /// Largest material height left between the passes, mm (≥ 0); infinite
    /// where some point between them is reached by neither wheel.
    pub scallop: f64,
    /// Largest depth a wheel reaches under the design surface between the
    /// passes (its edge on a concave section), mm (≥ 0).
    pub interference: f64,
    /// Largest distance between the contact points of the two passes at
    /// the same pass parameter, mm.
    pub stepover: f64,
}

/// Evaluates the gap between passes `a` and `b` (same direction and range)
/// at `samples` pass parameters and `between` surface points across at each.
pub fn gap(
    surface: &Surface,
    wheel: WheelShape,
    a: &PassCurve,
    b: &PassCurve,
    samples: &[f64],
    between: usize,
) -> Gap {
    let mut g = Gap {
        scallop: 0.0,
        interference: 0.0,
        stepover: 0.0,
    };
    for &s in samples {
        let (Some(fa), Some(fb)) = (a.frame(surface, s), b.frame(surface, s)) else {
            g.scallop = f64::INFINITY;
            continue;
        };
        let step = (fa.point - fb.point).norm();
        g.stepover = g.stepover.max(step);
        // The surface point a fraction `q` of the way from pass `a` to
        // pass `b` (across, at the same `s`), and its clearance to a wheel.
        let point_at = |q: f64| {
            let cross = a.cross + (b.cross - a.cross) * q;
            PassCurve { cross, ..*a }.frame(surface, s)
        };
        let clearance_to = |pass: &PassCurve, x: &PassFrame| {
            let f = foot_point(surface, pass, &x.point, s)?;
            clearance(wheel, &f, &x.point, &x.normal)
        };
        for k in 1..=between {
            let Some(x) = point_at(k as f64 / (between + 1) as f64) else {
                continue;
            };
            let (ca, cb) = (clearance_to(a, &x), clearance_to(b, &x));
            let left = match (ca, cb) {
                (Some(p), Some(q)) => p.min(q),
                (Some(p), None) | (None, Some(p)) => p,
                (None, None) => f64::INFINITY,
            };
            g.scallop = g.scallop.max(left.max(0.0));
            for c in [ca, cb].into_iter().flatten() {
                g.interference = g.interference.max(-c);
            }
        }
        // A wheel's edges reach half its width from its contact point:
        // beyond the neighbouring pass when the step is smaller. Each
        // wheel's interference is also looked for out to its edges, both
        // sides (a fixed number of points, the edges themselves included;
        // the scallop only between the passes).
        let reach = if step > 0.0 {
            0.5 * wheel.width / step
        } else {
            0.0
        };
        if reach > 0.0 && reach.is_finite() {
            let out = between / 2 + 1;
            // Evenly out to the edge, and just inside it: the reach counts
            // the step as a chord, the points lie along the surface, so the
            // last one may fall outside the width.
            let edge = [0.995, 0.98, 0.95].map(|f| f * reach);
            let even = (1..=out).map(|k| reach * k as f64 / out as f64);
            for t in even.chain(edge) {
                for (q, pass) in [(-t, a), (t, a), (1.0 - t, b), (1.0 + t, b)] {
                    if let Some(c) = point_at(q).and_then(|x| clearance_to(pass, &x)) {
                        g.interference = g.interference.max(-c);
                    }
                }
            }
        }
    }
    g
}
