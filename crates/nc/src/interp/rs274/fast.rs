//! The hot path: a line of literal axis words, perhaps with `G0`/`G1` and
//! `F` (`X12.345 Y-3.2 Z44.1 A12.5 C-93.25 F1200`, `G1 X… F…`), executed
//! without the general block machinery. Anything else — a comment, a
//! parameter, another word, a repeated word, an error to report — leaves
//! it to the general path, which reads the line again from its start.

use super::*;

impl Interp<'_, '_> {
    /// Executes a plain motion line; `false` (nothing done) when the line
    /// is not one.
    #[inline]
    pub(super) fn fast_line(&mut self, b: &[u8], start: usize) -> bool {
        let mut motion = match self.motion {
            Motion::Rapid | Motion::Linear => Some(self.motion),
            _ => None,
        };
        let mut set_motion = false;
        let mut values = [0.0f64; 9];
        let mut has = 0u32;
        let mut no_point = 0u32;
        let mut feed = None;
        let mut i = start;
        while i < b.len() {
            let c = b[i];
            if c == b' ' || c == b'\t' {
                i += 1;
                continue;
            }
            let letter = c.to_ascii_uppercase();
            let Some(n) = read_number(&b[i + 1..]) else {
                return false;
            };
            i += 1 + n.len;
            match letter {
                b'G' if !set_motion && (n.value == 0.0 || n.value == 1.0) => {
                    motion = Some(if n.value == 0.0 {
                        Motion::Rapid
                    } else {
                        Motion::Linear
                    });
                    set_motion = true;
                }
                b'F' if feed.is_none() && n.value >= 0.0 => feed = Some(n.value),
                _ => {
                    let Some(k) = AXIS_LETTERS.iter().position(|l| *l == letter) else {
                        return false;
                    };
                    if has & (1 << k) != 0 || self.letter_axis[k].is_none() {
                        return false;
                    }
                    has |= 1 << k;
                    values[k] = n.value;
                    if !n.has_point {
                        no_point |= 1 << k;
                    }
                }
            }
        }
        let Some(motion) = motion else {
            return false;
        };
        let inverse = self.m.feed_mode == FeedMode::InverseTime;
        if motion == Motion::Linear && has != 0 {
            // The general path reports a missing feed.
            let known = match feed {
                Some(f) => f > 0.0,
                None => !inverse && self.m.feed > 0.0,
            };
            if !known {
                return false;
            }
        }
        if set_motion {
            self.set_motion(motion);
        }
        if let Some(f) = feed {
            self.m.feed = if inverse { f } else { f * self.m.unit() };
        }
        if has == 0 {
            return true;
        }
        self.fast_move(motion, &values, has, no_point);
        true
    }

    #[inline]
    fn fast_move(&mut self, motion: Motion, values: &[f64; 9], has: u32, no_point: u32) {
        let fanuc_units = self.flavour == Flavour::Fanuc && !self.m.options.fanuc_calculator_input;
        let increment = if self.m.inch { 1e-4 } else { 1e-3 };
        let mut t = self.m.pos;
        let mut travel = [0.0; MAX_AXES];
        let (mut programmed, mut turned) = (0u32, 0u32);
        for (k, value) in values.iter().enumerate() {
            if has & (1 << k) == 0 {
                continue;
            }
            let Some(i) = self.letter_axis[k] else {
                continue;
            };
            let mut v = *value;
            if fanuc_units && no_point & (1 << k) != 0 {
                v *= increment;
            }
            let v = v * self.m.unit_of(i);
            programmed |= 1 << i;
            if self.incremental {
                if self.m.axes[i].endless {
                    travel[i] = v;
                    t[i] = super::super::machine::wrap(self.m.pos[i] + v);
                    turned |= 1 << i;
                } else {
                    t[i] = self.m.pos[i] + v;
                }
            } else if self.m.axes[i].endless {
                let (e, d) = self.m.rotary_target(i, v, RotaryMode::Continuous);
                t[i] = e;
                travel[i] = d;
                turned |= 1 << i;
            } else {
                t[i] = v;
            }
        }
        let kind = if motion == Motion::Rapid {
            MotionKind::Rapid
        } else {
            MotionKind::Linear
        };
        self.m.move_to(kind, &t, &travel, turned, programmed);
    }
}
