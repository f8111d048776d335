//! Tools and what turns them: `TLDATA`, `CUTTER`, `LOAD`, `LOADTL`,
//! `SELECT`, `SPINDL`, `COOLNT`, `CUTCOM`.

use std::io::BufRead;

use kinpost_diag::Diagnostic;

use super::{ClReader, Span};
use crate::{ClEvent, CutcomSide, Plane, SpindleDir, SpindleSpeed, ToolData};

/// Metres in a foot: `SFM` (surface feet per minute) to metres per minute.
const M_PER_FOOT: f64 = 0.3048;

impl<R: BufRead> ClReader<R> {
    /// `TLDATA/kind[,kind2…],values…` or `CUTTER/values…`.
    ///
    /// The known layouts (lengths converted to mm): NX `TLDATA/MILL,d,r,l,
    /// taper,tip[,…]` (diameter, lower corner radius, length, angles in
    /// degrees); `TLDATA/DRILL,…` and NX's `TLDATA/DRILL,MILL,…` start with
    /// the diameter; APT `CUTTER/d[,r,e,f,α,β,h]` (the 7-value form:
    /// diameter, corner radius, the corner's centre offsets `e`, `f`, the
    /// angles `α`, `β` in degrees and the height `h`).
    pub(super) fn tool_data(&mut self, args: Span, cutter: bool) -> Result<ClEvent, Diagnostic> {
        self.split(args);
        let mut words: Vec<String> = self
            .fields
            .iter()
            .take_while(|&&f| self.is_word(f))
            .map(|&f| self.word(f))
            .collect();
        let first = words.len();
        let kind = if cutter {
            if let Some(&f) = self.fields.first().filter(|_| first > 0) {
                let text = self.field(f).to_string();
                return Err(self.error(f, format!("unexpected `{text}`: CUTTER takes numbers")));
            }
            "CUTTER".to_string()
        } else if words.is_empty() {
            String::new()
        } else {
            words.remove(0)
        };
        let values = self.numbers(first..self.fields.len())?;
        let length = |k: usize| values.get(k).map(|&v| self.mm(v));
        let (corner_radius_mm, length_mm) = match kind.as_str() {
            "CUTTER" => (length(1), length(6)),
            "MILL" if words.is_empty() => (length(1), length(2)),
            _ => (None, None),
        };
        Ok(ClEvent::ToolData(Box::new(ToolData {
            diameter_mm: length(0),
            corner_radius_mm,
            length_mm,
            kind,
            words,
            values,
        })))
    }

    /// `LOAD/TOOL,n[,ADJUST,m]`.
    pub(super) fn load(&mut self, word: Span, args: Span) -> Result<ClEvent, Diagnostic> {
        let number = self.tool_number("LOAD", word, args)?;
        let adjust = self.adjust(2, args)?;
        Ok(ClEvent::LoadTool { number, adjust })
    }

    /// `SELECT/TOOL,n`.
    pub(super) fn select(&mut self, word: Span, args: Span) -> Result<ClEvent, Diagnostic> {
        let number = self.tool_number("SELECT", word, args)?;
        self.rest_ignored(2, args);
        Ok(ClEvent::SelectTool { number })
    }

    /// `LOADTL/n[,ADJUST,m]` (Creo, CATIA, Mastercam APT).
    pub(super) fn loadtl(&mut self, word: Span, args: Span) -> Result<ClEvent, Diagnostic> {
        self.split(args);
        if self.fields.is_empty() {
            return Err(self.error(word, "expected `LOADTL/n`"));
        }
        let number = self.whole(0, "tool number")?;
        // CATIA V5 writes `LOADTL/n,m`, m the tool's compensation number
        // (its PP table: `LOADTL/%MFG_TL_NUMBER,%MFG_TOOL_COMP`).
        if self.fields.len() == 2 && !self.is_word(self.fields[1]) {
            let m = self.whole(1, "compensation number")?;
            return Ok(ClEvent::LoadTool {
                number,
                adjust: Some(m),
            });
        }
        let adjust = self.adjust(1, args)?;
        Ok(ClEvent::LoadTool { number, adjust })
    }

    /// CATIA V5's `TOOLNO/n,d` (its tool change: the number `LOADTL`
    /// loads next, the nominal diameter), as the tool's data; the lathe's
    /// `TOOLNO/n,TURN` (and any further words) gives no diameter.
    pub(super) fn toolno(&mut self, word: Span, args: Span) -> Result<Option<ClEvent>, Diagnostic> {
        self.split(args);
        if self.fields.is_empty() {
            return Err(self.error(word, "expected `TOOLNO/n[,diameter]`"));
        }
        self.whole(0, "tool number")?;
        if self.fields.get(1).is_none_or(|&f| self.is_word(f)) {
            return Ok(None);
        }
        let value = self.numbers(1..2)?[0];
        Ok(Some(ClEvent::ToolData(Box::new(ToolData {
            kind: "TOOLNO".into(),
            words: Vec::new(),
            values: vec![value],
            diameter_mm: Some(self.mm(value)),
            corner_radius_mm: None,
            length_mm: None,
        }))))
    }

    /// `ADJUST,m` at field `k` (split already), if there; anything else
    /// from there on is ignored with a warning.
    fn adjust(&mut self, k: usize, args: Span) -> Result<Option<u32>, Diagnostic> {
        match self.fields.get(k) {
            Some(&f) if self.is(f, "ADJUST") && self.fields.len() > k + 1 => {
                let m = self.whole(k + 1, "length offset register (ADJUST)")?;
                self.rest_ignored(k + 2, args);
                Ok(Some(m))
            }
            _ => {
                self.rest_ignored(k, args);
                Ok(None)
            }
        }
    }

    /// Warns that the fields from `k` on are ignored.
    fn rest_ignored(&mut self, k: usize, args: Span) {
        if let Some(next) = self.fields.get(k) {
            let rest = (next.0, args.1);
            let text = self.text()[rest.0..rest.1].trim().to_string();
            self.warn(rest, format!("`{text}` after the tool number ignored"));
        }
    }

    /// The tool number of `LOAD/TOOL,n` and `SELECT/TOOL,n`.
    fn tool_number(&mut self, name: &str, word: Span, args: Span) -> Result<u32, Diagnostic> {
        self.split(args);
        let usage = format!("expected `{name}/TOOL,n`");
        let Some(&first) = self.fields.first() else {
            return Err(self.error(word, usage));
        };
        if !self.is(first, "TOOL") {
            return Err(self.error(first, usage));
        }
        if self.fields.len() < 2 {
            return Err(self.error(
                (first.1, first.1),
                format!("{usage}: the tool number is missing"),
            ));
        }
        self.whole(1, "tool number")
    }

    /// `SPINDL/[RPM,]n[,RPM|SFM|SMM][,CLW|CCLW][,RANGE,r][,MAXRPM,m]`,
    /// `SPINDL/ON` (the last speed again), `SPINDL/OFF`.
    pub(super) fn spindle(&mut self, args: Span) -> Result<ClEvent, Diagnostic> {
        self.split(args);
        let mut speed: Option<(f64, Span)> = None;
        let mut surface: Option<f64> = None; // metres per minute per unit
        let mut dir: Option<SpindleDir> = None;
        let mut range = None;
        let mut max_rpm = None;
        let mut k = 0;
        while k < self.fields.len() {
            let f = self.fields[k];
            k += 1;
            if !self.is_word(f) {
                if speed.is_some() {
                    let text = self.field(f).to_string();
                    self.warn(f, format!("`{text}` in SPINDL ignored"));
                } else {
                    speed = Some((self.number(f)?, f));
                }
                continue;
            }
            match self.word(f).as_str() {
                "OFF" => return Ok(ClEvent::SpindleOff),
                "ON" | "RPM" => {}
                "SFM" => surface = Some(M_PER_FOOT),
                "SMM" => surface = Some(1.0),
                "CLW" => dir = Some(SpindleDir::Clockwise),
                "CCLW" => dir = Some(SpindleDir::CounterClockwise),
                "RANGE" if k < self.fields.len() => {
                    range = Some(self.whole(k, "spindle range")?);
                    k += 1;
                }
                "MAXRPM" if k < self.fields.len() => {
                    let m = self.number(self.fields[k])?;
                    if m <= 0.0 {
                        return Err(self.error(self.fields[k], "MAXRPM must be positive"));
                    }
                    max_rpm = Some(m);
                    k += 1;
                }
                _ => {
                    let text = self.field(f).to_string();
                    self.warn(f, format!("`{text}` in SPINDL ignored"));
                }
            }
        }
        let (value, dir) = match speed {
            Some((value, span)) => {
                if value <= 0.0 {
                    return Err(self.error(
                        span,
                        format!(
                            "the spindle speed must be positive, got `{}` (use SPINDL/OFF to stop it)",
                            self.field(span)
                        ),
                    ));
                }
                let speed = match surface {
                    Some(m) => SpindleSpeed::SurfaceMetresPerMinute(value * m),
                    None => SpindleSpeed::Rpm(value),
                };
                (speed, dir.unwrap_or(SpindleDir::Clockwise))
            }
            None => match self.spindle {
                Some((value, last)) if surface.is_none() => (value, dir.unwrap_or(last)),
                _ => {
                    return Err(self.error(
                        args,
                        "SPINDL without a speed, and no earlier speed to restart",
                    ));
                }
            },
        };
        self.spindle = Some((value, dir));
        Ok(ClEvent::Spindle {
            speed: value,
            dir,
            range,
            max_rpm,
        })
    }

    /// `COOLNT/FLOOD|MIST|THRU|AIR|ON|OFF|…`.
    pub(super) fn coolant(&mut self, args: Span) -> Result<ClEvent, Diagnostic> {
        self.split(args);
        let Some(&first) = self.fields.first() else {
            return Ok(ClEvent::Coolant {
                on: true,
                mode: "ON".to_string(),
            });
        };
        let on = !self.fields.iter().any(|&f| self.is(f, "OFF"));
        // The mode is the first word that is not ON: `COOLNT/ON,MIST` is
        // mist, as `COOLNT/MIST` is.
        let mode = self
            .fields
            .iter()
            .find(|&&f| !self.is(f, "ON") && !self.is(f, "OFF"))
            .map_or(first, |&f| f);
        Ok(ClEvent::Coolant {
            on,
            mode: self.word(mode),
        })
    }

    /// `CUTCOM/LEFT|RIGHT|OFF[,XYPLAN|YZPLAN|ZXPLAN][,n]`.
    pub(super) fn cutcom(&mut self, word: Span, args: Span) -> Result<ClEvent, Diagnostic> {
        self.split(args);
        let usage = "expected `CUTCOM/LEFT|RIGHT|OFF[,XYPLAN|YZPLAN|ZXPLAN][,register]`";
        let mut side = None;
        let mut plane = None;
        let mut register = None;
        for k in 0..self.fields.len() {
            let f = self.fields[k];
            if !self.is_word(f) {
                if register.is_some() {
                    return Err(self.error(f, format!("a second register in CUTCOM; {usage}")));
                }
                register = Some(self.whole(k, "cutter compensation register")?);
                continue;
            }
            match self.word(f).as_str() {
                "LEFT" if side.is_none() => side = Some(CutcomSide::Left),
                "RIGHT" if side.is_none() => side = Some(CutcomSide::Right),
                "OFF" if side.is_none() => side = Some(CutcomSide::Off),
                "XYPLAN" if plane.is_none() => plane = Some(Plane::Xy),
                "YZPLAN" if plane.is_none() => plane = Some(Plane::Yz),
                "ZXPLAN" if plane.is_none() => plane = Some(Plane::Zx),
                other => {
                    return Err(self.error(f, format!("unexpected `{other}` in CUTCOM; {usage}")));
                }
            }
        }
        let Some(side) = side else {
            return Err(self.error(if self.fields.is_empty() { word } else { args }, usage));
        };
        Ok(ClEvent::CutterCompensation {
            side,
            plane,
            register,
        })
    }
}
