use std::collections::BTreeMap;

use kinpost_nc::{
    AxisSpec, Block, Dialect, Motion, NcError, NcWriter, ProgramInfo, Spindle, TemplateKind,
    check_template, read_program, read_program_full,
};

/// Machine axes of the MTS1600-500-6NC in chain order (DESIGN §2.1).
fn mts_axes() -> Vec<AxisSpec> {
    vec![
        AxisSpec::linear("X"),
        AxisSpec::endless("A"),
        AxisSpec::linear("Y"),
        AxisSpec::linear("Z"),
        AxisSpec::rotary("B"),
        AxisSpec::rotary("C").fixed(),
    ]
}

const FIGURE_28B: &str = include_str!("../../../../data/qiao2022/figure28b-verbatim.mpf");

/// The motion blocks of Qiao et al. 2022 Figure 28(b), as (X, Y, Z, B, A).
fn figure_blocks() -> Vec<(String, [f64; 5])> {
    FIGURE_28B
        .lines()
        .filter(|l| l.starts_with("X="))
        .map(|l| {
            let v: Vec<f64> = l
                .split_whitespace()
                .map(|w| {
                    let n = w
                        .trim_start_matches(|c: char| {
                            c.is_ascii_alphabetic() || c == '=' || c == '('
                        })
                        .trim_end_matches(')');
                    n.parse().unwrap()
                })
                .collect();
            (l.to_string(), [v[0], v[1], v[2], v[3], v[4]])
        })
        .collect()
}

fn text(w: NcWriter<Vec<u8>>) -> String {
    String::from_utf8(w.finish().unwrap()).unwrap()
}

#[test]
fn golden_qiao_figure28_feed_blocks() {
    let dialect = Dialect::builtin("sinumerik").unwrap();
    let axes = mts_axes();
    let figure = figure_blocks();
    assert_eq!(figure.len(), 11);
    let mut w = NcWriter::new(&dialect, &axes, Vec::new());
    for (k, (_, [x, y, z, b, a])) in figure.iter().enumerate() {
        // Perturb below the 4th decimal, with both signs (A slightly negative:
        // the DC word must still read 0.000, not 360.000 or -0.000).
        let e = if k % 2 == 0 { 3.7e-5 } else { -4.1e-5 };
        let values = [x + e, a - 2.0e-5, y - e, z + e, b + e, 0.0];
        w.block(&Block {
            line: None,
            number: None,
            arc: None,
            cl_line: Some(17 + k),
            motion: Motion::Feed,
            axes: &values,
            feed: Some(250.0),
        })
        .unwrap();
    }
    assert_eq!(w.blocks_written(), 11);
    let out = text(w);
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines[0], format!("{} F250", figure[0].0));
    for (k, line) in lines.iter().enumerate().skip(1) {
        assert_eq!(*line, figure[k].0);
    }
    assert_eq!(
        lines[0],
        "X=459.000 Y=8.807 Z361.368 B0.000 A=DC(0.000) F250"
    );
}

#[test]
fn sinumerik_rapid_then_feed_and_modal_feed() {
    let dialect = Dialect::builtin("sinumerik").unwrap();
    let axes = mts_axes();
    let mut w = NcWriter::new(&dialect, &axes, Vec::new());
    let p = [459.0, -90.0, 8.5, 380.0, 10.25, 0.0];
    w.block(&Block {
        line: None,
        number: None,
        arc: None,
        cl_line: Some(10),
        motion: Motion::Rapid,
        axes: &p,
        feed: None,
    })
    .unwrap();
    w.block(&Block {
        line: None,
        number: None,
        arc: None,
        cl_line: Some(12),
        motion: Motion::Rapid,
        axes: &p,
        feed: None,
    })
    .unwrap();
    w.block(&Block {
        line: None,
        number: None,
        arc: None,
        cl_line: Some(14),
        motion: Motion::Feed,
        axes: &p,
        feed: Some(250.0),
    })
    .unwrap();
    w.block(&Block {
        line: None,
        number: None,
        arc: None,
        cl_line: Some(15),
        motion: Motion::Feed,
        axes: &p,
        feed: Some(250.0),
    })
    .unwrap();
    w.block(&Block {
        line: None,
        number: None,
        arc: None,
        cl_line: Some(16),
        motion: Motion::Feed,
        axes: &p,
        feed: Some(312.5),
    })
    .unwrap();
    assert_eq!(
        text(w),
        "G0 X=459.000 Y=8.500 Z380.000 B10.250 A=DC(270.000)\n\
         X=459.000 Y=8.500 Z380.000 B10.250 A=DC(270.000)\n\
         G1 X=459.000 Y=8.500 Z380.000 B10.250 A=DC(270.000) F250\n\
         X=459.000 Y=8.500 Z380.000 B10.250 A=DC(270.000)\n\
         X=459.000 Y=8.500 Z380.000 B10.250 A=DC(270.000) F312.5\n"
    );
}

#[test]
fn quantized_matches_dialect_quantize_and_printed_text() {
    let dialect = Dialect::builtin("sinumerik").unwrap();
    let axes = mts_axes();
    let w = NcWriter::new(&dialect, &axes, Vec::new());
    assert_eq!(w.quantized(1, -0.00002), 0.0);
    assert_eq!(w.quantized(1, -90.0004), 270.0);
    assert_eq!(w.quantized(1, -90.0006), 269.999);
    assert_eq!(w.quantized(1, 719.9996), 0.0);
    assert_eq!(w.quantized(2, 8.80694), 8.807);
    assert_eq!(dialect.quantize(&axes[2], 8.80694), 8.807);
    assert_eq!(dialect.quantize(&axes[1], -90.0), 270.0);
}

#[test]
fn header_footer_templates_and_overrides() {
    let dialect = Dialect::builtin("sinumerik").unwrap();
    let axes = mts_axes();
    let mut info = ProgramInfo {
        program_name: "GRINDING PRESURE".into(),
        date: "2024-05-01".into(),
        machine: "MTS1600-500-6NC".into(),
        tool: "BELT".into(),
        tool_number: 1,
        cl_file: "figure28a.cls".into(),
        tool_loaded: true,
        length_register: 1,
        tcp_output: false,
        extra: BTreeMap::new(),
    };
    info.extra.insert("pressure".into(), "3000".into());
    let mut w = NcWriter::new(&dialect, &axes, Vec::new());
    w.header(&info, None).unwrap();
    w.footer(
        &info,
        Some("M30 ; {{ program_name }} H1={{ extra.pressure }} {{ pressure }}"),
    )
    .unwrap();
    let out = text(w);
    assert!(
        out.starts_with("; PROGRAM NAME: GRINDING PRESURE\n"),
        "{out}"
    );
    assert!(out.contains("; DATE: 2024-05-01\n"));
    assert!(out.contains("; MACHINE: MTS1600-500-6NC\n"));
    assert!(out.contains("(DIALECT sinumerik)\n"));
    assert!(
        out.ends_with("G01\nM30 ; GRINDING PRESURE H1=3000 3000\n"),
        "{out}"
    );
    assert!(!out.contains("\n\n"));
}

#[test]
fn figure_28b_header_as_machine_override() {
    // The header of Figure 28(b) as a machine file would give it.
    let header: String = FIGURE_28B
        .lines()
        .take_while(|l| !l.starts_with("X="))
        .collect::<Vec<_>>()
        .join("\n");
    let template = header
        .replace("GRINDING PRESURE", "{{ program_name }}")
        .replace("T1", "T{{ tool_number }}");
    let dialect = Dialect::builtin("sinumerik").unwrap();
    let axes = mts_axes();
    let info = ProgramInfo {
        program_name: "GRINDING PRESURE".into(),
        tool_number: 1,
        ..Default::default()
    };
    let mut w = NcWriter::new(&dialect, &axes, Vec::new());
    w.header(&info, Some(&template)).unwrap();
    let mut f = true;
    for (_, [x, y, z, b, a]) in figure_blocks() {
        w.block(&Block {
            line: None,
            number: None,
            arc: None,
            cl_line: None,
            motion: Motion::Feed,
            axes: &[x, a, y, z, b, 0.0],
            feed: if f { None } else { Some(250.0) },
        })
        .unwrap();
        f = false;
    }
    let out = text(w);
    let want: String = FIGURE_28B.lines().map(|l| format!("{l}\n")).collect();
    // Only the second block differs: it carries the F word.
    let diff: Vec<(&str, &str)> = out
        .lines()
        .zip(want.lines())
        .filter(|(a, b)| a != b)
        .collect();
    assert_eq!(
        diff,
        vec![(
            "X=459.000 Y=9.126 Z359.765 B0.000 A=DC(0.000) F250",
            "X=459.000 Y=9.126 Z359.765 B0.000 A=DC(0.000)"
        )]
    );
    // The reader reads our output back: the header's `N150 B0 C0` and
    // `N130 G01 B0 F5000` are motion too; 11 blocks from the body.
    let blocks = read_program(&dialect, &axes, "figure.mpf", &out).unwrap();
    let body: Vec<_> = blocks.iter().filter(|b| b.axes[0].is_some()).collect();
    assert_eq!(body.len(), 11);
    assert_eq!(
        body[0].axes,
        vec![
            Some(459.0),
            Some(0.0),
            Some(8.807),
            Some(361.368),
            Some(0.0),
            Some(0.0)
        ]
    );
    assert_eq!(body[0].feed, Some(5000.0));
    assert_eq!(body[1].feed, Some(250.0));
    assert!(body.iter().all(|b| b.motion == Motion::Feed));
}

#[test]
fn commands_tool_spindle_coolant() {
    let dialect = Dialect::builtin("sinumerik").unwrap();
    let axes = mts_axes();
    let mut w = NcWriter::new(&dialect, &axes, Vec::new());
    w.tool_change(3, "WHEEL").unwrap();
    w.spindle(Spindle::Cw(3013.0)).unwrap();
    w.spindle(Spindle::Ccw(3000.4)).unwrap();
    w.coolant(Some("flood")).unwrap();
    w.coolant(Some("mist")).unwrap();
    // As the CL reader gives it (COOLNT/MIST): templates see lower case.
    w.coolant(Some("MIST")).unwrap();
    w.coolant(None).unwrap();
    w.spindle(Spindle::Off).unwrap();
    w.comment("posted by (kinpost)\nline two").unwrap();
    w.insert("G642 U1030").unwrap();
    assert_eq!(
        text(w),
        "T3\nM6\nS3013 M03\nS3000 M04\nM08\nM07\nM07\nM09\nM05\n; posted by (kinpost) line two\nG642 U1030\n"
    );
}

/// The MTS1600 axes and its grinding-pressure word.
fn mts_axes_with_pressure() -> Vec<AxisSpec> {
    let mut axes = mts_axes();
    axes.push(AxisSpec::pressure_word("H1"));
    axes
}

/// One feed block at X = `x` with pressure `h1` (NaN: none programmed).
fn pressure_block<W: std::io::Write>(w: &mut NcWriter<W>, x: f64, h1: f64) {
    w.block(&Block {
        line: None,
        number: None,
        arc: None,
        cl_line: None,
        motion: Motion::Feed,
        axes: &[x, 0.0, 8.807, 361.368, 0.0, 0.0, h1],
        feed: Some(250.0),
    })
    .unwrap();
}

#[test]
fn pressure_word_on_its_own_line_when_it_changes() {
    let dialect = Dialect::builtin("sinumerik").unwrap();
    assert!(dialect.writes_pressure());
    let axes = mts_axes_with_pressure();
    let mut w = NcWriter::new(&dialect, &axes, Vec::new());
    for (x, h1) in [
        (1.0, f64::NAN),
        (2.0, 3000.0),
        (3.0, 3000.0),
        (4.0, 3000.4), // written as 3000: no change
        (5.0, 3250.0),
    ] {
        pressure_block(&mut w, x, h1);
    }
    let out = text(w);
    let body = |x: u8| format!("X={x}.000 Y=8.807 Z361.368 B0.000 A=DC(0.000)");
    assert_eq!(
        out,
        format!(
            "{} F250\nH1=3000\n{}\n{}\n{}\nH1=3250\n{}\n",
            body(1),
            body(2),
            body(3),
            body(4),
            body(5)
        )
    );
    assert_eq!(w_quantized_pressure(&dialect, 3000.4), 3000.0);
    // Read back: the pressure is modal, and its own line is not a block.
    let blocks = read_program(&dialect, &axes, "p.mpf", &out).unwrap();
    let pressures: Vec<Option<f64>> = blocks.iter().map(|b| b.axes[6]).collect();
    assert_eq!(
        pressures,
        vec![None, Some(3000.0), Some(3000.0), Some(3000.0), Some(3250.0)]
    );
}

fn w_quantized_pressure(dialect: &Dialect, v: f64) -> f64 {
    let w = NcWriter::new(dialect, &mts_axes_with_pressure(), Vec::new());
    assert_eq!(
        w.quantized(6, v),
        dialect.quantize(&AxisSpec::pressure_word("H1"), v)
    );
    w.quantized(6, v)
}

#[test]
fn pressure_word_numbering_template_and_dialects_without_it() {
    let src = r##"
name = "numbered"
extension = "nc"
[numbering]
enabled = true
[pressure]
prefix = "#{name}="
decimals = 1
[templates]
pressure = "G04 F2 ; {{ pressure_word }} {{ pressure }}"
"##;
    let dialect = Dialect::from_toml(src, "numbered.toml").unwrap();
    let mut axes = mts_axes_with_pressure();
    axes[6] = AxisSpec::pressure_word("P");
    let mut w = NcWriter::new(&dialect, &axes, Vec::new());
    pressure_block(&mut w, 1.0, 2.25);
    let out = text(w);
    assert!(
        out.starts_with("N10 #P=2.2\nN20 G04 F2 ; P 2.2\nN30 G1 X1.000"),
        "{out}"
    );
    let blocks = read_program(&dialect, &axes, "n.nc", &out).unwrap();
    assert_eq!(blocks.len(), 1);
    assert_eq!(blocks[0].axes[6], Some(2.2));

    // Fanuc has no pressure word: fine while none is programmed, an error
    // naming the dialect and the word as soon as one is.
    let fanuc = Dialect::builtin("fanuc").unwrap();
    assert!(!fanuc.writes_pressure());
    let axes = mts_axes_with_pressure();
    let mut w = NcWriter::new(&fanuc, &axes, Vec::new());
    pressure_block(&mut w, 1.0, f64::NAN);
    let e = w
        .block(&Block {
            line: None,
            number: None,
            arc: None,
            cl_line: None,
            motion: Motion::Feed,
            axes: &[1.0, 0.0, 8.807, 361.368, 0.0, 0.0, 3000.0],
            feed: None,
        })
        .unwrap_err();
    assert!(
        e.to_string()
            .contains("dialect `fanuc` cannot write the pressure word `H1`"),
        "{e}"
    );
    assert!(text(w).starts_with("G01 X1.000 Y8.807"));
}

#[test]
fn pressure_table_mistakes() {
    let base = "name = \"d\"\nextension = \"nc\"\n[pressure]\n";
    let e = Dialect::from_toml(&format!("{base}modal = false\n"), "d.toml")
        .unwrap_err()
        .to_string();
    assert!(e.contains("always modal"), "{e}");
    let e = Dialect::from_toml(&format!("{base}prefix = \"\"\n"), "d.toml")
        .unwrap_err()
        .to_string();
    assert!(e.contains("the pressure word needs a `prefix`"), "{e}");
    let e = Dialect::from_toml(&format!("{base}modulo = 360.0\n"), "d.toml")
        .unwrap_err()
        .to_string();
    assert!(e.contains("`modulo` does not apply"), "{e}");
}

#[test]
fn csv_pressure_column() {
    let dialect = Dialect::builtin("csv").unwrap();
    assert!(dialect.writes_pressure());
    let axes = mts_axes_with_pressure();
    let mut w = NcWriter::new(&dialect, &axes, Vec::new());
    pressure_block(&mut w, 1.0, f64::NAN);
    pressure_block(&mut w, 2.0, 3000.25);
    let out = text(w);
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines[0], "line,motion,X,A,Y,Z,B,C,H1,feed");
    assert!(lines[1].ends_with(",0.000000,,250.000000"), "{out}");
    assert!(lines[2].ends_with(",0.000000,3000.25,250.000000"), "{out}");
    let blocks = read_program(&dialect, &axes, "p.csv", &out).unwrap();
    assert_eq!(blocks[0].axes[6], None);
    assert_eq!(blocks[1].axes[6], Some(3000.25));
}

#[test]
fn template_render_errors_are_reported() {
    let dialect = Dialect::builtin("sinumerik").unwrap();
    let mut w = NcWriter::new(&dialect, &mts_axes(), Vec::new());
    let e = w
        .header(&ProgramInfo::default(), Some("{{ no_such_variable }}"))
        .unwrap_err();
    assert!(matches!(e, NcError::Template { .. }), "{e}");
    assert!(e.to_string().contains("undefined"), "{e}");
    let e = check_template(TemplateKind::Header, "G01\n{% if x %}").unwrap_err();
    assert!(e.range.is_some());
    assert_eq!(e.line, Some(2));
    assert!(check_template(TemplateKind::Header, "T{{ tool_number }}").is_ok());
    // A variable the header is not given, found without rendering: the
    // range is its first use.
    let source = "; {{ program_name }}\nT{{ tool_numbr }}";
    let e = check_template(TemplateKind::Footer, source).unwrap_err();
    assert!(e.message.contains("unknown variable `tool_numbr`"), "{e}");
    assert_eq!(&source[e.range.clone().unwrap()], "tool_numbr");
    assert_eq!(e.line, Some(2));
    // Tested with `is defined`: allowed.
    assert!(
        check_template(
            TemplateKind::Footer,
            "{% if extra is defined %}x{% endif %}"
        )
        .is_ok()
    );
    let mut vars = BTreeMap::new();
    vars.insert("x".to_string(), kinpost_nc::Value::from(2.5));
    assert_eq!(
        dialect.render_template("R{{ x | num }}", &vars).unwrap(),
        "R2.5"
    );
}

const HEIDENHAIN_LIKE: &str = r#"
name = "heidenhain-test"
extension = "h"
description = "Heidenhain conversational, as a user file"

[block]
order = ["X", "Y", "Z", "B", "A"]
after_axes = "R0"

[linear]
plus_sign = true
modal = true

[rotary]
plus_sign = true
modal = true

[feed]
decimals = 0
rapid = "FMAX"

[motion]
rapid = "L"
feed = "L"
modal = false

[numbering]
enabled = true
prefix = ""
start = 0
step = 1
header = true
comments = true

[comment]
prefix = "* - "
replace = { ";" = "," }

[templates]
header = "BEGIN PGM {{ program_name }} MM"
footer = "END PGM {{ program_name }} MM"
"#;

#[test]
fn user_dialect_heidenhain_like() {
    let d = Dialect::from_toml(HEIDENHAIN_LIKE, "heid.toml").unwrap();
    assert_eq!((d.name(), d.extension()), ("heidenhain-test", "h"));
    let axes = mts_axes();
    let info = ProgramInfo {
        program_name: "P1".into(),
        ..Default::default()
    };
    let mut w = NcWriter::new(&d, &axes, Vec::new());
    w.header(&info, None).unwrap();
    w.comment("approach; slowly").unwrap();
    w.block(&Block {
        line: None,
        number: None,
        arc: None,
        cl_line: None,
        motion: Motion::Rapid,
        axes: &[1.0, 0.0, -2.0, 3.0, 0.0, 0.0],
        feed: None,
    })
    .unwrap();
    w.block(&Block {
        line: None,
        number: None,
        arc: None,
        cl_line: None,
        motion: Motion::Feed,
        axes: &[1.0, 0.0, -2.5, 3.0, 0.0, 0.0],
        feed: Some(250.0),
    })
    .unwrap();
    // Nothing changed: no block at all.
    w.block(&Block {
        line: None,
        number: None,
        arc: None,
        cl_line: None,
        motion: Motion::Feed,
        axes: &[1.0, 0.0, -2.5, 3.0, 0.0, 0.0],
        feed: Some(250.0),
    })
    .unwrap();
    w.block(&Block {
        line: None,
        number: None,
        arc: None,
        cl_line: None,
        motion: Motion::Feed,
        axes: &[1.0, 0.0, -2.5, 3.0004, 0.0, 0.0],
        feed: Some(250.2),
    })
    .unwrap();
    w.block(&Block {
        line: None,
        number: None,
        arc: None,
        cl_line: None,
        motion: Motion::Feed,
        axes: &[1.0, 0.0, -2.5, 3.5, 0.0, 0.0],
        feed: Some(250.0),
    })
    .unwrap();
    assert_eq!(w.blocks_written(), 3);
    w.footer(&info, None).unwrap();
    let out = text(w);
    assert_eq!(
        out,
        "0 BEGIN PGM P1 MM\n\
         1 * - approach, slowly\n\
         2 L X+1.000 Y-2.000 Z+3.000 B+0.000 A+0.000 R0 FMAX\n\
         3 L Y-2.500 R0 F250\n\
         4 L Z+3.500 R0\n\
         5 END PGM P1 MM\n"
    );
    let blocks = read_program(&d, &axes, "p.h", &out).unwrap();
    assert_eq!(blocks.len(), 3);
    assert_eq!(blocks[0].motion, Motion::Rapid);
    assert_eq!(blocks[0].number, Some(2));
    assert_eq!(blocks[1].motion, Motion::Feed);
    assert_eq!(
        blocks[2].axes,
        vec![Some(1.0), Some(0.0), Some(-2.5), Some(3.5), Some(0.0), None]
    );
    assert_eq!(blocks[2].feed, Some(250.0));
}

#[test]
fn n_numbering_and_parenthesis_comments() {
    let src = r#"
name = "linuxcnc-test"
extension = "ngc"
[block]
write_fixed = true
[linear]
trailing_zeros = "trim"
leading_zero = false
[rotary]
trailing_zeros = "point"
[numbering]
enabled = true
start = 100
step = 5
digits = 4
wrap_after = 110
[comment]
prefix = "("
suffix = ")"
replace = { "(" = "[", ")" = "]" }
[templates]
header = "%\n(PROGRAM {{ program_name }})"
footer = "M2\n%"
"#;
    let d = Dialect::from_toml(src, "lcnc.toml").unwrap();
    let axes = [
        AxisSpec::linear("X"),
        AxisSpec::linear("Y"),
        AxisSpec::rotary("C").fixed(),
    ];
    let mut w = NcWriter::new(&d, &axes, Vec::new());
    let info = ProgramInfo {
        program_name: "T".into(),
        ..Default::default()
    };
    w.header(&info, None).unwrap();
    w.comment("a (nested) note").unwrap();
    w.block(&Block {
        line: None,
        number: None,
        arc: None,
        cl_line: None,
        motion: Motion::Rapid,
        axes: &[0.5, -0.25, 90.0],
        feed: None,
    })
    .unwrap();
    w.block(&Block {
        line: None,
        number: None,
        arc: None,
        cl_line: None,
        motion: Motion::Feed,
        axes: &[10.0, -0.25, 90.0],
        feed: Some(100.0),
    })
    .unwrap();
    w.block(&Block {
        line: None,
        number: None,
        arc: None,
        cl_line: None,
        motion: Motion::Feed,
        axes: &[11.0, -0.25, 90.0],
        feed: Some(100.0),
    })
    .unwrap();
    w.block(&Block {
        line: None,
        number: None,
        arc: None,
        cl_line: None,
        motion: Motion::Feed,
        axes: &[12.0, -0.25, 90.0],
        feed: Some(100.0),
    })
    .unwrap();
    w.footer(&info, None).unwrap();
    let out = text(w);
    assert_eq!(
        out,
        "%\n(PROGRAM T)\n(a [nested] note)\n\
         N0100 G0 X.5 Y-.25 C90.\n\
         N0105 G1 X10 Y-.25 C90. F100\n\
         N0110 X11 Y-.25 C90.\n\
         N0100 X12 Y-.25 C90.\n\
         M2\n%\n"
    );
    let read = read_program_full(&d, &axes, "t.ngc", &out).unwrap();
    assert_eq!(read.blocks.len(), 4);
    assert_eq!(
        read.blocks[0].axes,
        vec![Some(0.5), Some(-0.25), Some(90.0)]
    );
    assert_eq!(read.blocks[0].motion, Motion::Rapid);
    assert_eq!(read.blocks[3].number, Some(100));
    assert_eq!(read.blocks[3].feed, Some(100.0));
    assert_eq!(read.other_lines, vec![1, 8, 9]);
}

#[test]
fn csv_rows() {
    let d = Dialect::builtin("csv").unwrap();
    assert_eq!(d.extension(), "csv");
    let axes = mts_axes();
    let mut w = NcWriter::new(&d, &axes, Vec::new());
    w.header(&ProgramInfo::default(), None).unwrap();
    w.comment("dropped").unwrap();
    w.insert("dropped").unwrap();
    w.tool_change(1, "T").unwrap();
    w.block(&Block {
        line: None,
        number: None,
        arc: None,
        cl_line: Some(10),
        motion: Motion::Rapid,
        axes: &[459.0, -90.0, 8.80694, 361.368, 0.0, 0.0],
        feed: None,
    })
    .unwrap();
    w.block(&Block {
        line: None,
        number: None,
        arc: None,
        cl_line: None,
        motion: Motion::Feed,
        axes: &[459.0, -90.0, 8.80694, 361.368, 0.0, 0.0],
        feed: Some(250.0),
    })
    .unwrap();
    w.block(&Block {
        line: None,
        number: None,
        arc: None,
        cl_line: Some(17),
        motion: Motion::Feed,
        axes: &[459.0, -90.0, 8.80694, 361.368, 0.0, 0.0],
        feed: Some(250.0),
    })
    .unwrap();
    w.footer(&ProgramInfo::default(), None).unwrap();
    let out = text(w);
    assert_eq!(
        out,
        "line,motion,X,A,Y,Z,B,C,feed\n\
         10,rapid,459.000000,-90.000000,8.806940,361.368000,0.000000,0.000000,\n\
         ,feed,459.000000,-90.000000,8.806940,361.368000,0.000000,0.000000,250.000000\n\
         17,feed,459.000000,-90.000000,8.806940,361.368000,0.000000,0.000000,250.000000\n"
    );
    let blocks = read_program(&d, &axes, "p.csv", &out).unwrap();
    assert_eq!(blocks.len(), 3);
    assert_eq!(blocks[0].cl_line, Some(10));
    assert_eq!(blocks[1].cl_line, None);
    assert_eq!(blocks[1].feed, Some(250.0));
    assert_eq!(blocks[0].feed, None);
    assert_eq!(blocks[2].axes[2], Some(8.80694));
}

#[test]
fn csv_reader_errors_name_line_and_column() {
    let d = Dialect::builtin("csv").unwrap();
    let axes = [AxisSpec::linear("X"), AxisSpec::linear("Y")];
    let e = read_program(&d, &axes, "p.csv", "line,motion,X,Y,feed\n1,feed,1.0,x2,\n").unwrap_err();
    assert_eq!((e.file.as_str(), e.line, e.column), ("p.csv", 2, 12));
    let e = read_program(&d, &axes, "p.csv", "line,motion,X,Q,feed\n").unwrap_err();
    assert_eq!((e.line, e.column), (1, 15));
    let e = read_program(&d, &axes, "p.csv", "line,motion,X,Y,feed\n1,fed,1,2,\n").unwrap_err();
    assert_eq!((e.line, e.column), (2, 3));
    let head = "line,motion,X,Y,feed,feed_mode\n";
    let ok = format!("{head}1,feed,1,2,5,inverse-time\n2,feed,1,3,100,per-minute\n3,rapid,1,4,,\n");
    assert_eq!(read_program(&d, &axes, "p.csv", &ok).unwrap().len(), 3);
    let bad = format!("{head}1,feed,1,2,5,inverse\n");
    let e = read_program(&d, &axes, "p.csv", &bad).unwrap_err();
    assert_eq!((e.line, e.column), (2, 14));
    assert!(e.message.contains("feed mode"), "{}", e.message);
}

#[test]
fn empty_csv_has_header_row() {
    let d = Dialect::builtin("csv").unwrap();
    let w = NcWriter::new(&d, &[AxisSpec::linear("X")], Vec::new());
    assert_eq!(text(w), "line,motion,X,feed\n");
}

#[test]
fn bad_values_are_errors() {
    let d = Dialect::builtin("sinumerik").unwrap();
    let axes = mts_axes();
    let mut w = NcWriter::new(&d, &axes, Vec::new());
    let e = w
        .block(&Block {
            line: None,
            number: None,
            arc: None,
            cl_line: None,
            motion: Motion::Feed,
            axes: &[f64::NAN, 0.0, 0.0, 0.0, 0.0, 0.0],
            feed: None,
        })
        .unwrap_err();
    assert!(e.to_string().contains("X"), "{e}");
    assert!(
        w.block(&Block {
            line: None,
            number: None,
            arc: None,
            cl_line: None,
            motion: Motion::Feed,
            axes: &[1e300, 0.0, 0.0, 0.0, 0.0, 0.0],
            feed: None
        })
        .is_err()
    );
    assert!(
        w.block(&Block {
            line: None,
            number: None,
            arc: None,
            cl_line: None,
            motion: Motion::Feed,
            axes: &[0.0],
            feed: None
        })
        .is_err()
    );
    assert_eq!(w.blocks_written(), 0);
    assert_eq!(text(w), "");
}

#[test]
fn builtins_parse_and_list() {
    for name in Dialect::builtin_names() {
        let d = Dialect::builtin(name).unwrap();
        assert_eq!(d.name(), *name);
        assert!(Dialect::builtin_source(name).unwrap().contains("name ="));
    }
    assert!(Dialect::builtin("nope").is_none());
}

/// Shortest-path `DC` words are for endless (modulo) rotary axes only: a
/// tilting A (e.g. a trunnion's, −30…120°) is written as a plain position.
#[test]
fn sinumerik_dc_only_for_endless_axes() {
    let d = Dialect::builtin("sinumerik").unwrap();
    let axes = [
        AxisSpec::linear("X"),
        AxisSpec::rotary("A"),
        AxisSpec::endless("C"),
    ];
    let mut w = NcWriter::new(&d, &axes, Vec::new());
    let values = [1.0, -30.0, -90.0];
    w.block(&Block {
        line: None,
        number: None,
        arc: None,
        cl_line: Some(1),
        motion: Motion::Feed,
        axes: &values,
        feed: Some(100.0),
    })
    .unwrap();
    assert_eq!(w.quantized(1, -30.0), -30.0);
    assert_eq!(w.quantized(2, -90.0), 270.0);
    let out = text(w);
    assert!(out.contains("X=1.000 A-30.000 C=DC(270.000) F100"), "{out}");
}

/// The `[pressure]` examples of docs/dialects.md, added to the built-ins that
/// have none: written on their own line, read back by the same dialect.
#[test]
fn documented_pressure_tables() {
    for (name, table, line) in [
        (
            "fanuc",
            "prefix = \"#500=\"\ntrailing_zeros = \"point\"\n",
            "#500=3100.",
        ),
        (
            "heidenhain",
            "prefix = \"FN 0: Q100 = \"\nplus_sign = true\n",
            " FN 0: Q100 = +3100\n",
        ),
        ("linuxcnc", "prefix = \"M68 E0 Q\"\n", "\nM68 E0 Q3100\n"),
    ] {
        let source = format!(
            "{}\n[pressure]\n{table}",
            Dialect::builtin_source(name).unwrap()
        );
        let dialect = Dialect::from_toml(&source, &format!("{name}-pressure.toml"))
            .unwrap_or_else(|e| panic!("{e}"));
        assert!(dialect.writes_pressure());
        let axes = mts_axes_with_pressure();
        let mut w = NcWriter::new(&dialect, &axes, Vec::new());
        w.header(&ProgramInfo::default(), None).unwrap();
        for (x, h1) in [(1.0, f64::NAN), (2.0, 3000.0), (3.0, 3000.0), (4.0, 3100.0)] {
            pressure_block(&mut w, x, h1);
        }
        let out = text(w);
        assert!(out.contains(line), "{name}:\n{out}");
        let blocks = read_program(&dialect, &axes, "p", &out).unwrap();
        let pressures: Vec<Option<f64>> = blocks.iter().map(|b| b.axes[6]).collect();
        assert_eq!(
            pressures,
            [None, Some(3000.0), Some(3000.0), Some(3100.0)],
            "{name}:\n{out}"
        );
    }
}

#[test]
fn a_tool_change_under_tcp_control_renews_it_for_the_new_tool() {
    let dialect = Dialect::builtin("fanuc").unwrap();
    let axes = mts_axes();
    let mut w = NcWriter::new(&dialect, &axes, Vec::new());
    w.tool_change(1, "T1").unwrap();
    w.tcp(true).unwrap();
    w.tool_change(2, "T2").unwrap();
    w.tcp(false).unwrap();
    w.tool_change(3, "T3").unwrap();
    assert_eq!(
        text(w),
        // G43 for the first tool: the writer was not told (by a header)
        // that the program is tool-centre-point output before G43.4.
        "T1 M06\nG43 H1\nG43.4 H1\nG49\nT2 M06\nG43.4 H2\nG49\nT3 M06\n"
    );
}

/// `templates.outside_tcp` says which commands are written with
/// tool-centre-point control off: here the coolant, and not the tool
/// change (the default list is the tool change alone).
#[test]
fn outside_tcp_lists_the_commands_written_with_tcp_off() {
    let source = Dialect::builtin_source("fanuc").unwrap().replace(
        "[templates]\n",
        "[templates]\noutside_tcp = [\"coolant_on\"]\n",
    );
    let dialect = Dialect::from_toml(&source, "fanuc-coolant.toml").unwrap();
    let axes = mts_axes();
    let mut w = NcWriter::new(&dialect, &axes, Vec::new());
    w.tool_change(1, "T1").unwrap();
    w.tcp(true).unwrap();
    w.coolant(Some("flood")).unwrap();
    w.tool_change(2, "T2").unwrap();
    w.coolant(None).unwrap();
    w.tcp(false).unwrap();
    w.coolant(Some("flood")).unwrap();
    assert_eq!(
        text(w),
        "T1 M06\nG43 H1\nG43.4 H1\nG49\nM08\nG43.4 H1\nT2 M06\nM09\nG49\nM08\n"
    );
}

/// A block on the mts1600 axes with Z at `z` (feed blocks at F500).
fn z_block(w: &mut NcWriter<Vec<u8>>, motion: Motion, z: f64) {
    let q = [459.0, -90.0, 8.5, z, 10.25, 0.0];
    w.block(&Block {
        line: None,
        number: None,
        arc: None,
        cl_line: None,
        motion,
        axes: &q,
        feed: (motion == Motion::Feed).then_some(500.0),
    })
    .unwrap();
}

#[test]
fn after_a_tool_change_the_motion_word_and_every_axis_are_written_again() {
    let dialect = Dialect::builtin("fanuc").unwrap();
    let axes = mts_axes();
    let mut w = NcWriter::new(&dialect, &axes, Vec::new());
    z_block(&mut w, Motion::Rapid, 380.0);
    z_block(&mut w, Motion::Rapid, 400.0);
    w.tool_change(2, "T2").unwrap();
    z_block(&mut w, Motion::Rapid, 400.0);
    let out = text(w);
    // (The tool change applies the new tool's length: `G43 H2`.)
    assert_eq!(
        out,
        "G00 X459.000 Y8.500 Z380.000 A-90.000 B10.250\nZ400.000\nT2 M06\nG43 H2\nG00 X459.000 Y8.500 Z400.000 A-90.000 B10.250\n"
    );
}

#[test]
fn after_an_insert_the_next_block_states_motion_axes_and_feed() {
    // The INSERT's code may switch to rapid and move: a feed block that
    // relied on G01 and F being in force would run at rapid.
    let dialect = Dialect::builtin("fanuc").unwrap();
    let axes = mts_axes();
    let mut w = NcWriter::new(&dialect, &axes, Vec::new());
    for z in [380.0, 400.0] {
        z_block(&mut w, Motion::Feed, z);
    }
    w.insert("G00 Z450.").unwrap();
    for z in [410.0, 420.0] {
        z_block(&mut w, Motion::Feed, z);
    }
    assert_eq!(
        text(w),
        "G01 X459.000 Y8.500 Z380.000 A-90.000 B10.250 F500.\nZ400.000\nG00 Z450.\n\
         G01 X459.000 Y8.500 Z410.000 A-90.000 B10.250 F500.\nZ420.000\n"
    );
}

/// A block whose axis words all repeat the last ones (a repeated CL point)
/// writes nothing, not even its motion or feed word, and is not counted;
/// the next block that moves writes the motion and feed in force. A CSV
/// table keeps a row for it (a trace of every block).
#[test]
fn a_repeated_point_writes_no_block() {
    let axes = [AxisSpec::linear("X"), AxisSpec::linear("Z")];
    let blocks: [(Motion, [f64; 2], Option<f64>); 6] = [
        (Motion::Rapid, [0.0, 50.0], None),
        (Motion::Feed, [0.0, 10.0], Some(100.0)),
        (Motion::Feed, [0.0, 10.0], Some(200.0)),
        (Motion::Feed, [0.0, 10.0001], Some(200.0)),
        (Motion::Rapid, [0.0, 10.0], None),
        (Motion::Feed, [5.0, 10.0], Some(200.0)),
    ];
    let program = |name: &str| {
        let d = Dialect::builtin(name).unwrap();
        let mut w = NcWriter::new(&d, &axes, Vec::new());
        for (k, (motion, values, feed)) in blocks.iter().enumerate() {
            w.block(&Block {
                line: None,
                number: None,
                arc: None,
                cl_line: Some(k + 1),
                motion: *motion,
                axes: values,
                feed: *feed,
            })
            .unwrap();
        }
        let n = w.blocks_written();
        (text(w), n)
    };
    assert_eq!(
        program("fanuc"),
        (
            "G00 X0.000 Z50.000\nG01 Z10.000 F100.\nX5.000 F200.\n".to_string(),
            3
        )
    );
    assert_eq!(
        program("linuxcnc"),
        (
            "G0 X0.0000 Z50.0000\nG1 Z10.0000 F100\nZ10.0001 F200\nG0 Z10.0000\nG1 X5.0000\n"
                .to_string(),
            5
        )
    );
    assert_eq!(
        program("heidenhain"),
        (
            "0 L X+0.000 Z+50.000 R0 FMAX\n1 L Z+10.000 R0 F100\n2 L X+5.000 R0 F200\n".to_string(),
            3
        )
    );
    let (csv, rows) = program("csv");
    assert_eq!((csv.lines().count(), rows), (7, 6), "{csv}");
}

/// Every template renders with the variables the loader lets it use
/// (`ProgramInfo::VARIABLES` and `TemplateKind::variables`): what passes the
/// load-time check is given at post time.
#[test]
fn every_template_gets_the_variables_the_loader_accepts() {
    use kinpost_nc::TemplateKind;
    let mut src = String::from("name = \"x\"\nextension = \"nc\"\n[pressure]\n[templates]\n");
    for kind in TemplateKind::ALL {
        let vars: Vec<String> = ProgramInfo::VARIABLES
            .iter()
            .chain(kind.variables())
            .map(|v| format!("{{{{ {v} }}}}"))
            .collect();
        src.push_str(&format!("{} = \"{}\"\n", kind.key(), vars.join(" ")));
    }
    src.push_str("[cycle]\nkinds = [\"drill\"]\nretract = \"any\"\n");
    let dialect = Dialect::from_toml(&src, "all.toml").unwrap_or_else(|e| panic!("{e}"));
    let axes = mts_axes_with_pressure();
    let mut w = NcWriter::new(&dialect, &axes, Vec::new());
    let info = ProgramInfo::default();
    w.header(&info, None).unwrap();
    w.tool_change(2, "BALL").unwrap();
    w.spindle(Spindle::Cw(3000.0)).unwrap();
    w.spindle(Spindle::Off).unwrap();
    w.coolant(Some("MIST")).unwrap();
    w.coolant(None).unwrap();
    w.tcp(true).unwrap();
    w.tcp(false).unwrap();
    w.inverse_time(true).unwrap();
    w.inverse_time(false).unwrap();
    w.stop(false).unwrap();
    w.stop(true).unwrap();
    w.dwell(1.0).unwrap();
    w.cutter_compensation(Some((true, 1))).unwrap();
    w.cutter_compensation(None).unwrap();
    let hole = kinpost_nc::Hole {
        kind: kinpost_nc::HoleKind::Drill,
        x: 1.0,
        y: 2.0,
        top: 0.0,
        r: 2.0,
        bottom: -5.0,
        retract: 10.0,
        start_z: 10.0,
        peck: 0.0,
        dwell: 0.0,
        feed: 100.0,
        rpm: 1000.0,
        ccw: false,
    };
    assert!(w.hole(&hole).unwrap());
    pressure_block(&mut w, 1.0, 3000.0);
    w.footer(&info, None).unwrap();
    let out = text(w);
    assert_eq!(out.lines().count(), TemplateKind::ALL.len() + 2, "{out}");
}

/// `max_line_length` (LinuxCNC: 253 bytes with the newline): a comment, or
/// the comment a template line ends with (the program name), is cut to fit
/// at a character boundary; an INSERT, a template line that is not a
/// comment and a motion block are not shortened: errors.
#[test]
fn lines_fit_the_dialect_max_line_length() {
    let d = Dialect::builtin("linuxcnc").unwrap();
    assert_eq!(d.block_format().max_line_length, Some(253));
    assert_eq!(
        Dialect::builtin("sinumerik")
            .unwrap()
            .block_format()
            .max_line_length,
        Some(512)
    );
    let axes = [AxisSpec::linear("X")];
    let mut w = NcWriter::new(&d, &axes, Vec::new());
    let info = ProgramInfo {
        program_name: "P".repeat(300),
        ..ProgramInfo::default()
    };
    w.header(&info, None).unwrap();
    w.comment(&"c".repeat(251)).unwrap();
    w.comment(&format!("{}äb", "c".repeat(249))).unwrap();
    w.comment(&"c".repeat(250)).unwrap();
    let e = w
        .insert(&format!("(MSG, {})", "i".repeat(246)))
        .unwrap_err();
    assert!(
        matches!(
            e,
            NcError::LineTooLong {
                length: 254,
                max: 253,
                ..
            }
        ),
        "{e}"
    );
    assert!(e.to_string().contains("INSERT"), "{e}");
    w.insert(&format!("(MSG, {})", "i".repeat(245))).unwrap();
    let out = text(w);
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines[1], format!("(PROGRAM: {})", "P".repeat(241)));
    let tail = &lines[lines.len() - 4..];
    assert_eq!(tail[0], format!("({})", "c".repeat(250)));
    assert_eq!(tail[1], format!("({})", "c".repeat(249)));
    assert_eq!(tail[2], format!("({})", "c".repeat(250)));
    assert_eq!(tail[3].len(), 252);
    assert!(out.lines().all(|l| l.len() < 253), "{out}");

    // A template line that is not a comment, a block, a numbered comment.
    let src = "name = \"x\"\nextension = \"nc\"\n[block]\nmax_line_length = 20\n\
               [numbering]\nenabled = true\ncomments = true\n[comment]\nprefix = \"(\"\nsuffix = \")\"\n[templates]\n\
               header = \"(T) {{ program_name }}\"\ntool_change = \"T{{ tool_number }} (TOOL {{ tool_name }})\"\n";
    let d = Dialect::from_toml(src, "x.toml").unwrap();
    let axes = [AxisSpec::linear("X"), AxisSpec::linear("Y")];
    let mut w = NcWriter::new(&d, &axes, Vec::new());
    let e = w.header(&info, None).unwrap_err();
    assert!(matches!(e, NcError::LineTooLong { .. }), "{e}");
    assert!(e.to_string().contains("template `header`"), "{e}");
    w.tool_change(12, "BALL NOSE 6 MM").unwrap();
    w.comment("a remark longer than twenty").unwrap();
    let e = w
        .block(&Block {
            line: None,
            number: None,
            arc: None,
            cl_line: Some(7),
            motion: Motion::Feed,
            axes: &[1.0, 2.0],
            feed: Some(100.0),
        })
        .unwrap_err();
    assert!(e.to_string().contains("CL line 7"), "{e}");
    assert_eq!(text(w), "N10 T12 (TOOL BALL)\nN20 (a remark long)\n");
}

#[test]
fn fanuc_comments_and_header_names_are_ascii() {
    // A Fanuc reads ISO code: a tab or a character beyond ASCII in a
    // comment (from a CL `$$` or PARTNO) would stop the program loading.
    let d = Dialect::builtin("fanuc").unwrap();
    let axes = [AxisSpec::linear("X")];
    let mut w = NcWriter::new(&d, &axes, Vec::new());
    let info = ProgramInfo {
        program_name: "Gehäuse (5x)".into(),
        ..Default::default()
    };
    w.header(&info, None).unwrap();
    w.comment("Schrupp\tfräsen").unwrap();
    let out = String::from_utf8(w.finish().unwrap()).unwrap();
    assert!(out.contains("O0001 (Geh?use [5x])\n"), "{out}");
    assert!(out.contains("(Schrupp fr?sen)\n"), "{out}");
    assert!(out.is_ascii(), "{out}");
}

#[test]
fn arc_blocks_write_plane_arc_and_centre_words() {
    use kinpost_nc::{ArcMotion, ArcPlane};
    let dialect = Dialect::builtin("fanuc").unwrap();
    let axes = [
        AxisSpec::linear("X"),
        AxisSpec::linear("Y"),
        AxisSpec::linear("Z"),
    ];
    let mut w = NcWriter::new(&dialect, &axes, Vec::new());
    assert!(w.writes_arcs());
    w.block(&Block {
        line: None,
        number: None,
        arc: None,
        cl_line: None,
        motion: Motion::Feed,
        axes: &[10.0, 0.0, 5.0],
        feed: Some(300.0),
    })
    .unwrap();
    let arc = |plane, clockwise, axes: &'static [f64], centre_offset| Block {
        arc: Some(ArcMotion {
            plane,
            clockwise,
            centre_offset,
        }),
        ..Block::feed(axes, 300.0).with_cl_line(3)
    };
    w.block(&arc(
        ArcPlane::Xy,
        false,
        &[0.0, 10.0, 5.0],
        [-10.0, 0.0, 7.0],
    ))
    .unwrap();
    // The plane is written when it changes; the centre words in I J K
    // order; a linear block after an arc has its motion word.
    w.block(&arc(
        ArcPlane::Zx,
        true,
        &[0.0, 10.0, -5.0],
        [0.0, 1.0, -5.0],
    ))
    .unwrap();
    w.block(&arc(ArcPlane::Zx, true, &[0.0, 10.0, 5.0], [0.0, 1.0, 5.0]))
        .unwrap();
    w.block(&Block {
        line: None,
        number: None,
        arc: None,
        cl_line: None,
        motion: Motion::Feed,
        axes: &[1.0, 10.0, 5.0],
        feed: Some(300.0),
    })
    .unwrap();
    let text = String::from_utf8(w.finish().unwrap()).unwrap();
    assert_eq!(
        text,
        "G01 X10.000 Y0.000 Z5.000 F300.\n\
         G17 G03 X0.000 Y10.000 I-10.000 J0.000\n\
         G18 G02 Z-5.000 I0.000 K-5.000\n\
         G02 Z5.000 I0.000 K5.000\n\
         G01 X1.000\n"
    );
}

#[test]
fn a_dialect_without_arc_words_refuses_arc_blocks() {
    use kinpost_nc::{ArcMotion, ArcPlane, BlockError};
    let dialect = Dialect::builtin("csv").unwrap();
    assert!(dialect.arc_words().is_none());
    let axes = [
        AxisSpec::linear("X"),
        AxisSpec::linear("Y"),
        AxisSpec::linear("Z"),
    ];
    let mut w = NcWriter::new(&dialect, &axes, Vec::new());
    assert!(!w.writes_arcs());
    let circle = Some(ArcMotion {
        plane: ArcPlane::Xy,
        clockwise: false,
        centre_offset: [0.0; 3],
    });
    let e = w
        .block(&Block {
            arc: circle,
            ..Block::feed(&[0.0, 1.0, 0.0], 100.0)
        })
        .unwrap_err();
    assert!(matches!(e, BlockError::NoArcWords { .. }), "{e}");
    // A circle is a feed move, in every dialect.
    let mut w = NcWriter::new(&Dialect::builtin("fanuc").unwrap(), &axes, Vec::new());
    let e = w
        .block(&Block {
            arc: circle,
            ..Block::rapid(&[0.0, 1.0, 0.0])
        })
        .unwrap_err();
    assert!(matches!(e, BlockError::RapidArc { .. }), "{e}");
}

/// Heidenhain: the centre on a `CC` line of its own in absolute
/// coordinates (the start plus the offset; not again while it is in
/// force), then `C` with the sense word;
/// arcs the TNC would take in another plane, helices, and an arc with no
/// start written yet are refused with nothing written.
#[test]
fn heidenhain_writes_an_absolute_centre_line_and_refuses_other_planes() {
    use kinpost_nc::{ArcMotion, ArcPlane, BlockError};
    let dialect = Dialect::builtin("heidenhain").unwrap();
    let axes = [
        AxisSpec::linear("X"),
        AxisSpec::linear("Y"),
        AxisSpec::linear("Z"),
    ];
    let arc = |plane, clockwise, centre_offset| {
        Some(ArcMotion {
            plane,
            clockwise,
            centre_offset,
        })
    };
    let mut w = NcWriter::new(&dialect, &axes, Vec::new());
    let e = w
        .block(&Block {
            arc: arc(ArcPlane::Xy, true, [1.0, 0.0, 0.0]),
            ..Block::feed(&[2.0, 0.0, 0.0], 100.0)
        })
        .unwrap_err();
    assert!(matches!(e, BlockError::ArcStartUnknown { .. }), "{e}");
    w.block(&Block::feed(&[10.0, 5.0, -2.0], 100.0)).unwrap();
    // A quarter circle about (10, 15), counter-clockwise to (0, 15).
    w.block(&Block {
        arc: arc(ArcPlane::Xy, false, [0.0, 10.0, 0.0]),
        ..Block::feed(&[0.0, 15.0, -2.0], 100.0)
    })
    .unwrap();
    w.block(&Block {
        arc: arc(ArcPlane::Xy, true, [0.0, -10.0, 0.0]),
        ..Block::feed(&[10.0, 5.0, -2.0], 100.0)
    })
    .unwrap();
    // About the same centre: the CC in force is not written again.
    w.block(&Block {
        arc: arc(ArcPlane::Xy, false, [-10.0, 0.0, 0.0]),
        ..Block::feed(&[-10.0, 5.0, -2.0], 100.0)
    })
    .unwrap();
    for (plane, end, centre) in [
        (ArcPlane::Zx, [10.0, 5.0, 8.0], [0.0, 0.0, 5.0]),
        (ArcPlane::Yz, [10.0, 15.0, -2.0], [0.0, 5.0, 0.0]),
        // A helix: the end 1 mm lower.
        (ArcPlane::Xy, [10.0, 5.0, -3.0], [-5.0, 0.0, 0.0]),
    ] {
        let e = w
            .block(&Block {
                arc: arc(plane, false, centre),
                ..Block::feed(&end, 100.0)
            })
            .unwrap_err();
        assert!(matches!(e, BlockError::ArcNotWritable { .. }), "{e}");
    }
    let text = String::from_utf8(w.finish().unwrap()).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(
        lines,
        [
            "0 L X+10.000 Y+5.000 Z-2.000 R0 F100",
            "1 CC X+10.000 Y+15.000",
            "2 C X+0.000 Y+15.000 DR+ R0",
            "3 CC X+0.000 Y+5.000",
            "4 C X+10.000 Y+5.000 DR- R0",
            "5 C X-10.000 DR+ R0",
        ],
        "{text}"
    );
}

#[test]
fn an_arc_table_needs_all_its_words() {
    let e = Dialect::from_toml(
        "name = \"x\"\nextension = \"nc\"\n[arc]\nclockwise = \"G2\"\n",
        "x.toml",
    )
    .unwrap_err();
    assert!(e.to_string().contains("counter_clockwise"), "{e}");
}

/// Heidenhain's radius compensation is a word of the motion blocks: RL or
/// RR for R0 from CUTCOM/LEFT or RIGHT to CUTCOM/OFF, and the reader reads
/// the blocks back with it.
#[test]
fn heidenhain_compensation_is_rl_or_rr_on_the_blocks() {
    let dialect = Dialect::builtin("heidenhain").unwrap();
    let axes = mts_axes();
    let mut w = NcWriter::new(&dialect, &axes, Vec::new());
    z_block(&mut w, Motion::Feed, 380.0);
    w.cutter_compensation(Some((true, 1))).unwrap();
    z_block(&mut w, Motion::Feed, 381.0);
    z_block(&mut w, Motion::Feed, 382.0);
    w.cutter_compensation(None).unwrap();
    w.cutter_compensation(Some((false, 1))).unwrap();
    z_block(&mut w, Motion::Rapid, 383.0);
    w.cutter_compensation(None).unwrap();
    z_block(&mut w, Motion::Feed, 384.0);
    let out = text(w);
    let words: Vec<&str> = out
        .lines()
        .map(|l| l.split(' ').find(|w| w.starts_with('R')).unwrap())
        .collect();
    assert_eq!(words, ["R0", "RL", "RL", "RR", "R0"], "{out}");
    let read = kinpost_nc::read_program(&dialect, &axes, "h.h", &out).unwrap();
    assert_eq!(read.len(), 5, "{out}");
}

/// A left-hand tap (the spindle counter-clockwise) is not written as the
/// right-hand G84; a right-hand one is.
#[test]
fn a_left_hand_tap_is_not_a_g84() {
    let dialect = Dialect::builtin("fanuc").unwrap();
    let axes = mts_axes();
    let mut w = NcWriter::new(&dialect, &axes, Vec::new());
    let tap = kinpost_nc::Hole {
        kind: kinpost_nc::HoleKind::Tap,
        x: 1.0,
        y: 2.0,
        top: 0.0,
        r: 2.0,
        bottom: -5.0,
        retract: 2.0,
        start_z: 10.0,
        peck: 0.0,
        dwell: 0.0,
        feed: 500.0,
        rpm: 400.0,
        ccw: true,
    };
    assert!(!w.hole(&tap).unwrap());
    assert!(w.hole(&kinpost_nc::Hole { ccw: false, ..tap }).unwrap());
    assert!(text(w).contains("G84"));
}
