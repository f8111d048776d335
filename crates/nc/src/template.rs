//! minijinja set-up shared by dialect templates and machine-file overrides.

use std::collections::BTreeMap;
use std::ops::Range;

use minijinja::syntax::SyntaxConfig;
use minijinja::{Environment, UndefinedBehavior, Value};

use crate::NcError;

/// The work one rendering of a template may do, in minijinja fuel: about
/// one unit per instruction and one per 64 bytes of data it makes (strings
/// joined, lists built, output). Half a million units bound a render to
/// well under a second and about 32 MB, far beyond any header or tool
/// change (the built-in dialects' longest render, the header, uses a few
/// hundred). A template that needs more is an error (`OutOfFuel`), never a
/// run without end or an allocation that aborts the process.
pub const TEMPLATE_FUEL: u64 = 500_000;

/// The most text one rendering of a template may write: 1 MiB, thousands
/// of lines of header. More is an error.
pub const MAX_TEMPLATE_OUTPUT_BYTES: usize = 1 << 20;

/// How deep templates may nest (macros calling macros, includes): well
/// below minijinja's own 500, so that a recursive macro stops early.
pub const TEMPLATE_RECURSION_LIMIT: usize = 100;

/// The environment every dialect uses: `trim_blocks` and `lstrip_blocks` on
/// (block tags on their own lines leave no blank lines), undefined variables
/// are errors, plus the `num` filter.
pub(crate) fn environment() -> Environment<'static> {
    let mut env = Environment::new();
    if let Ok(syntax) = SyntaxConfig::builder()
        .trim_blocks(true)
        .lstrip_blocks(true)
        .build()
    {
        env.set_syntax(syntax);
    }
    env.set_undefined_behavior(UndefinedBehavior::Strict);
    env.set_debug(true);
    env.set_fuel(Some(TEMPLATE_FUEL));
    env.set_recursion_limit(TEMPLATE_RECURSION_LIMIT);
    env.add_filter("num", num);
    env.add_filter("name", name);
    env.add_filter("ascii", ascii);
    env.add_function("fail", fail);
    env
}

/// `{{ fail("message") }}`: the template refuses its input with that
/// message (a coolant mode the machine has no code for), and the post stops
/// with it at the CL statement.
fn fail(message: String) -> Result<Value, minijinja::Error> {
    Err(minijinja::Error::new(
        minijinja::ErrorKind::InvalidOperation,
        message,
    ))
}

/// `{{ text | ascii }}`: text for a controller that reads ASCII only (a
/// Fanuc): control characters (a tab) become blanks, anything beyond ASCII
/// `?`.
pub fn ascii(value: &str) -> String {
    value
        .chars()
        .map(|c| match c {
            c if c.is_ascii_control() => ' ',
            c if c.is_ascii() => c,
            _ => '?',
        })
        .collect()
}

/// `{{ program_name | name }}`: a name every controller takes as one word:
/// ASCII letters, digits, `_` and `-` kept, anything else `_` (a Heidenhain
/// `BEGIN PGM` name ends at a blank and a `;` starts a comment).
fn name(value: &str) -> String {
    value
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// `{{ value | num }}`, `{{ value | num(1) }}`: a number with at most that many
/// decimals (default 3), trailing zeros and a bare point removed, no `-0`.
/// `{{ value | num(3, true) }}` keeps the point of a whole number (`10.`):
/// a Fanuc control without decimal-point programming reads `X10` as
/// 10 µm.
fn num(value: f64, decimals: Option<u32>, point: Option<bool>) -> String {
    let d = decimals.unwrap_or(3).min(9) as usize;
    let mut s = format!("{value:.d$}");
    if s.contains('.') {
        while s.ends_with('0') {
            s.pop();
        }
        if s.ends_with('.') {
            s.pop();
        }
    }
    if s == "-0" {
        s.remove(0);
    }
    if point == Some(true) && !s.contains('.') {
        s.push('.');
    }
    s
}

/// The text a render writes, refused past [`MAX_TEMPLATE_OUTPUT_BYTES`].
#[derive(Default)]
struct Bounded {
    text: Vec<u8>,
    over: bool,
}

impl std::io::Write for Bounded {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        if self.text.len() + buf.len() > MAX_TEMPLATE_OUTPUT_BYTES {
            self.over = true;
            return Err(std::io::Error::other("template output limit"));
        }
        self.text.extend_from_slice(buf);
        Ok(buf.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// Renders `t` within the output limit (the fuel is the environment's).
fn render_bounded(
    t: &minijinja::Template<'_, '_>,
    vars: &BTreeMap<String, Value>,
) -> Result<String, minijinja::Error> {
    let mut out = Bounded::default();
    match t.render_captured_to(Value::from(vars.clone()), &mut out) {
        Ok(_) => Ok(String::from_utf8_lossy(&out.text).into_owned()),
        Err(_) if out.over => Err(minijinja::Error::new(
            minijinja::ErrorKind::InvalidOperation,
            format!(
                "the template writes more than {MAX_TEMPLATE_OUTPUT_BYTES} bytes (the limit of one template's output)"
            ),
        )),
        Err(e) => Err(e),
    }
}

/// Renders a template registered in `env`.
pub(crate) fn render(
    env: &Environment<'static>,
    name: &str,
    vars: &BTreeMap<String, Value>,
) -> Result<String, NcError> {
    let t = env.get_template(name).map_err(|e| to_error(name, &e))?;
    render_bounded(&t, vars).map_err(|e| to_error(name, &e))
}

/// Renders a template given as text (e.g. a machine file override).
pub(crate) fn render_str(
    env: &Environment<'static>,
    name: &str,
    source: &str,
    vars: &BTreeMap<String, Value>,
) -> Result<String, NcError> {
    let t = env
        .template_from_named_str(name, source)
        .map_err(|e| to_error(name, &e))?;
    render_bounded(&t, vars).map_err(|e| to_error(name, &e))
}

/// Whether `e` says a render went past its budget (fuel, output, nesting)
/// rather than that its input was wrong.
fn over_budget(e: &minijinja::Error) -> bool {
    if e.kind() == minijinja::ErrorKind::OutOfFuel {
        return true;
    }
    let detail = e.detail().unwrap_or("");
    detail.contains("recursion limit") || detail.contains("more than") && detail.contains("bytes")
}

/// The values a check renders every template with once: a program name,
/// a tool, a spindle speed, a coolant mode, a pressure, as a post would
/// give them.
pub(crate) fn sample_vars(dialect: &str, extra_names: &[&str]) -> BTreeMap<String, Value> {
    let axes = ["X", "Y", "Z", "A", "C"].map(crate::AxisSpec::linear);
    let info = crate::ProgramInfo {
        program_name: "SAMPLE".into(),
        date: "2025-01-01".into(),
        machine: "sample".into(),
        tool: "SAMPLE TOOL".into(),
        tool_number: 1,
        cl_file: "sample.cls".into(),
        tool_loaded: true,
        length_register: 1,
        tcp_output: false,
        extra: BTreeMap::new(),
    };
    let mut vars = info.template_vars(dialect, &axes);
    for name in extra_names {
        let v = match *name {
            "tool_name" => Value::from("SAMPLE TOOL"),
            "speed" => Value::from(1000.0),
            "clockwise" => Value::from(true),
            "direction" => Value::from("cw"),
            "mode" => Value::from("flood"),
            "pressure" => Value::from(3000.0),
            "pressure_word" => Value::from("H1"),
            "seconds" => Value::from(1.5),
            "milliseconds" => Value::from(1500),
            "side" => Value::from("left"),
            "register" => Value::from(1),
            "cycle" => Value::from("drill"),
            "first" | "changed" | "return_to_r" => Value::from(true),
            "x" | "y" | "top" | "r" | "bottom" | "retract" | "depth" | "clearance"
            | "retract_height" | "peck" | "dwell" | "feed" | "rpm" => Value::from(1.0),
            "dwell_ms" => Value::from(1000),
            _ => Value::from(""),
        };
        vars.insert((*name).to_string(), v);
    }
    vars
}

/// Renders template `name` of `env` once with `vars` and returns the error
/// only when it went past its budget (see [`TEMPLATE_FUEL`],
/// [`MAX_TEMPLATE_OUTPUT_BYTES`], [`TEMPLATE_RECURSION_LIMIT`]): a
/// template that fails on the sample values for a reason of its own (a
/// `fail(…)` for a mode the machine lacks) is left to the post.
pub(crate) fn budget_error(
    env: &Environment<'static>,
    name: &str,
    vars: &BTreeMap<String, Value>,
) -> Option<minijinja::Error> {
    let t = env.get_template(name).ok()?;
    match render_bounded(&t, vars) {
        Err(e) if over_budget(&e) => Some(e),
        _ => None,
    }
}

/// The variables template `name` (source `source`) reads that it is not
/// `given` (nor a global function such as `range`) and never tests with
/// `is defined` / `is undefined` or gives a `| default`: each with the byte
/// range of its first use, in template order. minijinja's static analysis
/// sees every branch, so a misspelt name is found before a post reaches it.
pub(crate) fn unknown_variables(
    env: &Environment<'static>,
    name: &str,
    source: &str,
    given: &[&str],
) -> Vec<(String, Range<usize>)> {
    let Ok(t) = env.get_template(name) else {
        return Vec::new();
    };
    let mut unknown: Vec<(String, Range<usize>)> = t
        .undeclared_variables(false)
        .into_iter()
        .filter(|v| !given.contains(&v.as_str()) && !env.globals().any(|(g, _)| g == v))
        .filter(|v| !uses(source, v).any(|at| optional(&source[at + v.len()..])))
        .map(|v| {
            let at = uses(source, &v).next().unwrap_or(0);
            let range = at..at + v.len();
            (v, range)
        })
        .collect();
    unknown.sort_by_key(|(_, r)| r.start);
    unknown
}

/// Byte offsets of `name` as a whole identifier (not an attribute, after
/// a `.`) inside the tags of `source` (`{{ … }}`, `{% … %}`).
fn uses<'a>(source: &'a str, name: &'a str) -> impl Iterator<Item = usize> + 'a {
    let ident = |c: char| c.is_ascii_alphanumeric() || c == '_';
    tags(source).flat_map(move |tag| {
        source[tag.clone()]
            .match_indices(name)
            .map(move |(i, _)| tag.start + i)
            .filter(move |&at| {
                let before = source[..at].chars().next_back();
                let after = source[at + name.len()..].chars().next();
                !before.is_some_and(|c| ident(c) || c == '.') && !after.is_some_and(ident)
            })
    })
}

/// The byte ranges inside the expression and statement tags of `source`.
fn tags(source: &str) -> impl Iterator<Item = Range<usize>> + '_ {
    let mut at = 0;
    std::iter::from_fn(move || {
        loop {
            let open = at + source.get(at..)?.find('{')?;
            let close = match source.as_bytes().get(open + 1) {
                Some(b'{') => "}}",
                Some(b'%') => "%}",
                _ => {
                    at = open + 1;
                    continue;
                }
            };
            let start = open + 2;
            let end = source[start..]
                .find(close)
                .map_or(source.len(), |i| start + i);
            at = end;
            return Some(start..end);
        }
    })
}

/// Whether the text after a variable makes it optional: `is [not]
/// defined`, `is undefined`, `| default(…)` or `| d(…)`.
fn optional(after: &str) -> bool {
    if let Some(rest) = word(after, "is") {
        let rest = word(rest, "not").unwrap_or(rest);
        return word(rest, "defined").is_some() || word(rest, "undefined").is_some();
    }
    match after.trim_start().strip_prefix('|') {
        Some(rest) => word(rest, "default").is_some() || word(rest, "d").is_some(),
        None => false,
    }
}

/// The text after the whole word `w` at the start of `s` (blanks before it
/// skipped).
fn word<'a>(s: &'a str, w: &str) -> Option<&'a str> {
    let rest = s.trim_start().strip_prefix(w)?;
    let next = rest.chars().next();
    (!next.is_some_and(|c| c.is_ascii_alphanumeric() || c == '_')).then_some(rest)
}

fn to_error(name: &str, e: &minijinja::Error) -> NcError {
    NcError::Template {
        template: name.to_string(),
        line: e.line(),
        range: e.range(),
        message: error_message(e),
    }
}

/// The error without minijinja's debug dump.
pub(crate) fn error_message(e: &minijinja::Error) -> String {
    match e.detail() {
        Some(d) => format!("{}: {d}", e.kind()),
        None => e.kind().to_string(),
    }
}

/// A template syntax error: message and byte range in the template text.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TemplateError {
    /// What is wrong.
    pub message: String,
    /// Byte range in the template source, when known.
    pub range: Option<Range<usize>>,
    /// 1-based line in the template source, when known.
    pub line: Option<usize>,
}

impl std::fmt::Display for TemplateError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for TemplateError {}

/// Maps a byte range inside a template string to a byte range in the TOML
/// file that holds it. `value_span` is the span of the TOML string value
/// (with its quotes, as `toml::Spanned` gives it), `text` the decoded
/// string. Exact when the string has no escape sequences (literal strings,
/// or basic strings without backslashes), else the start of the string.
pub fn template_span_in_toml(
    toml_source: &str,
    value_span: Range<usize>,
    text: &str,
    range: Option<Range<usize>>,
) -> Range<usize> {
    let fallback = value_span.start..value_span.start + 1;
    let Some(raw) = toml_source.get(value_span.clone()) else {
        return fallback;
    };
    let Some(range) = range else {
        return fallback;
    };
    match raw.find(text) {
        Some(at) if !text.is_empty() => {
            let base = value_span.start + at;
            let end = range
                .end
                .max(range.start + 1)
                .min(text.len().max(range.start + 1));
            base + range.start..base + end
        }
        _ => fallback,
    }
}

pub(crate) fn error_span_in_toml(
    toml_source: &str,
    value_span: Range<usize>,
    text: &str,
    e: &minijinja::Error,
) -> Range<usize> {
    template_span_in_toml(toml_source, value_span, text, error_range(text, e))
}

/// Where error `e` lies in template `text`: its byte range, or when it
/// gives only a line, the start of that line.
pub(crate) fn error_range(text: &str, e: &minijinja::Error) -> Option<Range<usize>> {
    e.range().or_else(|| {
        let start: usize = text
            .split_inclusive('\n')
            .take(e.line()?.saturating_sub(1))
            .map(str::len)
            .sum();
        (start <= text.len()).then_some(start..start + 1)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn name_filter() {
        let env = environment();
        let got = env
            .render_str(
                "{{ n | name }}",
                minijinja::context! { n => "TEST (V2) ; A=B Gehäuse-1" },
            )
            .unwrap();
        assert_eq!(got, "TEST__V2____A_B_Geh_use-1");
    }

    #[test]
    fn ascii_filter() {
        let env = environment();
        let got = env
            .render_str(
                "{{ n | ascii }}",
                minijinja::context! { n => "Gehäuse\tTeil – 1" },
            )
            .unwrap();
        assert_eq!(got, "Geh?use Teil ? 1");
    }

    #[test]
    fn num_filter() {
        assert_eq!(num(3000.0, None, None), "3000");
        assert_eq!(num(2.5, None, None), "2.5");
        assert_eq!(num(-0.0001, None, None), "0");
        assert_eq!(num(1.23456, Some(2), None), "1.23");
        assert_eq!(num(10.0, Some(3), Some(true)), "10.");
        assert_eq!(num(-0.0001, Some(3), Some(true)), "0.");
        assert_eq!(num(2.5, Some(3), Some(true)), "2.5");
    }

    #[test]
    fn syntax_error_has_range() {
        let e = crate::check_template(crate::TemplateKind::Header, "G01\n{{ foo ").unwrap_err();
        assert!(e.range.is_some(), "{e:?}");
    }
}
