//! Native canned cycles: where the checked moves of a CL hole are exactly
//! what a control's drilling cycle does on the program's X, Y, Z, the
//! program writes the cycle (`G81`, `MCALL CYCLE81`, `CYCL DEF 200`, …)
//! instead of its moves.
//!
//! The test is on the values as written, not on the geometry: the cycle
//! of the hole, its heights measured along the program's −Z from the top
//! of the hole (the bottom block's Z plus the depth), is expanded by the
//! same rules as the CL's (see [`crate::cycle`]), from where the tool
//! stands, and every move must round to the block the closed-loop check
//! passed, motion for motion, with X, Y and every other axis as before the
//! hole. Then the control, running the cycle, makes the checked blocks:
//! the hole's axis is the program's Z, the rotary axes stand still, and
//! nothing about the machine needs to be known here. A hole that fails
//! the test (a tilted hole on a table/table machine, a rotary move into
//! the hole, a peck the control cannot make) is written as its moves.

use kinpost_nc::{Hole, HoleKind, Motion};

use crate::cycle::{HoleCycle, HoleMotion, HoleStep, PECK_CLEARANCE_MM};
use crate::native_arc::ProgramAxes;

/// A checked block of a hole, as the check holds it.
#[derive(Debug, Clone, Copy)]
pub struct HoleBlock<'a> {
    /// The values handed over (unrounded), machine order.
    pub exact: &'a [f64],
    /// The values as written.
    pub written: &'a [f64],
    /// Rapid or feed.
    pub motion: Motion,
    /// The feed word of a feed block.
    pub feed: Option<f64>,
}

/// The kind and peck of the control's cycle that makes `cycle`'s motion,
/// if one does: pecks of one length (a first peck that differs is the
/// control's business only in Sinumerik's CYCLE83, which is not written),
/// and a chip break that backs off as LinuxCNC's G73 does and never leaves
/// the hole. A first peck that reaches the bottom is a plain drill
/// (SOLIDWORKS CAM's `DEEP2,…,1STPECK,5.,SUBPECK,2.` on shallow holes).
pub fn kind_of(cycle: &HoleCycle) -> Option<(HoleKind, f64)> {
    let whole = cycle.depth_mm + cycle.feed_start_mm;
    Some(match cycle.motion {
        HoleMotion::Drill => (HoleKind::Drill, 0.0),
        HoleMotion::Peck { first_mm, .. } | HoleMotion::ChipBreak { first_mm, .. }
            if first_mm >= whole =>
        {
            (HoleKind::Drill, 0.0)
        }
        HoleMotion::Peck { first_mm, next_mm } if first_mm == next_mm => (HoleKind::Peck, first_mm),
        HoleMotion::ChipBreak {
            first_mm,
            next_mm,
            back_off_mm,
            full_retract_every: None,
        } if first_mm == next_mm && back_off_mm == PECK_CLEARANCE_MM => {
            (HoleKind::ChipBreak, first_mm)
        }
        HoleMotion::Tap => (HoleKind::Tap, 0.0),
        HoleMotion::Bore => (HoleKind::Bore, 0.0),
        _ => return None,
    })
}

/// The hole the blocks make, and how many of them come first as plain
/// blocks (the rapid up to the feed start when the tool stands below it,
/// which the controls do in different ways), if the blocks are exactly the
/// cycle's moves (see the module's documentation). `start`: the values
/// written before the hole; `round`: the writer's rounding of a row of
/// values; `spindle`: the spindle speed in force and whether it turns
/// counter-clockwise.
pub fn fit(
    cycle: &HoleCycle,
    axes: &ProgramAxes,
    start: &[f64],
    blocks: &[HoleBlock<'_>],
    (rpm, ccw): (Option<f64>, bool),
    mut round: impl FnMut(&[f64], &mut [f64]),
) -> Option<(usize, Hole)> {
    let (kind, peck) = kind_of(cycle)?;
    let [x, y, z] = axes.xyz;
    if blocks.iter().any(|b| {
        axes.others
            .iter()
            .any(|&i| b.written[i].to_bits() != start[i].to_bits())
    }) {
        return None;
    }
    // The bottom: the deepest feed block.
    let bottom = blocks
        .iter()
        .filter(|b| b.motion == Motion::Feed)
        .min_by(|a, b| a.written[z].total_cmp(&b.written[z]))?;
    let feed = bottom.feed?;
    if blocks
        .iter()
        .any(|b| b.motion == Motion::Feed && b.feed.map(f64::to_bits) != Some(feed.to_bits()))
    {
        return None;
    }
    // Heights along the hole axis, from the exact bottom (no rounding
    // twice), rounded as the writer writes Z.
    let top_exact = bottom.exact[z] + cycle.depth_mm;
    let mut row = bottom.exact.to_vec();
    let mut out = vec![0.0; row.len()];
    let mut as_z = |v: f64| {
        row[z] = v;
        round(&row, &mut out);
        out[z]
    };
    let (top, r, retract) = (
        as_z(top_exact),
        as_z(top_exact + cycle.feed_start_mm),
        as_z(top_exact + cycle.retract_mm),
    );
    // The peck as the cycle's Q writes it: a peck the word rounds is not the
    // one checked, and the moves below then differ. A peck shorter than the
    // re-approach clearance (or the chip break's back-off) sends LinuxCNC's
    // G83 and G73 above R on the way back down (rs274ngc does not stop at
    // R there, as the expansion does): such a hole is written as moves.
    let peck = as_z(peck);
    if matches!(kind, HoleKind::Peck | HoleKind::ChipBreak) && peck < PECK_CLEARANCE_MM {
        return None;
    }
    let (hx, hy, bz) = (bottom.written[x], bottom.written[y], bottom.written[z]);
    // Below the feed start, the tool first rises to it, in a block of its
    // own.
    let mut from = [start[x], start[y], start[z]];
    let mut prefix = 0;
    if from[2] < r {
        let b = blocks.first()?;
        let up = [from[0], from[1], r];
        if b.motion != Motion::Rapid || !same_point(b, axes, up) {
            return None;
        }
        from = up;
        prefix = 1;
    }
    // The control's cycle, on the program's X, Y, Z: the heights from the
    // rounded top, so that the moves are the ones written.
    let control = HoleCycle {
        motion: match kind {
            HoleKind::Peck => HoleMotion::Peck {
                first_mm: peck,
                next_mm: peck,
            },
            HoleKind::ChipBreak => HoleMotion::ChipBreak {
                first_mm: peck,
                next_mm: peck,
                back_off_mm: PECK_CLEARANCE_MM,
                full_retract_every: None,
            },
            HoleKind::Drill => HoleMotion::Drill,
            _ => cycle.motion.clone(),
        },
        depth_mm: top - bz,
        feed_start_mm: r - top,
        retract_mm: retract - top,
        ..cycle.clone()
    };
    let mut moves = blocks[prefix..].iter();
    let (mut want, mut rounded) = (row, out);
    for step in control.expand([hx, hy, top], [0.0, 0.0, 1.0], from) {
        let (motion, p) = match step {
            HoleStep::Rapid(p) => (Motion::Rapid, p),
            HoleStep::Feed(p) => (Motion::Feed, p),
            HoleStep::Dwell(_) | HoleStep::ReverseSpindle(_) => continue,
        };
        let b = moves.next()?;
        want.copy_from_slice(b.exact);
        want[x] = p[0];
        want[y] = p[1];
        want[z] = p[2];
        round(&want, &mut rounded);
        if b.motion != motion || !same_point(b, axes, [rounded[x], rounded[y], rounded[z]]) {
            return None;
        }
    }
    if moves.next().is_some() {
        return None;
    }
    Some((
        prefix,
        Hole {
            kind,
            x: hx,
            y: hy,
            top,
            r,
            bottom: bz,
            retract,
            start_z: from[2],
            peck,
            dwell: cycle.dwell_s,
            feed,
            rpm: rpm.unwrap_or(0.0),
            ccw,
        },
    ))
}

/// Whether block `b` is written at program point `p`.
fn same_point(b: &HoleBlock<'_>, axes: &ProgramAxes, p: [f64; 3]) -> bool {
    axes.xyz
        .iter()
        .zip(p)
        .all(|(&i, v)| b.written[i].to_bits() == v.to_bits())
}
