//! The NC writer.

use std::collections::BTreeMap;
use std::io::{self, Write};
use std::sync::Arc;

use minijinja::{Environment, Value};

use crate::dialect::{CommentSyntax, Dialect, DialectKind, Numbering, TemplateKind};
use crate::number::{ENCODE_MAX, Formatter, write_u64};
use crate::template;
use crate::{AxisSpec, Block, Motion, NcError, ProgramInfo};

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

/// Longest separator + prefix of a word (checked when a dialect is loaded).
pub(crate) const MAX_LEAD: usize = 32;
/// Longest suffix of a word (checked when a dialect is loaded).
pub(crate) const MAX_SUFFIX: usize = 16;

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
    /// Last written value in units; meaningful when `known`.
    last: i64,
    known: bool,
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
            last: 0,
            known: false,
        }
    }
}

/// Room for one word in the line buffer: fixed-size copies of lead, number
/// and suffix.
const WORD_ROOM: usize = MAX_LEAD + ENCODE_MAX + MAX_SUFFIX;

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

    #[inline]
    fn put_padded<const N: usize>(&mut self, s: &[u8; N], len: usize) {
        self.bytes[self.len..self.len + N].copy_from_slice(s);
        self.len += len;
    }

    /// One word: lead (or prefix alone), number, suffix.
    #[inline(always)]
    fn put_word(&mut self, w: &Word, n: i64, first: bool) {
        if first {
            self.put_padded(&w.first, w.first_len);
        } else {
            self.put_padded(&w.lead, w.lead_len);
        }
        self.len = w.fmt.encode_into(n, &mut self.bytes, self.len);
        if w.suffix_len > 0 {
            self.put_padded(&w.suffix, w.suffix_len);
        }
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
    /// Per machine axis, the bits of the value [`NcWriter::quantize_axes`]
    /// last rounded and its units: the block that follows does not round
    /// them again.
    memo: Vec<Option<(u64, i64)>>,
    /// Words written in a block, in output order.
    words: Vec<Word>,
    /// The pressure word of an NC dialect, written on its own line (see
    /// [`AxisSpec::pressure`]).
    pressure: Option<PressureWord>,
    feed: Word,
    /// Whether the dialect's feed word is modal (feed per minute).
    feed_modal: bool,
    last_feed: Option<i64>,
    feed_rapid: Box<[u8]>,
    motion_rapid: Box<[u8]>,
    motion_feed: Box<[u8]>,
    motion_modal: bool,
    motion_state: Option<Motion>,
    after_axes: Box<[u8]>,
    sep: Box<[u8]>,
    eol: Box<[u8]>,
    numbering: Numbering,
    next_number: u64,
    comment: CommentSyntax,
    env: Arc<Environment<'static>>,
    dialect_name: String,
    vars: BTreeMap<String, Value>,
    blocks: u64,
    csv_header_done: bool,
}

/// The pressure word: its format and state (modal), and whether the
/// dialect can write it at all.
struct PressureWord {
    word: Word,
    name: String,
    writable: bool,
}

fn bytes(s: &str) -> Box<[u8]> {
    s.as_bytes().into()
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
                Word::new(i, sep, &wf, wf.modal && words_kind)
            })
            .collect::<Vec<_>>();
        let feed = Word::new(
            usize::MAX,
            sep,
            &dialect.feed.word,
            dialect.feed.word.modal && words_kind,
        );
        let m = &dialect.motion;
        // Room for the longest block.
        let room = dialect.numbering.prefix.len()
            + 24
            + sep.len()
            + m.rapid.len().max(m.feed.len())
            + (words.len() + 1) * WORD_ROOM
            + 2 * sep.len()
            + dialect.block.after_axes.len()
            + dialect.feed.rapid.len()
            + dialect.block.line_end.len()
            + 64;
        let vars = ProgramInfo::default().template_vars(&dialect.name, axes);
        NcWriter {
            out,
            kind: dialect.kind,
            buf: Vec::with_capacity(256),
            line: Line::new(room),
            units: vec![0; words.len()],
            names: axes.iter().map(|a| a.name.clone()).collect(),
            axis_specs: axes.to_vec(),
            memo: vec![None; formats.len()],
            formats,
            words,
            pressure,
            feed_modal: feed.modal,
            feed,
            last_feed: None,
            feed_rapid: bytes(&dialect.feed.rapid),
            motion_rapid: bytes(&m.rapid),
            motion_feed: bytes(&m.feed),
            motion_modal: m.modal,
            motion_state: m.initial,
            after_axes: bytes(&dialect.block.after_axes),
            sep: bytes(sep),
            eol: bytes(&dialect.block.line_end),
            numbering: dialect.numbering.clone(),
            next_number: dialect.numbering.start,
            comment: dialect.comment.clone(),
            env: dialect.env.clone(),
            dialect_name: dialect.name.clone(),
            vars,
            blocks: 0,
            csv_header_done: false,
        }
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
        for (i, (&v, w)) in axes.iter().zip(written.iter_mut()).enumerate() {
            let f = &self.formats[i];
            match f.units(v) {
                Ok(n) => {
                    self.memo[i] = Some((v.to_bits(), n));
                    *w = f.value_of_units(n);
                }
                Err(_) => {
                    self.memo[i] = None;
                    *w = v;
                }
            }
        }
    }

    /// The units of `v` for machine axis `index`, remembered by
    /// [`NcWriter::quantize_axes`] or worked out.
    #[inline(always)]
    fn units_of(&self, index: usize, v: f64) -> Result<i64, crate::NumberError> {
        match self.memo[index] {
            Some((bits, n)) if bits == v.to_bits() => Ok(n),
            _ => self.formats[index].units(v),
        }
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
        self.vars = info.template_vars(&self.dialect_name, &self.axis_specs);
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
        self.vars = info.template_vars(&self.dialect_name, &self.axis_specs);
        if self.kind == DialectKind::Csv {
            return Ok(());
        }
        self.template_lines(
            TemplateKind::Footer,
            override_template,
            None,
            self.numbering.header,
        )
    }

    /// Tool change (template `tool_change` with `tool_number` and `tool_name`;
    /// `tool` and `tool_number` are updated for later templates too).
    pub fn tool_change(&mut self, number: u32, name: &str) -> Result<(), NcError> {
        self.vars.insert("tool_number".into(), Value::from(number));
        self.vars.insert("tool".into(), Value::from(name));
        self.vars.insert("tool_name".into(), Value::from(name));
        self.command(TemplateKind::ToolChange, Vec::new())
    }

    /// Spindle on (`spindle_on` with `speed`, `clockwise`, `direction` =
    /// `cw`/`ccw`) or off (`spindle_off`).
    pub fn spindle(&mut self, state: Spindle) -> Result<(), NcError> {
        match state {
            Spindle::Off => self.command(TemplateKind::SpindleOff, Vec::new()),
            Spindle::Cw(s) | Spindle::Ccw(s) => {
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
            Some(m) => self.command(TemplateKind::CoolantOn, vec![("mode", Value::from(m))]),
        }
    }

    /// Tool-centre-point control on or off (templates `tcp_on`, `tcp_off`).
    pub fn tcp(&mut self, on: bool) -> Result<(), NcError> {
        let kind = if on {
            TemplateKind::TcpOn
        } else {
            TemplateKind::TcpOff
        };
        self.command(kind, Vec::new())
    }

    /// Inverse-time feed on or off (templates `inverse_time_on`,
    /// `inverse_time_off`). While on, every feed block carries its feed word
    /// (inverse time is not modal): the caller passes 1 / block time in
    /// minutes as the block's feed.
    pub fn inverse_time(&mut self, on: bool) -> Result<(), NcError> {
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
        let mut all = self.vars.clone();
        all.extend(vars.iter().map(|(k, v)| (k.clone(), v.clone())));
        let text = template::render_str(&self.env, "template", source, &all)?;
        self.write_lines(&text, self.numbering.commands)?;
        Ok(())
    }

    fn command(&mut self, kind: TemplateKind, extra: Vec<(&str, Value)>) -> Result<(), NcError> {
        if self.kind == DialectKind::Csv {
            return Ok(());
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
        self.write_lines(&text, numbered)?;
        Ok(())
    }

    /// Writes every non-empty line of `text`, numbered if asked.
    fn write_lines(&mut self, text: &str, numbered: bool) -> io::Result<()> {
        self.buf.clear();
        for line in text.lines() {
            let line = line.trim_end_matches('\r');
            if line.trim().is_empty() {
                continue;
            }
            if numbered && self.numbering.enabled {
                self.push_number();
            }
            self.buf.extend_from_slice(line.as_bytes());
            self.buf.extend_from_slice(&self.eol);
        }
        self.out.write_all(&self.buf)
    }

    /// A comment line (nothing when the dialect has comments off, or is CSV).
    pub fn comment(&mut self, text: &str) -> io::Result<()> {
        if self.kind == DialectKind::Csv || !self.comment.enabled {
            return Ok(());
        }
        self.buf.clear();
        if self.numbering.enabled && self.numbering.comments {
            self.push_number();
        }
        self.buf.extend_from_slice(self.comment.prefix.as_bytes());
        let mut body: String = text.replace(['\r', '\n'], " ");
        for (from, to) in &self.comment.replace {
            if body.contains(from.as_str()) {
                body = body.replace(from.as_str(), to);
            }
        }
        self.buf.extend_from_slice(body.as_bytes());
        self.buf.extend_from_slice(self.comment.suffix.as_bytes());
        self.buf.extend_from_slice(&self.eol);
        self.out.write_all(&self.buf)
    }

    /// A verbatim line (CL `INSERT`), never numbered; nothing for CSV.
    pub fn insert(&mut self, text: &str) -> io::Result<()> {
        if self.kind == DialectKind::Csv {
            return Ok(());
        }
        self.buf.clear();
        self.buf
            .extend_from_slice(text.replace(['\r', '\n'], " ").as_bytes());
        self.buf.extend_from_slice(&self.eol);
        self.out.write_all(&self.buf)
    }

    /// The next block number, with prefix and separator, into `out`.
    fn number_into(&mut self, out: &mut Vec<u8>) {
        out.extend_from_slice(self.numbering.prefix.as_bytes());
        write_u64(out, self.next_number, self.numbering.digits);
        out.extend_from_slice(&self.sep);
        if self.sep.is_empty() && self.numbering.prefix.is_empty() {
            // Heidenhain-style bare numbers need a space.
            out.push(b' ');
        }
        self.next_number = self.next_number.saturating_add(self.numbering.step);
        if let Some(w) = self.numbering.wrap_after
            && self.next_number > w
        {
            self.next_number = self.numbering.start;
        }
    }

    fn push_number(&mut self) {
        let mut buf = std::mem::take(&mut self.buf);
        self.number_into(&mut buf);
        self.buf = buf;
    }

    fn bad_value(&self, axis: usize, value: f64, e: crate::NumberError) -> io::Error {
        let name = self.names.get(axis).map_or("feed", String::as_str);
        io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("cannot write {name} = {value}: {e}"),
        )
    }

    /// Writes one motion block. Modal words that did not change are left
    /// out; a block in which nothing would be written is skipped entirely.
    /// Fails (`InvalidInput`) for a wrong number of axis values, or a value
    /// that is not finite or too large to write.
    #[inline]
    pub fn block(&mut self, block: &Block) -> io::Result<()> {
        if block.axes.len() != self.formats.len() {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!(
                    "block has {} axis values, the machine has {} axes",
                    block.axes.len(),
                    self.formats.len()
                ),
            ));
        }
        if self.kind == DialectKind::Csv {
            return self.csv_block(block);
        }
        if let Some(p) = &self.pressure
            && !block.axes[p.word.index].is_nan()
        {
            self.pressure_line(block.axes)?;
        }
        // Pass 1: quantize, decide what is written.
        let mut any = false;
        for (k, w) in self.words.iter().enumerate() {
            let v = block.axes[w.index];
            let n = match self.units_of(w.index, v) {
                Ok(n) => n,
                Err(e) => return Err(self.bad_value(w.index, v, e)),
            };
            self.units[k] = n;
            any |= !(w.modal && w.known && w.last == n);
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
            let n = match self.feed.fmt.units(f) {
                Ok(n) => n,
                Err(e) => return Err(self.bad_value(usize::MAX, f, e)),
            };
            if !(self.feed.modal && self.last_feed == Some(n)) {
                feed_units = Some(n);
            }
        }
        // A block is worth writing when it programs something: an axis or
        // feed word, or a change of a modal motion.
        if !(any || (write_motion && self.motion_modal) || feed_units.is_some()) {
            return Ok(());
        }

        // Pass 2: format.
        if self.numbering.enabled {
            let mut number = std::mem::take(&mut self.buf);
            number.clear();
            self.number_into(&mut number);
            self.line.len = 0;
            self.line.put(&number);
            self.buf = number;
        } else {
            self.line.len = 0;
        }
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
        self.blocks += 1;
        self.out.write_all(line.as_slice())
    }

    /// The pressure word on its own line, when the block's pressure differs
    /// from the last one written (then the `pressure` template, if any, e.g.
    /// a dwell while the wheel settles). NaN: no pressure programmed.
    fn pressure_line(&mut self, axes: &[f64]) -> io::Result<()> {
        let Some(p) = &self.pressure else {
            return Ok(());
        };
        let (index, value) = (p.word.index, axes[p.word.index]);
        if value.is_nan() {
            return Ok(());
        }
        if !p.writable {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!(
                    "dialect `{}` cannot write the pressure word `{}`: it has no [pressure] table",
                    self.dialect_name, p.name
                ),
            ));
        }
        let n = match p.word.fmt.units(value) {
            Ok(n) => n,
            Err(e) => return Err(self.bad_value(index, value, e)),
        };
        if p.word.known && p.word.last == n {
            return Ok(());
        }
        let mut number = std::mem::take(&mut self.buf);
        number.clear();
        if self.numbering.enabled && self.numbering.commands {
            self.number_into(&mut number);
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
        self.out.write_all(self.line.as_slice())?;
        let written = p.word.fmt.quantize(value);
        let name = Value::from(p.name.as_str());
        self.command(
            TemplateKind::Pressure,
            vec![("pressure", Value::from(written)), ("pressure_word", name)],
        )
        .map_err(|e| match e {
            NcError::Io(e) => e,
            other => io::Error::other(other.to_string()),
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
        self.buf.extend_from_slice(&self.eol);
        self.out.write_all(&self.buf)
    }

    fn csv_block(&mut self, block: &Block) -> io::Result<()> {
        if !self.csv_header_done {
            self.csv_header()?;
        }
        let mut line = std::mem::replace(&mut self.line, Line::new(0));
        line.len = 0;
        if let Some(l) = block.cl_line {
            self.buf.clear();
            write_u64(&mut self.buf, l as u64, 1);
            line.put(&self.buf);
        }
        line.put(&self.sep);
        line.put(block.motion.as_str().as_bytes());
        for w in &self.words {
            let v = block.axes[w.index];
            if v.is_nan() && self.axis_specs[w.index].pressure {
                // No pressure programmed: an empty field.
                line.put(&self.sep);
                continue;
            }
            let n = match self.units_of(w.index, v) {
                Ok(n) => n,
                Err(e) => {
                    self.line = line;
                    return Err(self.bad_value(w.index, v, e));
                }
            };
            line.put_word(w, n, false);
        }
        line.put(&self.sep);
        if block.motion == Motion::Feed
            && let Some(f) = block.feed
        {
            let n = match self.feed.fmt.units(f) {
                Ok(n) => n,
                Err(e) => {
                    self.line = line;
                    return Err(self.bad_value(usize::MAX, f, e));
                }
            };
            line.put_word(&self.feed, n, true);
        }
        line.put(&self.eol);
        self.blocks += 1;
        let result = self.out.write_all(line.as_slice());
        self.line = line;
        result
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
