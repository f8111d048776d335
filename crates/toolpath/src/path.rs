//! Planning the passes: where they lie, where their CL points are.

use kinpost_surface::Surface;
use nalgebra::{Isometry3, Vector3};

use crate::scallop::{Gap, PassCurve, PassFrame, WheelShape, gap};

/// The contact wheel.
pub type Wheel = WheelShape;

/// Which way the passes run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// Along u (v fixed per pass), stepping across in v.
    U,
    /// Along v (u fixed per pass), stepping across in u.
    V,
}

/// Which side of the surface the wheel is on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    /// The side of r_u × r_v.
    Plus,
    /// The other side.
    Minus,
}

/// How far apart the passes are.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Spacing {
    /// Largest distance between neighbouring passes' contact points, mm.
    Stepover(f64),
    /// Largest scallop height left between passes, mm (the step-over is
    /// also held to W·(1 − overlap)).
    Scallop(f64),
    /// Step-over W·(1 − overlap), overlap a fraction in [0, 1).
    Overlap(f64),
}

/// Everything `plan` needs.
#[derive(Debug, Clone)]
pub struct PathOptions {
    /// The contact wheel.
    pub wheel: Wheel,
    /// Passes along u or v.
    pub direction: Direction,
    /// The side of the surface the wheel is on.
    pub side: Side,
    /// How far apart the passes are.
    pub spacing: Spacing,
    /// Overlap used to cap the step-over in [`Spacing::Scallop`] mode.
    pub overlap: f64,
    /// Largest deviation between a CL segment and the surface, mm.
    pub chord_tolerance: f64,
    /// Largest turn of the tool axis between CL points, degrees.
    pub max_angle_deg: f64,
    /// Lead-in / lead-out distance along the normal, mm.
    pub lead: f64,
    /// Part of the parameter domain to grind: u0, u1, v0, v1 as fractions
    /// of the domain.
    pub region: [f64; 4],
    /// Placement of the surface in the CL (part) frame.
    pub placement: Isometry3<f64>,
}

impl Default for PathOptions {
    fn default() -> Self {
        PathOptions {
            wheel: Wheel {
                radius: 50.0,
                width: 20.0,
            },
            direction: Direction::U,
            side: Side::Plus,
            spacing: Spacing::Overlap(0.5),
            overlap: 0.5,
            chord_tolerance: 0.01,
            max_angle_deg: 2.0,
            lead: 5.0,
            region: [0.0, 1.0, 0.0, 1.0],
            placement: Isometry3::identity(),
        }
    }
}

/// Why no path can be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PathError {
    /// An option value that cannot be used (the message says which).
    #[error("{0}")]
    Options(String),
    /// The surface has no normal here.
    #[error("the surface is degenerate (no normal) at u = {u:.6}, v = {v:.6}")]
    Degenerate {
        /// Parameter u.
        u: f64,
        /// Parameter v.
        v: f64,
    },
    /// The options ask for more passes or CL points than a path may have,
    /// found before the work is done.
    #[error(
        "the path would need about {points} CL points ({passes} passes of about {per_pass} points) \
         for a chord tolerance of {chord_tolerance_mm} mm and a largest tool-axis turn of \
         {max_angle_deg}°: more than {limit}; loosen them"
    )]
    TooManyPoints {
        /// CL points needed, about.
        points: f64,
        /// Passes.
        passes: usize,
        /// CL points a pass, about.
        per_pass: f64,
        /// The chord tolerance asked for, mm.
        chord_tolerance_mm: f64,
        /// The largest turn asked for, degrees.
        max_angle_deg: f64,
        /// The most a path may have.
        limit: usize,
    },
    /// The step-over asks for more passes than a path may have.
    #[error(
        "the path would need about {passes} passes (a surface {cross_mm:.3} mm across at a \
         step-over of {stepover_mm} mm): more than {limit}"
    )]
    TooManyPasses {
        /// Passes needed, about.
        passes: f64,
        /// The surface's width across the passes, mm.
        cross_mm: f64,
        /// The step-over, mm.
        stepover_mm: f64,
        /// The most a path may have.
        limit: usize,
    },
    /// No step-over after a pass meets the scallop or overlap asked for.
    #[error(
        "no step-over meets the {what} after the pass at {cross:.6}: the wheel (width {width} mm) cannot cover the surface there"
    )]
    NoStep {
        /// What is asked for (`scallop height`, …).
        what: &'static str,
        /// The pass's fixed parameter.
        cross: f64,
        /// The wheel's width, mm.
        width: f64,
    },
}

/// One CL point on the surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactPoint {
    /// Parameter u.
    pub u: f64,
    /// Parameter v.
    pub v: f64,
    /// Contact point, surface coordinates.
    pub point: Vector3<f64>,
    /// Tool-side unit normal (the CL tool axis).
    pub axis: Vector3<f64>,
    /// Unit feed direction of the passes (the CL tool reference): the
    /// direction of increasing pass parameter, the same on zig and zag
    /// passes (a wheel runs both ways; turning the head 180° between
    /// passes would gain nothing).
    pub reference: Vector3<f64>,
}

/// One pass, in the order the wheel travels it.
#[derive(Debug, Clone, PartialEq)]
pub struct Pass {
    /// The fixed parameter (v for passes along u, u for passes along v).
    pub cross: f64,
    /// Its CL points.
    pub points: Vec<ContactPoint>,
}

/// What was planned, for the user.
#[derive(Debug, Clone, PartialEq)]
pub struct Report {
    /// Passes.
    pub passes: usize,
    /// CL points on the surface.
    pub points: usize,
    /// Length of the feed moves on the surface (without leads), mm.
    pub length_mm: f64,
    /// Per gap between neighbouring passes.
    pub gaps: Vec<Gap>,
    /// Largest scallop over all gaps, mm.
    pub scallop_max: f64,
    /// Largest wheel-edge interference, mm.
    pub interference_max: f64,
    /// Smallest and largest step-over, mm.
    pub stepover_min: f64,
    /// See `stepover_min`.
    pub stepover_max: f64,
    /// Largest deviation of a CL segment from the surface (checked at
    /// quarter points), mm.
    pub chord_error_max: f64,
    /// Smallest concave radius of the surface along the feed (where it
    /// bends towards the wheel), mm; a wheel of larger radius cuts in there.
    pub concave_feed_radius_min: Option<f64>,
}

/// The planned path.
#[derive(Debug, Clone, PartialEq)]
pub struct Toolpath {
    /// The passes in the order the wheel travels them.
    pub passes: Vec<Pass>,
    /// What was planned.
    pub report: Report,
}

fn check(ok: bool, msg: &str) -> Result<(), PathError> {
    if ok {
        Ok(())
    } else {
        Err(PathError::Options(msg.to_string()))
    }
}

fn positive(v: f64) -> bool {
    v.is_finite() && v > 0.0
}

impl PathOptions {
    fn validate(&self) -> Result<(), PathError> {
        check(
            positive(self.wheel.radius),
            "the wheel radius must be a positive number of mm",
        )?;
        check(
            positive(self.wheel.width),
            "the wheel width must be a positive number of mm",
        )?;
        check(
            positive(self.chord_tolerance) && self.chord_tolerance >= MIN_CHORD_TOLERANCE_MM,
            "the chord tolerance must be a number of mm from 1e-6 (1 nm: finer is below what a \
             machine moves and what the chord check can tell from rounding)",
        )?;
        check(
            positive(self.max_angle_deg) && self.max_angle_deg <= 90.0,
            "the largest tool-axis turn must be between 0 and 90 degrees",
        )?;
        check(
            self.lead.is_finite() && self.lead >= 0.0,
            "the lead must be a number of mm ≥ 0",
        )?;
        check(
            (0.0..1.0).contains(&self.overlap),
            "the overlap must be a fraction from 0 to below 1",
        )?;
        match self.spacing {
            Spacing::Stepover(s) => {
                check(positive(s), "the step-over must be a positive number of mm")?;
                check(
                    s <= self.wheel.width,
                    "the step-over is larger than the wheel width: strips between the passes would not be ground",
                )?;
            }
            Spacing::Scallop(h) => check(
                positive(h) && h >= MIN_CHORD_TOLERANCE_MM,
                "the scallop height must be a number of mm from 1e-6 (1 nm)",
            )?,
            Spacing::Overlap(o) => check(
                (0.0..1.0).contains(&o),
                "the overlap must be a fraction from 0 to below 1",
            )?,
        }
        let [u0, u1, v0, v1] = self.region;
        check(
            self.region.iter().all(|r| (0.0..=1.0).contains(r)) && u0 < u1 && v0 < v1,
            "the region must be u0,u1,v0,v1 with 0 ≤ u0 < u1 ≤ 1 and 0 ≤ v0 < v1 ≤ 1",
        )
    }
}

/// The finest chord tolerance: 1 nm. Below it the deviation of a chord
/// is lost in the rounding of the points (a pass would be cut into steps
/// of 1e-12 of its length until the point cap), and no machine moves so
/// finely.
pub const MIN_CHORD_TOLERANCE_MM: f64 = 1e-6;

/// The most passes a path may have.
pub const MAX_PASSES: usize = 100_000;

/// The most CL points a path may have, all passes together: 20 million
/// points, a CL file of about 1.5 GB.
pub const MAX_PATH_POINTS: usize = 20_000_000;

/// Samples per estimated pass or cross line (see [`estimate_points`]).
const ESTIMATE_SAMPLES: usize = 128;

/// The length of the surface across the passes (the largest of a few
/// lines at fixed pass parameter), for the number of passes a step-over
/// asks for.
fn cross_length(surface: &Surface, along_u: bool, s: (f64, f64), c: (f64, f64)) -> f64 {
    let mut longest = 0.0f64;
    for a in 0..=8 {
        let sp = s.0 + (s.1 - s.0) * f64::from(a) / 8.0;
        let at = |k: usize| {
            let cp = c.0 + (c.1 - c.0) * k as f64 / ESTIMATE_SAMPLES as f64;
            let (u, v) = if along_u { (sp, cp) } else { (cp, sp) };
            surface.point(u, v)
        };
        let length: f64 = (0..ESTIMATE_SAMPLES)
            .map(|k| (at(k + 1) - at(k)).norm())
            .sum();
        longest = longest.max(length);
    }
    longest
}

/// About how many CL points [`sample_pass`] takes on pass `pc`: along
/// each of [`ESTIMATE_SAMPLES`] pieces, the more of its length over the
/// chord step the curvature allows (√(8·tol/κ)) and its turn over the
/// largest turn, and at least the four steps a pass always has.
fn estimate_pass_points(surface: &Surface, pc: &PassCurve, options: &PathOptions) -> f64 {
    let tol = options.chord_tolerance;
    let max_angle = options.max_angle_deg.to_radians();
    let frames: Vec<PassFrame> = (0..=ESTIMATE_SAMPLES)
        .filter_map(|k| {
            let s = pc.s0 + (pc.s1 - pc.s0) * k as f64 / ESTIMATE_SAMPLES as f64;
            pc.frame(surface, s)
        })
        .collect();
    let steps: f64 = frames
        .windows(2)
        .map(|w| {
            let length = (w[1].point - w[0].point).norm();
            let speed = w[0].ds.norm();
            let kappa = if speed > 0.0 {
                w[0].ds.cross(&w[0].dss).norm() / speed.powi(3)
            } else {
                0.0
            };
            let by_chord = length * (kappa / (8.0 * tol)).sqrt();
            let by_turn = w[0].normal.angle(&w[1].normal) / max_angle;
            by_chord.max(by_turn)
        })
        .sum();
    steps.max(4.0) + 1.0
}

/// About how many CL points the passes at `crosses` take (a few passes
/// sampled, scaled to all): refused past [`MAX_PATH_POINTS`] before any
/// pass is sampled point by point.
fn check_point_count(
    surface: &Surface,
    options: &PathOptions,
    crosses: &[f64],
    curve: &dyn Fn(f64) -> PassCurve,
) -> Result<(), PathError> {
    let stride = crosses.len().div_ceil(17).max(1);
    let sampled: Vec<f64> = crosses
        .iter()
        .step_by(stride)
        .map(|&c| estimate_pass_points(surface, &curve(c), options))
        .collect();
    let per_pass = sampled.iter().sum::<f64>() / sampled.len().max(1) as f64;
    let points = per_pass * crosses.len() as f64;
    if points > MAX_PATH_POINTS as f64 {
        return Err(PathError::TooManyPoints {
            points: points.round(),
            passes: crosses.len(),
            per_pass: per_pass.round(),
            chord_tolerance_mm: options.chord_tolerance,
            max_angle_deg: options.max_angle_deg,
            limit: MAX_PATH_POINTS,
        });
    }
    Ok(())
}

/// Number of pass parameters sampled when choosing the next pass.
const SEARCH_SAMPLES: usize = 24;
/// Surface points between two passes when choosing the next pass.
const SEARCH_BETWEEN: usize = 5;
/// … and in the final report.
const REPORT_BETWEEN: usize = 9;

/// Plans the passes on `surface`.
pub fn plan(surface: &Surface, options: &PathOptions) -> Result<Toolpath, PathError> {
    options.validate()?;
    let (u0, u1) = surface.u_range();
    let (v0, v1) = surface.v_range();
    let [ru0, ru1, rv0, rv1] = options.region;
    let (pu0, pu1) = (u0 + (u1 - u0) * ru0, u0 + (u1 - u0) * ru1);
    let (pv0, pv1) = (v0 + (v1 - v0) * rv0, v0 + (v1 - v0) * rv1);
    let along_u = options.direction == Direction::U;
    let (s0, s1, c0, c1) = if along_u {
        (pu0, pu1, pv0, pv1)
    } else {
        (pv0, pv1, pu0, pu1)
    };
    let side = match options.side {
        Side::Plus => 1.0,
        Side::Minus => -1.0,
    };
    let curve = |cross: f64| PassCurve {
        along_u,
        cross,
        s0,
        s1,
        side,
    };
    let wheel = options.wheel;
    let samples: Vec<f64> = (0..=SEARCH_SAMPLES)
        .map(|k| s0 + (s1 - s0) * k as f64 / SEARCH_SAMPLES as f64)
        .collect();
    let cap = wheel.width * (1.0 - options.overlap);
    let (limit_stepover, limit_scallop, what) = match options.spacing {
        Spacing::Stepover(s) => (s, None, "step-over"),
        Spacing::Overlap(o) => (wheel.width * (1.0 - o), None, "step-over"),
        Spacing::Scallop(h) => (cap, Some(h), "scallop height"),
    };
    let fits = |a: f64, b: f64, between: usize, samples: &[f64]| -> bool {
        let g = gap(surface, wheel, &curve(a), &curve(b), samples, between);
        // (1 + 1e-9): a limit met exactly by the last pass is met.
        g.stepover <= limit_stepover * (1.0 + 1e-9)
            && g.scallop.is_finite()
            && limit_scallop.is_none_or(|h| g.scallop <= 0.9 * h)
    };

    // A step-over that would lay more passes than a path may have is
    // refused before the search (which would take long to find out).
    if !matches!(options.spacing, Spacing::Scallop(_)) {
        let across = cross_length(surface, along_u, (s0, s1), (c0, c1));
        let passes = across / limit_stepover + 1.0;
        if passes > MAX_PASSES as f64 {
            return Err(PathError::TooManyPasses {
                passes: passes.round(),
                cross_mm: across,
                stepover_mm: limit_stepover,
                limit: MAX_PASSES,
            });
        }
    }
    // A scallop height that even passes 1/MAX_PASSES of the surface apart
    // exceed somewhere needs more passes than a path may have: refused
    // before the search.
    if let Spacing::Scallop(h) = options.spacing {
        let step = (c1 - c0) / MAX_PASSES as f64;
        for k in 0..=8 {
            let c = c0 + (c1 - c0 - step) * f64::from(k) / 8.0;
            if !fits(c, c + step, SEARCH_BETWEEN, &samples) {
                let across = cross_length(surface, along_u, (s0, s1), (c0, c1));
                return Err(PathError::Options(format!(
                    "a scallop height of {h} mm needs passes closer than 1/{MAX_PASSES} of the \
                     surface ({:.6} mm) near the cross parameter {c:.6}: more than {MAX_PASSES} passes",
                    across / MAX_PASSES as f64
                )));
            }
        }
    }
    // Pass positions: each the farthest that still fits, by bisection.
    let mut crosses = vec![c0];
    while let Some(&last) = crosses.last() {
        if last >= c1 {
            break;
        }
        if fits(last, c1, SEARCH_BETWEEN, &samples) {
            crosses.push(c1);
            break;
        }
        let (mut lo, mut hi) = (last, c1);
        for _ in 0..48 {
            let mid = 0.5 * (lo + hi);
            if fits(last, mid, SEARCH_BETWEEN, &samples) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        if !(lo > last + 1e-9 * (c1 - c0)) {
            return Err(PathError::NoStep {
                what,
                cross: last,
                width: wheel.width,
            });
        }
        crosses.push(lo);
        if crosses.len() > MAX_PASSES {
            return Err(PathError::Options(format!(
                "more than {MAX_PASSES} passes: the step-over is too small"
            )));
        }
    }
    check_point_count(surface, options, &crosses, &curve)?;

    // The passes, checked at their own CL points; in scallop mode a gap
    // whose fine check exceeds the limit (the search samples more
    // coarsely) gets a pass in its middle, until every gap holds.
    let mut round = 0;
    let (passes, report) = loop {
        let (passes, report) = build(surface, options, &crosses, &curve, &samples, side)?;
        let Spacing::Scallop(h) = options.spacing else {
            break (passes, report);
        };
        let over: Vec<usize> = (0..report.gaps.len())
            .filter(|&k| report.gaps[k].scallop > h)
            .collect();
        if over.is_empty() || round == 8 {
            break (passes, report);
        }
        for &k in over.iter().rev() {
            crosses.insert(k + 1, 0.5 * (crosses[k] + crosses[k + 1]));
        }
        round += 1;
    };
    Ok(Toolpath { passes, report })
}

/// CL points of the passes at `crosses`, and the report.
fn build(
    surface: &Surface,
    options: &PathOptions,
    crosses: &[f64],
    curve: &dyn Fn(f64) -> PassCurve,
    samples: &[f64],
    side: f64,
) -> Result<(Vec<Pass>, Report), PathError> {
    let along_u = options.direction == Direction::U;
    let wheel = options.wheel;
    // CL points along each pass.
    let mut passes = Vec::with_capacity(crosses.len());
    let mut chord_error_max = 0.0f64;
    let mut concave_min: Option<f64> = None;
    for (k, &cross) in crosses.iter().enumerate() {
        let pc = curve(cross);
        let (params, err) = sample_pass(surface, &pc, options)?;
        chord_error_max = chord_error_max.max(err);
        let mut points = Vec::with_capacity(params.len());
        for &s in &params {
            let (u, v) = pc.uv(s);
            let f = pc.frame(surface, s).ok_or(PathError::Degenerate { u, v })?;
            // Normal curvature along the feed, seen from the wheel.
            if let Ok(g) = surface.geometry(u, v) {
                let d = surface.derivatives(u, v);
                let k_feed = g.normal_curvature(&d, &f.ds) * side;
                if k_feed > 0.0 {
                    let r = 1.0 / k_feed;
                    concave_min = Some(concave_min.map_or(r, |m: f64| m.min(r)));
                }
            }
            points.push(ContactPoint {
                u,
                v,
                point: f.point,
                axis: f.normal,
                reference: f.tangent(),
            });
        }
        if k % 2 == 1 {
            points.reverse();
        }
        passes.push(Pass { cross, points });
    }

    // The report: every gap at the passes' own CL parameters and between.
    let mut gaps = Vec::with_capacity(passes.len().saturating_sub(1));
    for w in crosses.windows(2) {
        let mut at: Vec<f64> = samples.to_vec();
        let pass = &passes[gaps.len()];
        at.extend(pass.points.iter().map(|p| if along_u { p.u } else { p.v }));
        at.sort_by(f64::total_cmp);
        at.dedup();
        let mids: Vec<f64> = at.windows(2).map(|p| 0.5 * (p[0] + p[1])).collect();
        at.extend(mids);
        gaps.push(gap(
            surface,
            wheel,
            &curve(w[0]),
            &curve(w[1]),
            &at,
            REPORT_BETWEEN,
        ));
    }
    let points = passes.iter().map(|p| p.points.len()).sum();
    let length_mm = passes
        .iter()
        .map(|p| {
            p.points
                .windows(2)
                .map(|w| (w[1].point - w[0].point).norm())
                .sum::<f64>()
        })
        .sum();
    let stepovers = gaps.iter().map(|g| g.stepover);
    let report = Report {
        passes: passes.len(),
        points,
        length_mm,
        scallop_max: gaps.iter().map(|g| g.scallop).fold(0.0, f64::max),
        interference_max: gaps.iter().map(|g| g.interference).fold(0.0, f64::max),
        stepover_min: if gaps.is_empty() {
            0.0
        } else {
            stepovers.clone().fold(f64::INFINITY, f64::min)
        },
        stepover_max: stepovers.fold(0.0, f64::max),
        chord_error_max,
        concave_feed_radius_min: concave_min,
        gaps,
    };
    Ok((passes, report))
}

/// Pass parameters of the CL points: from the curvature of the pass, each
/// step as long as the chord tolerance and the tool-axis turn allow (and at
/// most a quarter of the pass, so that the checks see every pass at least
/// four times), checked at the quarter points and halved until it holds. Returns the
/// parameters and the largest chord deviation found.
fn sample_pass(
    surface: &Surface,
    pc: &PassCurve,
    options: &PathOptions,
) -> Result<(Vec<f64>, f64), PathError> {
    let tol = options.chord_tolerance;
    let max_angle = options.max_angle_deg.to_radians();
    let frame = |s: f64| -> Result<PassFrame, PathError> {
        pc.frame(surface, s).ok_or_else(|| {
            let (u, v) = pc.uv(s);
            PathError::Degenerate { u, v }
        })
    };
    let span = pc.s1 - pc.s0;
    let mut s = pc.s0;
    let mut f = frame(s)?;
    let mut out = vec![s];
    let mut worst = 0.0f64;
    while s < pc.s1 {
        let speed = f.ds.norm();
        let kappa = f.ds.cross(&f.dss).norm() / speed.powi(3);
        let len = if kappa > 1e-12 {
            (8.0 * tol / kappa).sqrt()
        } else {
            f64::INFINITY
        };
        let mut ds = (len / speed).min(pc.s1 - s).min(span / 4.0);
        let mut accepted = None;
        for _ in 0..60 {
            let e = s + ds;
            let fe = frame(e)?;
            let chord = fe.point - f.point;
            let clen = chord.norm();
            let mut dev = 0.0f64;
            for q in [0.25, 0.5, 0.75] {
                let p = frame(s + ds * q)?.point - f.point;
                let off = if clen > 0.0 {
                    (p - chord * (p.dot(&chord) / (clen * clen))).norm()
                } else {
                    p.norm()
                };
                dev = dev.max(off);
            }
            let turn = f.normal.angle(&fe.normal);
            if (dev <= tol && turn <= max_angle) || ds < 1e-12 * span {
                accepted = Some((e, fe, dev));
                break;
            }
            ds *= 0.5;
        }
        let (e, fe, dev) = accepted.ok_or(PathError::Options(
            "the chord tolerance cannot be met (surface not smooth?)".into(),
        ))?;
        worst = worst.max(dev);
        // Snap a tiny remainder onto the end.
        let e = if pc.s1 - e < 1e-9 * span { pc.s1 } else { e };
        s = e;
        f = if e == pc.s1 { frame(e)? } else { fe };
        out.push(s);
        if out.len() > 10_000_000 {
            return Err(PathError::Options(
                "more than 10 million CL points on one pass".into(),
            ));
        }
    }
    Ok((out, worst))
}
