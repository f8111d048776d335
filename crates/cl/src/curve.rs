//! Curves of CL motion: circular arcs and helices (`CIRCLE/`) and rational
//! B-spline curves (`NURBS/`), with the points a post needs to follow them
//! within a chord tolerance.
//!
//! Everything here is pure geometry in mm and radians; the reader
//! ([`ClReader`](crate::ClReader)) turns statements into the inputs.
//!
//! # Arcs
//!
//! An [`Arc`] runs from a start point to an end point about an axis through
//! a centre, **counter-clockwise about the axis** (right-hand rule: with the
//! thumb along the axis, the fingers point the way the tool moves). The start
//! and end need not lie in the plane of the centre: their offset along the
//! axis is the rise of a helix, and the radius is measured in the plane
//! perpendicular to the axis. When start and end coincide (seen along the
//! axis) the arc is a full circle. `turns` adds whole turns: the end is
//! reached for the `turns`-th time.
//!
//! # Chord tolerance
//!
//! [`Arc::sample`] and [`Nurbs::sample`] return points such that the straight
//! segments between consecutive points (starting at the start point) stay
//! within `tolerance_mm` of the curve. For an arc the chord error of an angle
//! `δ` is the sagitta `r (1 − cos(δ/2))`, exactly; for a helix the same
//! bound holds (the rise is linear in the angle, as along the chord). For a
//! NURBS curve the sampler subdivides until the distance of the curve's
//! midpoint (and quarter points) from each chord is within the tolerance,
//! with a floor of segments per knot span so that no span is skipped.

use std::f64::consts::{PI, TAU};

use thiserror::Error;

use crate::Vec3;
use crate::vector::{add, cross, dot, norm, scale, sub};

/// The chord (mm) between start and end, seen along the axis, below which an
/// arc is a full circle rather than a vanishing one: CAM systems write the
/// end of a full circle with the start's digits, and a few thousandths of a
/// mm of rounding must not turn a full circle into no motion at all. No CAM
/// system writes an arc of 1 µm as a `CIRCLE`.
pub const FULL_CIRCLE_CHORD_MM: f64 = 1e-3;

/// How far (mm) the end point may be from the circle through the start point
/// (radii measured from the axis): CL files carry 4 to 6 decimals; a larger
/// difference means the statement is not an arc about that centre (or the
/// axis was read the wrong way), and following it would cut elsewhere.
pub const ARC_RADIUS_TOLERANCE_MM: f64 = 0.01;

/// The smallest radius (mm) of an arc: a start point on the axis has no
/// direction to turn about.
pub const MIN_ARC_RADIUS_MM: f64 = 1e-6;

/// Why an arc cannot be built.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ArcError {
    /// A coordinate or the axis is not finite.
    #[error("the arc's data are not finite numbers")]
    NotFinite,
    /// The axis is (nearly) zero.
    #[error("the arc's axis is a zero vector")]
    ZeroAxis,
    /// The start point lies on the axis.
    #[error("the arc's start point is on its axis (radius {radius_mm:.6} mm)")]
    StartOnAxis {
        /// Distance of the start point from the axis.
        radius_mm: f64,
    },
    /// The end point is not on the circle through the start point.
    #[error(
        "the arc's end point is {end_radius_mm:.4} mm from the axis, the start point {start_radius_mm:.4} mm: not on one circle (tolerance {ARC_RADIUS_TOLERANCE_MM} mm)"
    )]
    EndOffCircle {
        /// Radius at the start point.
        start_radius_mm: f64,
        /// Radius at the end point.
        end_radius_mm: f64,
    },
    /// `turns` is zero.
    #[error("an arc makes at least one turn (TIMES must be 1 or more)")]
    NoTurns,
    /// `turns` is more than [`MAX_ARC_TURNS`].
    #[error("an arc of {turns} turns: at most {MAX_ARC_TURNS} are read")]
    TooManyTurns {
        /// The turns asked for.
        turns: u32,
    },
}

/// The most turns an arc may make (NX `TIMES`): a thread-milling helix
/// makes a few dozen; a number beyond this is a corrupt record, and its
/// sampling would fill memory.
pub const MAX_ARC_TURNS: u32 = 1000;

/// The most points one curve is sampled into: a tolerance that needs more
/// is far below any machine's resolution (a mistake), refused rather than
/// filling memory.
pub const MAX_SAMPLE_POINTS: usize = 1 << 20;

/// Why a curve cannot be sampled.
#[derive(Debug, Clone, Copy, PartialEq, Error)]
pub enum SampleError {
    /// The tolerance is not a positive finite length.
    #[error("the chord tolerance must be a positive finite length, got {0}")]
    Tolerance(f64),
    /// The tolerance asks for more than [`MAX_SAMPLE_POINTS`] points.
    #[error(
        "the chord tolerance {tolerance_mm} mm needs more than {MAX_SAMPLE_POINTS} points for one curve"
    )]
    TooManyPoints {
        /// The tolerance asked for.
        tolerance_mm: f64,
    },
}

/// A circular arc or helix between two points; see the [module](self) docs.
#[derive(Debug, Clone, PartialEq)]
pub struct Arc {
    start: Vec3,
    end: Vec3,
    /// The centre, in the plane of the start point (perpendicular to the axis).
    centre: Vec3,
    /// Unit axis; the motion is counter-clockwise about it.
    axis: Vec3,
    /// Unit vector from the centre to the start point.
    u: Vec3,
    /// `axis × u`.
    v: Vec3,
    start_radius: f64,
    end_radius: f64,
    sweep: f64,
    rise: f64,
}

impl Arc {
    /// The arc from `start` to `end` counter-clockwise about `axis` (need
    /// not be unit length) through `centre`, ending on the `turns`-th
    /// arrival at `end` (1 for a plain arc).
    pub fn new(
        start: Vec3,
        end: Vec3,
        centre: Vec3,
        axis: Vec3,
        turns: u32,
    ) -> Result<Arc, ArcError> {
        let all = start.iter().chain(&end).chain(&centre).chain(&axis);
        if !all.clone().all(|v| v.is_finite()) {
            return Err(ArcError::NotFinite);
        }
        if turns == 0 {
            return Err(ArcError::NoTurns);
        }
        if turns > MAX_ARC_TURNS {
            return Err(ArcError::TooManyTurns { turns });
        }
        let n = norm(axis);
        // (The inputs are finite here: `n` is not NaN.)
        if n <= 1e-12 {
            return Err(ArcError::ZeroAxis);
        }
        let axis = scale(axis, 1.0 / n);
        // Offsets from the centre, split along and across the axis.
        let ds = sub(start, centre);
        let de = sub(end, centre);
        let hs = dot(ds, axis);
        let he = dot(de, axis);
        let ps = sub(ds, scale(axis, hs));
        let pe = sub(de, scale(axis, he));
        let start_radius = norm(ps);
        let end_radius = norm(pe);
        if start_radius <= MIN_ARC_RADIUS_MM {
            return Err(ArcError::StartOnAxis {
                radius_mm: start_radius,
            });
        }
        if (end_radius - start_radius).abs() > ARC_RADIUS_TOLERANCE_MM {
            return Err(ArcError::EndOffCircle {
                start_radius_mm: start_radius,
                end_radius_mm: end_radius,
            });
        }
        let u = scale(ps, 1.0 / start_radius);
        let v = cross(axis, u);
        // The angle from start to end about the axis, in (0, 2π].
        let mut angle = dot(cross(ps, pe), axis).atan2(dot(ps, pe));
        if angle < 0.0 {
            angle += TAU;
        }
        let chord = norm(sub(pe, ps));
        if chord < FULL_CIRCLE_CHORD_MM {
            angle = TAU;
        } else if angle == 0.0 {
            // Exactly opposite rounding: a point past the start.
            angle = TAU;
        }
        let sweep = angle + TAU * f64::from(turns - 1);
        Ok(Arc {
            start,
            end,
            centre: add(centre, scale(axis, hs)),
            axis,
            u,
            v,
            start_radius,
            end_radius,
            sweep,
            rise: he - hs,
        })
    }

    /// The start point, as given.
    pub fn start(&self) -> Vec3 {
        self.start
    }

    /// The end point, as given.
    pub fn end(&self) -> Vec3 {
        self.end
    }

    /// The centre, moved along the axis into the plane of the start point.
    pub fn centre(&self) -> Vec3 {
        self.centre
    }

    /// The unit axis (the motion is counter-clockwise about it).
    pub fn axis(&self) -> Vec3 {
        self.axis
    }

    /// The radius at the start point (mm).
    pub fn radius_mm(&self) -> f64 {
        self.start_radius
    }

    /// The angle swept (radians, positive, up to `2π · turns`).
    pub fn sweep_rad(&self) -> f64 {
        self.sweep
    }

    /// The displacement along the axis from start to end (mm; zero for a
    /// plane arc, the helix's rise otherwise).
    pub fn rise_mm(&self) -> f64 {
        self.rise
    }

    /// Whether start and end differ along the axis by more than 1 µm.
    pub fn is_helix(&self) -> bool {
        self.rise.abs() > 1e-3
    }

    /// The length of the path (mm).
    pub fn length_mm(&self) -> f64 {
        let r = 0.5 * (self.start_radius + self.end_radius);
        (r * self.sweep).hypot(self.rise)
    }

    /// The point at parameter `t` (0 = start, 1 = end; clamped to [0, 1]):
    /// the angle, the rise and the radius (which may differ by rounding
    /// between start and end) change in proportion to `t`. `t = 1` gives the
    /// end point exactly.
    pub fn point_at(&self, t: f64) -> Vec3 {
        let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
        if t == 0.0 {
            return self.start;
        }
        if t == 1.0 {
            return self.end;
        }
        let (s, c) = (self.sweep * t).sin_cos();
        let r = self.start_radius + (self.end_radius - self.start_radius) * t;
        let radial = add(scale(self.u, r * c), scale(self.v, r * s));
        add(add(self.centre, radial), scale(self.axis, self.rise * t))
    }

    /// The unit tangent (direction of motion) at parameter `t`.
    pub fn tangent_at(&self, t: f64) -> Vec3 {
        let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
        let (s, c) = (self.sweep * t).sin_cos();
        let r = self.start_radius + (self.end_radius - self.start_radius) * t;
        // d/dt of the point: the turning part plus the rise.
        let turning = add(scale(self.u, -r * s), scale(self.v, r * c));
        let d = add(scale(turning, self.sweep), scale(self.axis, self.rise));
        scale(d, 1.0 / norm(d))
    }

    /// The number of chords whose sagitta stays within `tolerance_mm`.
    pub fn segments(&self, tolerance_mm: f64) -> Result<usize, SampleError> {
        check_tolerance(tolerance_mm)?;
        let r = self.start_radius.max(self.end_radius);
        // The largest angle whose sagitta r (1 − cos(δ/2)) is the tolerance;
        // at most a half turn, so that no chord crosses the centre.
        let max_angle = if tolerance_mm >= r {
            PI
        } else {
            (2.0 * (1.0 - tolerance_mm / r).acos()).min(PI)
        };
        // (A tolerance far below the radius's rounding would ask for
        // billions of points: at least 1e-9 of the radius per chord.)
        let max_angle = max_angle.max(2.0 * (1.0 - 1e-9_f64).acos());
        let n = (self.sweep / max_angle).ceil();
        if n > MAX_SAMPLE_POINTS as f64 {
            return Err(SampleError::TooManyPoints { tolerance_mm });
        }
        Ok((n as usize).max(1))
    }

    /// Points along the arc after the start, the last being the end, such
    /// that the chords from the start point through them stay within
    /// `tolerance_mm` of the arc (equal angles).
    pub fn sample(&self, tolerance_mm: f64) -> Result<Vec<Vec3>, SampleError> {
        let n = self.segments(tolerance_mm)?;
        Ok((1..=n)
            .map(|k| self.point_at(k as f64 / n as f64))
            .collect())
    }
}

fn check_tolerance(tolerance_mm: f64) -> Result<(), SampleError> {
    if tolerance_mm.is_finite() && tolerance_mm > 0.0 {
        Ok(())
    } else {
        Err(SampleError::Tolerance(tolerance_mm))
    }
}

/// Why a NURBS curve cannot be built.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum NurbsError {
    /// The degree is zero.
    #[error("the degree of a NURBS curve must be 1 or more")]
    ZeroDegree,
    /// Too few control points for the degree.
    #[error("a NURBS curve of degree {degree} needs at least {} control points, got {points}", degree + 1)]
    TooFewPoints {
        /// The degree.
        degree: usize,
        /// Control points given.
        points: usize,
    },
    /// The knot vector has the wrong length.
    #[error("a NURBS curve of degree {degree} with {points} control points needs {} knots, got {knots}", points + degree + 1)]
    KnotCount {
        /// The degree.
        degree: usize,
        /// Control points given.
        points: usize,
        /// Knots given.
        knots: usize,
    },
    /// The knots decrease somewhere.
    #[error("the knots must not decrease: knot {index} is {value} after {previous}")]
    KnotsDecrease {
        /// 0-based index of the offending knot.
        index: usize,
        /// Its value.
        value: f64,
        /// The knot before it.
        previous: f64,
    },
    /// The curve's parameter domain is empty.
    #[error("the knots span no parameter range")]
    EmptyDomain,
    /// Weights and control points differ in number.
    #[error("{weights} weights for {points} control points")]
    WeightCount {
        /// Weights given.
        weights: usize,
        /// Control points given.
        points: usize,
    },
    /// A weight is zero, negative or not finite.
    #[error("the weight of control point {index} is {weight}: weights must be positive")]
    BadWeight {
        /// 0-based control point index.
        index: usize,
        /// The weight.
        weight: f64,
    },
    /// A number is not finite.
    #[error("a knot or control point is not a finite number")]
    NotFinite,
}

/// A rational B-spline curve in 3-D: degree, knot vector, control points and
/// weights (all 1 for a polynomial B-spline). Evaluated by de Boor's
/// algorithm on homogeneous coordinates (Piegl & Tiller, *The NURBS Book*,
/// §4.2, algorithm A4.1).
#[derive(Debug, Clone, PartialEq)]
pub struct Nurbs {
    degree: usize,
    knots: Vec<f64>,
    points: Vec<Vec3>,
    weights: Vec<f64>,
}

impl Nurbs {
    /// The same curve with every control point mapped by `f` (an affine
    /// map, a change of frame: the curve maps with its control points).
    pub fn map_points(&self, f: impl Fn(Vec3) -> Vec3) -> Nurbs {
        Nurbs {
            points: self.points.iter().map(|&p| f(p)).collect(),
            ..self.clone()
        }
    }

    /// A curve of `degree` with `knots` (`points.len() + degree + 1` of them,
    /// not decreasing), `points` and their `weights` (positive).
    pub fn new(
        degree: usize,
        knots: Vec<f64>,
        points: Vec<Vec3>,
        weights: Vec<f64>,
    ) -> Result<Nurbs, NurbsError> {
        if degree == 0 {
            return Err(NurbsError::ZeroDegree);
        }
        if points.len() < degree + 1 {
            return Err(NurbsError::TooFewPoints {
                degree,
                points: points.len(),
            });
        }
        if knots.len() != points.len() + degree + 1 {
            return Err(NurbsError::KnotCount {
                degree,
                points: points.len(),
                knots: knots.len(),
            });
        }
        if weights.len() != points.len() {
            return Err(NurbsError::WeightCount {
                weights: weights.len(),
                points: points.len(),
            });
        }
        if !knots.iter().all(|k| k.is_finite()) || !points.iter().flatten().all(|v| v.is_finite()) {
            return Err(NurbsError::NotFinite);
        }
        for (index, w) in knots.windows(2).enumerate() {
            if w[1] < w[0] {
                return Err(NurbsError::KnotsDecrease {
                    index: index + 1,
                    value: w[1],
                    previous: w[0],
                });
            }
        }
        for (index, &weight) in weights.iter().enumerate() {
            if !(weight.is_finite() && weight > 0.0) {
                return Err(NurbsError::BadWeight { index, weight });
            }
        }
        let n = points.len();
        if knots[n] <= knots[degree] {
            return Err(NurbsError::EmptyDomain);
        }
        Ok(Nurbs {
            degree,
            knots,
            points,
            weights,
        })
    }

    /// The degree.
    pub fn degree(&self) -> usize {
        self.degree
    }

    /// The knot vector.
    pub fn knots(&self) -> &[f64] {
        &self.knots
    }

    /// The control points (mm).
    pub fn points(&self) -> &[Vec3] {
        &self.points
    }

    /// The weights.
    pub fn weights(&self) -> &[f64] {
        &self.weights
    }

    /// The parameter range `[u_p, u_n]` the curve is defined on.
    pub fn domain(&self) -> (f64, f64) {
        (self.knots[self.degree], self.knots[self.points.len()])
    }

    /// The knot span `i` (p ≤ i < n) with `u_i ≤ u < u_{i+1}`; the last
    /// non-empty span at the end of the domain.
    fn span(&self, u: f64) -> usize {
        let p = self.degree;
        let n = self.points.len();
        if u >= self.knots[n] {
            // The last span with u_i < u_{i+1}.
            let mut i = n - 1;
            while i > p && self.knots[i] >= self.knots[n] {
                i -= 1;
            }
            return i;
        }
        // Binary search in [p, n): the largest i with u_i <= u.
        let (mut lo, mut hi) = (p, n);
        while hi - lo > 1 {
            let mid = (lo + hi) / 2;
            if self.knots[mid] <= u {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    }

    /// The point at parameter `u` (clamped to the domain).
    pub fn point_at(&self, u: f64) -> Vec3 {
        let (a, b) = self.domain();
        let u = if u.is_nan() { a } else { u.clamp(a, b) };
        let p = self.degree;
        let k = self.span(u);
        // Homogeneous control points of the span: (w x, w y, w z, w).
        let mut d: Vec<[f64; 4]> = (0..=p)
            .map(|j| {
                let i = k - p + j;
                let w = self.weights[i];
                let q = self.points[i];
                [w * q[0], w * q[1], w * q[2], w]
            })
            .collect();
        for r in 1..=p {
            for j in (r..=p).rev() {
                let i = k - p + j;
                let denom = self.knots[i + p + 1 - r] - self.knots[i];
                let alpha = if denom > 0.0 {
                    (u - self.knots[i]) / denom
                } else {
                    0.0
                };
                let lower = d[j - 1];
                for (c, v) in d[j].iter_mut().enumerate() {
                    *v = (1.0 - alpha) * lower[c] + alpha * *v;
                }
            }
        }
        let h = d[p];
        [h[0] / h[3], h[1] / h[3], h[2] / h[3]]
    }

    /// Points along the curve after its start, the last being its end, such
    /// that chords from the start point through them stay within
    /// `tolerance_mm` of the curve: each knot span is cut in at least
    /// `2 · degree` equal parameter steps, and a step is halved while the
    /// curve at its quarter, middle or three-quarter parameter lies farther
    /// than the tolerance from the chord (a check at three parameters of
    /// each chord, not a bound; at most 2¹⁶ chords a step, at most
    /// [`MAX_SAMPLE_POINTS`] in all).
    pub fn sample(&self, tolerance_mm: f64) -> Result<Vec<Vec3>, SampleError> {
        check_tolerance(tolerance_mm)?;
        let mut out = Vec::new();
        let n = self.points.len();
        let floor = 2 * self.degree;
        for i in self.degree..n {
            let (a, b) = (self.knots[i], self.knots[i + 1]);
            if b <= a {
                continue;
            }
            for s in 0..floor {
                let u0 = a + (b - a) * s as f64 / floor as f64;
                let u1 = a + (b - a) * (s + 1) as f64 / floor as f64;
                self.subdivide(u0, u1, tolerance_mm, 16, &mut out);
                if out.len() > MAX_SAMPLE_POINTS {
                    return Err(SampleError::TooManyPoints { tolerance_mm });
                }
            }
        }
        Ok(out)
    }

    /// Appends the points after `u0` up to `u1`.
    fn subdivide(&self, u0: f64, u1: f64, tolerance: f64, depth: u32, out: &mut Vec<Vec3>) {
        let p0 = self.point_at(u0);
        let p1 = self.point_at(u1);
        let ok = [0.25, 0.5, 0.75].iter().all(|&f| {
            let q = self.point_at(u0 + (u1 - u0) * f);
            distance_to_segment(q, p0, p1) <= tolerance
        });
        if ok || depth == 0 {
            out.push(p1);
        } else {
            let um = 0.5 * (u0 + u1);
            self.subdivide(u0, um, tolerance, depth - 1, out);
            self.subdivide(um, u1, tolerance, depth - 1, out);
        }
    }
}

/// The distance from `q` to the segment `a`–`b`.
pub fn distance_to_segment(q: Vec3, a: Vec3, b: Vec3) -> f64 {
    let ab = sub(b, a);
    let l2 = dot(ab, ab);
    let t = if l2 > 0.0 {
        (dot(sub(q, a), ab) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    norm(sub(q, add(a, scale(ab, t))))
}

#[cfg(test)]
mod tests;
