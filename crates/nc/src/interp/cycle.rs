//! Drilling cycles expanded into their real moves.
//!
//! A family turns its cycle words into a [`Hole`]: where the hole is, its
//! levels along the tool axis (the normal of the working plane) and a
//! list of [`Op`]s from the R plane down and back; [`drill`] positions the
//! tool and runs the ops as moves, dwells and spindle events.

use super::machine::Machine;
use super::source::Fail;
use super::{CycleRef, SpindleDir};

/// One step of a cycle, along the tool axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Op {
    /// Rapid to this level.
    Rapid(f64),
    /// Feed to this level.
    Feed(f64),
    /// Feed to this level at another feed rate (mm/min), then back to the
    /// programmed one.
    FeedAt(f64, f64),
    /// Dwell, seconds.
    Dwell(f64),
    /// Spindle stop.
    SpindleStop,
    /// Spindle on in the other direction (tapping).
    SpindleReverse,
    /// Spindle on in this direction.
    Spindle(SpindleDir),
    /// Rapid shift in the plane by (first, second), e.g. off the wall
    /// before a boring bar retracts.
    Shift(f64, f64),
}

/// One hole.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Hole {
    /// Cycle and the line that called it.
    pub cycle: CycleRef,
    /// Position in the plane (first, second), absolute.
    pub at: [f64; 2],
    /// The R plane (start of the feed), absolute level along the tool axis.
    pub r: f64,
    /// First move up to the R plane when the tool is below it (G-code
    /// cycles); otherwise the tool goes to the R plane from where it is.
    pub up_to_r_first: bool,
    /// Level the tool travels to the hole at (from where it is, in one
    /// rapid move); `None`: the level it is at.
    pub travel_level: Option<f64>,
    /// The cycle from the R plane on.
    pub ops: Vec<Op>,
}

/// Positions the tool over the hole (rapid in the plane at the current
/// level, raised to the R plane first if it is below and the cycle asks
/// so), rapids down to the R plane, then runs the ops. Fails when the
/// canned cycles' moves exceed the run's budget ([`Machine::charge_cycle`]).
pub(crate) fn drill(m: &mut Machine<'_>, hole: &Hole) -> Result<(), Fail> {
    m.charge_cycle(hole.ops.len() + 2)?;
    let [a, b, n] = m.state.plane.axes();
    let saved = m.cycle;
    m.cycle = Some(hole.cycle);
    let level = |m: &Machine<'_>| m.xyz_pos()[n];
    let at = |m: &Machine<'_>, first: Option<f64>, second: Option<f64>, normal: Option<f64>| {
        let mut p = [None; 3];
        p[a] = first;
        p[b] = second;
        p[n] = normal;
        let _ = m;
        p
    };
    if hole.up_to_r_first && level(m) < hole.r {
        let p = at(m, None, None, Some(hole.r));
        m.move_xyz(true, p[0], p[1], p[2]);
    }
    let cur = m.xyz_pos();
    let travel = hole.travel_level.filter(|l| *l != cur[n]);
    if cur[a] != hole.at[0] || cur[b] != hole.at[1] || travel.is_some() {
        let p = at(m, Some(hole.at[0]), Some(hole.at[1]), travel);
        m.move_xyz(true, p[0], p[1], p[2]);
    }
    if level(m) != hole.r {
        let p = at(m, None, None, Some(hole.r));
        m.move_xyz(true, p[0], p[1], p[2]);
    }
    let direction = m.state.spindle;
    for op in &hole.ops {
        match *op {
            Op::Rapid(z) | Op::Feed(z) => {
                let p = at(m, None, None, Some(z));
                m.move_xyz(matches!(op, Op::Rapid(_)), p[0], p[1], p[2]);
            }
            Op::FeedAt(z, f) => {
                let saved_feed = m.feed;
                m.feed = f;
                let p = at(m, None, None, Some(z));
                m.move_xyz(false, p[0], p[1], p[2]);
                m.feed = saved_feed;
            }
            Op::Dwell(s) => m.dwell(s),
            Op::SpindleStop => m.set_spindle(SpindleDir::Off),
            Op::SpindleReverse => m.set_spindle(match direction {
                SpindleDir::Ccw => SpindleDir::Cw,
                _ => SpindleDir::Ccw,
            }),
            Op::Spindle(d) => m.set_spindle(d),
            Op::Shift(da, db) => {
                let c = m.xyz_pos();
                let p = at(m, Some(c[a] + da), Some(c[b] + db), None);
                m.move_xyz(true, p[0], p[1], p[2]);
            }
        }
    }
    m.cycle = saved;
    Ok(())
}

/// Pecks from `r` down to `bottom` by `q` (G83 / G73 style): each peck
/// feeds `q` deeper; between pecks the tool rapids back to `r` (full
/// retract) or up by `clearance` (chip breaking), and with full retract
/// comes back down at rapid to `clearance` above the last depth. The last
/// feed reaches `bottom`; the retract after it is the caller's.
pub(crate) fn pecks(
    ops: &mut Vec<Op>,
    r: f64,
    bottom: f64,
    q: f64,
    clearance: f64,
    full_retract: bool,
) -> Result<(), String> {
    let q = q.abs();
    let count = ((r - bottom) / q).ceil();
    if count.is_nan() || count > MAX_PECKS {
        return Err(format!(
            "a peck of {q} mm from {r} down to {bottom} makes more than {MAX_PECKS} pecks"
        ));
    }
    let mut depth = r;
    loop {
        depth = (depth - q).max(bottom);
        ops.push(Op::Feed(depth));
        if depth <= bottom {
            return Ok(());
        }
        if full_retract {
            ops.push(Op::Rapid(r));
        }
        ops.push(Op::Rapid(depth + clearance));
    }
}

/// Most pecks of one hole (a peck depth of zero or a micrometre for a deep
/// hole is a mistake, not a program).
const MAX_PECKS: f64 = 100_000.0;
