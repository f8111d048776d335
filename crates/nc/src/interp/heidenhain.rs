//! Heidenhain.
use super::{Options, Report, Sink};
use crate::AxisSpec;
use kinpost_diag::Diagnostic;
pub(crate) fn run(
    _text: &str,
    _axes: &[AxisSpec],
    _options: &Options,
    file: &str,
    _sink: &mut dyn Sink,
) -> Result<Report, Diagnostic> {
    Err(Diagnostic::error(file, 0, 0, 0, "", "todo"))
}
