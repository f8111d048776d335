//! Dialect files: parsing, validation and the resolved settings.

use std::collections::BTreeMap;
use std::fmt;
use std::sync::Arc;

use kinpost_diag::{Diagnostic, Diagnostics, Severity};
use minijinja::Environment;
use serde::Deserialize;
use toml::Spanned;

use crate::template::{self, TemplateError, template_span_in_toml};
use crate::{AxisSpec, Motion, ProgramInfo};
use kinpost_number::{MAX_DECIMALS, NumberFormat, TrailingZeros};

/// Longest prefix of a word, in bytes (words are copied in fixed-size moves).
const MAX_PREFIX: usize = 24;
/// Longest separator + prefix of a word (the writer's fixed room).
pub(crate) const MAX_LEAD: usize = 32;
/// Longest suffix of a word (the writer's fixed room).
pub(crate) const MAX_SUFFIX: usize = 16;
/// Most digits a block number is padded to (the writer's number buffer).
const MAX_NUMBER_DIGITS: usize = 24;

/// A built-in dialect: its name and the text of `dialects/NAME.toml`.
macro_rules! dialect {
    ($name:literal) => {
        ($name, include_str!(concat!("../dialects/", $name, ".toml")))
    };
}

const BUILTINS: &[(&str, &str)] = &[
    dialect!("sinumerik"),
    dialect!("fanuc"),
    dialect!("heidenhain"),
    dialect!("linuxcnc"),
    dialect!("csv"),
];
const BUILTIN_NAMES: &[&str] = &["sinumerik", "fanuc", "heidenhain", "linuxcnc", "csv"];

/// What kind of file a dialect writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum DialectKind {
    /// An NC program: blocks of address words, templates, comments.
    #[default]
    Words,
    /// A table of axis values: a header row, then one row per motion block
    /// (`line`, `motion`, every machine axis in machine order, `feed`).
    Csv,
}

/// The complete format of one word: prefix, number, suffix, modality.
#[derive(Debug, Clone, PartialEq)]
pub struct WordFormat {
    /// Text before the number (`X=`, `A=DC(`, `F`).
    pub prefix: String,
    /// Text after the number (`)` for `DC(...)`).
    pub suffix: String,
    /// The number.
    pub number: NumberFormat,
    /// A modal word is written only when its (written) value changes.
    pub modal: bool,
}

/// The feed word.
#[derive(Debug, Clone, PartialEq)]
pub struct FeedFormat {
    /// Prefix, number format and modality of the `F` word.
    pub word: WordFormat,
    /// Literal word written on rapid blocks instead of a feed word
    /// (Heidenhain `FMAX`); empty for none.
    pub rapid: String,
    /// The feed mode a program in this dialect uses unless told otherwise:
    /// `tip`, `inverse-time` or `dpm` (`mode` in `[feed]`; the values are
    /// computed by the caller, the writer formats them like any feed).
    pub mode: Option<String>,
}

/// The feed modes a dialect may name as its default.
pub const FEED_MODES: [&str; 3] = ["tip", "inverse-time", "dpm"];

/// The motion (interpolation) words.
#[derive(Debug, Clone, PartialEq)]
pub struct MotionWords {
    /// Word for rapid blocks (`G0`, Heidenhain `L`); empty for none.
    pub rapid: String,
    /// Word for feed blocks (`G1`, Heidenhain `L`); empty for none.
    pub feed: String,
    /// Written only when the motion changes.
    pub modal: bool,
    /// The motion in force after the header (the header template sets it),
    /// `None` when unknown: the first block then always has its motion word.
    pub initial: Option<Motion>,
    /// Further spellings of the rapid word accepted by the reader (`G00`).
    pub rapid_aliases: Vec<String>,
    /// Further spellings of the feed word accepted by the reader (`G01`).
    pub feed_aliases: Vec<String>,
}

/// The circular interpolation words of a dialect (`[arc]`): a dialect
/// without them gets every arc as lines.
#[derive(Debug, Clone, PartialEq)]
pub struct ArcWords {
    /// Clockwise arc (`G2`), looking against the plane's normal.
    pub clockwise: String,
    /// Counter-clockwise arc (`G3`).
    pub counter_clockwise: String,
    /// The plane selection words, XY, ZX, YZ (`G17`, `G18`, `G19`),
    /// written when the plane changes.
    pub planes: [String; 3],
    /// The prefixes of the centre words on X, Y, Z (`I`, `J`, `K`):
    /// the centre relative to the arc's start point, in the linear axes'
    /// number format; absolute coordinates on a line of their own when
    /// `centre_block` is given.
    pub centre: [String; 3],
    /// The word of a centre line of its own before every arc line
    /// (Heidenhain `CC X+10.000 Y+20.000`), the centre in absolute
    /// coordinates; empty: the centre words are on the arc line, relative
    /// to its start.
    pub centre_block: String,
    /// Words that give the sense after the axis words, clockwise first
    /// (Heidenhain `DR-`, `DR+`), for dialects whose arc word is the same
    /// both ways (`C`); empty when the arc word says it.
    pub sense: [String; 2],
    /// The planes the controller takes circles in, XY, ZX, YZ: a dialect
    /// whose circles lie in the working plane of its tool call only
    /// (Heidenhain: X/Y under `TOOL CALL … Z`) writes the others as lines.
    pub native_planes: [bool; 3],
    /// Whether an arc block may rise along the plane's normal (a helix);
    /// else helices are written as lines.
    pub helix: bool,
}

/// Layout of a block (a line).
#[derive(Debug, Clone, PartialEq)]
pub struct BlockFormat {
    /// Axis names written first, in this order; the other axes follow in
    /// machine order. Names the machine does not have are ignored.
    pub order: Vec<String>,
    /// Whether axes the machine locks (`fixed`) are written.
    pub write_fixed: bool,
    /// Between words (`" "`; `""` for compact Fanuc style; `,` in csv).
    pub separator: String,
    /// End of every line (`"\n"`, `"\r\n"`).
    pub line_end: String,
    /// Literal words written after the axis words of every motion block
    /// (Heidenhain `R0`); empty for none.
    pub after_axes: String,
    /// The words that stand for `after_axes` while cutter radius
    /// compensation is on, left then right (Heidenhain `["RL", "RR"]`: its
    /// compensation is a word of the motion blocks); empty for a dialect
    /// that switches it with the `cutcom_on` template (`G41`).
    pub compensated: Vec<String>,
    /// Longest line the controller reads, in bytes, `line_end` included:
    /// longer comments are shortened, other longer lines are errors.
    pub max_line_length: Option<usize>,
}

/// Block numbers.
#[derive(Debug, Clone, PartialEq)]
pub struct Numbering {
    /// Whether blocks get numbers at all.
    pub enabled: bool,
    /// Text before the number (`N`; empty for Heidenhain).
    pub prefix: String,
    /// First number.
    pub start: u64,
    /// Increment.
    pub step: u64,
    /// Minimum number of digits (zero padded); 0 for none.
    pub digits: usize,
    /// After this number, numbering starts again at `start` (Fanuc N99999).
    pub wrap_after: Option<u64>,
    /// Number the lines of the header and footer templates.
    pub header: bool,
    /// Number the lines of the tool change, spindle, coolant and pressure templates.
    pub commands: bool,
    /// Number comment lines (Heidenhain `5 * - text`).
    pub comments: bool,
}

/// How comments are written.
#[derive(Debug, Clone, PartialEq)]
pub struct CommentSyntax {
    /// Comments are written at all.
    pub enabled: bool,
    /// Before the text (`; `, `(`, `* - `).
    pub prefix: String,
    /// After the text (`)`).
    pub suffix: String,
    /// Replacements applied to the text, e.g. `(` → `[`; line breaks always
    /// become spaces.
    pub replace: Vec<(String, String)>,
    /// The controller reads ASCII only: control characters (a tab) become
    /// blanks and anything beyond ASCII `?` (the template filter `ascii`
    /// does the same for template text).
    pub ascii: bool,
}

/// The templates a dialect may define.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum TemplateKind {
    /// Start of the program.
    Header,
    /// End of the program.
    Footer,
    /// Tool change (`tool_number`, `tool_name`).
    ToolChange,
    /// Spindle on (`speed`, `clockwise`, `direction`).
    SpindleOn,
    /// Spindle off.
    SpindleOff,
    /// Coolant on (`mode`).
    CoolantOn,
    /// Coolant off.
    CoolantOff,
    /// Process pressure (`pressure`, belt grinding H1).
    Pressure,
    /// Tool-centre-point control on (TRAORI, G43.4, M128, …).
    TcpOn,
    /// Tool-centre-point control off.
    TcpOff,
    /// Inverse-time feed on (`G93`): every feed word is 1 / block time in minutes.
    InverseTimeOn,
    /// Feed per minute again (`G94`).
    InverseTimeOff,
    /// Program stop (CL `STOP`: M00).
    Stop,
    /// Optional stop (CL `OPSTOP`: M01).
    OptionalStop,
    /// Dwell (CL `DELAY`, a cycle's dwell): `seconds` (a number) and
    /// `milliseconds` (a whole number).
    Dwell,
    /// Cutter radius compensation on (CL `CUTCOM/LEFT|RIGHT`): `side`
    /// (`left` or `right`) and `register` (the offset register).
    CutcomOn,
    /// Cutter radius compensation off (CL `CUTCOM/OFF`).
    CutcomOff,
    /// One hole of a canned drilling cycle (see [`crate::Hole`] and
    /// `[cycle]`).
    Cycle,
    /// The end of a series of holes (`G80`).
    CycleOff,
}

/// The variables of the `cycle` template besides the program's (see
/// docs/dialects.md, "Canned cycles").
pub const CYCLE_VARIABLES: &[&str] = &[
    "cycle",
    "first",
    "changed",
    "x",
    "y",
    "top",
    "r",
    "bottom",
    "retract",
    "return_to_r",
    "depth",
    "clearance",
    "retract_height",
    "peck",
    "dwell",
    "dwell_ms",
    "feed",
    "rpm",
];

/// How a dialect's cycles leave a hole (`[cycle] retract`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum CycleRetract {
    /// To the feed start (`G99`) or to where the tool stood when the
    /// series of cycles began (`G98`): ISO 6983-1 controls (Fanuc,
    /// LinuxCNC). A hole whose retract is neither is written as moves.
    InitialOrR,
    /// To any height the cycle names (Sinumerik `RTP`, Heidenhain `Q204`).
    Any,
}

/// The canned cycles a dialect writes (`[cycle]`): which kinds, and how
/// they retract. A dialect without it gets every hole as moves.
#[derive(Debug, Clone, PartialEq)]
pub struct CycleWords {
    /// The kinds written as cycles, by [`crate::HoleKind::as_str`].
    pub kinds: Vec<crate::HoleKind>,
    /// The kinds whose cycles can dwell at the bottom (`G82`, `G89`): a
    /// hole of another kind with a dwell is written as moves.
    pub dwell: Vec<crate::HoleKind>,
    /// How a hole is left.
    pub retract: CycleRetract,
}

impl TemplateKind {
    /// All kinds, in file order.
    pub const ALL: [TemplateKind; 19] = [
        TemplateKind::Header,
        TemplateKind::Footer,
        TemplateKind::ToolChange,
        TemplateKind::SpindleOn,
        TemplateKind::SpindleOff,
        TemplateKind::CoolantOn,
        TemplateKind::CoolantOff,
        TemplateKind::Pressure,
        TemplateKind::TcpOn,
        TemplateKind::TcpOff,
        TemplateKind::InverseTimeOn,
        TemplateKind::InverseTimeOff,
        TemplateKind::Stop,
        TemplateKind::OptionalStop,
        TemplateKind::Dwell,
        TemplateKind::CutcomOn,
        TemplateKind::CutcomOff,
        TemplateKind::Cycle,
        TemplateKind::CycleOff,
    ];

    /// The variables this template gets besides the program's
    /// ([`ProgramInfo::VARIABLES`](crate::ProgramInfo::VARIABLES)).
    pub fn variables(self) -> &'static [&'static str] {
        match self {
            TemplateKind::ToolChange => &["tool_name"],
            TemplateKind::SpindleOn => &["speed", "clockwise", "direction"],
            TemplateKind::CoolantOn => &["mode"],
            TemplateKind::Pressure => &["pressure", "pressure_word"],
            TemplateKind::Dwell => &["seconds", "milliseconds"],
            TemplateKind::CutcomOn => &["side", "register"],
            TemplateKind::Cycle => CYCLE_VARIABLES,
            _ => &[],
        }
    }

    /// A template written for a CL statement between motion blocks (not
    /// the header or footer, nor a switch of tool-centre-point control or
    /// inverse time): one `outside_tcp` may name.
    pub fn is_command(self) -> bool {
        matches!(
            self,
            TemplateKind::ToolChange
                | TemplateKind::SpindleOn
                | TemplateKind::SpindleOff
                | TemplateKind::CoolantOn
                | TemplateKind::CoolantOff
                | TemplateKind::Pressure
                | TemplateKind::Stop
                | TemplateKind::OptionalStop
                | TemplateKind::Dwell
                | TemplateKind::CutcomOn
                | TemplateKind::CutcomOff
        )
    }

    /// The key in `[templates]`.
    pub fn key(self) -> &'static str {
        match self {
            TemplateKind::Header => "header",
            TemplateKind::Footer => "footer",
            TemplateKind::ToolChange => "tool_change",
            TemplateKind::SpindleOn => "spindle_on",
            TemplateKind::SpindleOff => "spindle_off",
            TemplateKind::CoolantOn => "coolant_on",
            TemplateKind::CoolantOff => "coolant_off",
            TemplateKind::Pressure => "pressure",
            TemplateKind::TcpOn => "tcp_on",
            TemplateKind::TcpOff => "tcp_off",
            TemplateKind::InverseTimeOn => "inverse_time_on",
            TemplateKind::InverseTimeOff => "inverse_time_off",
            TemplateKind::Stop => "stop",
            TemplateKind::OptionalStop => "optional_stop",
            TemplateKind::Dwell => "dwell",
            TemplateKind::CutcomOn => "cutcom_on",
            TemplateKind::CutcomOff => "cutcom_off",
            TemplateKind::Cycle => "cycle",
            TemplateKind::CycleOff => "cycle_off",
        }
    }
}

/// The largest dialect file read: 1 MiB, hundreds of times a commented
/// dialect; a larger text is refused before it is parsed.
pub const MAX_DIALECT_FILE_BYTES: usize = 1 << 20;

/// A parsed, validated NC dialect.
#[derive(Clone)]
pub struct Dialect {
    pub(crate) name: String,
    pub(crate) extension: String,
    pub(crate) description: String,
    pub(crate) kind: DialectKind,
    pub(crate) block: BlockFormat,
    linear: PartialWord,
    rotary: PartialWord,
    /// Over `rotary`, for rotary axes that turn without end.
    endless: PartialWord,
    axis: BTreeMap<String, PartialWord>,
    /// The pressure word (`[pressure]`), when the dialect can write one.
    pressure: Option<PartialWord>,
    pub(crate) feed: FeedFormat,
    pub(crate) motion: MotionWords,
    pub(crate) arc: Option<ArcWords>,
    pub(crate) cycle: Option<CycleWords>,
    pub(crate) numbering: Numbering,
    pub(crate) comment: CommentSyntax,
    templates: BTreeMap<TemplateKind, String>,
    /// The templates written with tool-centre-point control off (`tcp_off`
    /// before, `tcp_on` after, while it is on).
    pub(crate) outside_tcp: Vec<TemplateKind>,
    pub(crate) env: Arc<Environment<'static>>,
}

impl fmt::Debug for Dialect {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Dialect")
            .field("name", &self.name)
            .field("extension", &self.extension)
            .field("kind", &self.kind)
            .field("block", &self.block)
            .field("feed", &self.feed)
            .field("motion", &self.motion)
            .field("numbering", &self.numbering)
            .field("comment", &self.comment)
            .field("templates", &self.templates)
            .finish_non_exhaustive()
    }
}

impl Dialect {
    /// A built-in dialect by name (see [`Dialect::builtin_names`]).
    pub fn builtin(name: &str) -> Option<Dialect> {
        let source = Self::builtin_source(name)?;
        // The built-in files are tested; a failure here is a bug in this crate.
        Some(
            Self::from_toml(source, &format!("<builtin>/{name}.toml"))
                .unwrap_or_else(|e| panic!("built-in dialect `{name}` is broken:\n{e}")),
        )
    }

    /// Names of the built-in dialects.
    pub fn builtin_names() -> &'static [&'static str] {
        BUILTIN_NAMES
    }

    /// The TOML text of a built-in dialect (for `kinpost dialect show`).
    pub fn builtin_source(name: &str) -> Option<&'static str> {
        BUILTINS.iter().find(|(n, _)| *n == name).map(|(_, s)| *s)
    }

    /// Parses and validates a dialect file. Every problem is reported as a
    /// diagnostic naming `file_name`, line and column.
    pub fn from_toml(source: &str, file_name: &str) -> Result<Dialect, Diagnostics> {
        let (raw, unknown) = parse_raw_dialect(source, file_name)?;
        let mut errors = unknown;
        let mut err = |span: std::ops::Range<usize>, msg: String| {
            errors.push(Diagnostic::at_byte_span(
                Severity::Error,
                file_name,
                source,
                span,
                msg,
            ));
        };

        let kind = raw.kind;
        check_name_and_extension(&raw, &mut err);
        let raw_feed_word = raw.feed.as_word();
        check_word_fields(&raw, &raw_feed_word, &mut err);
        let words = ResolvedWords::resolve(&raw, &raw_feed_word, &mut err);

        check_numbering(&raw.numbering, &mut err);
        let numbering = numbering_from(raw.numbering);
        let replace = comment_replacements(raw.comment.replace, &mut err);
        let (env, templates) = compile_templates(source, &raw.templates, &mut err);
        let outside_tcp = outside_tcp_templates(raw.templates.outside_tcp.as_deref(), &mut err);
        let motion = motion_words(raw.motion);

        check_separator(&raw.block, &mut err);
        if let Some(c) = &raw.block.compensated {
            let words = c.get_ref();
            if words.len() != 2
                || words
                    .iter()
                    .any(|w| w.trim().is_empty() || w.contains(['\n', '\r']))
            {
                err(
                    c.span(),
                    "`block.compensated`: two words, left then right (`[\"RL\", \"RR\"]`), each on one line".into(),
                );
            }
        }
        if let Some(arc) = &raw.arc {
            check_arc(arc, &mut err);
        }
        let cycle = raw
            .cycle
            .as_ref()
            .and_then(|c| check_cycle(c, raw.templates.cycle.is_some(), &mut err));
        if let (None, Some(t)) = (&raw.cycle, &raw.templates.cycle) {
            err(
                t.span(),
                "template `cycle` without a `[cycle]` table: say which kinds it writes (`kinds`) and how they retract (`retract`)".into(),
            );
        }
        check_feed_mode(&raw.feed, &mut err);
        check_line_end_and_length(
            &raw.block,
            &raw.comment.prefix,
            &raw.comment.suffix,
            &mut err,
        );
        let block = block_format(raw.block, kind);

        if !errors.is_empty() {
            return Err(Diagnostics(errors));
        }
        Ok(Dialect {
            name: raw.name.into_inner(),
            extension: raw.extension.into_inner(),
            description: raw.description,
            kind,
            block,
            linear: words.linear,
            rotary: words.rotary,
            endless: words.endless,
            axis: words.axis,
            pressure: match kind {
                // A table always has the pressure column.
                DialectKind::Csv => Some(
                    words
                        .pressure
                        .unwrap_or_else(|| PartialWord::pressure_base(kind)),
                ),
                DialectKind::Words => words.pressure,
            },
            feed: FeedFormat {
                word: words.feed,
                rapid: raw.feed.rapid,
                mode: raw.feed.mode.map(Spanned::into_inner),
            },
            motion,
            arc: raw.arc.map(|a| ArcWords {
                clockwise: a.clockwise.into_inner(),
                counter_clockwise: a.counter_clockwise,
                planes: a.planes,
                centre: a.centre,
                centre_block: a.centre_block,
                sense: a.sense,
                native_planes: PLANE_NAMES
                    .map(|n| a.native_planes.iter().any(|p| p.get_ref() == n)),
                helix: a.helix,
            }),
            cycle,
            numbering,
            comment: CommentSyntax {
                enabled: raw.comment.enabled,
                prefix: raw.comment.prefix,
                suffix: raw.comment.suffix,
                replace,
                ascii: raw.comment.ascii,
            },
            templates,
            outside_tcp,
            env: Arc::new(env),
        })
    }

    /// The dialect's name (`sinumerik`).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// File extension of programs, without the dot (`mpf`).
    pub fn extension(&self) -> &str {
        &self.extension
    }

    /// One-line description.
    pub fn description(&self) -> &str {
        &self.description
    }

    /// NC words or CSV table.
    pub fn kind(&self) -> DialectKind {
        self.kind
    }

    /// Block layout.
    pub fn block_format(&self) -> &BlockFormat {
        &self.block
    }

    /// The feed mode programs use unless told otherwise (see
    /// [`FeedFormat::mode`]).
    pub fn default_feed_mode(&self) -> Option<&str> {
        self.feed.mode.as_deref()
    }

    /// The feed word.
    pub fn feed_format(&self) -> &FeedFormat {
        &self.feed
    }

    /// Motion words.
    pub fn motion_words(&self) -> &MotionWords {
        &self.motion
    }

    /// The canned cycles (`[cycle]`), if the dialect writes them.
    pub fn cycle_words(&self) -> Option<&CycleWords> {
        self.cycle.as_ref()
    }

    /// The circular interpolation words (`[arc]`), if the dialect writes
    /// arcs.
    pub fn arc_words(&self) -> Option<&ArcWords> {
        self.arc.as_ref()
    }

    /// Block numbering.
    pub fn numbering(&self) -> &Numbering {
        &self.numbering
    }

    /// Comment syntax.
    pub fn comment_syntax(&self) -> &CommentSyntax {
        &self.comment
    }

    /// The source of a template, if the dialect defines it.
    pub fn template(&self, kind: TemplateKind) -> Option<&str> {
        self.templates.get(&kind).map(String::as_str)
    }

    /// Whether the dialect can write a pressure word (`[pressure]`; a CSV
    /// table always can: it is a column).
    pub fn writes_pressure(&self) -> bool {
        self.pressure.is_some()
    }

    /// The word format of one machine axis: built-in default, then
    /// `[linear]` or `[rotary]`, then `[axis.NAME]`. For the pressure word
    /// ([`AxisSpec::pressure`]): the `[pressure]` table over the defaults
    /// `{name}=`, no decimals (whatever a dialect without `[pressure]`
    /// would write; see [`Dialect::writes_pressure`]).
    pub fn word_format(&self, axis: &AxisSpec) -> WordFormat {
        if axis.pressure {
            return self
                .pressure
                .clone()
                .unwrap_or_else(|| PartialWord::pressure_base(self.kind))
                .resolve(&axis.name);
        }
        let kind_default = match (axis.rotary, axis.endless) {
            (true, true) => self.rotary.over(&self.endless),
            (true, false) => self.rotary.clone(),
            (false, _) => self.linear.clone(),
        };
        match self.axis.get(&axis.name) {
            Some(o) => kind_default.over(o).resolve(&axis.name),
            None => kind_default.resolve(&axis.name),
        }
    }

    /// The value exactly as it will be written for this axis (rounded to the
    /// axis decimals, ties to even; modulo applied), so the caller can run
    /// it through forward kinematics for the closed-loop check. Values that
    /// cannot be written (non-finite, too large) are returned unchanged.
    pub fn quantize(&self, axis: &AxisSpec, value: f64) -> f64 {
        self.word_format(axis).number.quantize(value)
    }

    /// Renders a template source (e.g. a machine file's header override) with
    /// this dialect's template settings, filters and limits; every string in
    /// `vars` is cleaned for the dialect first ([`CommentSyntax::clean`]).
    pub fn render_template(
        &self,
        source: &str,
        vars: &BTreeMap<String, minijinja::Value>,
    ) -> Result<String, crate::NcError> {
        let mut vars = vars.clone();
        self.comment.clean_vars(&mut vars);
        template::render_str(&self.env, "template", source, &vars)
    }
}

/// A word format with every setting optional (one layer of defaults).
#[derive(Debug, Clone, Default, PartialEq)]
struct PartialWord {
    prefix: Option<String>,
    suffix: Option<String>,
    decimals: Option<u8>,
    trailing_zeros: Option<TrailingZeros>,
    leading_zero: Option<bool>,
    plus_sign: Option<bool>,
    modulo: Option<f64>,
    modal: Option<bool>,
}

impl PartialWord {
    fn base(kind: DialectKind) -> PartialWord {
        let (prefix, decimals) = match kind {
            DialectKind::Words => ("{name}", 3),
            DialectKind::Csv => ("", 6),
        };
        PartialWord {
            prefix: Some(prefix.into()),
            suffix: Some(String::new()),
            decimals: Some(decimals),
            trailing_zeros: Some(TrailingZeros::Keep),
            leading_zero: Some(true),
            plus_sign: Some(false),
            modulo: None,
            modal: Some(false),
        }
    }

    /// Defaults of the pressure word: `H1=3000` (a CSV column: `3000`).
    fn pressure_base(kind: DialectKind) -> PartialWord {
        match kind {
            DialectKind::Words => PartialWord {
                prefix: Some("{name}=".into()),
                decimals: Some(0),
                trailing_zeros: Some(TrailingZeros::Trim),
                modal: Some(true),
                ..PartialWord::base(kind)
            },
            DialectKind::Csv => PartialWord {
                decimals: Some(3),
                trailing_zeros: Some(TrailingZeros::Trim),
                ..PartialWord::base(kind)
            },
        }
    }

    fn feed_base() -> PartialWord {
        PartialWord {
            prefix: Some("F".into()),
            trailing_zeros: Some(TrailingZeros::Trim),
            modal: Some(true),
            ..PartialWord::base(DialectKind::Words)
        }
    }

    /// `other`'s settings where given, else ours.
    fn over(&self, other: &PartialWord) -> PartialWord {
        PartialWord {
            prefix: other.prefix.clone().or_else(|| self.prefix.clone()),
            suffix: other.suffix.clone().or_else(|| self.suffix.clone()),
            decimals: other.decimals.or(self.decimals),
            trailing_zeros: other.trailing_zeros.or(self.trailing_zeros),
            leading_zero: other.leading_zero.or(self.leading_zero),
            plus_sign: other.plus_sign.or(self.plus_sign),
            modulo: other.modulo.or(self.modulo),
            modal: other.modal.or(self.modal),
        }
    }

    fn resolve(&self, name: &str) -> WordFormat {
        WordFormat {
            prefix: self
                .prefix
                .as_deref()
                .unwrap_or("{name}")
                .replace("{name}", name),
            suffix: self.suffix.clone().unwrap_or_default(),
            number: NumberFormat {
                decimals: self.decimals.unwrap_or(3),
                trailing_zeros: self.trailing_zeros.unwrap_or(TrailingZeros::Keep),
                leading_zero: self.leading_zero.unwrap_or(true),
                plus_sign: self.plus_sign.unwrap_or(false),
                modulo: self.modulo,
            },
            modal: self.modal.unwrap_or(false),
        }
    }
}

impl From<&RawWord> for PartialWord {
    fn from(w: &RawWord) -> Self {
        PartialWord {
            prefix: w.prefix.as_ref().map(|p| p.get_ref().clone()),
            suffix: w.suffix.as_ref().map(|p| p.get_ref().clone()),
            decimals: w.decimals.as_ref().map(|d| *d.get_ref()),
            trailing_zeros: w.trailing_zeros,
            leading_zero: w.leading_zero,
            plus_sign: w.plus_sign,
            modulo: w.modulo.as_ref().map(|m| *m.get_ref()),
            modal: w.modal,
        }
    }
}

// ------------------------------------------------------ dialect file checks
//
// The pieces of `Dialect::from_toml`, in the order it runs them: every
// mistake goes to `err` in file-reading order, so the diagnostics come out
// in the same order whatever the mistakes.

/// The dialect file as read by serde, with every unknown key and value (in
/// file order), or the file's first fatal mistake: too large (see
/// [`refuse_oversized`]), a TOML syntax error or a key of the wrong type
/// (reported after the unknown names found before it).
fn parse_raw_dialect(
    source: &str,
    file_name: &str,
) -> Result<(RawDialect, Vec<Diagnostic>), Diagnostics> {
    refuse_oversized(source, file_name)?;
    // serde would stop at the first unknown key or value: they are all
    // found here (the `Raw*` types let unknown keys pass), and reported
    // with the mistakes the checks after it find.
    let unknown = unknown_names(source, file_name);
    match toml::from_str(source) {
        Ok(raw) => Ok((raw, unknown)),
        Err(e) => {
            let first = Diagnostic::at_byte_span(
                Severity::Error,
                file_name,
                source,
                e.span().unwrap_or(0..0),
                e.message().trim_end().to_string(),
            );
            Err(Diagnostics(kinpost_diag::toml_names::with_serde_error(
                unknown, first,
            )))
        }
    }
}

/// A file over [`MAX_DIALECT_FILE_BYTES`] is refused before it is parsed:
/// it is not a dialect file, and parsing it would only cost time.
fn refuse_oversized(source: &str, file_name: &str) -> Result<(), Diagnostics> {
    match kinpost_diag::oversized_file(file_name, source, "dialect", MAX_DIALECT_FILE_BYTES) {
        Some(e) => Err(e.into()),
        None => Ok(()),
    }
}

/// The dialect names itself (`name` not blank) and its programs' bare
/// extension (no dot or path separator: the writer appends it to a stem).
fn check_name_and_extension(raw: &RawDialect, err: &mut dyn FnMut(std::ops::Range<usize>, String)) {
    if raw.name.get_ref().trim().is_empty() {
        err(raw.name.span(), "`name` must not be empty".into());
    }
    if raw.extension.get_ref().contains(['.', '/', '\\']) {
        err(
            raw.extension.span(),
            "`extension` is the bare extension, without a dot (e.g. `mpf`)".into(),
        );
    }
}

/// The fields of every word table (`[linear]`, `[rotary]`, `[endless]`,
/// each `[axis.NAME]`, `[pressure]`, the feed word), in that order, fit
/// the writer's fixed room and the number formatter's decimals.
fn check_word_fields(
    raw: &RawDialect,
    raw_feed_word: &RawWord,
    err: &mut dyn FnMut(std::ops::Range<usize>, String),
) {
    check_word(&raw.linear, err);
    check_word(&raw.rotary, err);
    check_word(&raw.endless, err);
    for w in raw.axis.values() {
        check_word(w, err);
    }
    if let Some(p) = &raw.pressure {
        check_pressure_word(p, raw.kind, err);
    }
    check_word(raw_feed_word, err);
}

/// One word table's prefix and suffix fit the writer's fixed room
/// ([`MAX_PREFIX`], [`MAX_SUFFIX`]) and its decimals the number formatter
/// ([`MAX_DECIMALS`]).
fn check_word(w: &RawWord, err: &mut dyn FnMut(std::ops::Range<usize>, String)) {
    if let Some(p) = &w.prefix
        && p.get_ref().len() > MAX_PREFIX
    {
        err(
            p.span(),
            format!("`prefix` may have at most {MAX_PREFIX} bytes"),
        );
    }
    if let Some(p) = &w.suffix
        && p.get_ref().len() > MAX_SUFFIX
    {
        err(
            p.span(),
            format!("`suffix` may have at most {MAX_SUFFIX} bytes"),
        );
    }
    if let Some(d) = &w.decimals
        && *d.get_ref() > MAX_DECIMALS
    {
        err(
            d.span(),
            format!("`decimals` must be between 0 and {MAX_DECIMALS}"),
        );
    }
}

/// `[pressure]`: the fields of any word, and what only the pressure word
/// asks: it is always modal, never taken modulo, and in an NC program it
/// has a prefix (a bare number would be read as something else).
fn check_pressure_word(
    p: &Spanned<RawWord>,
    kind: DialectKind,
    err: &mut dyn FnMut(std::ops::Range<usize>, String),
) {
    let w = p.get_ref();
    check_word(w, err);
    if w.modal == Some(false) {
        err(
            p.span(),
            "the pressure word is always modal (written when its value changes): leave `modal` out"
                .into(),
        );
    }
    if let Some(m) = &w.modulo {
        err(
            m.span(),
            "`modulo` does not apply to the pressure word".into(),
        );
    }
    if kind == DialectKind::Words && w.prefix.as_ref().is_some_and(|p| p.get_ref().is_empty()) {
        err(
            w.prefix.as_ref().map_or(p.span(), |p| p.span()),
            "the pressure word needs a `prefix` (e.g. \"{name}=\" for `H1=3000`)".into(),
        );
    }
}

/// The word layers of a dialect file over the built-in defaults, and the
/// resolved feed word.
struct ResolvedWords {
    linear: PartialWord,
    rotary: PartialWord,
    endless: PartialWord,
    axis: BTreeMap<String, PartialWord>,
    pressure: Option<PartialWord>,
    feed: WordFormat,
}

impl ResolvedWords {
    /// Lays the word tables over the defaults and checks each whole format
    /// as it will be written (modulo against decimals: only a combination
    /// of layers can be wrong), in the order of [`check_word_fields`].
    fn resolve(
        raw: &RawDialect,
        raw_feed_word: &RawWord,
        err: &mut dyn FnMut(std::ops::Range<usize>, String),
    ) -> ResolvedWords {
        let kind = raw.kind;
        let base = PartialWord::base(kind);
        let linear = base.over(&PartialWord::from(&raw.linear));
        let rotary = base.over(&PartialWord::from(&raw.rotary));
        let endless = PartialWord::from(&raw.endless);
        let axis: BTreeMap<String, PartialWord> = raw
            .axis
            .iter()
            .map(|(k, w)| (k.clone(), PartialWord::from(w)))
            .collect();
        check_whole_format(&raw.linear, &[linear.resolve("X")], err);
        check_whole_format(&raw.rotary, &[rotary.resolve("A")], err);
        check_whole_format(&raw.endless, &[rotary.over(&endless).resolve("A")], err);
        for (name, w) in &raw.axis {
            let o = PartialWord::from(w);
            check_whole_format(
                w,
                &[linear.over(&o).resolve(name), rotary.over(&o).resolve(name)],
                err,
            );
        }
        let pressure = raw
            .pressure
            .as_ref()
            .map(|p| PartialWord::pressure_base(kind).over(&PartialWord::from(p.get_ref())));
        if let (Some(p), Some(w)) = (&pressure, &raw.pressure) {
            check_whole_format(w.get_ref(), &[p.resolve("H1")], err);
        }
        let feed = PartialWord::feed_base()
            .over(&PartialWord::from(raw_feed_word))
            .resolve("F");
        check_whole_format(raw_feed_word, std::slice::from_ref(&feed), err);
        ResolvedWords {
            linear,
            rotary,
            endless,
            axis,
            pressure,
            feed,
        }
    }
}

/// The first of `resolved` (the formats table `w` takes part in) whose
/// number format is invalid, reported once at `w`'s `modulo` (else its
/// `decimals`). Decimals out of range were reported by [`check_word`].
fn check_whole_format(
    w: &RawWord,
    resolved: &[WordFormat],
    err: &mut dyn FnMut(std::ops::Range<usize>, String),
) {
    for r in resolved {
        if r.number.decimals <= MAX_DECIMALS
            && let Err(msg) = r.number.validate()
        {
            let span = w
                .modulo
                .as_ref()
                .map(|m| m.span())
                .or_else(|| w.decimals.as_ref().map(|d| d.span()))
                .unwrap_or(0..0);
            err(span, msg.to_string());
            break;
        }
    }
}

/// The block numbering of `[numbering]` (checked by [`check_numbering`]).
fn numbering_from(n: RawNumbering) -> Numbering {
    Numbering {
        enabled: n.enabled,
        prefix: n.prefix,
        start: *n.start.get_ref(),
        step: *n.step.get_ref(),
        digits: *n.digits.get_ref(),
        wrap_after: n.wrap_after.map(Spanned::into_inner),
        header: n.header,
        commands: n.commands,
        comments: n.comments,
    }
}

/// The replacements of `comment.replace`, in key order; an empty key
/// (which would match between every two characters) is an error.
fn comment_replacements(
    replace: BTreeMap<String, String>,
    err: &mut dyn FnMut(std::ops::Range<usize>, String),
) -> Vec<(String, String)> {
    let mut replacements = Vec::new();
    for (from, to) in replace {
        if from.is_empty() {
            err(0..0, "`comment.replace` has an empty key".into());
        }
        replacements.push((from, to));
    }
    replacements
}

/// Compiles every template once, in [`TemplateKind::ALL`] order, so a
/// syntax error, an unknown variable or a template over the render budget
/// is found at load and points into the TOML file, not at post time.
fn compile_templates(
    source: &str,
    raw: &RawTemplates,
    err: &mut dyn FnMut(std::ops::Range<usize>, String),
) -> (Environment<'static>, BTreeMap<TemplateKind, String>) {
    let mut env = template::environment();
    let mut templates = BTreeMap::new();
    for kind_t in TemplateKind::ALL {
        let Some(t) = raw.get(kind_t) else {
            continue;
        };
        if let Err(e) = env.add_template_owned(kind_t.key(), t.get_ref().clone()) {
            let span = template::error_span_in_toml(source, t.span(), t.get_ref(), &e);
            err(
                span,
                format!(
                    "template `{}`: {}",
                    kind_t.key(),
                    template::error_message(&e)
                ),
            );
        }
        check_variables(&env, kind_t, t, source, err);
        check_budget(&env, kind_t, t, source, err);
        templates.insert(kind_t, t.get_ref().clone());
    }
    (env, templates)
}

/// The templates written outside tool-centre-point control
/// (`templates.outside_tcp`): command templates only. A tool change moves
/// the axes and takes the new tool's length, so without the key it is the
/// tool change alone.
fn outside_tcp_templates(
    names: Option<&[Spanned<String>]>,
    err: &mut dyn FnMut(std::ops::Range<usize>, String),
) -> Vec<TemplateKind> {
    let mut outside_tcp = Vec::new();
    match names {
        None => outside_tcp.push(TemplateKind::ToolChange),
        Some(names) => {
            for name in names {
                match TemplateKind::ALL
                    .into_iter()
                    .find(|k| k.key() == name.get_ref())
                {
                    Some(k) if k.is_command() => outside_tcp.push(k),
                    _ => err(
                        name.span(),
                        format!(
                            "`templates.outside_tcp`: `{}` is not a command template (one of {})",
                            name.get_ref(),
                            TemplateKind::ALL
                                .into_iter()
                                .filter(|k| k.is_command())
                                .map(TemplateKind::key)
                                .collect::<Vec<_>>()
                                .join(", ")
                        ),
                    ),
                }
            }
        }
    }
    outside_tcp
}

/// The motion words of `[motion]` (serde has checked them).
fn motion_words(m: RawMotion) -> MotionWords {
    MotionWords {
        rapid: m.rapid,
        feed: m.feed,
        modal: m.modal,
        initial: match m.initial {
            RawInitial::None => None,
            RawInitial::Rapid => Some(Motion::Rapid),
            RawInitial::Feed => Some(Motion::Feed),
        },
        rapid_aliases: m.rapid_aliases,
        feed_aliases: m.feed_aliases,
    }
}

/// The word separator fits the writer's fixed room before a word's prefix
/// ([`MAX_LEAD`] − [`MAX_PREFIX`] bytes).
fn check_separator(block: &RawBlock, err: &mut dyn FnMut(std::ops::Range<usize>, String)) {
    if let Some(sep) = &block.separator
        && sep.get_ref().len() > MAX_LEAD - MAX_PREFIX
    {
        err(
            sep.span(),
            format!(
                "`separator` may have at most {} bytes",
                MAX_LEAD - MAX_PREFIX
            ),
        );
    }
}

/// The default feed mode, when given, is one of [`FEED_MODES`].
fn check_feed_mode(feed: &RawFeed, err: &mut dyn FnMut(std::ops::Range<usize>, String)) {
    if let Some(mode) = &feed.mode
        && !FEED_MODES.contains(&mode.get_ref().as_str())
    {
        err(
            mode.span(),
            format!(
                "unknown feed mode `{}`: use one of {}",
                mode.get_ref(),
                FEED_MODES.join(", ")
            ),
        );
    }
}

/// Every line ends with a newline, and a line length limit leaves room
/// for the shortest line it must hold: an empty comment (line end,
/// comment prefix and suffix).
fn check_line_end_and_length(
    block: &RawBlock,
    comment_prefix: &str,
    comment_suffix: &str,
    err: &mut dyn FnMut(std::ops::Range<usize>, String),
) {
    let line_end = block.line_end.get_ref();
    if !line_end.ends_with('\n') {
        err(
            block.line_end.span(),
            "`line_end` must end with a newline".into(),
        );
    }
    // The shortest line a limit must hold: an empty comment.
    let least = line_end.len() + comment_prefix.len() + comment_suffix.len();
    if let Some(max) = &block.max_line_length
        && *max.get_ref() <= least
    {
        err(
            max.span(),
            format!(
                "`max_line_length` counts the line end: it must be more than {least} bytes \
                 (line end, comment prefix and suffix)"
            ),
        );
    }
}

/// The block layout of `[block]`; the separator defaults to a blank
/// between NC words and a comma between CSV columns.
fn block_format(b: RawBlock, kind: DialectKind) -> BlockFormat {
    BlockFormat {
        order: b.order,
        write_fixed: b.write_fixed,
        separator: b
            .separator
            .as_ref()
            .map(|s| s.get_ref().clone())
            .unwrap_or_else(|| match kind {
                DialectKind::Words => " ".into(),
                DialectKind::Csv => ",".into(),
            }),
        line_end: b.line_end.get_ref().clone(),
        after_axes: b.after_axes,
        compensated: b.compensated.map(Spanned::into_inner).unwrap_or_default(),
        max_line_length: b.max_line_length.as_ref().map(|m| *m.get_ref()),
    }
}

/// A variable the template reads but is not given would fail only when a
/// post reaches the template: it is refused at load, where it is written.
fn check_variables(
    env: &Environment<'static>,
    kind: TemplateKind,
    t: &Spanned<String>,
    source: &str,
    err: &mut dyn FnMut(std::ops::Range<usize>, String),
) {
    let given = given_variables(kind);
    for (name, range) in template::unknown_variables(env, kind.key(), t.get_ref(), &given) {
        err(
            template_span_in_toml(source, t.span(), t.get_ref(), Some(range)),
            unknown_variable_message(kind, &name, &given),
        );
    }
}

/// A template that goes past its budget (fuel, output, nesting) with sample
/// values would stop a post, or run for long before it does: refused at
/// load, where it is written.
fn check_budget(
    env: &Environment<'static>,
    kind: TemplateKind,
    t: &Spanned<String>,
    source: &str,
    err: &mut dyn FnMut(std::ops::Range<usize>, String),
) {
    let vars = template::sample_vars("sample", kind.variables());
    if let Some(e) = template::budget_error(env, kind.key(), &vars) {
        err(
            template::error_span_in_toml(source, t.span(), t.get_ref(), &e),
            budget_message(kind, &e),
        );
    }
}

fn budget_message(kind: TemplateKind, e: &minijinja::Error) -> String {
    format!(
        "template `{}` rendered with sample values: {} (a template may run about {} \
         instructions, make about {} MB of data and write {} bytes)",
        kind.key(),
        template::error_message(e),
        template::TEMPLATE_FUEL,
        template::TEMPLATE_FUEL * 64 / 1_000_000,
        template::MAX_TEMPLATE_OUTPUT_BYTES,
    )
}

/// The variables the writer gives template `kind`.
fn given_variables(kind: TemplateKind) -> Vec<&'static str> {
    ProgramInfo::VARIABLES
        .iter()
        .chain(kind.variables())
        .copied()
        .collect()
}

fn unknown_variable_message(kind: TemplateKind, name: &str, given: &[&str]) -> String {
    format!(
        "template `{}`: unknown variable `{name}`; its variables are {} (a value the \
         caller may pass in `extra` is `extra.{name}`, or `{name}` tested with `is defined`)",
        kind.key(),
        given.join(", ")
    )
}

/// Checks a template that takes the place of the dialect's template `kind`
/// (a machine file's `[post] header` or `footer`) as a dialect file's own
/// are checked at load: its syntax, and that it reads only variables the
/// writer gives it. The error's range lies in `source`, for the loader to
/// report at its own place (see [`template_span_in_toml`]).
pub fn check_template(kind: TemplateKind, source: &str) -> Result<(), TemplateError> {
    let mut env = template::environment();
    if let Err(e) = env.add_template_owned(kind.key(), source.to_string()) {
        return Err(TemplateError {
            message: format!("template `{}`: {}", kind.key(), template::error_message(&e)),
            range: template::error_range(source, &e),
            line: e.line(),
        });
    }
    let given = given_variables(kind);
    match template::unknown_variables(&env, kind.key(), source, &given)
        .into_iter()
        .next()
    {
        Some((name, range)) => Err(TemplateError {
            message: unknown_variable_message(kind, &name, &given),
            line: Some(source[..range.start].matches('\n').count() + 1),
            range: Some(range),
        }),
        None => {
            let vars = template::sample_vars("sample", kind.variables());
            match template::budget_error(&env, kind.key(), &vars) {
                Some(e) => Err(TemplateError {
                    message: budget_message(kind, &e),
                    range: template::error_range(source, &e),
                    line: e.line(),
                }),
                None => Ok(()),
            }
        }
    }
}

/// Numbering values that cannot number blocks: a step of 0, more padding
/// than a number has digits, a wrap that comes back to `start` before the
/// second number (every block would get the same number).
fn check_numbering(n: &RawNumbering, err: &mut dyn FnMut(std::ops::Range<usize>, String)) {
    let (start, step) = (*n.start.get_ref(), *n.step.get_ref());
    if step == 0 {
        err(n.step.span(), "`step` must be at least 1".into());
    }
    if *n.digits.get_ref() > MAX_NUMBER_DIGITS {
        err(
            n.digits.span(),
            format!("`digits` must be between 0 and {MAX_NUMBER_DIGITS}"),
        );
    }
    if let Some(wrap) = &n.wrap_after {
        let second = start.checked_add(step.max(1));
        if second.is_none_or(|second| *wrap.get_ref() < second) {
            err(
                wrap.span(),
                format!(
                    "`wrap_after` must be at least `start` + `step` ({}): numbering would \
                     start again at {start} after every block",
                    second.map_or_else(|| "beyond 2^64".into(), |s| s.to_string())
                ),
            );
        }
    }
}

// ---------------------------------------------------------------- raw TOML

/// Every key the dialect file does not know and every unknown value of a
/// key that takes a word (`kind`, `trailing_zeros`, `initial`), in file
/// order. The `Raw*` types do not deny unknown keys themselves: this is
/// where they are refused.
fn unknown_names(source: &str, file: &str) -> Vec<Diagnostic> {
    use kinpost_diag::toml_names::{Unknown, names, table};
    let Ok(doc) = toml::de::DeTable::parse(source) else {
        return Vec::new();
    };
    let doc = doc.get_ref();
    let mut unknown = Unknown::default();
    unknown.check(
        doc,
        names::<RawDialect>(),
        &[("kind", names::<DialectKind>())],
    );
    let zeros = [("trailing_zeros", names::<TrailingZeros>())];
    let mut words: Vec<&toml::de::DeTable> = ["linear", "rotary", "endless", "pressure"]
        .iter()
        .filter_map(|name| table(doc, name))
        .collect();
    if let Some(axes) = table(doc, "axis") {
        words.extend(axes.keys().filter_map(|k| table(axes, k.get_ref())));
    }
    for t in words {
        unknown.check(t, names::<RawWord>(), &zeros);
    }
    for (name, fields, keywords) in [
        ("feed", names::<RawFeed>(), &zeros[..]),
        ("block", names::<RawBlock>(), &[]),
        (
            "motion",
            names::<RawMotion>(),
            &[("initial", names::<RawInitial>())],
        ),
        ("arc", names::<RawArc>(), &[]),
        (
            "cycle",
            names::<RawCycle>(),
            &[("retract", names::<CycleRetract>())],
        ),
        ("numbering", names::<RawNumbering>(), &[]),
        ("comment", names::<RawComment>(), &[]),
        ("templates", names::<RawTemplates>(), &[]),
    ] {
        if let Some(t) = table(doc, name) {
            unknown.check(t, fields, keywords);
        }
    }
    unknown.into_diagnostics(file, source)
}

#[derive(Deserialize)]
struct RawDialect {
    name: Spanned<String>,
    extension: Spanned<String>,
    #[serde(default)]
    description: String,
    #[serde(default)]
    kind: DialectKind,
    #[serde(default)]
    block: RawBlock,
    #[serde(default)]
    linear: RawWord,
    #[serde(default)]
    rotary: RawWord,
    #[serde(default)]
    endless: RawWord,
    #[serde(default)]
    axis: BTreeMap<String, RawWord>,
    pressure: Option<Spanned<RawWord>>,
    #[serde(default)]
    feed: RawFeed,
    #[serde(default)]
    motion: RawMotion,
    arc: Option<RawArc>,
    cycle: Option<Spanned<RawCycle>>,
    #[serde(default)]
    numbering: RawNumbering,
    #[serde(default)]
    comment: RawComment,
    #[serde(default)]
    templates: RawTemplates,
}

#[derive(Deserialize, Default)]
struct RawWord {
    prefix: Option<Spanned<String>>,
    suffix: Option<Spanned<String>>,
    decimals: Option<Spanned<u8>>,
    trailing_zeros: Option<TrailingZeros>,
    leading_zero: Option<bool>,
    plus_sign: Option<bool>,
    modulo: Option<Spanned<f64>>,
    modal: Option<bool>,
}

#[derive(Deserialize, Default)]
struct RawFeed {
    prefix: Option<Spanned<String>>,
    suffix: Option<Spanned<String>>,
    decimals: Option<Spanned<u8>>,
    trailing_zeros: Option<TrailingZeros>,
    leading_zero: Option<bool>,
    plus_sign: Option<bool>,
    modal: Option<bool>,
    #[serde(default)]
    rapid: String,
    mode: Option<Spanned<String>>,
}

impl RawFeed {
    /// The number settings of the feed word as a word layer.
    fn as_word(&self) -> RawWord {
        RawWord {
            prefix: self.prefix.clone(),
            suffix: self.suffix.clone(),
            decimals: self.decimals.clone(),
            trailing_zeros: self.trailing_zeros,
            leading_zero: self.leading_zero,
            plus_sign: self.plus_sign,
            modulo: None,
            modal: self.modal,
        }
    }
}

#[derive(Deserialize)]
struct RawBlock {
    #[serde(default)]
    order: Vec<String>,
    #[serde(default)]
    write_fixed: bool,
    separator: Option<Spanned<String>>,
    #[serde(default = "newline")]
    line_end: Spanned<String>,
    #[serde(default)]
    after_axes: String,
    #[serde(default)]
    compensated: Option<Spanned<Vec<String>>>,
    max_line_length: Option<Spanned<usize>>,
}

impl Default for RawBlock {
    fn default() -> Self {
        RawBlock {
            order: Vec::new(),
            write_fixed: false,
            separator: None,
            line_end: newline(),
            after_axes: String::new(),
            compensated: None,
            max_line_length: None,
        }
    }
}

fn newline() -> Spanned<String> {
    Spanned::new(0..0, "\n".into())
}

#[derive(Deserialize, Default, Clone, Copy)]
#[serde(rename_all = "lowercase")]
enum RawInitial {
    #[default]
    None,
    Rapid,
    Feed,
}

#[derive(Deserialize)]
struct RawCycle {
    kinds: Vec<Spanned<String>>,
    #[serde(default)]
    dwell: Vec<Spanned<String>>,
    retract: CycleRetract,
}

/// `[cycle]`: known kinds, and a `cycle` template to write them with.
fn check_cycle(
    raw: &Spanned<RawCycle>,
    has_template: bool,
    err: &mut dyn FnMut(std::ops::Range<usize>, String),
) -> Option<CycleWords> {
    if !has_template {
        err(
            raw.span(),
            "`[cycle]` needs a `cycle` template in `[templates]` to write the holes with".into(),
        );
    }
    let mut kinds_of = |key: &str, names: &[Spanned<String>]| {
        let mut kinds = Vec::new();
        for k in names {
            match crate::HoleKind::ALL
                .into_iter()
                .find(|h| h.as_str() == k.get_ref())
            {
                Some(h) => kinds.push(h),
                None => err(
                    k.span(),
                    format!(
                        "`[cycle] {key}`: `{}` is not a cycle kind (one of {})",
                        k.get_ref(),
                        crate::HoleKind::ALL.map(crate::HoleKind::as_str).join(", ")
                    ),
                ),
            }
        }
        kinds
    };
    let raw = raw.get_ref();
    Some(CycleWords {
        kinds: kinds_of("kinds", &raw.kinds),
        dwell: kinds_of("dwell", &raw.dwell),
        retract: raw.retract,
    })
}

#[derive(Deserialize)]
struct RawArc {
    clockwise: Spanned<String>,
    counter_clockwise: String,
    planes: [String; 3],
    centre: [String; 3],
    #[serde(default)]
    centre_block: String,
    #[serde(default)]
    sense: [String; 2],
    #[serde(default = "all_planes")]
    native_planes: Vec<Spanned<String>>,
    #[serde(default = "yes")]
    helix: bool,
}

/// The names of the planes in `[arc] native_planes`, in [`ArcPlane`] order.
const PLANE_NAMES: [&str; 3] = ["XY", "ZX", "YZ"];

fn all_planes() -> Vec<Spanned<String>> {
    PLANE_NAMES
        .map(|n| Spanned::new(0..0, n.to_string()))
        .into()
}

/// `[arc]`: the planes are known ones, and the sense can be told from the
/// words (an arc word the same both ways needs two sense words).
fn check_arc(arc: &RawArc, err: &mut dyn FnMut(std::ops::Range<usize>, String)) {
    for p in &arc.native_planes {
        if !PLANE_NAMES.contains(&p.get_ref().as_str()) {
            err(
                p.span(),
                format!(
                    "unknown plane `{}`: use {}",
                    p.get_ref(),
                    PLANE_NAMES.join(", ")
                ),
            );
        }
    }
    let same_word = *arc.clockwise.get_ref() == arc.counter_clockwise;
    if same_word && (arc.sense[0].is_empty() || arc.sense[0] == arc.sense[1]) {
        err(
            arc.clockwise.span(),
            "`clockwise` and `counter_clockwise` are the same word: give two different `sense` words (Heidenhain `sense = [\"DR-\", \"DR+\"]`)".to_string(),
        );
    }
}

#[derive(Deserialize)]
struct RawMotion {
    #[serde(default = "g0")]
    rapid: String,
    #[serde(default = "g1")]
    feed: String,
    #[serde(default = "yes")]
    modal: bool,
    #[serde(default)]
    initial: RawInitial,
    #[serde(default)]
    rapid_aliases: Vec<String>,
    #[serde(default)]
    feed_aliases: Vec<String>,
}

impl Default for RawMotion {
    fn default() -> Self {
        RawMotion {
            rapid: g0(),
            feed: g1(),
            modal: true,
            initial: RawInitial::None,
            rapid_aliases: Vec::new(),
            feed_aliases: Vec::new(),
        }
    }
}

fn g0() -> String {
    "G0".into()
}
fn g1() -> String {
    "G1".into()
}
fn yes() -> bool {
    true
}

#[derive(Deserialize)]
struct RawNumbering {
    #[serde(default)]
    enabled: bool,
    #[serde(default = "n_prefix")]
    prefix: String,
    #[serde(default = "ten_spanned")]
    start: Spanned<u64>,
    #[serde(default = "ten_spanned")]
    step: Spanned<u64>,
    #[serde(default = "zero_spanned")]
    digits: Spanned<usize>,
    wrap_after: Option<Spanned<u64>>,
    #[serde(default)]
    header: bool,
    #[serde(default = "yes")]
    commands: bool,
    #[serde(default)]
    comments: bool,
}

impl Default for RawNumbering {
    fn default() -> Self {
        RawNumbering {
            enabled: false,
            prefix: n_prefix(),
            start: ten_spanned(),
            step: ten_spanned(),
            digits: zero_spanned(),
            wrap_after: None,
            header: false,
            commands: true,
            comments: false,
        }
    }
}

fn n_prefix() -> String {
    "N".into()
}
fn ten_spanned() -> Spanned<u64> {
    Spanned::new(0..0, 10)
}
fn zero_spanned() -> Spanned<usize> {
    Spanned::new(0..0, 0)
}

#[derive(Deserialize)]
struct RawComment {
    #[serde(default = "yes")]
    enabled: bool,
    #[serde(default = "semicolon")]
    prefix: String,
    #[serde(default)]
    suffix: String,
    #[serde(default)]
    replace: BTreeMap<String, String>,
    #[serde(default)]
    ascii: bool,
}

impl Default for RawComment {
    fn default() -> Self {
        RawComment {
            enabled: true,
            prefix: semicolon(),
            suffix: String::new(),
            replace: BTreeMap::new(),
            ascii: false,
        }
    }
}

fn semicolon() -> String {
    "; ".into()
}

#[derive(Deserialize, Default)]
struct RawTemplates {
    header: Option<Spanned<String>>,
    footer: Option<Spanned<String>>,
    tool_change: Option<Spanned<String>>,
    spindle_on: Option<Spanned<String>>,
    spindle_off: Option<Spanned<String>>,
    coolant_on: Option<Spanned<String>>,
    coolant_off: Option<Spanned<String>>,
    pressure: Option<Spanned<String>>,
    tcp_on: Option<Spanned<String>>,
    tcp_off: Option<Spanned<String>>,
    inverse_time_on: Option<Spanned<String>>,
    inverse_time_off: Option<Spanned<String>>,
    stop: Option<Spanned<String>>,
    optional_stop: Option<Spanned<String>>,
    dwell: Option<Spanned<String>>,
    cutcom_on: Option<Spanned<String>>,
    cutcom_off: Option<Spanned<String>>,
    cycle: Option<Spanned<String>>,
    cycle_off: Option<Spanned<String>>,
    outside_tcp: Option<Vec<Spanned<String>>>,
}

impl RawTemplates {
    fn get(&self, kind: TemplateKind) -> Option<&Spanned<String>> {
        match kind {
            TemplateKind::Header => self.header.as_ref(),
            TemplateKind::Footer => self.footer.as_ref(),
            TemplateKind::ToolChange => self.tool_change.as_ref(),
            TemplateKind::SpindleOn => self.spindle_on.as_ref(),
            TemplateKind::SpindleOff => self.spindle_off.as_ref(),
            TemplateKind::CoolantOn => self.coolant_on.as_ref(),
            TemplateKind::CoolantOff => self.coolant_off.as_ref(),
            TemplateKind::TcpOn => self.tcp_on.as_ref(),
            TemplateKind::TcpOff => self.tcp_off.as_ref(),
            TemplateKind::InverseTimeOn => self.inverse_time_on.as_ref(),
            TemplateKind::InverseTimeOff => self.inverse_time_off.as_ref(),
            TemplateKind::Pressure => self.pressure.as_ref(),
            TemplateKind::Stop => self.stop.as_ref(),
            TemplateKind::OptionalStop => self.optional_stop.as_ref(),
            TemplateKind::Dwell => self.dwell.as_ref(),
            TemplateKind::CutcomOn => self.cutcom_on.as_ref(),
            TemplateKind::CutcomOff => self.cutcom_off.as_ref(),
            TemplateKind::Cycle => self.cycle.as_ref(),
            TemplateKind::CycleOff => self.cycle_off.as_ref(),
        }
    }
}
