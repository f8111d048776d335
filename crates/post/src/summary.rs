//! The summary of a post run, printed on the terminal and written as JSON.

use kinpost_diag::Diagnostic;
pub use kinpost_plan::SingularStretch;
use serde::Serialize;

use crate::check::CheckReport;
use crate::motion::MotionReport;
pub use crate::motion::Reconfiguration;
pub use crate::motion::feed::FeedClamp;

/// What a post run did.
#[derive(Debug, Clone, PartialEq)]
pub struct Summary {
    /// CL points (GOTOs) read.
    pub cl_points: u64,
    /// Motion blocks written.
    pub blocks: u64,
    /// Harmless problems of the input, in line order.
    pub warnings: Vec<Diagnostic>,
    /// Largest distance between a block's tool point (values as written,
    /// through the forward kinematics) and its CL point, mm.
    pub max_position_error_mm: f64,
    /// CL line of the block with that largest position error.
    pub max_position_error_line: Option<usize>,
    /// Largest angle between a block's tool axis and its CL axis (in
    /// 6-axis output also between the reference directions, each normal to
    /// its tool axis), rad.
    pub max_axis_error_rad: f64,
    /// The position tolerance the check used, mm.
    pub tolerance_mm: f64,
    /// The axis tolerance the check used, rad.
    pub tolerance_rad: f64,
    /// Wall-clock time of the run.
    pub seconds: f64,
    /// The path planning: singular stretches, reconfigurations, inserted
    /// blocks, feed clamps.
    pub planning: Planning,
}

/// What the planner did to the path.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct Planning {
    /// Runs of CL points whose tool axis lies within the singular cone,
    /// where the singular angle was held or interpolated (or was free: a
    /// point exactly on the singular direction, written exactly, takes the
    /// angle of its neighbour).
    pub singular_stretches: Vec<SingularStretch>,
    /// Retract-and-reconfigure events.
    pub reconfigurations: Vec<Reconfiguration>,
    /// Blocks the post inserted: linearization, retracts, re-approaches.
    pub inserted_blocks: u64,
    /// Largest distance of the contact point at the joint-space midpoint of a
    /// feed block from its straight CL segment, mm: an upper bound, exact
    /// where the midpoint was computed, the chain's chord bound (plus 1e-6 mm)
    /// where that bound alone showed the block within the tolerance.
    pub max_linearization_error_mm: f64,
    /// Largest angle between the tool axis of an inserted linearization
    /// block and the CL's interpolated one, degrees (where an angle is held
    /// near the pole, or the interpolated axis passes where the machine
    /// cannot point), and the CL line of the segment.
    pub max_inserted_axis_deviation_deg: f64,
    /// See `max_inserted_axis_deviation_deg`.
    pub max_inserted_axis_deviation_line: Option<usize>,
    /// Largest change of one rotary axis between two consecutive feed
    /// blocks, degrees, and the CL line of the block.
    pub max_rotary_step_deg: f64,
    /// See `max_rotary_step_deg`.
    pub max_rotary_step_line: Option<usize>,
    /// Feed blocks slowed down to the axes' maximum velocities (the first
    /// 1000), and how many there were in all.
    pub feed_clamps: Vec<FeedClamp>,
    /// See `feed_clamps`.
    pub feed_clamp_count: u64,
    /// Blocks whose CL tool axis lies just outside the directions the
    /// machine can point (CL rounding, up to
    /// [`PostOptions::axis_rounding_rad`](crate::PostOptions::axis_rounding_rad)) and that
    /// the closed-loop check passed only against the nearest direction it
    /// can point: how many, the largest distance of such a CL axis from
    /// that direction (rad), and the CL line of the first.
    pub beyond_reach_blocks: u64,
    /// See `beyond_reach_blocks`.
    pub max_beyond_reach_rad: f64,
    /// See `beyond_reach_blocks`.
    pub first_beyond_reach_line: Option<usize>,
    /// CL arcs (pieces of a full turn counted one by one) written as
    /// circular blocks (`--arcs native`); left out of the JSON when 0.
    #[serde(skip_serializing_if = "is_zero")]
    pub native_arcs: u64,
    /// Holes of CL canned cycles written as the dialect's cycles
    /// (`--cycles native`); left out of the JSON when 0.
    #[serde(skip_serializing_if = "is_zero")]
    pub native_cycles: u64,
}

impl Planning {
    /// The figures of the stages after the program.
    pub(crate) fn of(
        stretches: Vec<SingularStretch>,
        m: MotionReport,
        c: &CheckReport,
    ) -> Planning {
        Planning {
            singular_stretches: stretches,
            reconfigurations: m.reconfigurations,
            inserted_blocks: m.inserted_blocks,
            max_linearization_error_mm: m.linearization.max_error_mm,
            max_inserted_axis_deviation_deg: m.linearization.max_axis_deviation_deg,
            max_inserted_axis_deviation_line: m.linearization.max_axis_deviation_line,
            max_rotary_step_deg: m.max_rotary_step_deg,
            max_rotary_step_line: m.max_rotary_step_line,
            feed_clamps: m.feed_clamps,
            feed_clamp_count: m.feed_clamp_count,
            beyond_reach_blocks: c.beyond_reach_blocks,
            max_beyond_reach_rad: c.max_beyond_reach_rad,
            first_beyond_reach_line: c.first_beyond_reach_line,
            native_arcs: c.native_arcs,
            native_cycles: c.native_cycles,
        }
    }
}

fn is_zero(n: &u64) -> bool {
    *n == 0
}

#[derive(Serialize)]
struct JsonWarning<'a> {
    file: &'a str,
    line: usize,
    column: usize,
    message: &'a str,
}

#[derive(Serialize)]
struct JsonSummary<'a> {
    cl_points: u64,
    blocks: u64,
    warnings: Vec<JsonWarning<'a>>,
    max_position_error_mm: f64,
    max_position_error_line: Option<usize>,
    max_axis_error_rad: f64,
    tolerance_mm: f64,
    tolerance_rad: f64,
    seconds: f64,
    #[serde(flatten)]
    planning: &'a Planning,
}

impl Summary {
    /// The summary as pretty-printed JSON.
    pub fn to_json(&self) -> String {
        let json = JsonSummary {
            cl_points: self.cl_points,
            blocks: self.blocks,
            warnings: self
                .warnings
                .iter()
                .map(|w| JsonWarning {
                    file: &w.file,
                    line: w.line,
                    column: w.column,
                    message: &w.message,
                })
                .collect(),
            max_position_error_mm: self.max_position_error_mm,
            max_position_error_line: self.max_position_error_line,
            max_axis_error_rad: self.max_axis_error_rad,
            tolerance_mm: self.tolerance_mm,
            tolerance_rad: self.tolerance_rad,
            seconds: self.seconds,
            planning: &self.planning,
        };
        serde_json::to_string_pretty(&json).expect("plain data serializes") + "\n"
    }

    /// One line for the terminal.
    pub fn one_line(&self) -> String {
        let p = &self.planning;
        let mut planning = String::new();
        if p.inserted_blocks > 0 {
            planning += &format!(
                "; {} inserted block(s), linearization max {:.4} mm",
                p.inserted_blocks, p.max_linearization_error_mm
            );
        }
        if p.max_inserted_axis_deviation_deg >= 1e-4 {
            planning += &format!(
                "; an inserted block's tool axis up to {:.4}° off the CL's interpolation (before CL line {})",
                p.max_inserted_axis_deviation_deg,
                p.max_inserted_axis_deviation_line.unwrap_or(0)
            );
        }
        if !p.singular_stretches.is_empty() {
            // The held angle leaves the tool axis off the CL there (the
            // closed loop above counts the other blocks).
            let held = p
                .singular_stretches
                .iter()
                .map(|s| s.max_axis_deviation_deg)
                .fold(0.0, f64::max);
            planning += &format!(
                "; {} singular stretch(es), tool axis held within {held:.4}°",
                p.singular_stretches.len()
            );
        }
        if !p.reconfigurations.is_empty() {
            planning += &format!("; {} reconfiguration(s)", p.reconfigurations.len());
            let uncut: Vec<&Reconfiguration> = p
                .reconfigurations
                .iter()
                .filter(|r| r.uncut_mm > 0.0)
                .collect();
            if !uncut.is_empty() {
                let mm: f64 = uncut.iter().map(|r| r.uncut_mm).sum();
                planning += &format!(
                    " ({} leaving {mm:.3} mm of the path uncut, first before CL line {})",
                    uncut.len(),
                    uncut[0].line
                );
            }
        }
        if p.beyond_reach_blocks > 0 {
            planning += &format!(
                "; {} block(s) with a CL tool axis up to {:.1e} rad beyond reach (CL rounding), checked against the nearest, first at CL line {}",
                p.beyond_reach_blocks,
                p.max_beyond_reach_rad,
                p.first_beyond_reach_line.unwrap_or(0)
            );
        }
        if p.native_arcs > 0 {
            planning += &format!("; {} arc(s) written as circular blocks", p.native_arcs);
        }
        if p.native_cycles > 0 {
            planning += &format!("; {} hole(s) written as canned cycles", p.native_cycles);
        }
        if p.feed_clamp_count > 0 {
            planning += &format!("; {} feed block(s) clamped", p.feed_clamp_count);
        }
        format!(
            "{} CL points, {} blocks, {} warning(s); closed loop: max {:.6} mm / {:.3e} rad (tolerance {:.6} mm / {:.3e} rad){planning}; {:.3} s",
            self.cl_points,
            self.blocks,
            self.warnings.len(),
            self.max_position_error_mm,
            self.max_axis_error_rad,
            self.tolerance_mm,
            self.tolerance_rad,
            self.seconds
        )
    }
}
