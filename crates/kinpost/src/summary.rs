//! The summary of a post run, printed on the terminal and written as JSON.

use kinpost_diag::Diagnostic;
use serde::Serialize;

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
    /// Largest angle between a block's tool axis and its CL axis, rad.
    pub max_axis_error_rad: f64,
    /// The position tolerance the check used, mm.
    pub tolerance_mm: f64,
    /// The axis tolerance the check used, rad.
    pub tolerance_rad: f64,
    /// Wall-clock time of the run.
    pub seconds: f64,
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
        };
        serde_json::to_string_pretty(&json).expect("plain data serializes") + "\n"
    }

    /// One line for the terminal.
    pub fn one_line(&self) -> String {
        format!(
            "{} CL points, {} blocks, {} warning(s); closed loop: max {:.6} mm / {:.3e} rad (tolerance {:.6} mm / {:.3e} rad); {:.3} s",
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
