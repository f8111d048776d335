//! Hostile input to the writer: text from outside never becomes code,
//! templates run within their budget, every number written is in range.

use std::time::{Duration, Instant};

use kinpost_nc::{
    AxisSpec, Block, Dialect, Motion, NcError, NcWriter, ProgramInfo, Spindle, TemplateKind,
    check_template,
};

/// The built-in dialect `base` with its header template replaced.
fn dialect_with_header(base: &str, header: &str) -> Result<Dialect, kinpost_nc::Diagnostics> {
    let source = Dialect::builtin_source(base).unwrap();
    let start = source.find("header = '''").unwrap();
    let end = start + 12 + source[start + 12..].find("'''").unwrap() + 3;
    let source = format!(
        "{}header = '''\n{header}'''{}",
        &source[..start],
        &source[end..]
    );
    Dialect::from_toml(&source, "mine.toml")
}

fn axes() -> Vec<AxisSpec> {
    ["X", "Y", "Z"].map(AxisSpec::linear).to_vec()
}

fn header_text(dialect: &Dialect, info: &ProgramInfo) -> String {
    let mut w = NcWriter::new(dialect, &axes(), Vec::new());
    w.header(info, None).unwrap();
    String::from_utf8(w.finish().unwrap()).unwrap()
}

#[test]
fn names_with_line_breaks_and_controls_stay_in_their_comment() {
    let hostile = ProgramInfo {
        program_name: "NAME\rG00 Z-100".into(),
        cl_file: "part\nG0 Z-100\n;.cls".into(),
        tool: "T\u{0}\u{c}\u{b}\u{1b}1) G0 Z-1 (".into(),
        machine: "m\u{2028}G0".into(),
        tool_number: 1,
        ..ProgramInfo::default()
    };
    for name in Dialect::builtin_names() {
        let d = Dialect::builtin(name).unwrap();
        let text = header_text(&d, &hostile);
        assert!(
            !text.bytes().any(|b| b < 0x20 && b != b'\n'),
            "{name}: {text:?}"
        );
        for line in text.lines() {
            // No line of the header starts with the injected code.
            let code = line.trim_start_matches(|c: char| c.is_ascii_digit() || c == ' ');
            assert!(
                !code.starts_with("G0 Z")
                    && !code.starts_with("G00 Z")
                    && !code.starts_with(";.cls"),
                "{name}: {text}"
            );
        }
        if *name == "fanuc" || *name == "linuxcnc" {
            // The `)` of the tool name does not close the comment.
            let tool_line = text.lines().find(|l| l.contains("TOOL:")).unwrap();
            assert_eq!(tool_line.matches(')').count(), 1, "{name}: {tool_line}");
        }
    }
}

#[test]
fn a_tool_name_and_a_comment_cannot_break_a_line() {
    let d = Dialect::builtin("linuxcnc").unwrap();
    let mut w = NcWriter::new(&d, &axes(), Vec::new());
    w.tool_change(2, "EM\nG0 Z-100").unwrap();
    w.comment("note\u{1b}\rM30 ) G0 Z-5").unwrap();
    let text = String::from_utf8(w.finish().unwrap()).unwrap();
    assert!(!text.contains('\r') && !text.contains('\u{1b}'), "{text:?}");
    assert!(
        text.lines()
            .all(|l| !l.starts_with("G0") && !l.starts_with("M30")),
        "{text}"
    );
    let comment = text.lines().last().unwrap();
    assert_eq!(comment, "(note  M30 ] G0 Z-5)");
}

#[test]
fn insert_stays_the_one_pass_through() {
    let d = Dialect::builtin("sinumerik").unwrap();
    let mut w = NcWriter::new(&d, &axes(), Vec::new());
    w.insert("G0 Z100 ; (as written)").unwrap();
    let text = String::from_utf8(w.finish().unwrap()).unwrap();
    assert_eq!(text, "G0 Z100 ; (as written)\n");
}

/// A template that would run without end, or build gigabytes, is refused
/// when the dialect file is loaded, at its line in the file, and quickly.
#[test]
fn runaway_dialect_templates_are_refused_at_load() {
    let loops =
        "{% for a in range(100000) %}{% for b in range(100000) %}{{ a }}{% endfor %}{% endfor %}\n";
    let doubling = "{% set ns = namespace(s='0123456789') %}{% for i in range(60) %}{% set ns.s = ns.s ~ ns.s %}{% endfor %}{{ ns.s | length }}\n";
    let unrolled = format!(
        "{}{{{{ s }}}}\n",
        "{% set s = (s | default('x')) ~ (s | default('x')) %}".repeat(64)
    );
    let recursion = "{% macro r(n) %}{{ r(n + 1) }}{% endmacro %}{{ r(0) }}\n";
    let wide = "{{ 'x' * 4000000 }}\n";
    for (what, t) in [
        ("nested loops", loops.to_string()),
        ("doubling", doubling.to_string()),
        ("unrolled doubling", unrolled),
        ("recursion", recursion.to_string()),
        ("wide output", wide.to_string()),
    ] {
        let started = Instant::now();
        let e = match dialect_with_header("sinumerik", &format!("; x\n{t}")) {
            Ok(_) => panic!("{what}: loaded"),
            Err(e) => e,
        };
        assert!(started.elapsed() < Duration::from_secs(10), "{what}");
        let d = &e.0[0];
        assert!(d.location().starts_with("mine.toml:"), "{what}: {d}");
        assert!(d.line > 1, "{what}: {d}");
        assert!(
            d.message.contains("rendered with sample values"),
            "{what}: {d}"
        );
    }
}

#[test]
fn runaway_machine_templates_are_refused_by_the_check() {
    let t = "{% for a in range(100000) %}{% for b in range(100000) %}x{% endfor %}{% endfor %}";
    let e = check_template(TemplateKind::Header, t).unwrap_err();
    assert!(e.message.contains("fuel"), "{e}");
    assert!(e.range.is_some(), "{e:?}");
    // An ordinary template with a `fail` for values it does not take is
    // not a budget error: it is left to the post.
    check_template(
        TemplateKind::Footer,
        "{% if tool == 'x' %}{{ fail('no') }}{% endif %}M30",
    )
    .unwrap();
}

/// A template whose work depends on the program's values stops at its
/// budget during the post too, as an error.
#[test]
fn a_data_dependent_runaway_stops_during_the_post() {
    let source = Dialect::builtin_source("sinumerik").unwrap().replace(
        "spindle_on = \"S{{ speed | num(0) }} {{ 'M03' if clockwise else 'M04' }}\"",
        "spindle_on = \"{% for i in range(speed | int // 100) %}{% for j in range(speed | int // 100) %}{% endfor %}{% endfor %}S{{ speed | num(0) }}\"",
    );
    let d = Dialect::from_toml(&source, "mine.toml").unwrap();
    let mut w = NcWriter::new(&d, &axes(), Vec::new());
    let started = Instant::now();
    let e = w.spindle(Spindle::Cw(90_000.0)).unwrap_err();
    assert!(started.elapsed() < Duration::from_secs(10));
    assert!(e.to_string().contains("fuel"), "{e}");
}

#[test]
fn spindle_speeds_that_cannot_be_written_are_errors() {
    for name in Dialect::builtin_names() {
        let d = Dialect::builtin(name).unwrap();
        for bad in [0.4, 0.0, -1.0, 1e308, f64::INFINITY, f64::NAN, 1e6] {
            let mut w = NcWriter::new(&d, &axes(), Vec::new());
            match w.spindle(Spindle::Cw(bad)) {
                Err(NcError::Value { what, .. }) => assert_eq!(what, "spindle speed"),
                other => panic!("{name} S{bad}: {other:?}"),
            }
        }
        let mut w = NcWriter::new(&d, &axes(), Vec::new());
        w.spindle(Spindle::Ccw(0.5)).unwrap();
        w.spindle(Spindle::Cw(999_999.0)).unwrap();
    }
}

#[test]
fn tool_numbers_out_of_range_are_errors() {
    let d = Dialect::builtin("fanuc").unwrap();
    let mut w = NcWriter::new(&d, &axes(), Vec::new());
    assert!(matches!(w.tool_change(0, "x"), Err(NcError::Value { .. })));
    assert!(matches!(
        w.tool_change(100_000_000, "x"),
        Err(NcError::Value { .. })
    ));
    w.tool_change(99_999_999, "x").unwrap();
    let info = ProgramInfo {
        tool_number: u32::MAX,
        ..ProgramInfo::default()
    };
    let mut w = NcWriter::new(&d, &axes(), Vec::new());
    assert!(matches!(w.header(&info, None), Err(NcError::Value { .. })));
}

/// Numbers near the top of `u64` run out with an error, never repeat.
#[test]
fn block_numbers_that_would_overflow_are_an_error() {
    let source = Dialect::builtin_source("fanuc").unwrap();
    let start = source.find("\n[numbering]\n").unwrap() + 1;
    let end = start + source[start..].find("\n[").unwrap();
    let numbering = format!(
        "[numbering]\nenabled = true\nprefix = \"N\"\nstart = {}\nstep = 10\nheader = false\ncommands = false\ncomments = false\n",
        u64::MAX - 25
    );
    let source = format!("{}{numbering}{}", &source[..start], &source[end..]);
    let d = Dialect::from_toml(&source, "n.toml").unwrap();
    let mut w = NcWriter::new(&d, &axes(), Vec::new());
    let mut written = 0;
    let mut error = None;
    for i in 0..10 {
        let values = [f64::from(i), 0.0, 0.0];
        let block = Block {
            line: None,
            number: None,
            arc: None,
            cl_line: Some(1),
            motion: Motion::Feed,
            axes: &values,
            feed: Some(100.0),
        };
        match w.block(&block) {
            Ok(()) => written += 1,
            Err(e) => {
                error = Some(e);
                break;
            }
        }
    }
    assert_eq!(written, 3);
    let e = error.expect("the numbers run out");
    assert!(e.to_string().contains("run out"), "{e}");
    let text = String::from_utf8(w.finish().unwrap()).unwrap();
    let numbers: Vec<&str> = text
        .lines()
        .filter_map(|l| l.split_whitespace().next())
        .collect();
    let mut unique = numbers.clone();
    unique.sort_unstable();
    unique.dedup();
    assert_eq!(unique.len(), numbers.len(), "{text}");
}

/// A canned cycle's repeat count (and its pecks) multiply its moves: they
/// are bounded by the run's block budget like loops, so a bored hole
/// repeated 33,333,330 times (Fanuc K) under a budget of 20,000 stops at once with an
/// error (found by fuzzing: it ran for minutes).
#[test]
fn canned_cycle_repeats_are_bounded_like_loops() {
    use kinpost_nc::interp::{Family, Options, Step, run};
    let text = "L83330M96M99g85k33333330C777777777777777777736\n";
    let options = Options {
        max_executed_blocks: 20_000,
        ..Options::default()
    };
    let axes = [
        AxisSpec::linear("X"),
        AxisSpec::endless("A"),
        AxisSpec::linear("Y"),
        AxisSpec::linear("Z"),
        AxisSpec::rotary("B"),
        AxisSpec::rotary("C"),
    ];
    // (Each family reads the bytes its own way; Fanuc takes K as the
    // repeat count.)
    let mut messages = Vec::new();
    for family in [
        Family::Sinumerik,
        Family::Fanuc,
        Family::LinuxCnc,
        Family::Heidenhain,
        Family::Csv,
    ] {
        let started = Instant::now();
        if let Err(e) = run(text, family, &axes, &options, "cycle", &mut |_: &Step| {}) {
            messages.push(e.message);
        }
        assert!(started.elapsed() < Duration::from_secs(5), "{family:?}");
    }
    assert!(
        messages
            .iter()
            .any(|m| m.contains("canned cycles make more than 20000 moves")),
        "{messages:?}"
    );
    // The same cycle repeated a few times runs.
    let ok = "G0 X0 Y0 Z10\nG91 G85 X1 Y0 Z-2 R1 L3 F100\nM2\n";
    run(
        ok,
        Family::LinuxCnc,
        &axes,
        &options,
        "ok.ngc",
        &mut |_: &Step| {},
    )
    .unwrap();
}
