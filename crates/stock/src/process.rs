//! Belt-grinding process model: the force of the pressure axis, the
//! contact pressure of a compliant wheel, and removal by Preston's law.
//!
//! **Force.** The pressure axis (H1 on the MTS1600, Qi (thesis), §2.2–2.4:
//! a pneumatic cylinder of 40 mm bore drives the four-bar linkage that
//! carries the wheel) sets the normal force. The process file gives the
//! calibration H1 → newtons as a piecewise-linear table, clamped at its
//! ends, like the machine file's `[pressure] alpha_deg`.
//!
//! **Contact (Winkler).** The contact wheel's rubber is an elastic
//! foundation: the pressure at a point is p = k·δ, δ the interference of
//! the undeformed wheel with the part there, k (N/mm³) the foundation
//! modulus. For a wheel of radius R (effective radius R_e with the part's
//! curvature κ along the feed: 1/R_e = 1/R + κ) pressed δ₀ into the part,
//! with the parabolic profile δ(x) = δ₀ − x²/(2R_e) over the contact length
//! |x| ≤ a = √(2R_e·δ₀), uniform across the belt width W:
//!
//! F = W·∫p dx = (4/3)·k·W·a·δ₀ = (4/3)·k·W·√(2R_e)·δ₀^{3/2},
//!
//! so δ₀ = (3F / (4kW√(2R_e)))^{2/3} and the peak pressure is p₀ = k·δ₀.
//!
//! **Removal (Preston).** Δh = K_p·p·v_belt·Δt, v_belt = ω·R from the
//! spindle speed and the wheel radius. A point of a flat part under a pass
//! at feed v_f sees the whole pressure profile once:
//!
//! h = K_p·v_belt/v_f·∫p dx = K_p·v_belt·F / (v_f·W)
//!
//! (independent of k: the stiffness shapes the profile, not its integral).
//! [`Stock::grind_move`] removes, at every ray under the patch, the depth
//! K_p·v_belt/v_f·(P(s) − P(s − L)) along the tool axis, P the cumulative
//! pressure integral, s the point's position along the move of length L.
//!
//! **Calibration** ([`calibrate`]): passes give K_p by least squares through
//! the origin (depth = K_p·x, x = v_belt·F/(v_f·W)); dwells (the wheel held
//! still for T seconds) give k: the trace's peak depth is
//! K_p·v_belt·T·p₀ = K_p·v_belt·T·c·k^{1/3}, c = (3F/(4W√(2R)))^{2/3}, linear
//! in θ = k^{1/3}, fitted by least squares through the origin with K_p from
//! the passes.
//!
//! The process file:
//!
//! ```toml
//! [force]
//! axis = "H1"
//! # H1 -> normal force in N (piecewise linear, clamped at the ends)
//! newtons = [[3000, 300.0], [3600, 0.0]]
//!
//! [wheel]
//! preston_mm2_per_n = 2.0e-6     # K_p: Δh[mm] = K_p · p[N/mm²] · v[mm/s] · Δt[s]
//! stiffness_n_per_mm3 = 3.0      # Winkler modulus k: p = k · δ
//! ```

use std::f64::consts::PI;

use kinpost_diag::{Diagnostic, Severity};
use nalgebra::Vector3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::design::nearest_end;
use crate::dexel::subtract;
use crate::stock::{CutError, Stock};
use crate::tool::{Tool, ToolError, ToolPose};

/// The process model of a belt grinder.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProcessModel {
    /// The force of the pressure axis.
    pub force: ForceCalibration,
    /// The wheel's compliance and the belt's removal coefficient.
    pub wheel: WheelProcess,
}

/// The calibration of the pressure axis.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ForceCalibration {
    /// The axis word (H1).
    pub axis: String,
    /// (axis value, normal force in N), in increasing axis value.
    pub newtons: Vec<[f64; 2]>,
}

/// Preston's coefficient and the Winkler modulus of the wheel.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WheelProcess {
    /// K_p, mm²/N.
    pub preston_mm2_per_n: f64,
    /// k, N/mm³.
    pub stiffness_n_per_mm3: f64,
}

/// The contact of a pressed wheel (Winkler, parabolic profile).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Contact {
    /// Normal force, N.
    pub force_n: f64,
    /// Interference at the centre, mm.
    pub indentation_mm: f64,
    /// Half the contact length along the feed, mm.
    pub half_length_mm: f64,
    /// Peak pressure, N/mm² (MPa).
    pub peak_pressure_mpa: f64,
    /// Effective radius along the feed, mm.
    pub effective_radius_mm: f64,
    /// Belt width, mm.
    pub width_mm: f64,
    /// Winkler modulus, N/mm³.
    pub stiffness_n_per_mm3: f64,
}

impl Contact {
    /// ∫ p dx from the leading edge −a to x (N/mm): 0 before the patch, F/W
    /// after it.
    pub fn cumulative(&self, x: f64) -> f64 {
        let (a, d, r, k) = (
            self.half_length_mm,
            self.indentation_mm,
            self.effective_radius_mm,
            self.stiffness_n_per_mm3,
        );
        let x = x.clamp(-a, a);
        k * (d * (x + a) - (x * x * x + a * a * a) / (6.0 * r))
    }

    /// The pressure at x along the feed from the patch centre, N/mm².
    pub fn pressure(&self, x: f64) -> f64 {
        let d = self.indentation_mm - x * x / (2.0 * self.effective_radius_mm);
        self.stiffness_n_per_mm3 * d.max(0.0)
    }
}

/// Why a process file or a process computation fails.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ProcessError {
    /// A value is out of its range.
    #[error("{what} must be {why}, not {value}")]
    Value {
        /// The quantity.
        what: &'static str,
        /// Its value.
        value: f64,
        /// What it must be.
        why: &'static str,
    },
    /// The tool is not a contact wheel.
    #[error("the process model grinds with a contact wheel, not a {0}")]
    NotAWheel(&'static str),
    /// Cutting failed.
    #[error(transparent)]
    Cut(#[from] CutError),
    /// Calibration needs data.
    #[error("calibration needs at least one {0} trace with a positive depth")]
    NoData(&'static str),
}

fn check(what: &'static str, value: f64, why: &'static str, ok: bool) -> Result<f64, ProcessError> {
    if ok && value.is_finite() {
        Ok(value)
    } else {
        Err(ProcessError::Value { what, value, why })
    }
}

impl ProcessModel {
    /// Reads a process file (TOML, the form in the module doc).
    pub fn from_toml(src: &str, file: &str) -> Result<ProcessModel, Diagnostic> {
        let m: ProcessModel = from_toml(src, file)?;
        m.validate().map_err(|e| {
            let key = match e {
                ProcessError::Value { what, .. } if what.starts_with("force") => "newtons",
                ProcessError::Value { what, .. } if what.starts_with("Preston") => {
                    "preston_mm2_per_n"
                }
                _ => "stiffness_n_per_mm3",
            };
            let start = src.find(key).unwrap_or(0);
            Diagnostic::at_byte_span(
                Severity::Error,
                file,
                src,
                start..start + key.len(),
                e.to_string(),
            )
        })?;
        Ok(m)
    }

    /// Checks every value.
    pub fn validate(&self) -> Result<(), ProcessError> {
        let w = &self.wheel;
        check(
            "Preston's coefficient (mm²/N)",
            w.preston_mm2_per_n,
            "a number ≥ 0",
            w.preston_mm2_per_n >= 0.0,
        )?;
        check(
            "the wheel stiffness (N/mm³)",
            w.stiffness_n_per_mm3,
            "a positive number",
            w.stiffness_n_per_mm3 > 0.0,
        )?;
        let t = &self.force.newtons;
        if t.is_empty() {
            return Err(ProcessError::Value {
                what: "force table length",
                value: 0.0,
                why: "at least one row",
            });
        }
        for (i, row) in t.iter().enumerate() {
            check("force table axis value", row[0], "finite", true)?;
            check("force (N)", row[1], "a number ≥ 0", row[1] >= 0.0)?;
            if i > 0 {
                check(
                    "force table axis value",
                    row[0],
                    "increasing down the table",
                    row[0] > t[i - 1][0],
                )?;
            }
        }
        Ok(())
    }

    /// The normal force at an axis value, N (piecewise linear, clamped).
    pub fn force_n(&self, axis_value: f64) -> f64 {
        let t = &self.force.newtons;
        if axis_value <= t[0][0] {
            return t[0][1];
        }
        for w in t.windows(2) {
            if axis_value <= w[1][0] {
                let s = (axis_value - w[0][0]) / (w[1][0] - w[0][0]);
                return w[0][1] + s * (w[1][1] - w[0][1]);
            }
        }
        t[t.len() - 1][1]
    }

    /// The contact of a wheel of `radius` and `width` pressed with `force_n`
    /// on a part of curvature `curvature_per_mm` along the feed (> 0 convex).
    pub fn contact(
        &self,
        force_n: f64,
        radius_mm: f64,
        width_mm: f64,
        curvature_per_mm: f64,
    ) -> Result<Contact, ProcessError> {
        check("the force (N)", force_n, "a number ≥ 0", force_n >= 0.0)?;
        check(
            "the wheel radius (mm)",
            radius_mm,
            "positive",
            radius_mm > 0.0,
        )?;
        check("the wheel width (mm)", width_mm, "positive", width_mm > 0.0)?;
        let inv = 1.0 / radius_mm + curvature_per_mm;
        check(
            "1/R + κ (1/mm)",
            inv,
            "positive (the part bends away from the wheel less than the wheel)",
            inv > 0.0,
        )?;
        let re = 1.0 / inv;
        let k = self.wheel.stiffness_n_per_mm3;
        let d = (3.0 * force_n / (4.0 * k * width_mm * (2.0 * re).sqrt())).powf(2.0 / 3.0);
        Ok(Contact {
            force_n,
            indentation_mm: d,
            half_length_mm: (2.0 * re * d).sqrt(),
            peak_pressure_mpa: k * d,
            effective_radius_mm: re,
            width_mm,
            stiffness_n_per_mm3: k,
        })
    }

    /// Depth ground from a flat part by one pass, mm: K_p·v_belt·F/(v_f·W).
    pub fn pass_depth_mm(
        &self,
        force_n: f64,
        belt_mm_s: f64,
        feed_mm_s: f64,
        width_mm: f64,
    ) -> f64 {
        self.wheel.preston_mm2_per_n * belt_mm_s * force_n / (feed_mm_s * width_mm)
    }
}

/// Belt speed, mm/s, of a wheel of `radius_mm` turning at `rpm`.
pub fn belt_speed_mm_s(rpm: f64, radius_mm: f64) -> f64 {
    2.0 * PI * rpm / 60.0 * radius_mm
}

/// What one grinding move removed.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GrindStats {
    /// The contact.
    pub contact: Contact,
    /// Belt speed, mm/s.
    pub belt_mm_s: f64,
    /// Depth of a full pass at this force and feed on a flat, mm.
    pub pass_depth_mm: f64,
    /// Rays ground.
    pub rays: u64,
    /// Smallest and largest depth removed at a ray, along the tool axis, mm.
    pub depth_range_mm: [f64; 2],
    /// Volume ground away, mm³: the length removed from every ray times
    /// its cross-section.
    #[serde(default)]
    pub removed_volume_mm3: f64,
}

/// Operating conditions of a grinding move.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Conditions {
    /// Normal force, N (see [`ProcessModel::force_n`]).
    pub force_n: f64,
    /// Spindle (wheel) speed, rpm.
    pub spindle_rpm: f64,
    /// Feed along the move, mm/min.
    pub feed_mm_min: f64,
    /// Part curvature along the feed, 1/mm (0 for a flat).
    pub curvature_per_mm: f64,
}

impl Stock {
    /// Grinds one straight move with the process model instead of the rigid
    /// wheel: every ray whose surface point lies under the swept contact
    /// patch loses, along the tool axis (the axis of the move's start), the
    /// Preston depth K_p·v_belt/v_f·(P(s) − P(s − L)) (module doc). The rays
    /// are those of the family most nearly along the tool axis; the surface
    /// point is the end of the material facing the wheel nearest to the
    /// contact plane.
    pub fn grind_move(
        &mut self,
        model: &ProcessModel,
        tool: &Tool,
        from: &ToolPose,
        to: &ToolPose,
        conditions: &Conditions,
        move_id: u32,
    ) -> Result<GrindStats, ProcessError> {
        let Tool::ContactWheel { radius, width, .. } = *tool else {
            return Err(ProcessError::NotAWheel(tool.name()));
        };
        let placed = tool
            .place(from)
            .map_err(|e| ProcessError::Cut(CutError::Tool(e)))?;
        tool.place(to)
            .map_err(|e| ProcessError::Cut(CutError::Tool(e)))?;
        check(
            "the feed (mm/min)",
            conditions.feed_mm_min,
            "positive",
            conditions.feed_mm_min > 0.0,
        )?;
        check(
            "the spindle speed (rpm)",
            conditions.spindle_rpm,
            "a number ≥ 0",
            conditions.spindle_rpm >= 0.0,
        )?;
        let contact = model.contact(
            conditions.force_n,
            radius,
            width,
            conditions.curvature_per_mm,
        )?;
        let belt = belt_speed_mm_s(conditions.spindle_rpm, radius);
        let feed = conditions.feed_mm_min / 60.0;
        let n = from.axis.into_inner();
        let wheel_axis = placed.axis;
        let travel = to.point - from.point;
        let len = travel.norm();
        if !(len > 0.0) {
            return Err(ProcessError::Cut(CutError::Tool(ToolError::Dimension {
                name: "move length",
                value: len,
                why: "a grinding move must move",
            })));
        }
        let f = travel / len;
        let kp = model.wheel.preston_mm2_per_n * belt / feed;
        let depth_at = |q: &Vector3<f64>| -> f64 {
            let r = q - from.point.coords;
            let (s, y) = (r.dot(&f), r.dot(&wheel_axis));
            if y.abs() > width / 2.0 {
                return 0.0;
            }
            kp * (contact.cumulative(s) - contact.cumulative(s - len))
        };
        let k = (0..3)
            .max_by(|&a, &b| n[a].abs().total_cmp(&n[b].abs()))
            .unwrap_or(2);
        let facing: i8 = if n[k] > 0.0 { 1 } else { -1 };
        let a = contact.half_length_mm;
        // Bounds of the patch swept along the move.
        let corners = [-a, len + a].into_iter().flat_map(|s| {
            [-width / 2.0, width / 2.0].map(|y| from.point.coords + s * f + y * wheel_axis)
        });
        let (mut lo, mut hi) = (
            Vector3::repeat(f64::INFINITY),
            Vector3::repeat(f64::NEG_INFINITY),
        );
        for c in corners {
            lo = lo.inf(&c);
            hi = hi.sup(&c);
        }
        let (origin, h, counts) = (self.origin(), self.resolution_mm(), self.counts());
        let fam = &mut self.families_mut()[k];
        let (u, v, nu) = (fam.u, fam.v, fam.nu);
        let range = |i: usize| {
            let a0 = ((lo[i] - origin[i]) / h - 0.5).ceil().max(0.0);
            let b0 = ((hi[i] - origin[i]) / h - 0.5)
                .floor()
                .min(counts[i] as f64 - 1.0);
            (a0 <= b0).then_some((a0 as usize, b0 as usize))
        };
        let mut stats = GrindStats {
            contact,
            belt_mm_s: belt,
            pass_depth_mm: model.pass_depth_mm(conditions.force_n, belt, feed, width),
            rays: 0,
            depth_range_mm: [0.0, 0.0],
            removed_volume_mm3: 0.0,
        };
        let (Some((u0, u1)), Some((v0, v1))) = (range(u), range(v)) else {
            return Ok(stats);
        };
        let p0 = from.point.coords;
        let length = |ray: &crate::dexel::Ray| ray.iter().map(|s| s.hi - s.lo).sum::<f64>();
        let per_row: Vec<(u64, f64, f64, f64)> = fam.rays[v0 * nu..(v1 + 1) * nu]
            .par_chunks_mut(nu)
            .enumerate()
            .map(|(jv, row)| {
                let pv = origin[v] + ((v0 + jv) as f64 + 0.5) * h;
                let mut acc = (0u64, f64::INFINITY, 0.0f64, 0.0f64);
                for (ju, ray) in row[u0..=u1].iter_mut().enumerate() {
                    let pu = origin[u] + ((u0 + ju) as f64 + 0.5) * h;
                    // The contact plane n·(x − p0) = 0 on this ray.
                    let tp = p0[k] - (n[u] * (pu - p0[u]) + n[v] * (pv - p0[v])) / n[k];
                    let Some((t, _)) = nearest_end(ray, tp, facing) else {
                        continue;
                    };
                    let mut q = Vector3::zeros();
                    q[u] = pu;
                    q[v] = pv;
                    q[k] = t;
                    let dh = depth_at(&q);
                    if dh > 0.0 {
                        let along = dh / n[k].abs();
                        let before = length(ray);
                        if facing > 0 {
                            subtract(ray, t - along, t + 1e-9, move_id);
                        } else {
                            subtract(ray, t - 1e-9, t + along, move_id);
                        }
                        acc.0 += 1;
                        acc.1 = acc.1.min(dh);
                        acc.2 = acc.2.max(dh);
                        acc.3 += before - length(ray);
                    }
                }
                acc
            })
            .collect();
        for (rays, mn, mx, removed) in per_row {
            stats.removed_volume_mm3 += removed * h * h;
            if rays > 0 {
                stats.depth_range_mm = if stats.rays == 0 {
                    [mn, mx]
                } else {
                    [
                        stats.depth_range_mm[0].min(mn),
                        stats.depth_range_mm[1].max(mx),
                    ]
                };
                stats.rays += rays;
            }
        }
        self.note_ground(stats.removed_volume_mm3);
        Ok(stats)
    }
}

/// A measured trace for [`calibrate`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum Trace {
    /// A pass over a flat at constant feed; its steady depth.
    Pass {
        /// Normal force, N.
        force_n: f64,
        /// Belt speed, mm/s.
        belt_mm_s: f64,
        /// Feed, mm/s.
        feed_mm_s: f64,
        /// Belt width, mm.
        width_mm: f64,
        /// Measured depth, mm.
        depth_mm: f64,
    },
    /// The wheel held still on a flat for a time; the trace's peak depth.
    Dwell {
        /// Normal force, N.
        force_n: f64,
        /// Belt speed, mm/s.
        belt_mm_s: f64,
        /// Dwell, s.
        dwell_s: f64,
        /// Belt width, mm.
        width_mm: f64,
        /// Wheel radius, mm.
        radius_mm: f64,
        /// Measured peak depth, mm.
        depth_mm: f64,
    },
}

/// A file of measured traces (TOML), for [`calibrate`]:
///
/// ```toml
/// [[trace]]
/// kind = "pass"        # a pass over a flat at constant feed: its steady depth
/// force_n = 150.0
/// belt_mm_s = 7854.0   # 2π · rpm / 60 · wheel radius
/// feed_mm_s = 8.333
/// width_mm = 25.0
/// depth_mm = 0.0141
///
/// [[trace]]
/// kind = "dwell"       # the wheel held still: the trace's peak depth
/// force_n = 150.0
/// belt_mm_s = 7854.0
/// dwell_s = 2.0
/// width_mm = 25.0
/// radius_mm = 25.0
/// depth_mm = 0.029
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TraceFile {
    /// The traces.
    pub trace: Vec<Trace>,
}

impl TraceFile {
    /// Reads a trace file (located errors).
    pub fn from_toml(src: &str, file: &str) -> Result<TraceFile, Diagnostic> {
        from_toml(src, file)
    }
}

/// A TOML file's value, or the parser's error located in `file`.
fn from_toml<T: serde::de::DeserializeOwned>(src: &str, file: &str) -> Result<T, Diagnostic> {
    toml::from_str(src).map_err(|e| {
        Diagnostic::at_byte_span(
            Severity::Error,
            file,
            src,
            e.span().unwrap_or(0..0),
            e.message().trim_end(),
        )
    })
}

impl ProcessModel {
    /// The model as a process file (TOML; the inverse of
    /// [`ProcessModel::from_toml`]).
    pub fn to_toml(&self) -> String {
        toml::to_string(self).unwrap_or_default()
    }

    /// The same model with the wheel's coefficients of `fit` (the
    /// stiffness kept when the fit has no dwell).
    pub fn calibrated(&self, fit: &Calibration) -> ProcessModel {
        let mut m = self.clone();
        m.wheel.preston_mm2_per_n = fit.preston_mm2_per_n;
        if let Some(k) = fit.stiffness_n_per_mm3 {
            m.wheel.stiffness_n_per_mm3 = k;
        }
        m
    }
}

/// The fitted coefficients.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Calibration {
    /// K_p, mm²/N.
    pub preston_mm2_per_n: f64,
    /// k, N/mm³ (`None` without dwell traces).
    pub stiffness_n_per_mm3: Option<f64>,
    /// Root-mean-square depth residual of the fit, mm.
    pub rms_mm: f64,
}

/// Fits K_p (passes) and the Winkler modulus (dwells) by least squares
/// (module doc).
pub fn calibrate(traces: &[Trace]) -> Result<Calibration, ProcessError> {
    let (mut sxx, mut sxy) = (0.0, 0.0);
    for t in traces {
        if let Trace::Pass {
            force_n,
            belt_mm_s,
            feed_mm_s,
            width_mm,
            depth_mm,
        } = *t
        {
            let x = belt_mm_s * force_n / (feed_mm_s * width_mm);
            check(
                "a pass's v·F/(v_f·W)",
                x,
                "a positive finite number",
                x > 0.0,
            )?;
            check("a measured depth (mm)", depth_mm, "a finite number", true)?;
            sxx += x * x;
            sxy += x * depth_mm;
        }
    }
    if !(sxx > 0.0 && sxy > 0.0) {
        return Err(ProcessError::NoData("pass"));
    }
    let kp = sxy / sxx;
    let (mut szz, mut szy) = (0.0, 0.0);
    for t in traces {
        if let Trace::Dwell {
            force_n,
            belt_mm_s,
            dwell_s,
            width_mm,
            radius_mm,
            depth_mm,
        } = *t
        {
            let c = (3.0 * force_n / (4.0 * width_mm * (2.0 * radius_mm).sqrt())).powf(2.0 / 3.0);
            let z = kp * belt_mm_s * dwell_s * c;
            check(
                "a dwell's K_p·v·T·c",
                z,
                "a positive finite number",
                z > 0.0,
            )?;
            check("a measured depth (mm)", depth_mm, "a finite number", true)?;
            szz += z * z;
            szy += z * depth_mm;
        }
    }
    let stiffness = (szz > 0.0).then(|| (szy / szz).max(0.0).powi(3));
    let mut sq = 0.0;
    for t in traces {
        let (model, measured) = match *t {
            Trace::Pass {
                force_n,
                belt_mm_s,
                feed_mm_s,
                width_mm,
                depth_mm,
            } => (kp * belt_mm_s * force_n / (feed_mm_s * width_mm), depth_mm),
            Trace::Dwell {
                force_n,
                belt_mm_s,
                dwell_s,
                width_mm,
                radius_mm,
                depth_mm,
            } => {
                let c =
                    (3.0 * force_n / (4.0 * width_mm * (2.0 * radius_mm).sqrt())).powf(2.0 / 3.0);
                (
                    kp * belt_mm_s * dwell_s * c * stiffness.unwrap_or(0.0).cbrt(),
                    depth_mm,
                )
            }
        };
        sq += (model - measured).powi(2);
    }
    Ok(Calibration {
        preston_mm2_per_n: kp,
        stiffness_n_per_mm3: stiffness,
        rms_mm: (sq / traces.len() as f64).sqrt(),
    })
}
