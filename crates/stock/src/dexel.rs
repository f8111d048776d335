//! Solid intervals along one ray, and their subtraction.

use serde::{Deserialize, Serialize};
use smallvec::SmallVec;

use crate::tolerance::SLIVER_MM;

/// The move id of a face of the stock that no move has cut.
pub const UNCUT: u32 = u32::MAX;

/// One solid interval of a ray, with the move that last cut each end.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Segment {
    /// Where the material starts along the ray (mm, part frame coordinate).
    pub lo: f64,
    /// Where it ends.
    pub hi: f64,
    /// The move that made the lower end ([`UNCUT`]: the stock's own face).
    pub lo_move: u32,
    /// The move that made the upper end.
    pub hi_move: u32,
}

/// The sorted, disjoint solid intervals of one ray; one is kept inline.
pub type Ray = SmallVec<[Segment; 1]>;

/// Removes the open interval (a, b) from the ray; the ends it creates
/// remember `id`. Intervals shorter than `SLIVER_MM` disappear.
pub fn subtract(ray: &mut Ray, a: f64, b: f64, id: u32) {
    // Fast path: nothing overlaps.
    if !(a < b) || ray.is_empty() || b <= ray[0].lo || a >= ray[ray.len() - 1].hi {
        return;
    }
    let mut i = 0;
    while i < ray.len() {
        let s = ray[i];
        if s.hi <= a {
            i += 1;
            continue;
        }
        if s.lo >= b {
            break;
        }
        let keep_low = s.lo < a && a - s.lo >= SLIVER_MM;
        let keep_high = s.hi > b && s.hi - b >= SLIVER_MM;
        match (keep_low, keep_high) {
            (true, true) => {
                ray[i].hi = a;
                ray[i].hi_move = id;
                ray.insert(
                    i + 1,
                    Segment {
                        lo: b,
                        hi: s.hi,
                        lo_move: id,
                        hi_move: s.hi_move,
                    },
                );
                return;
            }
            (true, false) => {
                ray[i].hi = a;
                ray[i].hi_move = id;
                i += 1;
            }
            (false, true) => {
                ray[i].lo = b;
                ray[i].lo_move = id;
                return;
            }
            (false, false) => {
                ray.remove(i);
            }
        }
    }
}

/// Whether the coordinate `t` is inside the solid of the ray (closed
/// intervals).
pub fn contains(ray: &[Segment], t: f64) -> bool {
    let i = ray.partition_point(|s| s.hi < t);
    i < ray.len() && ray[i].lo <= t
}

/// Adds the closed interval [a, b] of material (ends marked [`UNCUT`]),
/// merging with what it touches.
pub fn add(ray: &mut Ray, a: f64, b: f64) {
    if !(a < b) {
        return;
    }
    let first = ray.partition_point(|s| s.hi < a);
    let mut last = first;
    let mut seg = Segment {
        lo: a,
        hi: b,
        lo_move: UNCUT,
        hi_move: UNCUT,
    };
    while last < ray.len() && ray[last].lo <= b {
        let s = ray[last];
        if s.lo < seg.lo {
            seg.lo = s.lo;
            seg.lo_move = s.lo_move;
        }
        if s.hi > seg.hi {
            seg.hi = s.hi;
            seg.hi_move = s.hi_move;
        }
        last += 1;
    }
    ray.drain(first..last);
    ray.insert(first, seg);
}

/// Subtracts the union of the spans from the ray.
pub fn remove_spans(ray: &mut Ray, spans: &mut [crate::kernel::Span], id: u32) {
    match spans.len() {
        0 => {}
        1 => subtract(ray, spans[0].lo, spans[0].hi, id),
        _ => {
            spans.sort_by(|a, b| a.lo.total_cmp(&b.lo));
            let mut cur = spans[0];
            for s in &spans[1..] {
                if s.lo <= cur.hi {
                    cur.hi = cur.hi.max(s.hi);
                } else {
                    subtract(ray, cur.lo, cur.hi, id);
                    cur = *s;
                }
            }
            subtract(ray, cur.lo, cur.hi, id);
        }
    }
}
