//! Motion statements beyond the plain `GOTO`: Creo's continuation points,
//! `CIRCLE`, `NURBS` with its `KNOT` and `CNTRL` records, `FROM`, `GOHOME`,
//! `GODLTA`, `TLAXIS` and `FEDRAT`.

use std::io::BufRead;

use kinpost_diag::Diagnostic;

use super::{ClReader, PendingCircle, Span, skip_blanks};
use crate::curve::{ARC_RADIUS_TOLERANCE_MM, MAX_ARC_TURNS, MIN_ARC_RADIUS_MM, Nurbs};
use crate::vector::{dot, norm, normalize, scale, sub};
use crate::{Circle, ClEvent, FeedUnit, Statement, Units, Vec3};

/// The degrees of NURBS curves the reader accepts (NX writes cubics; the
/// degree comes from the counts of knots and control points, so a wrong
/// count would show as an absurd degree).
const NURBS_DEGREES: std::ops::RangeInclusive<usize> = 1..=9;

impl<R: BufRead> ClReader<R> {
    /// A line of numbers after a `GOTO`: Creo writes the further points of
    /// one `GOTO` on lines of their own (`GOTO / x, y, z` then `x, y, z`
    /// lines). After a `GOTO` that ended an arc, each further point also
    /// ends an arc of the same circle (Creo's `POINTS_&_ARC` output): the
    /// `CIRCLE` is given again before it.
    pub(super) fn continuation_point(
        &mut self,
        start: usize,
    ) -> Result<Option<ClEvent>, Diagnostic> {
        let args: Span = (start, self.text_bytes().len());
        if self.goto_count == 0 {
            self.arc_goto = None;
            return Err(self.error(
                args,
                "a line of numbers that does not follow a GOTO: only the further points of a GOTO may stand alone",
            ));
        }
        let Some(pending) = self.arc_goto.take() else {
            return self.goto(args).map(Some);
        };
        // The point ends an arc of the same circle: check and read it as
        // such, then hand out the circle first and the point next.
        self.circle = Some(pending.clone());
        self.update_goto_special();
        match self.goto(args) {
            Ok(event) => {
                let line = self.segments[0].line;
                self.held = Some(Box::new(Statement { line, event }));
                self.update_slow();
                Ok(Some(ClEvent::Circle(Box::new(pending.circle))))
            }
            Err(e) => {
                // The failed point has no effect: the arc still applies.
                self.circle = None;
                self.arc_goto = Some(pending);
                self.update_goto_special();
                Err(e)
            }
        }
    }

    /// A motion statement other than `GOTO` while a `CIRCLE` waits for
    /// its end point.
    pub(super) fn no_pending_circle(&self, word: Span) -> Result<(), Diagnostic> {
        match &self.circle {
            None => Ok(()),
            Some(pending) => {
                let name = self.text()[word.0..word.1].to_ascii_uppercase();
                Err(self.error(
                    word,
                    format!(
                        "{name} while the CIRCLE of line {} waits for the GOTO that ends it",
                        pending.line
                    ),
                ))
            }
        }
    }

    /// `CIRCLE/x,y,z,i,j,k[,r[,t,f,d,e]][,TIMES,n]`: see the crate docs for
    /// the forms and the direction of each.
    pub(super) fn circle(&mut self, word: Span, args: Span) -> Result<ClEvent, Diagnostic> {
        self.no_pending_circle(word)?;
        self.split(args);
        let numbers = self
            .fields
            .iter()
            .take_while(|&&f| !self.is_word(f))
            .count();
        let mut turns = 1;
        let mut k = numbers;
        while k < self.fields.len() {
            let f = self.fields[k];
            if self.is(f, "TIMES") && k + 1 < self.fields.len() {
                turns = self.whole(k + 1, "number of turns (TIMES)")?;
                if turns == 0 || turns > MAX_ARC_TURNS {
                    return Err(self.error(
                        self.fields[k + 1],
                        format!("TIMES must be 1 to {MAX_ARC_TURNS}"),
                    ));
                }
                k += 2;
            } else {
                let text = self.field(f).to_string();
                return Err(self.error(
                    f,
                    format!("unexpected `{text}` in CIRCLE; expected TIMES,n after the numbers"),
                ));
            }
        }
        let v = self.numbers(0..numbers)?;
        // NX writes the axis about which the tool turns clockwise (its
        // documentation: "the circle axis vector, assuming a clockwise
        // direction"; every arc of the NX files in data/cl/nx joins its
        // neighbours only that way): the reverse of the right-hand rule.
        let (radius, nx) = match v.len() {
            6 => (None, false),
            7 => (Some(v[6]), false),
            11 => (Some(v[6]), true),
            n => {
                return Err(self.error(
                    if n == 0 { word } else { args },
                    format!(
                        "CIRCLE has {n} values, expected 6 (x,y,z,i,j,k: SOLIDWORKS CAM), 7 (x,y,z,i,j,k,r) or 11 (NX: x,y,z,i,j,k,r,t,f,d,e)"
                    ),
                ));
            }
        };
        let Some(mut axis) = normalize([v[3], v[4], v[5]]) else {
            return Err(self.error(
                (self.fields[3].0, self.fields[5].1),
                "the circle's axis (i,j,k) is zero or not finite",
            ));
        };
        if nx {
            // (`+ 0.0`: no negative zeros in the event.)
            axis = axis.map(|v| -v + 0.0);
        }
        let centre = self.mm3([v[0], v[1], v[2]]);
        let Some(start) = self.last_point else {
            return Err(self.error(
                word,
                "CIRCLE before any GOTO: an arc starts at the current point",
            ));
        };
        // The current point's distance from the axis.
        let d = sub(start, centre);
        let start_radius = norm(sub(d, scale(axis, dot(d, axis))));
        if !start_radius.is_finite() {
            return Err(self.error(
                args,
                "the circle's centre is too far from the current point for a finite radius",
            ));
        }
        let radius_mm = match radius {
            Some(r) => {
                let r = self.mm(r);
                if !(r > 0.0 && r.is_finite()) {
                    return Err(self.error(
                        self.fields[6],
                        format!(
                            "the circle's radius must be positive, got `{}`",
                            self.field(self.fields[6])
                        ),
                    ));
                }
                if (r - start_radius).abs() > ARC_RADIUS_TOLERANCE_MM {
                    return Err(self.error(
                        args,
                        format!(
                            "the current point is {start_radius:.4} mm from the circle's axis, the CIRCLE says radius {r:.4} mm: the arc cannot start here (tolerance {ARC_RADIUS_TOLERANCE_MM} mm)"
                        ),
                    ));
                }
                r
            }
            None => start_radius,
        };
        if start_radius < MIN_ARC_RADIUS_MM {
            return Err(self.error(
                args,
                "the current point is on the circle's axis: the arc has no radius",
            ));
        }
        let circle = Circle {
            centre,
            axis,
            radius_mm,
            turns,
            tolerance_mm: nx.then(|| self.mm(v[7])),
            tool_diameter_mm: nx.then(|| self.mm(v[9])),
            tool_corner_radius_mm: nx.then(|| self.mm(v[10])),
        };
        let (line, source) = self.statement_line();
        let source = String::from_utf8_lossy(source).into_owned();
        self.circle = Some(Box::new(PendingCircle {
            circle: circle.clone(),
            line,
            source,
        }));
        self.update_goto_special();
        Ok(ClEvent::Circle(Box::new(circle)))
    }

    /// `NURBS/` followed by `KNOT/` and `CNTRL/` records (NX): the current
    /// point is the first control point, the `CNTRL` records are the others
    /// (`x,y,z` or `x,y,z,w`), the knots start with `degree + 1` zeros that
    /// are not written and end with the last written knot repeated
    /// `degree + 1` times. So the degree is the number of control points
    /// less the number of knots written.
    pub(super) fn nurbs(&mut self, word: Span, args: Span) -> Result<ClEvent, Diagnostic> {
        self.no_pending_circle(word)?;
        if skip_blanks(self.text_bytes(), args.0) < args.1 {
            return Err(self.error(
                args,
                "NURBS/ takes no values: its KNOT/ and CNTRL/ records follow",
            ));
        }
        // Read the records that follow.
        self.own_text();
        let record = |line: &str| {
            let upper = line.get(..5).map(str::to_ascii_uppercase);
            upper.is_some_and(|u| u.starts_with("KNOT") || u == "CNTRL")
        };
        while self.take_line_if(record)? {}
        let mut knots = Vec::new();
        let mut points = Vec::new();
        let mut weights = Vec::new();
        for s in 1..self.segments.len() {
            let seg = self.segments[s];
            let b = self.text.as_bytes();
            let start = skip_blanks(b, seg.text_start);
            let slash = b[start..seg.text_end].iter().position(|&c| c == b'/');
            let Some(slash) = slash else {
                return Err(self.error(
                    (start, seg.text_end),
                    "expected `/` after the record's word",
                ));
            };
            let is_knot = self.text[start..start + 4].eq_ignore_ascii_case("KNOT");
            self.split((start + slash + 1, seg.text_end));
            if is_knot {
                knots.extend(self.numbers(0..self.fields.len())?);
            } else {
                let v = self.numbers(0..self.fields.len())?;
                match v.len() {
                    3 => weights.push(1.0),
                    4 => weights.push(v[3]),
                    n => {
                        return Err(self.error(
                            (start, seg.text_end),
                            format!("CNTRL has {n} values, expected 3 (x,y,z) or 4 (x,y,z,w)"),
                        ));
                    }
                }
                points.push(self.mm3([v[0], v[1], v[2]]));
            }
        }
        let Some(start) = self.last_point else {
            return Err(self.error(
                word,
                "NURBS before any GOTO: the curve starts at the current point",
            ));
        };
        let whole = (word.0, self.segments.last().map_or(word.1, |s| s.text_end));
        if knots.is_empty() || points.is_empty() {
            return Err(self.error(
                whole,
                "a NURBS needs its KNOT/ and CNTRL/ records on the lines after it",
            ));
        }
        // The first control point is the current point (weight 1).
        points.insert(0, start);
        weights.insert(0, 1.0);
        let degree = (points.len() as isize) - (knots.len() as isize);
        if !NURBS_DEGREES.contains(&(degree.max(0) as usize)) || degree < 1 {
            return Err(self.error(
                whole,
                format!(
                    "a NURBS with {} control points (the current point and {} CNTRL) and {} knots would have degree {degree}: expected {} to {}",
                    points.len(),
                    points.len() - 1,
                    knots.len(),
                    NURBS_DEGREES.start(),
                    NURBS_DEGREES.end()
                ),
            ));
        }
        let degree = degree as usize;
        let last = *knots.last().expect("knots checked non-empty");
        let mut full = vec![0.0; degree + 1];
        full.extend_from_slice(&knots);
        full.extend(std::iter::repeat_n(last, degree));
        let end = *points.last().expect("points checked non-empty");
        match Nurbs::new(degree, full, points, weights) {
            Ok(curve) => {
                self.last_point = Some(end);
                Ok(ClEvent::Nurbs(curve))
            }
            Err(e) => Err(self.error(whole, format!("invalid NURBS: {e}"))),
        }
    }

    /// `FROM/x,y,z[,i,j,k]`: the start point (and tool axis).
    pub(super) fn from(&mut self, word: Span, args: Span) -> Result<ClEvent, Diagnostic> {
        self.no_pending_circle(word)?;
        let (point, axis) = self.point_and_axis("FROM", word, args)?;
        if let Some(axis) = axis {
            self.axis = Some(axis);
        }
        self.last_point = Some(point);
        self.from = Some(point);
        Ok(ClEvent::From { point, axis })
    }

    /// `GOHOME[/x,y,z[,i,j,k]]`: back to the home point.
    pub(super) fn gohome(&mut self, word: Span, args: Span) -> Result<ClEvent, Diagnostic> {
        self.no_pending_circle(word)?;
        if skip_blanks(self.text_bytes(), args.0) >= args.1 {
            let point = self.from;
            if point.is_some() {
                self.last_point = point;
            }
            return Ok(ClEvent::GoHome { point, axis: None });
        }
        let (point, axis) = self.point_and_axis("GOHOME", word, args)?;
        if let Some(axis) = axis {
            self.axis = Some(axis);
        }
        self.last_point = Some(point);
        Ok(ClEvent::GoHome {
            point: Some(point),
            axis,
        })
    }

    /// `x,y,z[,i,j,k]` of `FROM` and `GOHOME`: the point in mm and the unit
    /// axis.
    fn point_and_axis(
        &mut self,
        name: &str,
        word: Span,
        args: Span,
    ) -> Result<(Vec3, Option<Vec3>), Diagnostic> {
        self.split(args);
        let n = self.fields.len();
        if n != 3 && n != 6 {
            return Err(self.error(
                if n == 0 { word } else { args },
                format!("{name} has {n} values, expected 3 (x,y,z) or 6 (x,y,z,i,j,k)"),
            ));
        }
        let v = self.numbers(0..n)?;
        let point = self.mm3([v[0], v[1], v[2]]);
        let axis = if n == 6 {
            match normalize([v[3], v[4], v[5]]) {
                Some(axis) => Some(axis),
                None => {
                    return Err(self.error(
                        (self.fields[3].0, self.fields[5].1),
                        "the tool axis (i,j,k) is zero or not finite",
                    ));
                }
            }
        } else {
            None
        };
        Ok((point, axis))
    }

    /// `TLAXIS/i,j,k`: the tool axis of the three-value `GOTO`s that follow.
    pub(super) fn tlaxis(&mut self, word: Span, args: Span) -> Result<Option<ClEvent>, Diagnostic> {
        self.split(args);
        if self.fields.len() != 3 || self.fields.iter().any(|&f| self.is_word(f)) {
            return Err(self.error(
                (word.0, args.1),
                "expected `TLAXIS/i,j,k`; other TLAXIS forms (NORMPS, ATANGL, …) belong to the APT part-program language, not to CL data: have the CAM system output the tool axis",
            ));
        }
        let v = self.numbers(0..3)?;
        match normalize([v[0], v[1], v[2]]) {
            Some(axis) => {
                self.axis = Some(axis);
                Ok(None)
            }
            None => Err(self.error(args, "the tool axis (i,j,k) is zero or not finite")),
        }
    }

    /// `GODLTA/dx,dy,dz` (a move by that much) or `GODLTA/d` (along the
    /// tool axis): a `GOTO` relative to the current point, tool axis kept.
    pub(super) fn godlta(&mut self, word: Span, args: Span) -> Result<ClEvent, Diagnostic> {
        self.no_pending_circle(word)?;
        self.split(args);
        let (Some(last), Some(axis)) = (self.last_point, self.axis) else {
            return Err(self.error(
                (word.0, args.1),
                "GODLTA before any GOTO: a relative move needs a point to start from",
            ));
        };
        let d = match self.fields.len() {
            1 => {
                let t = self.mm(self.number(self.fields[0])?);
                axis.map(|a| a * t)
            }
            3 => {
                let v = self.numbers(0..3)?;
                self.mm3([v[0], v[1], v[2]])
            }
            n => {
                return Err(self.error(
                    args,
                    format!(
                        "GODLTA has {n} values, expected 1 (along the tool axis) or 3 (dx,dy,dz)"
                    ),
                ));
            }
        };
        // A three-value GOTO to the moved point.
        let point = [last[0] + d[0], last[1] + d[1], last[2] + d[2]];
        let (point, axis, motion) = self.finish_move(args, point, [0.0; 9], 3)?;
        Ok(ClEvent::Goto {
            point,
            axis,
            reference: self.reference,
            motion,
        })
    }

    /// `FEDRAT/[unit,]f` or `FEDRAT/f[,unit]`, in mm; it cancels a `RAPID`
    /// no move used (with a warning).
    pub(super) fn fedrat(&mut self, word: Span, args: Span) -> Result<ClEvent, Diagnostic> {
        self.split(args);
        let mut value: Option<(f64, Span)> = None;
        let mut unit: Option<(FeedUnit, Span)> = None;
        for k in 0..self.fields.len() {
            let f = self.fields[k];
            if self.is_word(f) {
                let Some(u) = feed_unit(&self.word(f)) else {
                    return Err(self.error(
                        f,
                        format!(
                            "unknown feed unit `{}`; expected MMPM, IPM, MMPR or IPR",
                            self.word(f)
                        ),
                    ));
                };
                if unit.is_some() {
                    return Err(self.error(f, "FEDRAT has two units"));
                }
                unit = Some((u, f));
            } else {
                if value.is_some() {
                    return Err(self.error(f, "FEDRAT has two feed values"));
                }
                value = Some((self.number(f)?, f));
            }
        }
        let Some((value, span)) = value else {
            return Err(self.error(args, "FEDRAT without a feed value"));
        };
        if value <= 0.0 {
            return Err(self.error(
                span,
                format!("the feed rate must be positive, got `{}`", self.field(span)),
            ));
        }
        let (unit, unit_span) = unit.unwrap_or(match self.units {
            Units::Mm => (FeedUnit::Mmpm, span),
            Units::Inch => (FeedUnit::Ipm, span),
        });
        let feed = self.feed_mm(value, unit, unit_span)?;
        // APT: a feed rate cancels a RAPID that no move has used.
        if std::mem::take(&mut self.rapid) {
            self.warn(
                (word.0, args.1),
                "FEDRAT after RAPID: the next move is at this feed, not rapid",
            );
        }
        Ok(ClEvent::Feedrate {
            value: feed.value,
            unit: feed.unit,
        })
    }

    /// A feed in `unit` as mm per minute or revolution; an inch unit in a
    /// file whose length units are unknown is an error (its lengths would
    /// be taken as mm).
    pub(super) fn feed_mm(
        &self,
        value: f64,
        unit: FeedUnit,
        span: Span,
    ) -> Result<crate::Feed, Diagnostic> {
        if unit.is_inch() && !self.units_known {
            let name = match unit {
                FeedUnit::Ipm => "IPM, inches per minute",
                _ => "IPR, inches per revolution",
            };
            return Err(self.error(
                span,
                format!(
                    "an inch feed ({name}) in a file that does not declare its units (no UNITS statement): its lengths would be read as mm; give `--units inch` if the file is in inches (or `--units mm` if its lengths are mm)"
                ),
            ));
        }
        Ok(match unit {
            FeedUnit::Mmpm | FeedUnit::Mmpr => crate::Feed { value, unit },
            FeedUnit::Ipm => crate::Feed {
                value: value * crate::MM_PER_INCH,
                unit: FeedUnit::Mmpm,
            },
            FeedUnit::Ipr => crate::Feed {
                value: value * crate::MM_PER_INCH,
                unit: FeedUnit::Mmpr,
            },
        })
    }
}

/// The feed unit a word names.
pub(super) fn feed_unit(word: &str) -> Option<FeedUnit> {
    Some(match word {
        "MMPM" => FeedUnit::Mmpm,
        "IPM" => FeedUnit::Ipm,
        "MMPR" => FeedUnit::Mmpr,
        "IPR" => FeedUnit::Ipr,
        _ => return None,
    })
}
