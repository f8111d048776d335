//! `CYCLE/…`: canned cycles in the couplet forms of NX, Creo and SOLIDWORKS
//! CAM (ISO 4343:2000 style `keyword,value` pairs).

use std::io::BufRead;

use kinpost_diag::Diagnostic;

use super::motion::feed_unit;
use super::{ClReader, Span};
use crate::number::parse_number;
use crate::{ClEvent, Cycle, CycleKind, Dwell, Feed, FeedUnit};

/// The positional forms read, for the error messages.
const POSITIONAL: &str = "`depth, clearance` or `depth, IPM|MMPM|IPR|MMPR, feed, clearance`";

/// The couplet keywords a cycle may carry, for the error message.
const KEYWORDS: &str = "FEDTO, DEPTH, RAPTO, CLEAR, RTRCTO, RETURN, STEP, INCR, 1STPECK, SUBPECK, DWELL, REV, BACK, TIMES, PITCH, MMPM, IPM, MMPR, IPR";

impl<R: BufRead> ClReader<R> {
    /// `CYCLE/kind[,kind2],keyword,value,…`, `CYCLE/OFF`; SOLIDWORKS CAM's
    /// `CYCLE/INIT` and `CYCLE/CLEAR` (no parameters) announce the cycle
    /// statement that follows and give nothing.
    pub(super) fn cycle(&mut self, word: Span, args: Span) -> Result<Option<ClEvent>, Diagnostic> {
        self.no_pending_circle(word)?;
        self.split(args);
        let Some(&first) = self.fields.first() else {
            return Err(self.error(word, "CYCLE needs a kind (DRILL, DEEP, TAP, …) or OFF"));
        };
        let n = self.fields.len();
        let kind_word = self.word(first);
        match kind_word.as_str() {
            "OFF" if n == 1 => return Ok(Some(ClEvent::CycleOff)),
            "INIT" | "CLEAR" if n == 1 => return Ok(None),
            _ => {}
        }
        if !self.is_word(first) {
            return Err(self.error(
                first,
                "expected the cycle's kind (DRILL, DEEP, BRKCHP, TAP, BORE, REAM, …)",
            ));
        }
        let mut kind = match kind_word.as_str() {
            "DRILL" => CycleKind::Drill,
            "DEEP" | "DEEP2" => CycleKind::Deep,
            "BRKCHP" => CycleKind::BreakChip,
            "TAP" => CycleKind::Tap,
            "BORE" => CycleKind::Bore,
            "REAM" => CycleKind::Ream,
            "FACE" => CycleKind::Face,
            "CSINK" => CycleKind::Countersink,
            "THRU" => CycleKind::Thru,
            other => CycleKind::Other(other.to_string()),
        };
        let mut k = 1;
        // NX: `CYCLE/DRILL,DEEP,…`, `CYCLE/DRILL,BRKCHP,…`.
        if kind == CycleKind::Drill && k < n {
            match self.word(self.fields[k]).as_str() {
                "DEEP" => (kind, k) = (CycleKind::Deep, k + 1),
                "BRKCHP" => (kind, k) = (CycleKind::BreakChip, k + 1),
                _ => {}
            }
        }
        let mut cycle = Cycle {
            kind,
            depth_mm: None,
            feed_start_mm: None,
            retract_mm: None,
            peck_mm: None,
            next_peck_mm: None,
            dwell: None,
            feed: None,
            pitch_mm: None,
            back_off_mm: None,
            full_retract_every: None,
        };
        if k < n && !self.is_word(self.fields[k]) {
            self.positional_cycle(&mut cycle, k)?;
            return Ok(Some(ClEvent::Cycle(Box::new(cycle))));
        }
        let mut rapto: Option<f64> = None;
        let mut clear: Option<f64> = None;
        while k < n {
            let key_span = self.fields[k];
            let key = self.word(key_span);
            if parse_number(&key).is_some() {
                return Err(self.error(
                    key_span,
                    format!(
                        "a number where a keyword ({KEYWORDS}) is expected: positional values come right after the kind ({POSITIONAL})"
                    ),
                ));
            }
            let Some(&value_span) = self.fields.get(k + 1) else {
                return Err(self.error(key_span, format!("`{key}` in CYCLE without its value")));
            };
            if self.is_word(value_span) {
                return Err(self.error(key_span, format!("`{key}` in CYCLE without its value")));
            }
            let value = self.number(value_span)?;
            k += 2;
            match key.as_str() {
                // The depth is a distance into the material; CAM systems
                // differ in its sign (SOLIDWORKS CAM writes it positive).
                "FEDTO" | "DEPTH" => cycle.depth_mm = Some(self.mm(value).abs()),
                "RAPTO" => rapto = Some(self.mm(value)),
                "CLEAR" => clear = Some(self.mm(value)),
                "RTRCTO" => cycle.retract_mm = Some(self.mm(value)),
                // Creo: 0 returns to the retract plane, not to a height
                // above the hole.
                "RETURN" => cycle.retract_mm = (value != 0.0).then(|| self.mm(value)),
                "STEP" => {
                    cycle.peck_mm = Some(self.mm(value).abs());
                    // A second STEP value: the later pecks.
                    if let Some(&next) = self.fields.get(k)
                        && !self.is_word(next)
                    {
                        cycle.next_peck_mm = Some(self.mm(self.number(next)?).abs());
                        k += 1;
                    }
                }
                "INCR" | "1STPECK" => cycle.peck_mm = Some(self.mm(value).abs()),
                "SUBPECK" => cycle.next_peck_mm = Some(self.mm(value).abs()),
                "DWELL" => cycle.dwell = (value != 0.0).then_some(Dwell::Seconds(value)),
                "REV" => cycle.dwell = (value != 0.0).then_some(Dwell::Revolutions(value)),
                "PITCH" => cycle.pitch_mm = Some(self.mm(value)),
                // Creo's chip breaking (BRKCHP): back off after each peck,
                // leave the hole after every n pecks.
                "BACK" => cycle.back_off_mm = (value != 0.0).then(|| self.mm(value).abs()),
                "TIMES" => {
                    let n = self.whole(k - 1, "number of pecks (TIMES)")?;
                    cycle.full_retract_every = (n != 0).then_some(n);
                }
                unit => match feed_unit(unit) {
                    Some(unit) => cycle.feed = Some(self.cycle_feed(value_span, unit, key_span)?),
                    None => {
                        return Err(self.error(
                            key_span,
                            format!("unknown word `{key}` in CYCLE; expected one of {KEYWORDS}"),
                        ));
                    }
                },
            }
        }
        // Creo's RAPTO advances the rapid from CLEAR toward the hole.
        cycle.feed_start_mm = match clear {
            Some(clear) => Some(clear - rapto.unwrap_or(0.0)),
            None => rapto,
        };
        Ok(Some(ClEvent::Cycle(Box::new(cycle))))
    }

    /// APT's positional cycle, the values in a fixed order after the kind
    /// (`CYCLE/DRILL, depth, IPM, feed, rapid plane`: the depth into the
    /// material and the height above the hole point where the feed starts),
    /// and the two-value form CATIA V5 writes, `CYCLE/DRILL, depth,
    /// clearance`, with the feed of the last FEDRAT. Only the single-pass
    /// kinds have a positional form: a peck or a thread needs its keywords.
    fn positional_cycle(&mut self, cycle: &mut Cycle, k: usize) -> Result<(), Diagnostic> {
        let first = self.fields[k];
        let kinds = [
            CycleKind::Drill,
            CycleKind::Face,
            CycleKind::Bore,
            CycleKind::Ream,
            CycleKind::Countersink,
        ];
        if !kinds.contains(&cycle.kind) {
            return Err(self.error(
                first,
                format!(
                    "a number where a keyword ({KEYWORDS}) is expected: positional values ({POSITIONAL}) are read for DRILL, FACE, BORE, REAM and CSINK only"
                ),
            ));
        }
        let values = &self.fields[k..];
        let bad = |this: &Self| {
            this.error(
                first,
                format!("positional CYCLE values are {POSITIONAL} (APT's fixed order)"),
            )
        };
        let (depth, clearance) = match *values {
            [depth, clearance] if !self.is_word(clearance) => (depth, clearance),
            [depth, unit, feed, clearance] if !self.is_word(feed) && !self.is_word(clearance) => {
                let Some(unit_kind) = feed_unit(&self.word(unit)) else {
                    return Err(bad(self));
                };
                cycle.feed = Some(self.cycle_feed(feed, unit_kind, unit)?);
                (depth, clearance)
            }
            _ => return Err(bad(self)),
        };
        cycle.depth_mm = Some(self.mm(self.number(depth)?).abs());
        cycle.feed_start_mm = Some(self.mm(self.number(clearance)?));
        Ok(())
    }

    /// A cycle's own feed: the number at `value` in `unit` (the word at
    /// `unit_span`), which must be positive.
    fn cycle_feed(&self, value: Span, unit: FeedUnit, unit_span: Span) -> Result<Feed, Diagnostic> {
        let v = self.number(value)?;
        if v <= 0.0 {
            return Err(self.error(
                value,
                format!(
                    "the cycle's feed rate must be positive, got `{}`",
                    self.field(value)
                ),
            ));
        }
        self.feed_mm(v, unit, unit_span)
    }
}
