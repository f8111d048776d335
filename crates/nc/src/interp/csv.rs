//! kinpost's CSV table: one row per motion block (`line`, `motion`, the
//! axes, `feed`, optional `feed_mode`), read by the table reader and turned
//! into moves.

use kinpost_diag::Diagnostic;

use super::machine::Machine;
use super::{FeedMode, MAX_AXES, MotionKind, Options, Report, Sink};
use crate::dialect::Dialect;
use crate::{AxisSpec, Motion};

/// Runs a CSV table.
pub(crate) fn run(
    text: &str,
    axes: &[AxisSpec],
    options: &Options,
    file: &str,
    sink: &mut dyn Sink,
) -> Result<Report, Diagnostic> {
    let dialect = Dialect::builtin("csv").expect("the csv dialect is built in");
    let program = crate::reader::read_csv(&dialect, axes, file, text)?;
    let feed_modes = feed_mode_column(text);
    let mut m = Machine::new(axes, options, sink);
    for (k, block) in program.blocks.iter().enumerate() {
        m.at_line(block.line, None);
        m.report.executed_blocks += 1;
        let mut target = m.pos;
        let mut programmed = 0u32;
        for (i, v) in block.axes.iter().enumerate().take(MAX_AXES) {
            if let Some(v) = v {
                target[i] = *v;
                programmed |= 1 << i;
            }
        }
        if let Some(f) = block.feed {
            m.feed = f;
        }
        if let Some(mode) = feed_modes.get(k).copied().flatten() {
            m.feed_mode = mode;
        }
        let kind = match block.motion {
            Motion::Rapid => MotionKind::Rapid,
            Motion::Feed => MotionKind::Linear,
        };
        let cl = block.cl_line;
        m.emit_cl_move(cl, kind, &target, programmed);
    }
    Ok(std::mem::take(&mut m.report))
}

/// The `feed_mode` column of every row, if the table has one.
fn feed_mode_column(text: &str) -> Vec<Option<FeedMode>> {
    let mut lines = text.lines().filter(|l| !l.trim().is_empty());
    let Some(header) = lines.next() else {
        return Vec::new();
    };
    let Some(col) = header.split(',').position(|h| h.trim() == "feed_mode") else {
        return Vec::new();
    };
    lines
        .map(|l| match l.split(',').nth(col).map(str::trim) {
            Some("inverse-time") => Some(FeedMode::InverseTime),
            Some("per-minute") => Some(FeedMode::PerMinute),
            _ => None,
        })
        .collect()
}
