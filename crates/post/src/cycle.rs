//! Canned drilling cycles (`CYCLE/…`) expanded into plain moves: each hole
//! becomes rapid and feed moves along the hole axis (the tool axis of its
//! `GOTO`), dwells and, for tapping, spindle reversals. Pure geometry: the
//! program stage hands the moves on as CL points.
//!
//! Heights are measured along the hole axis from the hole point (the
//! `GOTO`'s point, the top of the hole): the feed starts at `feed_start`
//! (the R plane of G81…), the bottom is at `−depth`, the tool leaves the
//! hole to `retract` (the R plane when the CL gives none, as G99). The
//! motion of each kind follows the canned cycles of ISO 6983-1 controls as
//! LinuxCNC documents them (G81 drill, G82 with dwell, G83 peck, G73 chip
//! break, G84 tap, G85/G89 bore with feed out); the small distances a
//! control takes by itself (the peck clearance) are LinuxCNC's.

use kinpost_cl::{Cycle, CycleKind, Dwell};

/// After a full retract, a peck cycle comes back down in rapid to this far
/// above the depth already drilled, then feeds on; a chip-breaking cycle
/// without its own back-off (Creo `BACK`) backs off this much. 0.254 mm
/// (0.010 in) is what LinuxCNC's G83 and G73 take (LinuxCNC G-code
/// reference, "G83 Peck Drilling", "G73 Drilling Cycle with Chip
/// Breaking").
pub const PECK_CLEARANCE_MM: f64 = 0.254;

/// The most pecks of one hole: a peck far smaller than the depth (a unit
/// mistake) would write millions of blocks.
pub const MAX_PECKS: usize = 10_000;

/// Moves shorter than this (mm) are not written: the tool is there already
/// (the first hole under the point the CL left the tool at).
const SAME_POINT_MM: f64 = 1e-9;

/// Why a cycle cannot be expanded.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CycleError {
    /// No depth (`FEDTO`, `DEPTH`).
    #[error("CYCLE has no depth (FEDTO or DEPTH): how deep to drill is not known")]
    NoDepth,
    /// A distance that is not a positive finite number.
    #[error("CYCLE {what} is {value} mm: it must be a finite number above 0")]
    Distance {
        /// Which parameter.
        what: &'static str,
        /// Its value.
        value: f64,
    },
    /// The pecks of one hole would be too many.
    #[error("CYCLE: {pecks} pecks of {peck_mm} mm for one hole, more than {max}")]
    TooManyPecks {
        /// Pecks needed.
        pecks: f64,
        /// The peck.
        peck_mm: f64,
        /// [`MAX_PECKS`].
        max: usize,
    },
    /// A cycle kind with no agreed motion.
    #[error(
        "CYCLE/{0}: no motion is known for this cycle kind (DRILL, DEEP, BRKCHP, TAP, BORE, REAM, FACE, CSINK, THRU are)"
    )]
    Kind(String),
    /// No feed rate for the cycle.
    #[error("CYCLE has no feed rate and no FEDRAT is in force")]
    NoFeed,
    /// Tapping with the spindle off.
    #[error(
        "CYCLE/TAP reverses the spindle, but no spindle speed is in force: give SPINDL/rpm before it"
    )]
    TapWithoutSpindle,
    /// A feed or dwell per revolution with the spindle off.
    #[error("CYCLE gives a {0} per revolution, but no spindle speed is in force")]
    PerRevWithoutSpindle(&'static str),
}

/// A cycle's parameters resolved for expansion: distances in mm, feeds in
/// mm/min, dwell in seconds.
#[derive(Debug, Clone, PartialEq)]
pub struct HoleCycle {
    /// The motion.
    pub motion: HoleMotion,
    /// Depth below the hole point (positive).
    pub depth_mm: f64,
    /// Height of the feed start (R plane) above the hole point.
    pub feed_start_mm: f64,
    /// Height the tool leaves the hole to.
    pub retract_mm: f64,
    /// Feed of the cutting moves, mm/min.
    pub feed_mm_min: f64,
    /// Dwell at the bottom, seconds (0: none).
    pub dwell_s: f64,
}

/// What the tool does in a hole.
#[derive(Debug, Clone, PartialEq)]
pub enum HoleMotion {
    /// Feed to depth, rapid out (G81, G82 with a dwell).
    Drill,
    /// Pecks: feed `first`, then `next`, rapid out to the feed start after
    /// each (G83).
    Peck {
        /// First peck.
        first_mm: f64,
        /// Later pecks.
        next_mm: f64,
    },
    /// Pecks with a back-off of `back_off_mm` after each, out to the feed
    /// start after every `full_retract_every` pecks (G73; `None`: never).
    ChipBreak {
        /// First peck.
        first_mm: f64,
        /// Later pecks.
        next_mm: f64,
        /// Back-off after a peck.
        back_off_mm: f64,
        /// Leave the hole after this many pecks.
        full_retract_every: Option<u32>,
    },
    /// Tapping: feed in, spindle reversed, feed out, spindle as before
    /// (G84).
    Tap,
    /// Feed in, feed out (G85, G89 with a dwell).
    Bore,
}

/// One step of an expanded hole.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum HoleStep {
    /// Rapid to the point.
    Rapid([f64; 3]),
    /// Feed to the point at the cycle's feed.
    Feed([f64; 3]),
    /// Dwell, seconds.
    Dwell(f64),
    /// The spindle turns the other way (`true`) or as before (`false`).
    ReverseSpindle(bool),
}

fn positive(what: &'static str, value: f64) -> Result<f64, CycleError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(CycleError::Distance { what, value })
    }
}

impl HoleCycle {
    /// Whether `cycle` is a peck or chip-breaking cycle that gives no peck
    /// length: it is drilled in one peck, and the post says so.
    pub fn single_peck(cycle: &Cycle) -> bool {
        matches!(cycle.kind, CycleKind::Deep | CycleKind::BreakChip) && cycle.peck_mm.is_none()
    }

    /// The cycle of a `CYCLE` statement with the feed (mm/min) and spindle
    /// speed (rpm) in force.
    pub fn resolve(
        cycle: &Cycle,
        feed_mm_min: Option<f64>,
        rpm: Option<f64>,
    ) -> Result<HoleCycle, CycleError> {
        // A depth of 0 (NX writes `FEDTO,0` when the hole point is the
        // bottom, as for a spot or countersink at the point) feeds from the
        // feed start down to the hole point.
        let depth_mm = cycle.depth_mm.ok_or(CycleError::NoDepth)?;
        if !(depth_mm.is_finite() && depth_mm >= 0.0) {
            return Err(CycleError::Distance {
                what: "depth",
                value: depth_mm,
            });
        }
        // No RAPTO/CLEAR: the feed starts at the hole point.
        let feed_start_mm = cycle.feed_start_mm.unwrap_or(0.0);
        if !feed_start_mm.is_finite() {
            return Err(CycleError::Distance {
                what: "feed start (RAPTO, CLEAR)",
                value: feed_start_mm,
            });
        }
        let retract_mm = cycle.retract_mm.unwrap_or(feed_start_mm);
        if !retract_mm.is_finite() {
            return Err(CycleError::Distance {
                what: "retract (RTRCTO, RETURN)",
                value: retract_mm,
            });
        }
        let per_rev = |what| rpm.ok_or(CycleError::PerRevWithoutSpindle(what));
        let mut feed = match cycle.feed {
            Some(f) if f.unit.per_revolution() => f.value * per_rev("feed")?,
            Some(f) => f.value,
            None => feed_mm_min.ok_or(CycleError::NoFeed)?,
        };
        let dwell_s = match cycle.dwell {
            None => 0.0,
            Some(Dwell::Seconds(s)) => s,
            Some(Dwell::Revolutions(n)) => n * 60.0 / per_rev("dwell")?,
        };
        // No peck given (NX "Drill, Deep" with no increment): one peck,
        // the whole feed (see [`HoleCycle::single_peck`]).
        let whole = depth_mm + feed_start_mm.max(0.0);
        let peck = || -> Result<(f64, f64), CycleError> {
            let Some(first) = cycle.peck_mm else {
                return Ok((whole.max(f64::MIN_POSITIVE), whole.max(f64::MIN_POSITIVE)));
            };
            let first = positive("peck", first)?;
            let next = positive("later peck", cycle.next_peck_mm.unwrap_or(first))?;
            let pecks = (depth_mm + feed_start_mm.max(0.0)) / first.min(next);
            if pecks > MAX_PECKS as f64 {
                return Err(CycleError::TooManyPecks {
                    pecks: pecks.ceil(),
                    peck_mm: first.min(next),
                    max: MAX_PECKS,
                });
            }
            Ok((first, next))
        };
        let motion = match &cycle.kind {
            CycleKind::Drill | CycleKind::Face | CycleKind::Countersink | CycleKind::Thru => {
                HoleMotion::Drill
            }
            CycleKind::Deep => {
                let (first_mm, next_mm) = peck()?;
                HoleMotion::Peck { first_mm, next_mm }
            }
            CycleKind::BreakChip => {
                let (first_mm, next_mm) = peck()?;
                HoleMotion::ChipBreak {
                    first_mm,
                    next_mm,
                    back_off_mm: positive(
                        "back-off (BACK)",
                        cycle.back_off_mm.unwrap_or(PECK_CLEARANCE_MM),
                    )?,
                    full_retract_every: cycle.full_retract_every.filter(|&n| n > 0),
                }
            }
            CycleKind::Tap => {
                if rpm.is_none() {
                    return Err(CycleError::TapWithoutSpindle);
                }
                // A pitch fixes the feed: one pitch per revolution.
                if let Some(p) = cycle.pitch_mm {
                    feed = positive("pitch", p)? * per_rev("tapping pitch")?;
                }
                HoleMotion::Tap
            }
            CycleKind::Bore | CycleKind::Ream => HoleMotion::Bore,
            CycleKind::Other(word) => return Err(CycleError::Kind(word.clone())),
        };
        Ok(HoleCycle {
            motion,
            depth_mm,
            feed_start_mm,
            retract_mm,
            feed_mm_min: positive("feed", feed)?,
            dwell_s: if dwell_s.is_finite() && dwell_s > 0.0 {
                dwell_s
            } else {
                0.0
            },
        })
    }

    /// The steps of the hole at `hole` with axis `axis` (unit), the tool
    /// being at `from`: up along the axis to the feed start if it is below
    /// it, across to the hole axis at that height, down to the feed start
    /// in rapid, the cycle, out to the retract height. The last step leaves
    /// the tool at `hole + retract · axis`.
    pub fn expand(&self, hole: [f64; 3], axis: [f64; 3], from: [f64; 3]) -> Vec<HoleStep> {
        self.steps(hole, axis, Some(from))
    }

    /// The steps of the first hole of a program, where the tool is not
    /// known to be anywhere yet: a rapid to the hole axis at the retract
    /// height (or the feed start, if higher), down to the feed start, the
    /// cycle, out (see [`HoleCycle::expand`]).
    pub fn expand_from_unknown(&self, hole: [f64; 3], axis: [f64; 3]) -> Vec<HoleStep> {
        self.steps(hole, axis, None)
    }

    fn steps(&self, hole: [f64; 3], axis: [f64; 3], from: Option<[f64; 3]>) -> Vec<HoleStep> {
        let at = |h: f64| [0, 1, 2].map(|i| hole[i] + h * axis[i]);
        let r = self.feed_start_mm;
        let mut steps = Steps {
            out: Vec::new(),
            at: from.unwrap_or([f64::NAN; 3]),
        };
        match from {
            Some(from) => {
                let height = (0..3).map(|i| (from[i] - hole[i]) * axis[i]).sum::<f64>();
                if height < r {
                    steps.rapid([0, 1, 2].map(|i| from[i] + (r - height) * axis[i]));
                }
                steps.rapid(at(height.max(r)));
            }
            None => {
                let clear = self.retract_mm.max(r);
                steps.out.push(HoleStep::Rapid(at(clear)));
                steps.at = at(clear);
            }
        }
        steps.rapid(at(r));
        let bottom = -self.depth_mm;
        match self.motion {
            HoleMotion::Drill => steps.feed(at(bottom)),
            HoleMotion::Bore | HoleMotion::Tap => steps.feed(at(bottom)),
            HoleMotion::Peck { first_mm, next_mm } => {
                let mut done = r;
                let mut peck = first_mm;
                loop {
                    // (Not above R: rs274ngc's G83 would go there for a
                    // peck under the clearance; such holes are never
                    // written as G83, see `native_cycle`.)
                    if done < r {
                        steps.rapid(at((done + PECK_CLEARANCE_MM).min(r)));
                    }
                    done = (done - peck).max(bottom);
                    steps.feed(at(done));
                    if done <= bottom {
                        break;
                    }
                    steps.rapid(at(r));
                    peck = next_mm;
                }
            }
            HoleMotion::ChipBreak {
                first_mm,
                next_mm,
                back_off_mm,
                full_retract_every,
            } => {
                let mut done = r;
                let mut peck = first_mm;
                let mut count = 0u32;
                let mut out_of_hole = false;
                loop {
                    if out_of_hole {
                        steps.rapid(at((done + PECK_CLEARANCE_MM).min(r)));
                    }
                    done = (done - peck).max(bottom);
                    steps.feed(at(done));
                    count += 1;
                    if done <= bottom {
                        break;
                    }
                    out_of_hole = full_retract_every.is_some_and(|n| count.is_multiple_of(n));
                    if out_of_hole {
                        steps.rapid(at(r));
                    } else {
                        steps.rapid(at((done + back_off_mm).min(r)));
                    }
                    peck = next_mm;
                }
            }
        }
        if self.dwell_s > 0.0 {
            steps.out.push(HoleStep::Dwell(self.dwell_s));
        }
        match self.motion {
            HoleMotion::Tap => {
                steps.out.push(HoleStep::ReverseSpindle(true));
                steps.feed(at(r));
                steps.out.push(HoleStep::ReverseSpindle(false));
            }
            HoleMotion::Bore => steps.feed(at(r)),
            _ => {}
        }
        steps.rapid(at(self.retract_mm));
        steps.out
    }
}

/// The steps so far and where they leave the tool.
struct Steps {
    out: Vec<HoleStep>,
    at: [f64; 3],
}

impl Steps {
    fn far(&self, p: [f64; 3]) -> bool {
        (0..3).map(|i| (p[i] - self.at[i]).powi(2)).sum::<f64>() > SAME_POINT_MM * SAME_POINT_MM
    }

    fn rapid(&mut self, p: [f64; 3]) {
        if self.far(p) {
            self.out.push(HoleStep::Rapid(p));
            self.at = p;
        }
    }

    fn feed(&mut self, p: [f64; 3]) {
        if self.far(p) {
            self.out.push(HoleStep::Feed(p));
            self.at = p;
        }
    }
}

#[cfg(test)]
mod tests;
