//! The NC writer.

use std::collections::BTreeMap;
use std::io::{self, Write};
use std::sync::Arc;

use minijinja::{Environment, Value};

use crate::dialect::{
    CommentSyntax, Dialect, DialectKind, MAX_LEAD, MAX_SUFFIX, Numbering, TemplateKind,
};
use crate::template;
use crate::{
    ArcMotion, AxisSpec, Block, BlockError, Hole, Motion, NcError, NumbersRunOut, ProgramInfo,
};
use kinpost_number::{ENCODE_MAX, Formatter, encode_u64, write_u64};

/// Spindle state for [`NcWriter::spindle`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Spindle {
    /// Spindle stop.
    Off,
    /// Clockwise at this speed (1/min).
    Cw(f64),
    /// Counter-clockwise at this speed (1/min).
    Ccw(f64),
}

/// One word (axis or feed), resolved for the hot path: prefix and suffix
/// padded to fixed sizes so that they are copied with fixed-size moves.
#[derive(Debug, Clone)]
struct Word {
    /// Index in the machine order (axis words).
    index: usize,
    /// Separator and prefix.
    lead: [u8; MAX_LEAD],
    lead_len: usize,
    /// Prefix alone (first word of a block).
    first: [u8; MAX_LEAD],
    first_len: usize,
    suffix: [u8; MAX_SUFFIX],
    suffix_len: usize,
    fmt: Formatter,
    modal: bool,
    /// The pressure word (a CSV column: empty while NaN).
    pressure: bool,
    /// The bits of the value [`NcWriter::quantize_axes`] last rounded for
    /// this word's axis and its units (initially, and after a value that
    /// cannot be written, those of 0.0: always right).
    memo: (u64, i64),
    /// Last written value in units; meaningful when `known`.
    last: i64,
    known: bool,
}

impl Word {
    /// The units of `v`, remembered by [`NcWriter::quantize_axes`] or
    /// worked out.
    #[inline(always)]
    fn units(&self, v: f64) -> Result<i64, crate::NumberError> {
        if self.memo.0 == v.to_bits() {
            Ok(self.memo.1)
        } else {
            self.fmt.units(v)
        }
    }
}

fn padded<const N: usize>(s: &str) -> ([u8; N], usize) {
    let mut a = [0u8; N];
    let n = s.len().min(N);
    a[..n].copy_from_slice(&s.as_bytes()[..n]);
    (a, n)
}

impl Word {
    fn new(index: usize, sep: &str, wf: &crate::WordFormat, modal: bool) -> Word {
        let (lead, lead_len) = padded(&format!("{sep}{}", wf.prefix));
        let (first, first_len) = padded(&wf.prefix);
        let (suffix, suffix_len) = padded(&wf.suffix);
        Word {
            index,
            lead,
            lead_len,
            first,
            first_len,
            suffix,
            suffix_len,
            fmt: wf.number.formatter(),
            modal,
            pressure: false,
            memo: (0, 0),
            last: 0,
            known: false,
        }
    }
}

/// Room for one word in the line buffer: fixed-size copies of lead, number
/// and suffix.
const WORD_ROOM: usize = MAX_LEAD + ENCODE_MAX + MAX_SUFFIX;

/// Longest text copied with one fixed-size move by [`put_text`].
const SHORT_TEXT: usize = 16;

/// A fixed piece of a block (motion word, separator, line end): padded for
/// a fixed-size copy when it is short.
#[derive(Clone)]
struct Text {
    padded: [u8; SHORT_TEXT],
    full: Box<[u8]>,
}

impl Text {
    fn new(s: &str) -> Text {
        let (padded, _) = padded(s);
        Text {
            padded,
            full: s.as_bytes().into(),
        }
    }

    fn is_empty(&self) -> bool {
        self.full.is_empty()
    }
}

impl std::ops::Deref for Text {
    type Target = [u8];
    fn deref(&self) -> &[u8] {
        &self.full
    }
}

/// Writes `t` at `at` (and up to [`SHORT_TEXT`] bytes past its end when it
/// is short); returns where it ends.
#[inline(always)]
fn put_text(buf: &mut [u8], at: usize, t: &Text) -> usize {
    let len = t.full.len();
    if len <= SHORT_TEXT {
        buf[at..at + SHORT_TEXT].copy_from_slice(&t.padded);
    } else {
        buf[at..at + len].copy_from_slice(&t.full);
    }
    at + len
}

/// One word at `at`: lead (or prefix alone), number, suffix; returns where
/// it ends. Uses (overwrites) [`WORD_ROOM`] bytes from `at`.
#[inline(always)]
fn put_word(buf: &mut [u8], at: usize, w: &Word, n: i64, first: bool) -> usize {
    let Some(room) = buf[at..].first_chunk_mut::<WORD_ROOM>() else {
        unreachable!("the line buffer has room for every word")
    };
    let (lead, lead_len) = if first {
        (&w.first, w.first_len)
    } else {
        (&w.lead, w.lead_len)
    };
    room[..MAX_LEAD].copy_from_slice(lead);
    let end = w.fmt.encode_into(n, room, lead_len.min(MAX_LEAD));
    room[end..end + MAX_SUFFIX].copy_from_slice(&w.suffix);
    at + end + w.suffix_len
}

/// The line being formatted: a buffer with room for the longest block, so
/// that words are written with fixed-size copies.
struct Line {
    bytes: Vec<u8>,
    len: usize,
}

impl Line {
    fn new(room: usize) -> Line {
        Line {
            bytes: vec![0; room],
            len: 0,
        }
    }

    #[inline]
    fn put(&mut self, s: &[u8]) {
        let end = self.len + s.len();
        self.bytes[self.len..end].copy_from_slice(s);
        self.len = end;
    }

    /// One word: lead (or prefix alone), number, suffix.
    #[inline(always)]
    fn put_word(&mut self, w: &Word, n: i64, first: bool) {
        self.len = put_word(&mut self.bytes, self.len, w, n, first);
    }

    fn as_slice(&self) -> &[u8] {
        &self.bytes[..self.len]
    }
}

/// Writes an NC program in one dialect.
///
/// Motion blocks ([`NcWriter::block`]) are formatted into a reusable buffer
/// with dedicated number formatting (no allocation) and handed to the output
/// with one `write_all` per block; wrap a file in a `BufWriter` yourself.
pub struct NcWriter<W: Write> {
    out: W,
    kind: DialectKind,
    /// Template, comment and insert lines.
    buf: Vec<u8>,
    /// Motion blocks.
    line: Line,
    /// Units of the current block, per written word.
    units: Vec<i64>,
    names: Vec<String>,
    axis_specs: Vec<AxisSpec>,
    /// Number format per machine axis (machine order).
    formats: Vec<Formatter>,
    /// Machine axes that no word writes (locked axes a dialect leaves
    /// out, the pressure word of an NC dialect).
    unworded: Vec<usize>,
    /// Words written in a block, in output order.
    words: Vec<Word>,
    /// An NC dialect with an axis word that is not modal: every block is
    /// written, and [`NcWriter::plain_block`] writes it in one pass.
    plain: bool,
    /// The pressure word of an NC dialect, written on its own line (see
    /// [`AxisSpec::pressure`]).
    pressure: Option<PressureWord>,
    feed: Word,
    /// Whether the dialect's feed word is modal (feed per minute).
    feed_modal: bool,
    last_feed: Option<i64>,
    /// The bits of the last feed value worked out and its units (initially
    /// those of 0.0): a feed that does not change is not rounded again.
    feed_memo: (u64, i64),
    feed_rapid: Text,
    motion_rapid: Text,
    motion_feed: Text,
    motion_modal: bool,
    motion_state: Option<Motion>,
    after_axes: Text,
    /// `after_axes` while compensation is off, and the words for it while
    /// it is on, left then right (`[block] compensated`).
    after_axes_plain: Text,
    compensated: Option<[Text; 2]>,
    sep: Text,
    eol: Text,
    /// `max_line_length` (`usize::MAX` for none), line end included.
    max_line: usize,
    numbering: Numbering,
    next_number: u64,
    /// The number after the last one written does not fit in a `u64`.
    numbers_exhausted: bool,
    comment: CommentSyntax,
    env: Arc<Environment<'static>>,
    dialect_name: String,
    vars: BTreeMap<String, Value>,
    blocks: u64,
    csv_header_done: bool,
    /// CSV: a last column `feed_mode` says what each feed row's feed is.
    feed_mode_column: bool,
    /// Inverse-time feed is on (between `inverse_time(true)` and
    /// `inverse_time(false)`).
    inverse_time_on: bool,
    /// Tool-centre-point control is on: the commands of `outside_tcp` (a
    /// tool change, for the new tool's length) turn it off first and on
    /// again after.
    tcp_on: bool,
    /// The templates written with tool-centre-point control off
    /// ([`Dialect`]'s `templates.outside_tcp`).
    outside_tcp: Vec<TemplateKind>,
    /// The arc words, when the dialect writes arcs.
    arc: Option<Box<ArcWords>>,
    /// The canned cycles the dialect writes (`[cycle]`).
    cycle: Option<crate::CycleWords>,
    /// The series of cycle holes written last, until something else is
    /// written (then `cycle_off` ends it).
    series: Option<Series>,
}

/// A series of canned-cycle holes in force: where the tool stood when it
/// began (the initial level `G98` returns to) and its last hole.
#[derive(Debug, Clone, Copy)]
struct Series {
    initial_z: f64,
    last: Hole,
}

/// The arc words of a writer: motion and plane words, the centre words in
/// the linear axes' number format, and the plane in force.
struct ArcWords {
    clockwise: Text,
    counter_clockwise: Text,
    planes: [Text; 3],
    centre: [Word; 3],
    /// The word of the centre's own line (Heidenhain `CC`): the centre is
    /// then absolute, from the last written values of the words of
    /// `xyz` (indices into the writer's words).
    centre_block: Option<Text>,
    xyz: [Option<usize>; 3],
    /// Sense words after the axis words, clockwise first (`DR-`, `DR+`).
    sense: Option<[Text; 2]>,
    /// The planes written as arcs (XY, ZX, YZ), and whether helices are.
    native_planes: [bool; 3],
    helix: bool,
    /// The plane last selected (`None`: as the header left it, unknown).
    plane: Option<crate::ArcPlane>,
    /// The centre line last written (its plane and two words, units): the
    /// controller keeps it (Heidenhain's CC is modal), so the same centre
    /// is not written again.
    centre_in_force: Option<(crate::ArcPlane, [i64; 2])>,
}

/// Room for the longest motion block of `dialect` with `words` axis words.
fn line_room(dialect: &Dialect, words: usize) -> usize {
    let (m, sep) = (&dialect.motion, &dialect.block.separator);
    dialect.numbering.prefix.len()
        + 24
        + sep.len()
        + m.rapid.len().max(m.feed.len())
        + (words + 1) * WORD_ROOM
        + 2 * sep.len()
        + dialect
            .block
            .compensated
            .iter()
            .map(String::len)
            .fold(dialect.block.after_axes.len(), usize::max)
        + dialect.feed.rapid.len()
        + dialect.block.line_end.len()
        // (and a CSV `feed_mode` field)
        + sep.len()
        + 16
        + 64
        // (and an arc block's plane, arc and centre words)
        + 2 * WORD_ROOM
        + 64
}

/// The pressure word: its format and state (modal), and whether the
/// dialect can write it at all.
struct PressureWord {
    word: Word,
    name: String,
    writable: bool,
}

impl<W: Write> NcWriter<W> {
    /// A writer for a machine with these axes (machine order). Resolves the
    /// word format of every axis once.
    pub fn new(dialect: &Dialect, axes: &[AxisSpec], out: W) -> Self {
        let words_kind = dialect.kind == DialectKind::Words;
        let formats: Vec<Formatter> = axes
            .iter()
            .map(|a| dialect.word_format(a).number.formatter())
            .collect();
        // Output order: `order` first, then the others in machine order.
        let mut order: Vec<usize> = Vec::with_capacity(axes.len());
        if words_kind {
            for name in &dialect.block.order {
                if let Some(i) = axes.iter().position(|a| &a.name == name)
                    && !order.contains(&i)
                {
                    order.push(i);
                }
            }
        }
        for i in 0..axes.len() {
            if !order.contains(&i) {
                order.push(i);
            }
        }
        let sep = &dialect.block.separator;
        // In an NC program the pressure word has a line of its own; in a
        // table it is a column.
        let pressure = axes
            .iter()
            .position(|a| a.pressure)
            .filter(|_| words_kind)
            .map(|i| PressureWord {
                word: Word::new(i, sep, &dialect.word_format(&axes[i]), true),
                name: axes[i].name.clone(),
                writable: dialect.writes_pressure(),
            });
        let words = order
            .into_iter()
            .filter(|&i| !(words_kind && axes[i].pressure))
            .filter(|&i| !words_kind || dialect.block.write_fixed || !axes[i].fixed)
            .map(|i| {
                let wf = dialect.word_format(&axes[i]);
                Word {
                    pressure: axes[i].pressure,
                    ..Word::new(i, sep, &wf, wf.modal && words_kind)
                }
            })
            .collect::<Vec<_>>();
        // Some axis word is written in every block: no block is skipped.
        let plain = words_kind && words.iter().any(|w| !w.modal);
        let feed = Word::new(
            usize::MAX,
            sep,
            &dialect.feed.word,
            dialect.feed.word.modal && words_kind,
        );
        let m = &dialect.motion;
        let room = line_room(dialect, words.len());
        let arc = dialect.arc.as_ref().filter(|_| words_kind).map(|a| {
            let linear = dialect.word_format(&AxisSpec::linear("X"));
            let centre = |k: usize| {
                let wf = crate::WordFormat {
                    prefix: a.centre[k].clone(),
                    suffix: String::new(),
                    ..linear.clone()
                };
                Word::new(usize::MAX, sep, &wf, false)
            };
            Box::new(ArcWords {
                clockwise: Text::new(&a.clockwise),
                counter_clockwise: Text::new(&a.counter_clockwise),
                planes: [0, 1, 2].map(|k| Text::new(&a.planes[k])),
                centre: [0, 1, 2].map(centre),
                centre_block: (!a.centre_block.is_empty()).then(|| Text::new(&a.centre_block)),
                xyz: ["X", "Y", "Z"].map(|n| {
                    words.iter().position(|w| {
                        !axes[w.index].rotary && axes[w.index].name.eq_ignore_ascii_case(n)
                    })
                }),
                sense: (!a.sense[0].is_empty()).then(|| a.sense.each_ref().map(|t| Text::new(t))),
                native_planes: a.native_planes,
                helix: a.helix,
                plane: None,
                centre_in_force: None,
            })
        });
        let vars = ProgramInfo::default().template_vars(&dialect.name, axes);
        NcWriter {
            out,
            kind: dialect.kind,
            buf: Vec::with_capacity(256),
            line: Line::new(room),
            units: vec![0; words.len()],
            names: axes.iter().map(|a| a.name.clone()).collect(),
            axis_specs: axes.to_vec(),
            unworded: (0..axes.len())
                .filter(|i| !words.iter().any(|w| w.index == *i))
                .collect(),
            formats,
            words,
            plain,
            pressure,
            feed_modal: feed.modal,
            feed,
            last_feed: None,
            feed_memo: (0, 0),
            feed_rapid: Text::new(&dialect.feed.rapid),
            motion_rapid: Text::new(&m.rapid),
            motion_feed: Text::new(&m.feed),
            motion_modal: m.modal,
            motion_state: m.initial,
            after_axes: Text::new(&dialect.block.after_axes),
            after_axes_plain: Text::new(&dialect.block.after_axes),
            compensated: match dialect.block.compensated.as_slice() {
                [l, r] if words_kind => Some([Text::new(l), Text::new(r)]),
                _ => None,
            },
            sep: Text::new(sep),
            eol: Text::new(&dialect.block.line_end),
            max_line: dialect.block.max_line_length.unwrap_or(usize::MAX),
            numbering: dialect.numbering.clone(),
            next_number: dialect.numbering.start,
            numbers_exhausted: false,
            comment: dialect.comment.clone(),
            env: dialect.env.clone(),
            dialect_name: dialect.name.clone(),
            vars,
            blocks: 0,
            csv_header_done: false,
            feed_mode_column: false,
            inverse_time_on: false,
            tcp_on: false,
            outside_tcp: dialect.outside_tcp.clone(),
            arc,
            cycle: dialect.cycle.clone().filter(|_| words_kind),
            series: None,
        }
    }

    /// The centre offset `value` on program axis `k` (0 = X, 1 = Y, 2 =
    /// Z) exactly as an arc block writes it (the value itself for a
    /// dialect without arc words).
    pub fn quantized_centre(&self, k: usize, value: f64) -> f64 {
        match &self.arc {
            Some(a) if k < 3 => a.centre[k].fmt.quantize(value),
            _ => value,
        }
    }

    /// Whether the dialect writes arc blocks ([`NcWriter::arc`]).
    pub fn writes_arcs(&self) -> bool {
        self.arc.is_some()
    }

    /// Whether the dialect writes an arc in `plane` as an arc block, a
    /// helix (rising along the plane's normal) or not: its `[arc]`
    /// `native_planes` and `helix`. Other arcs are written as lines.
    pub fn writes_arc(&self, plane: crate::ArcPlane, helix: bool) -> bool {
        self.arc
            .as_ref()
            .is_some_and(|a| a.native_planes[plane.index()] && (a.helix || !helix))
    }

    /// Writes a circular block ([`NcWriter::block`] with an arc): the
    /// plane word when the plane changes, the arc word, the axis words of
    /// the end point that change, the two centre words of the plane
    /// (relative to the start point) and the feed word. The next straight
    /// block writes its motion word.
    fn arc(&mut self, block: &Block<&[f64]>, circle: &ArcMotion) -> Result<(), BlockError> {
        if block.motion == Motion::Rapid {
            return Err(BlockError::RapidArc {
                cl_line: block.cl_line,
            });
        }
        let Some(mut arc) = self.arc.take() else {
            return Err(BlockError::NoArcWords {
                dialect: self.dialect_name.clone(),
            });
        };
        // A new pressure goes on its line before the arc, as before a
        // straight block.
        if let Err(e) = self.pressure_line(block) {
            self.arc = Some(arc);
            return Err(e);
        }
        let done = self.arc_line(&mut arc, block, circle);
        self.arc = Some(arc);
        done
    }

    fn arc_line(
        &mut self,
        arc: &mut ArcWords,
        block: &Block<&[f64]>,
        circle: &ArcMotion,
    ) -> Result<(), BlockError> {
        for (k, w) in self.words.iter().enumerate() {
            let v = block.axes[w.index];
            self.units[k] = w.units(v).map_err(|e| self.bad_value(w.index, v, e))?;
        }
        // The centre words in the order I, J, K.
        let [a, b, normal] = circle.plane.axes();
        let helix = arc.xyz[normal].is_some_and(|j| {
            let w = &self.words[j];
            w.known && w.last != self.units[j]
        });
        if !arc.native_planes[circle.plane.index()] || (helix && !arc.helix) {
            return Err(BlockError::ArcNotWritable {
                dialect: self.dialect_name.clone(),
                plane: circle.plane,
                helix,
            });
        }
        let (a, b) = (a.min(b), a.max(b));
        let mut centre = [0i64; 2];
        for (c, axis) in centre.iter_mut().zip([a, b]) {
            let mut v = circle.centre_offset[axis];
            if arc.centre_block.is_some() {
                let start = arc.xyz[axis]
                    .map(|j| &self.words[j])
                    .filter(|w| w.known)
                    .ok_or(BlockError::ArcStartUnknown {
                        cl_line: block.cl_line,
                    })?;
                v += start.fmt.value(start.last);
            }
            *c = arc.centre[axis]
                .fmt
                .units(v)
                .map_err(|e| BlockError::Value {
                    word: arc.centre[axis].first[..arc.centre[axis].first_len]
                        .iter()
                        .map(|&c| c as char)
                        .collect(),
                    value: v,
                    error: e,
                })?;
        }
        let mut feed_units = None;
        if let Some(f) = block.feed {
            let n = self
                .feed_units(f)
                .map_err(|e| self.bad_value(usize::MAX, f, e))?;
            if !(self.feed.modal && self.last_feed == Some(n)) {
                feed_units = Some(n);
            }
        }
        if let Some(cc) = &arc.centre_block
            && arc.centre_in_force != Some((circle.plane, centre))
        {
            self.centre_line(cc, &arc.centre, [a, b], centre, block.cl_line)?;
            arc.centre_in_force = Some((circle.plane, centre));
        }
        self.start_line()?;
        let line = &mut self.line;
        let mut first = true;
        let put = |line: &mut Line, t: &Text, first: &mut bool| {
            if !*first {
                line.put(&self.sep);
            }
            line.put(t);
            *first = false;
        };
        if arc.plane != Some(circle.plane) && !arc.planes[circle.plane.index()].is_empty() {
            put(line, &arc.planes[circle.plane.index()], &mut first);
        }
        arc.plane = Some(circle.plane);
        let word = if circle.clockwise {
            &arc.clockwise
        } else {
            &arc.counter_clockwise
        };
        put(line, word, &mut first);
        for (k, w) in self.words.iter_mut().enumerate() {
            let n = self.units[k];
            if w.modal && w.known && w.last == n {
                continue;
            }
            w.last = n;
            w.known = true;
            line.put_word(w, n, first);
            first = false;
        }
        if arc.centre_block.is_none() {
            for (c, axis) in centre.into_iter().zip([a, b]) {
                line.put_word(&arc.centre[axis], c, first);
                first = false;
            }
        }
        if let Some(sense) = &arc.sense {
            put(line, &sense[usize::from(!circle.clockwise)], &mut first);
        }
        if !self.after_axes.is_empty() {
            line.put(&self.sep);
            line.put(&self.after_axes);
        }
        if let Some(n) = feed_units {
            line.put_word(&self.feed, n, first);
            self.last_feed = Some(n);
        }
        line.put(&self.eol);
        // The arc word is modal on the controller: the next linear block
        // says what it is.
        self.motion_state = None;
        if self.line.len > self.max_line {
            return Err(self.too_long(block.cl_line));
        }
        self.blocks += 1;
        Ok(self.out.write_all(self.line.as_slice())?)
    }

    /// The centre line of its own before an arc line (Heidenhain `CC X+…
    /// Y+…`): the word `cc` and the plane's two centre words (absolute).
    fn centre_line(
        &mut self,
        cc: &Text,
        words: &[Word; 3],
        axes: [usize; 2],
        centre: [i64; 2],
        cl_line: Option<usize>,
    ) -> Result<(), BlockError> {
        self.start_line()?;
        self.line.put(cc);
        for (c, axis) in centre.into_iter().zip(axes) {
            self.line.put_word(&words[axis], c, false);
        }
        self.line.put(&self.eol);
        if self.line.len > self.max_line {
            return Err(self.too_long(cl_line));
        }
        Ok(self.out.write_all(self.line.as_slice())?)
    }

    /// The value exactly as it is written for machine axis `axis_index`
    /// (same as [`Dialect::quantize`] for that axis).
    #[inline]
    pub fn quantized(&self, axis_index: usize, value: f64) -> f64 {
        self.formats[axis_index].quantize(value)
    }

    /// Rounds the values of the first `axes.len()` machine axes as they are
    /// written (see [`NcWriter::quantized`]) into `written`, and remembers
    /// their units for the next [`NcWriter::block`] with these values, which
    /// then does not round them again. A value that cannot be written is
    /// copied unchanged (the block fails on it).
    #[inline]
    pub fn quantize_axes(&mut self, axes: &[f64], written: &mut [f64]) {
        let n = axes.len().min(written.len());
        let (axes, written) = (&axes[..n], &mut written[..n]);
        // Each word remembers the units of its axis.
        for w in &mut self.words {
            if w.index < n {
                let v = axes[w.index];
                written[w.index] = match w.fmt.units(v) {
                    Ok(u) => {
                        w.memo = (v.to_bits(), u);
                        w.fmt.value_of_units(u)
                    }
                    Err(_) => {
                        w.memo = (0, 0);
                        v
                    }
                };
            }
        }
        for &i in &self.unworded {
            if i < n {
                written[i] = self.formats[i].quantize(axes[i]);
            }
        }
    }

    /// The output, as written so far (every line goes to it whole, at once).
    pub fn get_ref(&self) -> &W {
        &self.out
    }

    /// Number of motion blocks written so far.
    pub fn blocks_written(&self) -> u64 {
        self.blocks
    }

    /// Writes the header: `override_template` if given (e.g. from the machine
    /// file), else the dialect's `header` template. For a CSV dialect, the
    /// column row. Also remembers `info` for all later templates.
    pub fn header(
        &mut self,
        info: &ProgramInfo,
        override_template: Option<&str>,
    ) -> Result<(), NcError> {
        check_tool_number(info.tool_number, false)?;
        self.program_vars(info);
        if self.kind == DialectKind::Csv {
            self.csv_header()?;
            return Ok(());
        }
        self.template_lines(
            TemplateKind::Header,
            override_template,
            None,
            self.numbering.header,
        )
    }

    /// Writes the footer: `override_template` if given, else the dialect's
    /// `footer` template. Nothing for a CSV dialect.
    pub fn footer(
        &mut self,
        info: &ProgramInfo,
        override_template: Option<&str>,
    ) -> Result<(), NcError> {
        self.program_vars(info);
        if self.kind == DialectKind::Csv {
            return Ok(());
        }
        self.end_cycle_series()?;
        self.template_lines(
            TemplateKind::Footer,
            override_template,
            None,
            self.numbering.header,
        )
    }

    /// The template variables of the program `info`, with `tcp` as it is.
    /// Every text in them (program name, file name, tool, machine, extra
    /// variables) is cleaned for the dialect ([`CommentSyntax::clean`]):
    /// no text from outside puts a line break or the end of a comment into
    /// the program.
    fn program_vars(&mut self, info: &ProgramInfo) {
        self.vars = info.template_vars(&self.dialect_name, &self.axis_specs);
        self.comment.clean_vars(&mut self.vars);
        self.vars.insert("tcp".into(), Value::from(self.tcp_on));
    }

    /// Tool change (template `tool_change` with `tool_number` and `tool_name`;
    /// `tool` and `tool_number` are updated for later templates too). With
    /// tool-centre-point control on, it is turned off before and on again
    /// after, for the new tool (unless the dialect's `outside_tcp` leaves
    /// `tool_change` out). The next block writes every axis word.
    /// The name is cleaned for the dialect ([`CommentSyntax::clean`]); a
    /// tool number outside 1 ..= [`MAX_TOOL_NUMBER`] is an error.
    pub fn tool_change(&mut self, number: u32, name: &str) -> Result<(), NcError> {
        self.tool_change_with_register(number, name, number)
    }

    /// A tool change as [`NcWriter::tool_change`] with the new tool's
    /// length offset register (template variable `length_register`, for
    /// `G43 H…`; the CL's `ADJUST`).
    pub fn tool_change_with_register(
        &mut self,
        number: u32,
        name: &str,
        register: u32,
    ) -> Result<(), NcError> {
        check_tool_number(number, true)?;
        check_tool_number(register, false)?;
        let name = self.comment.clean(name).into_owned();
        self.vars
            .insert("length_register".into(), Value::from(register));
        self.vars.insert("tool_loaded".into(), Value::from(true));
        self.vars.insert("tool_number".into(), Value::from(number));
        self.vars.insert("tool".into(), Value::from(name.as_str()));
        self.vars.insert("tool_name".into(), Value::from(name));
        self.command(TemplateKind::ToolChange, Vec::new())?;
        // The change moves the axes to where the machine changes tools, and
        // its cycle may leave another motion mode and feed in force.
        self.forget_modal_state();
        Ok(())
    }

    /// Spindle on (`spindle_on` with `speed`, `clockwise`, `direction` =
    /// `cw`/`ccw`) or off (`spindle_off`).
    /// A speed that writes as 0 in whole rpm (below 0.5) or above
    /// [`MAX_SPINDLE_RPM`] (not finite included) is an error.
    pub fn spindle(&mut self, state: Spindle) -> Result<(), NcError> {
        match state {
            Spindle::Off => self.command(TemplateKind::SpindleOff, Vec::new()),
            Spindle::Cw(s) | Spindle::Ccw(s) => {
                check_spindle_speed(s)?;
                let cw = matches!(state, Spindle::Cw(_));
                self.command(
                    TemplateKind::SpindleOn,
                    vec![
                        ("speed", Value::from(s)),
                        ("clockwise", Value::from(cw)),
                        ("direction", Value::from(if cw { "cw" } else { "ccw" })),
                    ],
                )
            }
        }
    }

    /// Coolant on in a mode (`coolant_on` with `mode`, e.g. `flood`, `mist`)
    /// or off (`None`, template `coolant_off`).
    pub fn coolant(&mut self, mode: Option<&str>) -> Result<(), NcError> {
        match mode {
            None => self.command(TemplateKind::CoolantOff, Vec::new()),
            // Templates see the mode in lower case (`mist`, `flood`), as
            // docs/dialects.md documents, whatever case the CL wrote.
            Some(m) => self.command(
                TemplateKind::CoolantOn,
                vec![(
                    "mode",
                    Value::from(self.comment.clean(&m.to_ascii_lowercase()).into_owned()),
                )],
            ),
        }
    }

    /// A program stop (`stop`, CL `STOP`) or an optional stop
    /// (`optional_stop`, CL `OPSTOP`). A dialect without the template is an
    /// error ([`NcError::MissingTemplate`]); nothing for CSV.
    pub fn stop(&mut self, optional: bool) -> Result<(), NcError> {
        let kind = if optional {
            TemplateKind::OptionalStop
        } else {
            TemplateKind::Stop
        };
        self.required_command(kind, Vec::new())
    }

    /// A dwell of `seconds` (template `dwell` with `seconds` and
    /// `milliseconds`, rounded to a whole number). A dwell that is not
    /// finite or not above zero, or longer than [`MAX_DWELL_SECONDS`], is an
    /// error; so is a dialect without the template.
    pub fn dwell(&mut self, seconds: f64) -> Result<(), NcError> {
        if !(seconds.is_finite() && seconds > 0.0 && seconds <= MAX_DWELL_SECONDS) {
            return Err(NcError::Value {
                what: "dwell",
                value: format!("{seconds} s"),
                reason: format!("a dwell is more than 0 and at most {MAX_DWELL_SECONDS} s"),
            });
        }
        let ms = (seconds * 1000.0).round() as u64;
        self.required_command(
            TemplateKind::Dwell,
            vec![
                ("seconds", Value::from(seconds)),
                ("milliseconds", Value::from(ms)),
            ],
        )
    }

    /// Cutter radius compensation on the `left` (`true`) or right side
    /// with offset `register` (template `cutcom_on` with `side` = `left` /
    /// `right` and `register`), or off (`None`, template `cutcom_off`). A
    /// dialect without the template is an error.
    pub fn cutter_compensation(&mut self, on: Option<(bool, u32)>) -> Result<(), NcError> {
        // A dialect whose compensation is a word of the motion blocks
        // (Heidenhain RL/RR for R0) writes it there; its templates, if
        // any, are written as well.
        if let Some([left_word, right_word]) = &self.compensated {
            let vars = match on {
                None => {
                    self.after_axes = self.after_axes_plain.clone();
                    Vec::new()
                }
                Some((left, register)) => {
                    self.after_axes = if left {
                        left_word.clone()
                    } else {
                        right_word.clone()
                    };
                    vec![
                        ("side", Value::from(if left { "left" } else { "right" })),
                        ("register", Value::from(register)),
                    ]
                }
            };
            let kind = if on.is_some() {
                TemplateKind::CutcomOn
            } else {
                TemplateKind::CutcomOff
            };
            return self.command(kind, vars);
        }
        match on {
            None => self.required_command(TemplateKind::CutcomOff, Vec::new()),
            Some((left, register)) => {
                // The templates compensate in the XY plane of the header.
                self.select_xy_plane()?;
                self.required_command(
                    TemplateKind::CutcomOn,
                    vec![
                        ("side", Value::from(if left { "left" } else { "right" })),
                        ("register", Value::from(register)),
                    ],
                )
            }
        }
    }

    /// The XY plane (`G17`) again after an arc in another plane, for what
    /// works in the header's plane (compensation, drilling cycles).
    fn select_xy_plane(&mut self) -> Result<(), NcError> {
        if let Some(a) = self.arc.as_mut()
            && a.plane.is_some_and(|p| p != crate::ArcPlane::Xy)
        {
            a.plane = Some(crate::ArcPlane::Xy);
            let word = String::from_utf8_lossy(&a.planes[0]).into_owned();
            self.insert(&word)?;
        }
        Ok(())
    }

    /// Whether the dialect writes canned cycles (`[cycle]`).
    pub fn writes_cycles(&self) -> bool {
        self.cycle.is_some()
    }

    /// One hole of a canned cycle, written with the dialect's `cycle`
    /// template (see docs/dialects.md, "Canned cycles"); `Ok(false)`, with
    /// nothing written, when the dialect cannot write it as a cycle: no
    /// `[cycle]` or not this kind, inverse-time feed on (a cycle's F is per
    /// minute), a tap with no spindle speed or a left-hand one (spindle
    /// counter-clockwise), a dwell the kind's cycle cannot
    /// make (`[cycle] dwell`), the tool below the feed start or the bottom
    /// not below it, a retract below the feed start, or, for a dialect
    /// whose cycles return to the feed start or the initial level only
    /// (`G99`/`G98`), a retract to neither. The caller then writes the
    /// hole's moves. A hole after the first of a series gets `first` false,
    /// and `changed` false when only its X and Y differ from the hole
    /// before; anything else written ends the series with `cycle_off`
    /// (`G80`).
    pub fn hole(&mut self, hole: &Hole) -> Result<bool, NcError> {
        let Some(words) = &self.cycle else {
            return Ok(false);
        };
        let finite = [hole.x, hole.y, hole.top, hole.r, hole.bottom, hole.retract]
            .iter()
            .chain([
                &hole.start_z,
                &hole.peck,
                &hole.dwell,
                &hole.feed,
                &hole.rpm,
            ])
            .all(|v| v.is_finite());
        if self.inverse_time_on
            || !finite
            || !words.kinds.contains(&hole.kind)
            || (hole.dwell > 0.0 && !words.dwell.contains(&hole.kind))
            || !(hole.bottom < hole.r && hole.r <= hole.start_z && hole.r <= hole.retract)
            || hole.feed <= 0.0
            // (A tap's pitch is its feed over the speed; the cycles written
            // tap right-hand threads.)
            || (hole.kind == crate::HoleKind::Tap && (hole.rpm <= 0.0 || hole.ccw))
        {
            return Ok(false);
        }
        let return_to_r = hole.retract == hole.r;
        let mut continues = self.series.is_some();
        if !return_to_r && words.retract == crate::CycleRetract::InitialOrR {
            // G98 goes back to where the series began.
            match self.series {
                Some(s) if s.initial_z == hole.retract => {}
                _ if hole.start_z == hole.retract => continues = false,
                _ => return Ok(false),
            }
        }
        if !continues {
            self.end_cycle_series()?;
        }
        // The cycles drill along Z of the XY plane.
        self.select_xy_plane()?;
        let changed = self.series.is_none_or(|s| {
            let last = s.last;
            (last.kind, last.top, last.r, last.bottom, last.retract)
                != (hole.kind, hole.top, hole.r, hole.bottom, hole.retract)
                || (last.peck, last.dwell, last.feed, last.rpm)
                    != (hole.peck, hole.dwell, hole.feed, hole.rpm)
        });
        let vars = vec![
            ("cycle", Value::from(hole.kind.as_str())),
            ("first", Value::from(self.series.is_none())),
            ("changed", Value::from(changed)),
            ("x", Value::from(hole.x)),
            ("y", Value::from(hole.y)),
            ("top", Value::from(hole.top)),
            ("r", Value::from(hole.r)),
            ("bottom", Value::from(hole.bottom)),
            ("retract", Value::from(hole.retract)),
            ("return_to_r", Value::from(return_to_r)),
            ("depth", Value::from(hole.top - hole.bottom)),
            ("clearance", Value::from(hole.r - hole.top)),
            ("retract_height", Value::from(hole.retract - hole.top)),
            ("peck", Value::from(hole.peck)),
            ("dwell", Value::from(hole.dwell)),
            (
                "dwell_ms",
                Value::from((hole.dwell * 1000.0).round() as u64),
            ),
            ("feed", Value::from(hole.feed)),
            ("rpm", Value::from(hole.rpm)),
        ];
        self.command(TemplateKind::Cycle, vars)?;
        let initial_z = self.series.map_or(hole.start_z, |s| s.initial_z);
        self.series = Some(Series {
            initial_z,
            last: *hole,
        });
        // The cycle leaves the tool at the retract, in another motion mode.
        self.forget_modal_state();
        Ok(true)
    }

    /// Ends the series of cycle holes in force, if any (`cycle_off`).
    fn end_cycle_series(&mut self) -> Result<(), NcError> {
        if self.series.take().is_some() {
            self.command(TemplateKind::CycleOff, Vec::new())?;
        }
        Ok(())
    }

    /// A command the program asks for (a stop, a dwell): a dialect without
    /// its template cannot write it, an error rather than a silent drop.
    fn required_command(
        &mut self,
        kind: TemplateKind,
        extra: Vec<(&str, Value)>,
    ) -> Result<(), NcError> {
        if self.kind != DialectKind::Csv && self.env.get_template(kind.key()).is_err() {
            return Err(NcError::MissingTemplate {
                template: kind.key(),
                dialect: self.dialect_name.clone(),
            });
        }
        self.command(kind, extra)
    }

    /// Tool-centre-point control on or off (templates `tcp_on`, `tcp_off`).
    /// A program that turns it on is tool-centre-point output (template
    /// variable `tcp_output` true from then on, whatever the header said).
    pub fn tcp(&mut self, on: bool) -> Result<(), NcError> {
        self.tcp_on = on;
        self.vars.insert("tcp".into(), Value::from(on));
        if on {
            self.vars.insert("tcp_output".into(), Value::from(true));
        }
        let kind = if on {
            TemplateKind::TcpOn
        } else {
            TemplateKind::TcpOff
        };
        self.command(kind, Vec::new())
    }

    /// CSV output of a program whose feed words change meaning (inverse
    /// time, with the blocks from an unknown start per minute): a last
    /// column `feed_mode` says, on every feed row, `inverse-time` or
    /// `per-minute` (empty on rapid rows). Call before the header; nothing
    /// for an NC dialect, whose `inverse_time_on`/`inverse_time_off` lines
    /// say it.
    pub fn add_feed_mode_column(&mut self) {
        self.feed_mode_column = self.kind == DialectKind::Csv;
    }

    /// Inverse-time feed on or off (templates `inverse_time_on`,
    /// `inverse_time_off`). While on, every feed block carries its feed word
    /// (inverse time is not modal): the caller passes 1 / block time in
    /// minutes as the block's feed.
    pub fn inverse_time(&mut self, on: bool) -> Result<(), NcError> {
        self.inverse_time_on = on;
        let kind = if on {
            TemplateKind::InverseTimeOn
        } else {
            TemplateKind::InverseTimeOff
        };
        self.command(kind, Vec::new())?;
        self.feed.modal = self.feed_modal && !on;
        self.last_feed = None;
        Ok(())
    }

    /// Renders a template source with the program variables plus `vars`
    /// and writes its lines (numbered like commands). For machine-specific
    /// snippets.
    pub fn template(
        &mut self,
        source: &str,
        vars: &BTreeMap<String, Value>,
    ) -> Result<(), NcError> {
        if self.kind == DialectKind::Csv {
            return Ok(());
        }
        self.end_cycle_series()?;
        let mut all = self.vars.clone();
        all.extend(
            vars.iter()
                .map(|(k, v)| (k.clone(), self.comment.clean_value(v))),
        );
        let text = template::render_str(&self.env, "template", source, &all)?;
        self.write_lines(&text, self.numbering.commands, "template")
    }

    /// A command template (tool change, spindle, coolant, pressure), with
    /// tool-centre-point control off around it where the dialect says so.
    fn command(&mut self, kind: TemplateKind, extra: Vec<(&str, Value)>) -> Result<(), NcError> {
        if self.kind == DialectKind::Csv {
            return Ok(());
        }
        if !matches!(kind, TemplateKind::Cycle | TemplateKind::CycleOff) {
            self.end_cycle_series()?;
        }
        if self.tcp_on
            && self.outside_tcp.contains(&kind)
            && self.env.get_template(kind.key()).is_ok()
        {
            self.tcp(false)?;
            self.command(kind, extra)?;
            return self.tcp(true);
        }
        let extra = if extra.is_empty() {
            None
        } else {
            let mut vars = self.vars.clone();
            for (k, v) in extra {
                vars.insert(k.to_string(), v);
            }
            Some(vars)
        };
        self.template_lines(kind, None, extra.as_ref(), self.numbering.commands)
    }

    fn template_lines(
        &mut self,
        kind: TemplateKind,
        override_template: Option<&str>,
        vars: Option<&BTreeMap<String, Value>>,
        numbered: bool,
    ) -> Result<(), NcError> {
        let vars = vars.unwrap_or(&self.vars);
        let text = match override_template {
            Some(src) => template::render_str(&self.env, kind.key(), src, vars)?,
            None => {
                if self.env.get_template(kind.key()).is_err() {
                    return Ok(());
                }
                template::render(&self.env, kind.key(), vars)?
            }
        };
        self.write_lines(&text, numbered, kind.key())
    }

    /// Writes every non-empty line of `text` (of template `template`),
    /// numbered if asked. A line longer than `max_line_length` loses the
    /// end of the comment it ends with (the program name in `(PROGRAM:
    /// …)`); any other is an error.
    fn write_lines(&mut self, text: &str, numbered: bool, template: &str) -> Result<(), NcError> {
        self.buf.clear();
        for line in text.lines() {
            let line = line.trim_end_matches('\r');
            if line.trim().is_empty() {
                continue;
            }
            let start = self.buf.len();
            if numbered && self.numbering.enabled {
                self.push_number()?;
            }
            let used = self.buf.len() - start + self.eol.len();
            let room = self.max_line.saturating_sub(used);
            let Some((head, tail)) = fit(line, room, &self.comment) else {
                return Err(NcError::LineTooLong {
                    source: format!("template `{template}`"),
                    text: line.to_string(),
                    length: used + line.len(),
                    max: self.max_line,
                });
            };
            self.buf.extend_from_slice(head.as_bytes());
            self.buf.extend_from_slice(tail.as_bytes());
            self.buf.extend_from_slice(&self.eol);
        }
        Ok(self.out.write_all(&self.buf)?)
    }

    /// A comment line (nothing when the dialect has comments off, or is CSV),
    /// its text cut to fit `max_line_length` (it is only a remark).
    pub fn comment(&mut self, text: &str) -> Result<(), NcError> {
        if self.kind == DialectKind::Csv || !self.comment.enabled {
            return Ok(());
        }
        // (A comment belongs to what comes next, after the cycles.)
        self.end_cycle_series()?;
        self.buf.clear();
        if self.numbering.enabled && self.numbering.comments {
            self.push_number()?;
        }
        self.buf.extend_from_slice(self.comment.prefix.as_bytes());
        let body = self.comment.clean(text);
        let used = self.buf.len() + self.comment.suffix.len() + self.eol.len();
        let Some(room) = self.max_line.checked_sub(used) else {
            return Err(NcError::LineTooLong {
                source: "comment".into(),
                text: String::from_utf8_lossy(&self.buf).into_owned(),
                length: used,
                max: self.max_line,
            });
        };
        let cut = floor_boundary(&body, room);
        self.buf.extend_from_slice(&body.as_bytes()[..cut]);
        self.buf.extend_from_slice(self.comment.suffix.as_bytes());
        self.buf.extend_from_slice(&self.eol);
        Ok(self.out.write_all(&self.buf)?)
    }

    /// A verbatim line (CL `INSERT`), never numbered; nothing for CSV. One
    /// longer than `max_line_length` is an error: it is code, not a remark.
    pub fn insert(&mut self, text: &str) -> Result<(), NcError> {
        if self.kind == DialectKind::Csv {
            return Ok(());
        }
        self.end_cycle_series()?;
        let text = text.replace(['\r', '\n'], " ");
        let length = text.len() + self.eol.len();
        if length > self.max_line {
            return Err(NcError::LineTooLong {
                source: "INSERT".into(),
                text,
                length,
                max: self.max_line,
            });
        }
        self.buf.clear();
        self.buf.extend_from_slice(text.as_bytes());
        self.buf.extend_from_slice(&self.eol);
        self.out.write_all(&self.buf)?;
        // Its code may move the axes or switch motion mode and feed (a
        // `G0 Z100` left the next feed block at rapid).
        self.forget_modal_state();
        Ok(())
    }

    /// After code the writer did not write itself (a tool change, an
    /// `INSERT`): the next motion block states its motion word, every axis
    /// word and its feed word again.
    fn forget_modal_state(&mut self) {
        for w in &mut self.words {
            w.known = false;
        }
        self.motion_state = None;
        self.last_feed = None;
    }

    /// The next block number, with prefix and separator, into `out`.
    /// Fails once the numbers run out: the number after the last one
    /// written does not fit in 64 bits and the dialect does not wrap
    /// (`wrap_after`). Numbers never repeat without a wrap.
    fn number_into(&mut self, out: &mut Vec<u8>) -> Result<(), NumbersRunOut> {
        if self.numbers_exhausted {
            return Err(NumbersRunOut {
                last: self.next_number,
            });
        }
        out.extend_from_slice(self.numbering.prefix.as_bytes());
        write_u64(out, self.next_number, self.numbering.digits);
        out.extend_from_slice(&self.sep);
        if self.sep.is_empty() && self.numbering.prefix.is_empty() {
            // Heidenhain-style bare numbers need a space.
            out.push(b' ');
        }
        match self.next_number.checked_add(self.numbering.step) {
            Some(n) => self.next_number = n,
            None if self.numbering.wrap_after.is_some() => {
                self.next_number = self.numbering.start;
            }
            None => self.numbers_exhausted = true,
        }
        if let Some(w) = self.numbering.wrap_after
            && self.next_number > w
        {
            self.next_number = self.numbering.start;
        }
        Ok(())
    }

    fn push_number(&mut self) -> Result<(), NumbersRunOut> {
        let mut buf = std::mem::take(&mut self.buf);
        let done = self.number_into(&mut buf);
        self.buf = buf;
        done
    }

    /// The line in `self.line` is longer than `max_line_length`.
    #[cold]
    fn too_long(&self, cl_line: Option<usize>) -> BlockError {
        BlockError::TooLong {
            text: String::from_utf8_lossy(self.line.as_slice())
                .trim_end()
                .to_string(),
            cl_line,
            length: self.line.len,
            max: self.max_line,
        }
    }

    fn bad_value(&self, axis: usize, value: f64, error: crate::NumberError) -> BlockError {
        BlockError::Value {
            word: self.names.get(axis).map_or("feed", String::as_str).into(),
            value,
            error,
        }
    }

    /// Writes one motion block. Modal words that did not change are left
    /// out; a block in which no axis word would be written is skipped
    /// entirely (with non-modal axis words every block is written; a CSV
    /// row is written for every block). A block with an arc is written as
    /// a circular block (see [`NcWriter::writes_arcs`]). The block's `line`
    /// is not read (the writer knows its own lines).
    /// Fails for a wrong number of axis values, a value that is not finite
    /// or too large to write, a line longer than the dialect allows, an arc
    /// on a rapid block or for a dialect without arc words, or the output.
    #[inline(always)]
    pub fn block<A: AsRef<[f64]>>(&mut self, block: &Block<A>) -> Result<(), BlockError> {
        let block = block.map_axes(|a| a.as_ref());
        if self.series.is_some() {
            self.end_cycle_series().map_err(|e| match e {
                NcError::Io(e) => BlockError::Io(e),
                other => BlockError::Template(other),
            })?;
        }
        if block.axes.len() != self.formats.len() {
            return Err(BlockError::AxisCount {
                got: block.axes.len(),
                want: self.formats.len(),
            });
        }
        if let Some(circle) = &block.arc {
            return self.arc(&block, circle);
        }
        self.straight(&block)
    }

    /// A straight block (see [`NcWriter::block`]), its axis count checked.
    #[inline(always)]
    fn straight(&mut self, block: &Block<&[f64]>) -> Result<(), BlockError> {
        if self.kind == DialectKind::Csv {
            return self.csv_block(block);
        }
        if let Some(p) = &self.pressure
            && !block.axes[p.word.index].is_nan()
        {
            self.pressure_line(block)?;
        }
        if self.plain {
            return self.plain_block(block);
        }
        // Pass 1: quantize, decide what is written.
        let mut any = false;
        for (k, w) in self.words.iter().enumerate() {
            let v = block.axes[w.index];
            let n = match w.units(v) {
                Ok(n) => n,
                Err(e) => return Err(self.bad_value(w.index, v, e)),
            };
            self.units[k] = n;
            any |= !(w.modal && w.known && w.last == n);
        }
        // A block that changes no axis word (a repeated point) moves
        // nothing: no line, and the motion and feed stay unwritten for the
        // next block that moves.
        if !any {
            return Ok(());
        }
        let motion_word: &[u8] = match block.motion {
            Motion::Rapid => &self.motion_rapid,
            Motion::Feed => &self.motion_feed,
        };
        let write_motion = !motion_word.is_empty()
            && (!self.motion_modal || self.motion_state != Some(block.motion));
        let mut feed_units = None;
        if block.motion == Motion::Feed
            && let Some(f) = block.feed
        {
            let n = match self.feed_units(f) {
                Ok(n) => n,
                Err(e) => return Err(self.bad_value(usize::MAX, f, e)),
            };
            if !(self.feed.modal && self.last_feed == Some(n)) {
                feed_units = Some(n);
            }
        }

        // Pass 2: format.
        self.start_line()?;
        let line = &mut self.line;
        let mut first = true;
        if write_motion {
            line.put(match block.motion {
                Motion::Rapid => &self.motion_rapid,
                Motion::Feed => &self.motion_feed,
            });
            first = false;
        }
        self.motion_state = Some(block.motion);
        for (k, w) in self.words.iter_mut().enumerate() {
            let n = self.units[k];
            if w.modal && w.known && w.last == n {
                continue;
            }
            w.last = n;
            w.known = true;
            line.put_word(w, n, first);
            first = false;
        }
        if !self.after_axes.is_empty() {
            if !first {
                line.put(&self.sep);
            }
            first = false;
            line.put(&self.after_axes);
        }
        if let Some(n) = feed_units {
            line.put_word(&self.feed, n, first);
            first = false;
            self.last_feed = Some(n);
        }
        if block.motion == Motion::Rapid && !self.feed_rapid.is_empty() {
            if !first {
                line.put(&self.sep);
            }
            line.put(&self.feed_rapid);
        }
        line.put(&self.eol);
        if self.line.len > self.max_line {
            return Err(self.too_long(block.cl_line));
        }
        self.blocks += 1;
        Ok(self.out.write_all(self.line.as_slice())?)
    }

    /// Starts the motion block line: empty, or the block number when
    /// numbering is on. Returns its length.
    #[inline(always)]
    fn start_line(&mut self) -> Result<usize, BlockError> {
        self.line.len = 0;
        if self.numbering.enabled {
            let mut number = std::mem::take(&mut self.buf);
            number.clear();
            let done = self.number_into(&mut number);
            self.line.put(&number);
            self.buf = number;
            done?;
        }
        Ok(self.line.len)
    }

    /// [`NcWriter::block`] (after the pressure line) for a dialect in which
    /// every block is written: words are formatted as their values are
    /// looked up. Nothing changes (the block number included) when a value
    /// cannot be written.
    #[inline(always)]
    fn plain_block(&mut self, block: &Block<&[f64]>) -> Result<(), BlockError> {
        let write_motion = !self.motion_word(block.motion).is_empty()
            && (!self.motion_modal || self.motion_state != Some(block.motion));
        let number_before = self.next_number;
        let mut len = self.start_line()?;
        let buf = &mut self.line.bytes[..];
        let mut first = true;
        if write_motion {
            len = put_text(
                buf,
                len,
                match block.motion {
                    Motion::Rapid => &self.motion_rapid,
                    Motion::Feed => &self.motion_feed,
                },
            );
            first = false;
        }
        for w in &self.words {
            let v = block.axes[w.index];
            let n = match w.units(v) {
                Ok(n) => n,
                Err(e) => {
                    self.next_number = number_before;
                    return Err(self.bad_value(w.index, v, e));
                }
            };
            len = put_word(buf, len, w, n, first);
            first = false;
        }
        let mut feed_units = None;
        if block.motion == Motion::Feed
            && let Some(f) = block.feed
        {
            let n = match self.feed_units(f) {
                Ok(n) => n,
                Err(e) => {
                    self.next_number = number_before;
                    return Err(self.bad_value(usize::MAX, f, e));
                }
            };
            if !(self.feed.modal && self.last_feed == Some(n)) {
                feed_units = Some(n);
            }
        }
        let buf = &mut self.line.bytes[..];
        if !self.after_axes.is_empty() {
            len = put_text(buf, len, &self.sep);
            len = put_text(buf, len, &self.after_axes);
        }
        if let Some(n) = feed_units {
            len = put_word(buf, len, &self.feed, n, false);
            self.last_feed = Some(n);
        }
        if block.motion == Motion::Rapid && !self.feed_rapid.is_empty() {
            len = put_text(buf, len, &self.sep);
            len = put_text(buf, len, &self.feed_rapid);
        }
        len = put_text(buf, len, &self.eol);
        self.line.len = len;
        if len > self.max_line {
            return Err(self.too_long(block.cl_line));
        }
        self.motion_state = Some(block.motion);
        self.blocks += 1;
        Ok(self.out.write_all(self.line.as_slice())?)
    }

    /// The units of feed value `f`, remembered while it does not change.
    #[inline(always)]
    fn feed_units(&mut self, f: f64) -> Result<i64, crate::NumberError> {
        if self.feed_memo.0 == f.to_bits() {
            return Ok(self.feed_memo.1);
        }
        let n = self.feed.fmt.units(f)?;
        self.feed_memo = (f.to_bits(), n);
        Ok(n)
    }

    /// Whether the feed word of a positive feed `f` reads 0: the
    /// dialect's feed decimals are too few for it.
    pub fn feed_rounds_to_zero(&self, f: f64) -> bool {
        f > 0.0 && self.feed.fmt.units(f).is_ok_and(|n| n == 0)
    }

    fn motion_word(&self, motion: Motion) -> &[u8] {
        match motion {
            Motion::Rapid => &self.motion_rapid,
            Motion::Feed => &self.motion_feed,
        }
    }

    /// The pressure word on its own line, when the block's pressure differs
    /// from the last one written (then the `pressure` template, if any, e.g.
    /// a dwell while the wheel settles). NaN: no pressure programmed.
    fn pressure_line(&mut self, block: &Block<&[f64]>) -> Result<(), BlockError> {
        let Some(p) = &self.pressure else {
            return Ok(());
        };
        let (index, value) = (p.word.index, block.axes[p.word.index]);
        if value.is_nan() {
            return Ok(());
        }
        if !p.writable {
            return Err(BlockError::NoPressureWord {
                dialect: self.dialect_name.clone(),
                word: p.name.clone(),
            });
        }
        let n = match p.word.fmt.units(value) {
            Ok(n) => n,
            Err(e) => return Err(self.bad_value(index, value, e)),
        };
        if n == 0 && value != 0.0 {
            // (As for feeds: a pressure asked for must not be written as
            // none.)
            return Err(BlockError::PressureRoundsToZero {
                word: p.name.clone(),
                value,
            });
        }
        if p.word.known && p.word.last == n {
            return Ok(());
        }
        let mut number = std::mem::take(&mut self.buf);
        number.clear();
        if self.numbering.enabled
            && self.numbering.commands
            && let Err(e) = self.number_into(&mut number)
        {
            self.buf = number;
            return Err(e.into());
        }
        self.line.len = 0;
        self.line.put(&number);
        self.buf = number;
        let Some(p) = &mut self.pressure else {
            unreachable!("checked above")
        };
        p.word.last = n;
        p.word.known = true;
        self.line.put_word(&p.word, n, true);
        self.line.put(&self.eol);
        if self.line.len > self.max_line {
            return Err(self.too_long(block.cl_line));
        }
        self.out.write_all(self.line.as_slice())?;
        let written = p.word.fmt.quantize(value);
        let name = Value::from(p.name.as_str());
        self.command(
            TemplateKind::Pressure,
            vec![("pressure", Value::from(written)), ("pressure_word", name)],
        )
        .map_err(|e| match e {
            NcError::Io(e) => BlockError::Io(e),
            other => BlockError::Template(other),
        })
    }

    fn csv_header(&mut self) -> io::Result<()> {
        if self.csv_header_done {
            return Ok(());
        }
        self.csv_header_done = true;
        self.buf.clear();
        self.buf.extend_from_slice(b"line");
        self.buf.extend_from_slice(&self.sep);
        self.buf.extend_from_slice(b"motion");
        for w in &self.words {
            self.buf.extend_from_slice(&self.sep);
            self.buf.extend_from_slice(self.names[w.index].as_bytes());
        }
        self.buf.extend_from_slice(&self.sep);
        self.buf.extend_from_slice(b"feed");
        if self.feed_mode_column {
            self.buf.extend_from_slice(&self.sep);
            self.buf.extend_from_slice(b"feed_mode");
        }
        self.buf.extend_from_slice(&self.eol);
        self.out.write_all(&self.buf)
    }

    fn csv_block(&mut self, block: &Block<&[f64]>) -> Result<(), BlockError> {
        if !self.csv_header_done {
            self.csv_header()?;
        }
        let buf = &mut self.line.bytes[..];
        let mut len = 0;
        if let Some(l) = block.cl_line {
            len = encode_u64(buf, len, l as u64);
        }
        len = put_text(buf, len, &self.sep);
        let motion: &[u8; 8] = match block.motion {
            Motion::Rapid => b"rapid\0\0\0",
            Motion::Feed => b"feed\0\0\0\0",
        };
        buf[len..len + 8].copy_from_slice(motion);
        len += block.motion.as_str().len();
        for w in &self.words {
            let v = block.axes[w.index];
            if w.pressure && v.is_nan() {
                // No pressure programmed: an empty field.
                len = put_text(buf, len, &self.sep);
                continue;
            }
            let n = match w.units(v) {
                Ok(n) => n,
                Err(e) => return Err(self.bad_value(w.index, v, e)),
            };
            len = put_word(buf, len, w, n, false);
        }
        len = put_text(&mut self.line.bytes, len, &self.sep);
        if block.motion == Motion::Feed
            && let Some(f) = block.feed
        {
            let n = match self.feed_units(f) {
                Ok(n) => n,
                Err(e) => return Err(self.bad_value(usize::MAX, f, e)),
            };
            len = put_word(&mut self.line.bytes, len, &self.feed, n, true);
        }
        if self.feed_mode_column {
            len = put_text(&mut self.line.bytes, len, &self.sep);
            if block.motion == Motion::Feed && block.feed.is_some() {
                let mode: &[u8] = if self.inverse_time_on {
                    b"inverse-time"
                } else {
                    b"per-minute"
                };
                self.line.bytes[len..len + mode.len()].copy_from_slice(mode);
                len += mode.len();
            }
        }
        len = put_text(&mut self.line.bytes, len, &self.eol);
        self.line.len = len;
        if len > self.max_line {
            return Err(self.too_long(block.cl_line));
        }
        self.blocks += 1;
        Ok(self.out.write_all(self.line.as_slice())?)
    }

    /// Flushes and returns the output.
    pub fn finish(mut self) -> io::Result<W> {
        if self.kind == DialectKind::Csv && !self.csv_header_done {
            self.csv_header()?;
        }
        self.out.flush()?;
        Ok(self.out)
    }
}

/// The fastest spindle speed a program may ask for, rpm: six digits in
/// whole rpm, above any machining spindle (high-speed and air-turbine
/// spindles run up to a few 100 000 rpm). A larger value is an error,
/// not a word of hundreds of digits.
pub const MAX_SPINDLE_RPM: f64 = 999_999.0;

/// The longest dwell written, seconds: a day. Controls take a few digits
/// of seconds (Fanuc `G04 P` in ms has 8 digits, about 27 hours); a longer
/// one is a unit mistake (milliseconds read as seconds), refused.
pub const MAX_DWELL_SECONDS: f64 = 86_400.0;

/// The largest tool number a program may ask for: eight digits, the
/// longest T word of the common controllers (Fanuc `T` with eight digits;
/// Sinumerik and Heidenhain allow fewer: their controller says so).
pub const MAX_TOOL_NUMBER: u32 = 99_999_999;

/// A spindle speed every dialect writes in whole rpm: not one that writes
/// as 0 (below 0.5 rpm), nor one above [`MAX_SPINDLE_RPM`].
fn check_spindle_speed(rpm: f64) -> Result<(), NcError> {
    if rpm.is_finite() && (0.5..=MAX_SPINDLE_RPM).contains(&rpm) {
        return Ok(());
    }
    let reason = if rpm.is_finite() && rpm < 0.5 && rpm > -0.5 {
        "it would be written as S0 (whole rpm)".to_string()
    } else {
        format!("a spindle speed must be from 0.5 to {MAX_SPINDLE_RPM} rpm")
    };
    Err(NcError::Value {
        what: "spindle speed",
        value: rpm.to_string(),
        reason,
    })
}

/// A tool number from 1 (0 is "no tool" on most controllers; allowed in the
/// header, where it means "unknown", when `change` is false) to
/// [`MAX_TOOL_NUMBER`].
fn check_tool_number(number: u32, change: bool) -> Result<(), NcError> {
    if number <= MAX_TOOL_NUMBER && (number > 0 || !change) {
        return Ok(());
    }
    Err(NcError::Value {
        what: "tool number",
        value: number.to_string(),
        reason: if number == 0 {
            "tool 0 unloads the spindle on most controllers: load a tool from 1".into()
        } else {
            format!("a tool number must be from 1 to {MAX_TOOL_NUMBER}")
        },
    })
}

/// `line` cut to `room` bytes, as a head and a tail to join: the end of the
/// text of the comment it ends with goes (a remark; the code before it stays
/// whole). `None` when that is not enough.
fn fit<'a>(line: &'a str, room: usize, comment: &CommentSyntax) -> Option<(&'a str, &'a str)> {
    if line.len() <= room {
        return Some((line, ""));
    }
    let body = comment_body(line, comment)?;
    let excess = line.len() - room;
    if excess > body.len() {
        return None;
    }
    let keep = floor_boundary(line, body.end - excess);
    Some((&line[..keep], &line[body.end..]))
}

/// The byte range of the text of the comment `line` ends with, in the
/// dialect's comment syntax: after the last prefix before the suffix, or
/// after the first prefix where comments run to the end of the line.
fn comment_body(line: &str, comment: &CommentSyntax) -> Option<std::ops::Range<usize>> {
    let (prefix, suffix) = (comment.prefix.as_str(), comment.suffix.as_str());
    if prefix.is_empty() {
        return None;
    }
    let end = line.strip_suffix(suffix)?.len();
    let start = if suffix.is_empty() {
        line.find(prefix)?
    } else {
        line[..end].rfind(prefix)?
    };
    Some(start + prefix.len()..end)
}

/// The largest char boundary of `s` at or before `at`.
fn floor_boundary(s: &str, at: usize) -> usize {
    let mut at = at.min(s.len());
    while !s.is_char_boundary(at) {
        at -= 1;
    }
    at
}
