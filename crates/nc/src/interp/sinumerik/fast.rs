//! The hot path: a line of one-letter axis words with literal values
//! (`X=459.000 Y=8.807 Z361.368 B0.000 A=DC(0.000)`), perhaps `G0`/`G1`
//! and `F`, executed without the general block machinery. Anything else
//! leaves the line to the general path, which reads it again.

use super::*;

impl Interp<'_, '_> {
    /// Executes a plain motion line; `false` (nothing done) when the line
    /// is not one.
    #[inline]
    pub(super) fn fast_line(&mut self, b: &[u8], start: usize) -> bool {
        if self.mcall.is_some() {
            return false;
        }
        let mut motion = self.motion;
        let mut set_motion = false;
        let mut values = [0.0f64; MAX_AXES];
        let mut modes = [None; MAX_AXES];
        let mut axes = 0u32;
        let mut feed = None;
        let mut i = start;
        while i < b.len() {
            let c = b[i];
            if c == b' ' || c == b'\t' {
                i += 1;
                continue;
            }
            if c == b';' {
                break;
            }
            let letter = c.to_ascii_uppercase();
            if !letter.is_ascii_uppercase() {
                return false;
            }
            i += 1;
            let eq = b.get(i) == Some(&b'=');
            if eq {
                i += 1;
            }
            let mut mode = AxisMode::Plain;
            if eq && b.get(i).is_some_and(u8::is_ascii_alphabetic) {
                let Some((m, len)) = rotary_function(&b[i..]) else {
                    return false;
                };
                mode = m;
                i += len;
            }
            let Some(n) = read_number(&b[i..]) else {
                return false;
            };
            i += n.len;
            if mode != AxisMode::Plain {
                if b.get(i) != Some(&b')') {
                    return false;
                }
                i += 1;
            }
            // A word ends at a blank, a comment or the end of the line.
            if !matches!(b.get(i), None | Some(b' ' | b'\t' | b';')) {
                return false;
            }
            match letter {
                b'G' if !eq && !set_motion && (n.value == 0.0 || n.value == 1.0) => {
                    motion = if n.value == 0.0 {
                        Motion::Rapid
                    } else {
                        Motion::Linear
                    };
                    set_motion = true;
                }
                b'F' if feed.is_none() && n.value >= 0.0 && mode == AxisMode::Plain => {
                    feed = Some(n.value)
                }
                _ => {
                    let Some(k) = self.letter_axis[usize::from(letter - b'A')] else {
                        return false;
                    };
                    if axes & (1 << k) != 0 {
                        return false;
                    }
                    axes |= 1 << k;
                    values[k] = n.value;
                    modes[k] = Some(mode);
                }
            }
        }
        if !matches!(motion, Motion::Rapid | Motion::Linear)
            || axes != 0 && !self.motion_set && !set_motion
        {
            return false;
        }
        let inverse = self.m.feed_mode == FeedMode::InverseTime;
        if motion == Motion::Linear && axes != 0 && !feed.map_or(self.m.feed > 0.0, |f| f > 0.0) {
            return false;
        }
        let Ok((t, travel, turned)) = self.targets_of(axes, &values, &modes, false, 0) else {
            return false;
        };
        if set_motion {
            self.set_motion(motion);
        }
        if let Some(f) = feed {
            self.m.feed = if inverse { f } else { f * self.m.unit() };
        }
        if axes != 0 {
            let kind = if motion == Motion::Rapid {
                MotionKind::Rapid
            } else {
                MotionKind::Linear
            };
            let before = self.m.xyz_pos();
            self.m.move_to(kind, &t, &travel, turned, axes);
            self.note_tangent(before, None);
        }
        true
    }
}

/// `DC(`, `ACP(`, `ACN(`, `AC(`, `IC(` at the start of `b`: the mode and
/// the bytes it took.
fn rotary_function(b: &[u8]) -> Option<(AxisMode, usize)> {
    for (name, mode) in [
        (&b"DC("[..], AxisMode::Dc),
        (b"ACP(", AxisMode::Acp),
        (b"ACN(", AxisMode::Acn),
        (b"AC(", AxisMode::Ac),
        (b"IC(", AxisMode::Ic),
    ] {
        if b.len() >= name.len() && b[..name.len()].eq_ignore_ascii_case(name) {
            return Some((mode, name.len()));
        }
    }
    None
}
