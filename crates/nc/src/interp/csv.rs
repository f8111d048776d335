//! kinpost's CSV table, one row per motion block (`line`, `motion`, the
//! axes, `feed`, an optional `feed_mode`; `crates/nc/dialects/csv.toml`),
//! read row by row into moves (nothing is kept but the current row).

use kinpost_diag::Diagnostic;

use super::machine::Machine;
use super::num::read_number;
use super::source::{Fail, Source, diagnostic, fail};
use super::{FeedMode, MAX_AXES, MotionKind, Options, Report, Sink};
use crate::AxisSpec;

#[derive(Clone, Copy)]
enum Col {
    Line,
    Motion,
    Axis(usize),
    Feed,
    FeedMode,
}

/// Runs a CSV table.
pub(crate) fn run(
    text: &str,
    axes: &[AxisSpec],
    options: &Options,
    file: &str,
    sink: &mut dyn Sink,
) -> Result<Report, Diagnostic> {
    let mut m = Machine::new(axes, options, sink);
    let mut src = Source::new(text);
    let mut columns: Option<Vec<Col>> = None;
    while let Some(line) = src.next_line() {
        if line.text.trim().is_empty() {
            continue;
        }
        m.at_line(line.no, None);
        let r = match &columns {
            None => header(line.text, axes).map(|c| columns = Some(c)),
            Some(cols) => row(&mut m, line.text, cols),
        };
        r.map_err(|f| diagnostic(file, &line, f, false))?;
    }
    Ok(std::mem::take(&mut m.report))
}

fn header(text: &str, axes: &[AxisSpec]) -> Result<Vec<Col>, Fail> {
    let mut cols = Vec::new();
    let mut at = 0;
    for field in text.split(',') {
        let name = field.trim();
        cols.push(match name {
            "line" => Col::Line,
            "motion" => Col::Motion,
            "feed" => Col::Feed,
            "feed_mode" => Col::FeedMode,
            _ => match axes.iter().position(|a| a.name == name) {
                Some(i) if i < MAX_AXES => Col::Axis(i),
                _ => {
                    return fail(
                        at,
                        field.len(),
                        format!("unknown column `{name}` (not an axis of the machine)"),
                    );
                }
            },
        });
        at += field.len() + 1;
    }
    Ok(cols)
}

fn row(m: &mut Machine<'_>, text: &str, cols: &[Col]) -> Result<(), Fail> {
    m.count_block()?;
    let fields = text.split(',').count();
    if fields != cols.len() {
        return fail(
            0,
            text.len(),
            format!("row has {fields} fields, the header has {}", cols.len()),
        );
    }
    let mut cl_line = None;
    let mut kind = MotionKind::Linear;
    let mut values = [0.0; MAX_AXES];
    let mut programmed = 0u32;
    let mut at = 0;
    for (field, col) in text.split(',').zip(cols) {
        let v = field.trim();
        let bad = |what: &str| fail(at, field.len(), format!("malformed {what} `{v}`"));
        match *col {
            Col::Line if !v.is_empty() => match v.parse::<usize>() {
                Ok(n) => cl_line = Some(n),
                Err(_) => return bad("line number"),
            },
            Col::Motion => {
                kind = match v {
                    "rapid" => MotionKind::Rapid,
                    "feed" => MotionKind::Linear,
                    _ => return bad("motion (expected `rapid` or `feed`)"),
                }
            }
            Col::Axis(i) if !v.is_empty() => match number(v) {
                Some(x) => {
                    values[i] = x;
                    programmed |= 1 << i;
                }
                None => return bad("number"),
            },
            Col::Feed if !v.is_empty() => match number(v) {
                Some(f) => m.feed = f,
                None => return bad("feed"),
            },
            Col::FeedMode => match v {
                "" => {}
                "per-minute" => m.feed_mode = FeedMode::PerMinute,
                "inverse-time" => m.feed_mode = FeedMode::InverseTime,
                _ => return bad("feed mode (expected `per-minute`, `inverse-time` or nothing)"),
            },
            _ => {}
        }
        at += field.len() + 1;
    }
    m.emit_cl_move(cl_line, kind, &values, programmed);
    Ok(())
}

/// The whole field as a number.
fn number(v: &str) -> Option<f64> {
    let n = read_number(v.as_bytes())?;
    (n.len == v.len()).then_some(n.value)
}
