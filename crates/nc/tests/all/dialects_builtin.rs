//! The built-in dialects, each on the same short program: header, comment,
//! tool change, spindle, coolant, rapid and feed blocks with modal changes,
//! footer. The expected texts were reviewed by hand against the controllers'
//! syntax; each program is also read back with `read_program`.

use std::collections::BTreeMap;

use kinpost_nc::{
    AxisSpec, Block, Dialect, Motion, NcWriter, ProgramInfo, Spindle, read_program,
    read_program_full,
};

/// The MTS1600's axes in machine order (C locked): exercises `block.order`
/// and fixed axes.
fn axes() -> Vec<AxisSpec> {
    vec![
        AxisSpec::linear("X"),
        AxisSpec::endless("A"),
        AxisSpec::linear("Y"),
        AxisSpec::linear("Z"),
        AxisSpec::rotary("B"),
        AxisSpec::rotary("C").fixed(),
    ]
}

/// (motion, X A Y Z B C, feed) of the program's blocks.
const BLOCKS: &[(Motion, [f64; 6], Option<f64>)] = &[
    (
        Motion::Rapid,
        [459.0, 0.0, 8.80694, 361.36839, 0.0, 0.0],
        None,
    ),
    (
        Motion::Feed,
        [459.0, 0.0, 8.80694, 350.12345, -20.00049, 0.0],
        Some(250.0),
    ),
    // A negative, X changes; the same feed (modal: no F word).
    (
        Motion::Feed,
        [460.5, -12.345678, 8.80694, 350.12345, -20.00049, 0.0],
        Some(250.0),
    ),
    // Y alone, a new feed.
    (
        Motion::Feed,
        [460.5, -12.345678, -0.00004, 350.12345, -20.00049, 0.0],
        Some(300.5),
    ),
    // Nothing changes as written: no block in modal dialects.
    (
        Motion::Feed,
        [460.5, -12.345678, 0.00001, 350.12345, -20.00049, 0.0],
        Some(300.5),
    ),
    // Rapid retract.
    (
        Motion::Rapid,
        [460.5, -12.345678, 0.0, 380.0, -20.00049, 0.0],
        None,
    ),
];

fn info() -> ProgramInfo {
    ProgramInfo {
        program_name: "DEMO (1)".into(),
        date: "2025-01-31".into(),
        machine: "mts1600".into(),
        tool: "WHEEL".into(),
        tool_number: 1,
        cl_file: "demo.cls".into(),
        tool_loaded: true,
        length_register: 1,
        tcp_output: false,
        extra: BTreeMap::new(),
    }
}

fn program(name: &str) -> String {
    let dialect = Dialect::builtin(name).unwrap();
    let axes = axes();
    let mut w = NcWriter::new(&dialect, &axes, Vec::new());
    let info = info();
    w.header(&info, None).unwrap();
    w.comment("TOOL PATH: ROUGH (A), FINISH").unwrap();
    w.tool_change(2, "BELT").unwrap();
    w.spindle(Spindle::Cw(3000.0)).unwrap();
    w.coolant(Some("flood")).unwrap();
    for (k, (motion, values, feed)) in BLOCKS.iter().enumerate() {
        w.block(&Block {
            line: None,
            number: None,
            arc: None,
            cl_line: Some(10 + k),
            motion: *motion,
            axes: values,
            feed: *feed,
        })
        .unwrap();
    }
    w.coolant(None).unwrap();
    w.spindle(Spindle::Off).unwrap();
    w.footer(&info, None).unwrap();
    String::from_utf8(w.finish().unwrap()).unwrap()
}

#[track_caller]
fn assert_text(name: &str, expected: &str) {
    let got = program(name);
    assert!(
        got == expected,
        "dialect {name}:\n--- got\n{got}--- expected\n{expected}"
    );
}

#[test]
fn fanuc_program() {
    assert_text("fanuc", FANUC);
}

#[test]
fn heidenhain_program() {
    assert_text("heidenhain", HEIDENHAIN);
}

#[test]
fn linuxcnc_program() {
    assert_text("linuxcnc", LINUXCNC);
}

#[test]
fn sinumerik_program() {
    assert_text("sinumerik", SINUMERIK);
}

#[test]
fn csv_program() {
    assert_text("csv", CSV);
}

/// Every dialect's program read back gives the blocks' values exactly as
/// the dialect quantizes them (modal words carried over; the locked C is
/// not written), the motions, and the feeds in force.
#[test]
fn every_builtin_reads_back() {
    let axes = axes();
    for name in Dialect::builtin_names() {
        let dialect = Dialect::builtin(name).unwrap();
        let text = program(name);
        let read =
            read_program(&dialect, &axes, "demo", &text).unwrap_or_else(|e| panic!("{name}: {e}"));
        // The block that changes nothing as written is absent from programs
        // with modal axis words, present in the others.
        // (Sinumerik writes every axis word in every block.)
        let expected: Vec<usize> = if matches!(*name, "csv" | "sinumerik") {
            (0..BLOCKS.len()).collect()
        } else {
            vec![0, 1, 2, 3, 5]
        };
        assert_eq!(read.len(), expected.len(), "{name}:\n{text}");
        let mut feed = None;
        for (b, &k) in read.iter().zip(&expected) {
            let (motion, values, f) = BLOCKS[k];
            assert_eq!(b.motion, motion, "{name}: block {k}");
            for (i, a) in axes.iter().enumerate() {
                let want = if a.fixed && dialect.kind() != kinpost_nc::DialectKind::Csv {
                    None
                } else {
                    Some(dialect.quantize(a, values[i]))
                };
                assert_eq!(b.axes[i], want, "{name}: block {k} axis {}", a.name);
            }
            if motion == Motion::Feed {
                feed = f;
            }
            let want_feed = if dialect.kind() == kinpost_nc::DialectKind::Csv {
                if motion == Motion::Feed { f } else { None }
            } else {
                feed
            };
            assert_eq!(b.feed, want_feed, "{name}: block {k} feed");
        }
    }
}

/// The header, footer and command lines are not taken for motion blocks,
/// and every line of the NC programs is accounted for.
#[test]
fn other_lines_are_the_non_motion_lines() {
    let axes = axes();
    for name in ["fanuc", "heidenhain", "linuxcnc"] {
        let dialect = Dialect::builtin(name).unwrap();
        let text = program(name);
        let p = read_program_full(&dialect, &axes, "demo", &text).unwrap();
        let motion_lines: Vec<usize> = p.blocks.iter().filter_map(|b| b.line).collect();
        for (i, line) in text.lines().enumerate() {
            let n = i + 1;
            let is_motion = motion_lines.contains(&n);
            let words: Vec<&str> = line.split(' ').collect();
            let looks_like_motion = if name == "heidenhain" {
                words.get(1) == Some(&"L")
            } else {
                !line.starts_with('(')
                    && words.iter().any(|w| {
                        let mut c = w.chars();
                        c.next().is_some_and(|l| "XYZAB".contains(l))
                            && c.next().is_some_and(|d| d.is_ascii_digit() || d == '-')
                    })
            };
            assert_eq!(is_motion, looks_like_motion, "{name} line {n}: {line}");
        }
    }
}

/// Heidenhain block numbers run from 0 on every line, one apart.
#[test]
fn heidenhain_numbers_every_line_from_zero() {
    let text = program("heidenhain");
    for (i, line) in text.lines().enumerate() {
        let n: usize = line.split(' ').next().unwrap().parse().unwrap();
        assert_eq!(n, i, "{line}");
    }
}

/// Fanuc block numbers, when turned on, are N10, N20, ... on motion blocks
/// and commands, and wrap after N99999.
#[test]
fn fanuc_numbering_can_be_turned_on() {
    let src = Dialect::builtin_source("fanuc").unwrap().replace(
        "[numbering]\nenabled = false",
        "[numbering]\nenabled = true",
    );
    let dialect = Dialect::from_toml(&src, "fanuc-n.toml").unwrap();
    let axes = [AxisSpec::linear("X"), AxisSpec::linear("Y")];
    let mut w = NcWriter::new(&dialect, &axes, Vec::new());
    w.header(&info(), None).unwrap();
    w.tool_change(3, "T").unwrap();
    for k in 0..3 {
        w.block(&Block {
            line: None,
            number: None,
            arc: None,
            cl_line: None,
            motion: Motion::Feed,
            axes: &[k as f64, 1.0],
            feed: Some(100.0),
        })
        .unwrap();
    }
    let text = String::from_utf8(w.finish().unwrap()).unwrap();
    assert!(
        text.ends_with(
            "G54\nT1 M06\nG43 H1\nN10 T3 M06\nN20 G43 H3\nN30 G01 X0.000 Y1.000 F100.\nN40 X1.000\nN50 X2.000\n"
        ),
        "{text}"
    );
    let read = read_program(&dialect, &axes, "n", &text).unwrap();
    assert_eq!(
        read.iter().map(|b| b.number).collect::<Vec<_>>(),
        [Some(30), Some(40), Some(50)]
    );
}

/// LinuxCNC comments never nest and never start an active comment
/// (`(MSG,`, `(LOGOPEN,`, `(PY,` ...).
#[test]
fn linuxcnc_comments_are_passive() {
    let dialect = Dialect::builtin("linuxcnc").unwrap();
    let axes = [AxisSpec::linear("X")];
    let mut w = NcWriter::new(&dialect, &axes, Vec::new());
    w.comment("LOGOPEN,/tmp/x (a (b))").unwrap();
    w.comment("py, import os").unwrap();
    let text = String::from_utf8(w.finish().unwrap()).unwrap();
    assert_eq!(text, "(LOGOPEN;/tmp/x [a [b]])\n(py; import os)\n");
}

/// The Fanuc program number comes from `extra.program_number`.
#[test]
fn fanuc_program_number_from_extra() {
    let dialect = Dialect::builtin("fanuc").unwrap();
    let axes = [AxisSpec::linear("X")];
    let mut w = NcWriter::new(&dialect, &axes, Vec::new());
    let mut info = info();
    info.extra.insert("program_number".into(), "1234".into());
    w.header(&info, None).unwrap();
    let text = String::from_utf8(w.finish().unwrap()).unwrap();
    assert!(text.starts_with("%\nO1234 (DEMO [1])\n"), "{text}");
}

const FANUC: &str = "\
%
O0001 (DEMO [1])
(MACHINE: mts1600)
(TOOL: WHEEL)
(CL FILE: demo.cls)
(DATE: 2025-01-31)
(POSTED BY KINPOST, DIALECT fanuc)
G90 G17 G21 G40 G80 G94
G54
T1 M06
G43 H1
(TOOL PATH: ROUGH [A], FINISH)
T2 M06
G43 H2
S3000 M03
M08
G00 X459.000 Y8.807 Z361.368 A0.000 B0.000
G01 Z350.123 B-20.000 F250.
X460.500 A-12.346
Y0.000 F300.5
G00 Z380.000
M09
M05
M05
M09
G49
M30
%
";
const HEIDENHAIN: &str = "\
0 BEGIN PGM DEMO__1_ MM
1 * - MACHINE: mts1600
2 * - TOOL: WHEEL
3 * - CL FILE: demo.cls
4 * - DATE: 2025-01-31
5 * - POSTED BY KINPOST (DIALECT heidenhain)
6 TOOL CALL 1 Z
7 * - TOOL PATH: ROUGH (A), FINISH
8 TOOL CALL 2 Z
9 TOOL CALL 2 Z S3000
10 M3
11 M8
12 L X+459.000 Y+8.807 Z+361.368 A+0.000 B+0.000 R0 FMAX
13 L Z+350.123 B-20.000 R0 F250
14 L X+460.500 A-12.346 R0
15 L Y+0.000 R0 F300.5
16 L Z+380.000 R0 FMAX
17 M9
18 M5
19 M5
20 M9
21 M30
22 END PGM DEMO__1_ MM
";
const LINUXCNC: &str = "\
%
(PROGRAM: DEMO [1])
(MACHINE: mts1600)
(TOOL: WHEEL)
(CL FILE: demo.cls)
(DATE: 2025-01-31)
(POSTED BY KINPOST; DIALECT linuxcnc)
G21 G90 G40 G64 P0.01
G17 G54 G94
T1 M6
G43 H1
(TOOL PATH: ROUGH [A]; FINISH)
T2 M6
G43 H2
S3000 M3
M8
G0 X459.0000 Y8.8069 Z361.3684 A0.0000 B0.0000
G1 Z350.1234 B-20.0005 F250
X460.5000 A-12.3457
Y0.0000 F300.5
G0 Z380.0000
M9
M5
M5
M9
G49
M2
%
";
const SINUMERIK: &str = "\
; PROGRAM NAME: DEMO (1)
; MACHINE: mts1600
; TOOL: WHEEL
; CL FILE: demo.cls
; DATE: 2025-01-31
; POSTED BY KINPOST (DIALECT sinumerik)
G90 G71 G17 G64
T1
M6
G01
; TOOL PATH: ROUGH (A), FINISH
T2
M6
S3000 M03
M08
G0 X=459.000 Y=8.807 Z361.368 B0.000 A=DC(0.000)
G1 X=459.000 Y=8.807 Z350.123 B-20.000 A=DC(0.000) F250
X=460.500 Y=8.807 Z350.123 B-20.000 A=DC(347.654)
X=460.500 Y=0.000 Z350.123 B-20.000 A=DC(347.654) F300.5
X=460.500 Y=0.000 Z350.123 B-20.000 A=DC(347.654)
G0 X=460.500 Y=0.000 Z380.000 B-20.000 A=DC(347.654)
M09
M05
M05
M09
M30
";
const CSV: &str = "\
line,motion,X,A,Y,Z,B,C,feed
10,rapid,459.000000,0.000000,8.806940,361.368390,0.000000,0.000000,
11,feed,459.000000,0.000000,8.806940,350.123450,-20.000490,0.000000,250.000000
12,feed,460.500000,-12.345678,8.806940,350.123450,-20.000490,0.000000,250.000000
13,feed,460.500000,-12.345678,-0.000040,350.123450,-20.000490,0.000000,300.500000
14,feed,460.500000,-12.345678,0.000010,350.123450,-20.000490,0.000000,300.500000
15,rapid,460.500000,-12.345678,0.000000,380.000000,-20.000490,0.000000,
";
