//! The setting of the part program: units, frames (`MSYS`, `CSYS`),
//! `MULTAX`, `MACHIN`, `DELAY`, `CLAMP`, `ORIGIN`, `SETUP` and the
//! `PRESSURE` extension.

use std::io::BufRead;

use kinpost_diag::Diagnostic;

use super::{ClReader, Span};
use crate::{ClEvent, Dwell, Frame, Units};

impl<R: BufRead> ClReader<R> {
    /// `UNITS/MM|INCHES` (also `UNIT/…`): the lengths that follow are in
    /// these units (the reader converts them to mm).
    pub(super) fn units_statement(
        &mut self,
        word: Span,
        args: Span,
    ) -> Result<ClEvent, Diagnostic> {
        self.split(args);
        let units = match self.fields.as_slice() {
            [f] => match self.word(*f).as_str() {
                "MM" | "MILLIMETERS" | "MILLIMETRES" => Units::Mm,
                "IN" | "INCH" | "INCHES" => Units::Inch,
                _ => {
                    return Err(self.error(
                        *f,
                        format!("unknown units `{}`; expected MM or INCHES", self.field(*f)),
                    ));
                }
            },
            [] => return Err(self.error(word, "expected `UNITS/MM` or `UNITS/INCHES`")),
            [_, second, ..] => {
                return Err(self.error((second.0, args.1), "expected `UNITS/MM` or `UNITS/INCHES`"));
            }
        };
        if let Some(given) = self.units_given
            && given != units
        {
            let name = |u: Units| match u {
                Units::Mm => "mm",
                Units::Inch => "inch",
            };
            return Err(self.error(
                (word.0, args.1),
                format!(
                    "the file declares its units as {}, but `--units {}` was given: drop the option or fix the file",
                    name(units),
                    name(given)
                ),
            ));
        }
        self.set_units(units);
        self.units_known = true;
        Ok(ClEvent::Units(units))
    }

    pub(super) fn multax(&mut self, args: Span) -> Result<ClEvent, Diagnostic> {
        self.split(args);
        match self.fields.as_slice() {
            [] => Ok(ClEvent::Multax(true)),
            [f] if self.is(*f, "ON") => Ok(ClEvent::Multax(true)),
            [f] if self.is(*f, "OFF") => Ok(ClEvent::Multax(false)),
            _ => Err(self.error(args, "expected `MULTAX`, `MULTAX/ON` or `MULTAX/OFF`")),
        }
    }

    pub(super) fn pressure(&mut self, word: Span, args: Span) -> Result<ClEvent, Diagnostic> {
        self.split(args);
        let (name, f) = match self.fields.as_slice() {
            [f] => (None, *f),
            [w, f] if self.is_word(*w) => (Some(self.field(*w).to_string()), *f),
            [] => return Err(self.error(word, "expected `PRESSURE/[word,]value`")),
            _ => return Err(self.error(args, "expected `PRESSURE/[word,]value`")),
        };
        let value = self.number(f)?;
        if value < 0.0 {
            return Err(self.error(
                f,
                format!("the pressure must not be negative, got `{}`", self.field(f)),
            ));
        }
        Ok(ClEvent::Pressure { word: name, value })
    }

    /// `MSYS/x,y,z[,xi,xj,xk[,yi,yj,yk]]`: NX's machine coordinate system.
    /// Each operation may have its own (several setups in one file); the
    /// post decides what a change means.
    pub(super) fn msys(&mut self, args: Span) -> Result<ClEvent, Diagnostic> {
        self.split(args);
        let mut count = self.fields.len();
        // A record cut short often keeps its trailing comma.
        if count > 1 && self.fields[count - 1].0 == self.fields[count - 1].1 {
            count -= 1;
        }
        let mut v = [0.0; 9];
        for (k, value) in v.iter_mut().enumerate().take(count) {
            *value = self.number(self.fields[k])?;
        }
        if count < 3 {
            return Err(self.error(args, "MSYS needs at least the origin x,y,z"));
        }
        let origin = self.mm3([v[0], v[1], v[2]]);
        let x = (count >= 6).then_some([v[3], v[4], v[5]]);
        let y = (count >= 9).then_some([v[6], v[7], v[8]]);
        let frame = match (x, y) {
            (Some(x), Some(y)) => match Frame::from_axes(origin, x, y) {
                Ok(frame) => Some(Box::new(frame)),
                Err(e) => {
                    return Err(
                        self.error((self.fields[3].0, self.fields[8].1), format!("MSYS: {e}"))
                    );
                }
            },
            _ => None,
        };
        if count != 3 && count != 9 {
            let detail = match count {
                4 | 5 => "only the origin is used",
                6..=8 => {
                    "the line looks cut short: the origin and the X axis are used, the Y axis is missing"
                }
                _ => "the values after the ninth are ignored",
            };
            self.warn(
                args,
                format!("MSYS has {count} values, expected 3 or 9; {detail}"),
            );
        }
        Ok(ClEvent::MachineSystem {
            origin,
            x,
            y,
            frame,
        })
    }

    /// `CSYS/` with a 3 × 4 matrix, row by row ([`Frame::from_rows`]).
    pub(super) fn csys(&mut self, word: Span, args: Span) -> Result<ClEvent, Diagnostic> {
        self.split(args);
        if self.fields.len() != 12 {
            return Err(self.error(
                if self.fields.is_empty() { word } else { args },
                format!(
                    "CSYS has {} values, expected 12 (a 3x4 matrix)",
                    self.fields.len()
                ),
            ));
        }
        let mut m = [0.0; 12];
        for (k, value) in m.iter_mut().enumerate() {
            *value = self.number(self.fields[k])?;
        }
        for k in [3, 7, 11] {
            m[k] = self.mm(m[k]);
        }
        match Frame::from_rows(m) {
            Ok(frame) => Ok(ClEvent::CoordinateSystem(frame)),
            Err(e) => Err(self.error(args, format!("CSYS: {e}"))),
        }
    }

    /// `DELAY/t[,REV]` (seconds, or revolutions), `DWELL/t`.
    pub(super) fn delay(&mut self, word: Span, args: Span) -> Result<ClEvent, Diagnostic> {
        self.split(args);
        let name = self.text()[word.0..word.1].to_ascii_uppercase();
        let usage = format!("expected `{name}/t` (seconds) or `{name}/t,REV` (revolutions)");
        let (t, rev) = match self.fields.as_slice() {
            [t] => (*t, false),
            [t, w] if self.is(*w, "REV") => (*t, true),
            [] => return Err(self.error(word, usage)),
            _ => return Err(self.error(args, usage)),
        };
        let value = self.number(t)?;
        if value < 0.0 {
            return Err(self.error(
                t,
                format!("the dwell must not be negative, got `{}`", self.field(t)),
            ));
        }
        Ok(ClEvent::Dwell(if rev {
            Dwell::Revolutions(value)
        } else {
            Dwell::Seconds(value)
        }))
    }

    /// `MACHIN/name[,…]`.
    pub(super) fn machin(&mut self, word: Span, args: Span) -> Result<ClEvent, Diagnostic> {
        self.split(args);
        let mut fields = self.fields.iter().map(|&f| self.field(f).to_string());
        let Some(name) = fields.next().filter(|n| !n.is_empty()) else {
            return Err(self.error(word, "expected `MACHIN/name[,…]`"));
        };
        let args = fields.collect();
        Ok(ClEvent::Machine { name, args })
    }

    /// `CLAMP/[ON|OFF,]words…`.
    pub(super) fn clamp(&mut self, args: Span) -> Result<ClEvent, Diagnostic> {
        self.split(args);
        let on = !self.fields.iter().any(|&f| self.is(f, "OFF"));
        let words = self
            .fields
            .iter()
            .filter(|&&f| !self.is(f, "ON") && !self.is(f, "OFF"))
            .map(|&f| self.word(f))
            .collect();
        Ok(ClEvent::Clamp { on, words })
    }

    /// `ORIGIN/x,y,z`.
    pub(super) fn origin(&mut self, word: Span, args: Span) -> Result<ClEvent, Diagnostic> {
        self.split(args);
        if self.fields.len() != 3 {
            return Err(self.error(
                if self.fields.is_empty() { word } else { args },
                format!(
                    "ORIGIN has {} values, expected 3 (x,y,z)",
                    self.fields.len()
                ),
            ));
        }
        let v = self.numbers(0..3)?;
        Ok(ClEvent::Origin(self.mm3([v[0], v[1], v[2]])))
    }

    /// SOLIDWORKS CAM's `SETUP/START,n` and `SETUP/END,n`.
    pub(super) fn setup(&mut self, word: Span, args: Span) -> Result<ClEvent, Diagnostic> {
        self.split(args);
        let usage = "expected `SETUP/START,n` or `SETUP/END,n`";
        let start = match self.fields.as_slice() {
            [w, _] if self.is(*w, "START") => true,
            [w, _] if self.is(*w, "END") => false,
            [] => return Err(self.error(word, usage)),
            _ => return Err(self.error(args, usage)),
        };
        let number = self.whole(1, "setup number")?;
        Ok(ClEvent::Setup { start, number })
    }
}
