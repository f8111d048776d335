//! The hot path: `L` blocks of literal axis words (`L X+459.000
//! Y+8.807 Z+361.368 A+0.000 R0 F250`, `… R0 FMAX`), executed without the
//! general word machinery. Anything else (Q parameters, M functions,
//! incremental words, other compensation) leaves the line to the general
//! path, which reads it again.

use super::words::Contour;
use super::*;

impl Interp<'_, '_> {
    /// Executes a plain `L` line; `false` (nothing done) when the line is
    /// not one.
    #[inline]
    pub(super) fn fast_line(&mut self, b: &[u8], start: usize) -> bool {
        if self.modal_call || !matches!(b.get(start..start + 2), Some(b"L " | b"l ")) {
            return false;
        }
        let mut w = Contour::default();
        let mut seen = 0u32;
        let mut i = start + 2;
        while i < b.len() {
            let c = b[i].to_ascii_uppercase();
            if c == b' ' || c == b'\t' {
                i += 1;
                continue;
            }
            if c == b';' {
                break;
            }
            let rest = &b[i..];
            let word_end = rest
                .iter()
                .position(|x| *x == b' ' || *x == b'\t')
                .unwrap_or(rest.len());
            let word = &rest[..word_end];
            if word.eq_ignore_ascii_case(b"R0") {
                w.comp = Some(CutterComp::Off);
            } else if word.eq_ignore_ascii_case(b"FMAX") {
                w.rapid = true;
            } else {
                let Some(n) = read_number(&word[1..]) else {
                    return false;
                };
                if n.len + 1 != word.len() {
                    return false;
                }
                if c == b'F' {
                    if n.value < 0.0 || w.feed.is_some() {
                        return false;
                    }
                    w.feed = Some(n.value);
                } else {
                    let Some(k) = self.letter_axis[usize::from(c.wrapping_sub(b'A')).min(25)]
                    else {
                        return false;
                    };
                    if !c.is_ascii_uppercase() || seen & (1 << k) != 0 {
                        return false;
                    }
                    seen |= 1 << k;
                    w.axis[k] = Some((n.value * self.m.unit_of(k), false));
                }
            }
            i += word_end;
        }
        if seen == 0 || !w.rapid && !w.feed.map_or(self.m.feed > 0.0, |f| f > 0.0) {
            return false;
        }
        if let Some(f) = w.feed {
            self.m.set_feed_mode(FeedMode::PerMinute);
            self.m.feed = f * self.m.unit();
        }
        if let Some(comp) = w.comp {
            self.m.set_cutter_comp(comp);
        }
        w.first_axis_at = Some(start);
        self.straight(&w, false, start).is_ok()
    }
}
