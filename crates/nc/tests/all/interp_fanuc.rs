//! Fanuc programs written by hand from the rules of the Fanuc 0i-MF
//! operator's manual (B-64604EN): "Decimal point programming", "Custom
//! macro" (variables, vacant #0, arithmetic, GOTO, IF, WHILE … DO / END,
//! G65 macro call with argument specification I), "Subprogram" (M98/M99),
//! "Canned cycle for drilling" (G81, G83, G98/G99, repetition K),
//! "Programmable data input" (G10 L2), "Tool center point control" (G43.4).
//! Each expected value is worked out by hand in the comments.

use kinpost_nc::AxisSpec;
use kinpost_nc::interp::{Event, Family, MotionKind, Options, Step, read_all};

fn axes() -> Vec<AxisSpec> {
    vec![
        AxisSpec::linear("X"),
        AxisSpec::linear("Y"),
        AxisSpec::linear("Z"),
        AxisSpec::rotary("A"),
        AxisSpec::rotary("C"),
    ]
}

fn steps(text: &str, options: &Options) -> Vec<Step> {
    read_all(text, Family::Fanuc, &axes(), options, "f.nc")
        .unwrap_or_else(|e| panic!("{e}"))
        .0
}

/// (line, 'R'/'F'/'A', X Y Z) of every move.
fn xyz(steps: &[Step]) -> Vec<(usize, char, [f64; 3])> {
    steps
        .iter()
        .filter_map(|s| match &s.event {
            Event::Move(m) => Some((
                s.line,
                match m.kind {
                    MotionKind::Rapid => 'R',
                    MotionKind::Linear => 'F',
                    MotionKind::Arc(_) => 'A',
                },
                [m.axes()[0], m.axes()[1], m.axes()[2]],
            )),
            _ => None,
        })
        .collect()
}

fn assert_moves(got: &[(usize, char, [f64; 3])], want: &[(usize, char, [f64; 3])]) {
    assert_eq!(got.len(), want.len(), "{got:?}");
    for (g, w) in got.iter().zip(want) {
        assert!(
            g.0 == w.0 && g.1 == w.1 && g.2.iter().zip(&w.2).all(|(a, b)| (a - b).abs() < 1e-9),
            "{g:?} != {w:?}"
        );
    }
}

/// "Decimal point programming": without a point an address of a length is
/// in least input increments (0.001 mm, 0.0001 inch); a variable's value
/// is taken as it is; F is in mm/min either way.
#[test]
fn decimal_point_rules() {
    let s = steps(
        "%\nO0001\nG21 G90 G00 X1 Y1. Z1.5\n#1=10\nG01 X#1 F100\nG20 G00 Y1\nG21 G04 P1500\nG04 X2.\nM30\n%\n",
        &Options::default(),
    );
    // X1 → 0.001 mm, Y1. → 1 mm, Z1.5 → 1.5 mm; X#1 → 10 mm;
    // G20 Y1 → 0.0001 inch = 0.00254 mm.
    assert_moves(
        &xyz(&s),
        &[
            (3, 'R', [0.001, 1.0, 1.5]),
            (5, 'F', [10.0, 1.0, 1.5]),
            (6, 'R', [10.0, 0.00254, 1.5]),
        ],
    );
    let feed = s.iter().find_map(|s| match &s.event {
        Event::Move(m) if s.line == 5 => Some(m.feed),
        _ => None,
    });
    assert_eq!(feed, Some(100.0));
    // P1500 → 1.5 s; X2. → 2 s.
    let dwells: Vec<f64> = s
        .iter()
        .filter_map(|s| match s.event {
            Event::Dwell { seconds } => Some(seconds),
            _ => None,
        })
        .collect();
    assert_eq!(dwells, [1.5, 2.0]);
    // With the calculator-type input parameter (DPI) X1 is 1 mm.
    let options = Options {
        fanuc_calculator_input: true,
        ..Options::default()
    };
    assert_moves(
        &xyz(&steps("G00 X1\nM30\n", &options)),
        &[(1, 'R', [1.0, 0.0, 0.0])],
    );
}

/// Variables, vacant #0, IF … GOTO, IF … THEN, WHILE … DO / END.
#[test]
fn macro_statements() {
    let s = steps(
        "G90 G00 X0\n#3=#0\n#4=#3+5.\nG00 X#3 Y#4\nIF [#3 EQ #0] GOTO 100\nG00 X99.\nN100 IF [#4 GT 4.] THEN #5=2.\n\
         #1=1.\nWHILE [#1 LE 3.] DO 1\nG01 X[#1*10.] F200.\n#1=#1+1.\nEND 1\n\
         G00 Z[#5*[3+1]] X[SQRT[16.]+ABS[-1.]] Y[FIX[2.7]+FUP[2.2]]\n\
         G00 X[ROUND[2.5]] Y[10 MOD 4] Z[[6 AND 3]+[4 OR 1]]\nM30\n",
        &Options::default(),
    );
    // #3 vacant: X#3 is left out; #4 = vacant + 5 = 5 → Y5.
    // #3 EQ #0 holds: the jump skips X99.
    // #4 = 5 > 4: #5 = 2. The loop moves X10, X20, X30.
    // Z = 2·4 = 8, X = 4 + 1 = 5, Y = 2 + 3 = 5.
    // ROUND 2.5 = 3; 10 MOD 4 = 2; 6 AND 3 = 2, 4 OR 1 = 5 → 7.
    assert_moves(
        &xyz(&s),
        &[
            (1, 'R', [0.0, 0.0, 0.0]),
            (4, 'R', [0.0, 5.0, 0.0]),
            (10, 'F', [10.0, 5.0, 0.0]),
            (10, 'F', [20.0, 5.0, 0.0]),
            (10, 'F', [30.0, 5.0, 0.0]),
            (13, 'R', [5.0, 5.0, 8.0]),
            (14, 'R', [3.0, 2.0, 7.0]),
        ],
    );
}

/// G65 macro call with arguments (A → #1, B → #2, X → #24), its own local
/// variables, M99 back; M98 with L repeats.
#[test]
fn macro_and_subprogram_calls() {
    let s = steps(
        "O0001\n#1=100.\nG90 G00 X0 Y0\nG65 P9010 A1. B2. X5.\nG00 Y#1\nM98 P1000 L2\nM30\n\
         O9010\nG01 X[#1+#2+#24] F100.\n#1=7.\nM99\n\
         O1000\nG91 G00 Z1.\nG90\nM99\n",
        &Options::default(),
    );
    // The macro moves X to 1 + 2 + 5 = 8; its #1 = 7 is its own: back in
    // the main program #1 is still 100. M98 L2 raises Z by 1 twice.
    assert_moves(
        &xyz(&s),
        &[
            (3, 'R', [0.0, 0.0, 0.0]),
            (9, 'F', [8.0, 0.0, 0.0]),
            (5, 'R', [8.0, 100.0, 0.0]),
            (13, 'R', [8.0, 100.0, 1.0]),
            (13, 'R', [8.0, 100.0, 2.0]),
        ],
    );
}

/// G81 with G98 / G99, repeated with K in G91; G83 with its clearance.
#[test]
fn drilling_cycles() {
    let s = steps(
        "G90 G17 G00 X0 Y0 Z20.\nF100.\nG99 G81 X10. Y10. Z-5. R2.\nG98 X20.\nG80\n\
         G91 G99 G81 X5. Z-7. R-18. K2\nG90 G80\nG00 Z10.\nG98 G83 X50. Y0 Z-6. R1. Q2.5\nG80\nM30\n",
        &Options {
            fanuc_peck_clearance_mm: Some(0.5),
            ..Options::default()
        },
    );
    // Line 3 (G99): rapid to (10,10) at the initial level 20, down to R 2,
    // feed to −5, back to R 2. Line 4 (G98): to (20,10) at the level it is
    // at (the R plane), feed to −5, back to the initial level 20.
    // Line 6, G91: R = initial 20 − 18 = 2, bottom = 2 − 7 = −5; two holes
    // 5 apart from X20: X25, X30; G99 back to R.
    // Line 9, G83 from Z10: R 1, pecks of 2.5 from 1: −1.5, then back to R,
    // down to −1.5 + 0.5 = −1, feed −4, back to R, down to −3.5, feed −6;
    // G98: back to the initial level 10.
    assert_moves(
        &xyz(&s),
        &[
            (1, 'R', [0.0, 0.0, 20.0]),
            (3, 'R', [10.0, 10.0, 20.0]),
            (3, 'R', [10.0, 10.0, 2.0]),
            (3, 'F', [10.0, 10.0, -5.0]),
            (3, 'R', [10.0, 10.0, 2.0]),
            (4, 'R', [20.0, 10.0, 2.0]),
            (4, 'F', [20.0, 10.0, -5.0]),
            (4, 'R', [20.0, 10.0, 20.0]),
            (6, 'R', [25.0, 10.0, 20.0]),
            (6, 'R', [25.0, 10.0, 2.0]),
            (6, 'F', [25.0, 10.0, -5.0]),
            (6, 'R', [25.0, 10.0, 2.0]),
            (6, 'R', [30.0, 10.0, 2.0]),
            (6, 'F', [30.0, 10.0, -5.0]),
            (6, 'R', [30.0, 10.0, 2.0]),
            (8, 'R', [30.0, 10.0, 10.0]),
            (9, 'R', [50.0, 0.0, 10.0]),
            (9, 'R', [50.0, 0.0, 1.0]),
            (9, 'F', [50.0, 0.0, -1.5]),
            (9, 'R', [50.0, 0.0, 1.0]),
            (9, 'R', [50.0, 0.0, -1.0]),
            (9, 'F', [50.0, 0.0, -4.0]),
            (9, 'R', [50.0, 0.0, 1.0]),
            (9, 'R', [50.0, 0.0, -3.5]),
            (9, 'F', [50.0, 0.0, -6.0]),
            (9, 'R', [50.0, 0.0, 10.0]),
        ],
    );
}

/// Arcs: R < 0 for more than half a circle; G18 with I/K.
#[test]
fn arcs() {
    let s = steps(
        "G90 G17 G00 X0 Y0 Z0\nG02 X10. Y10. R-10. F100.\nG18 G03 X0 Z10. I-10. K0\nM30\n",
        &Options::default(),
    );
    let arcs: Vec<([f64; 3], bool, f64)> = s
        .iter()
        .filter_map(|s| match &s.event {
            Event::Move(m) => match &m.kind {
                MotionKind::Arc(a) => Some((a.centre_mm, a.clockwise, a.sweep_deg)),
                _ => None,
            },
            _ => None,
        })
        .collect();
    // (0,0) → (10,10) clockwise with R−10: the short clockwise arc has its
    // centre right of the chord, at (10, 0); R < 0 takes the other one,
    // (0, 10), and the long way: from −90° down to 0° − 360°, 270°.
    assert!(
        arcs[0].0[0].abs() < 1e-9 && (arcs[0].0[1] - 10.0).abs() < 1e-9 && arcs[0].1,
        "{arcs:?}"
    );
    assert!((arcs[0].2 - 270.0).abs() < 1e-9);
    // G18 from (X10, Z0) about (X0, Z0) to (X0, Z10), counter-clockwise
    // seen from +Y (Z → X): from angle atan2(x=10, z=0) = 90° to
    // atan2(0, 10) = 0°, CCW: 270°.
    assert!(
        arcs[1].0[0].abs() < 1e-9 && arcs[1].0[2].abs() < 1e-9 && !arcs[1].1,
        "{arcs:?}"
    );
    assert!((arcs[1].2 - 270.0).abs() < 1e-9, "{arcs:?}");
}

/// G10 L2 sets G54; G53 moves in machine coordinates; G43.4 / G49.
#[test]
fn offsets_and_tcp() {
    let s = steps(
        "G10 L2 P1 X100. Y50.\nG90 G54 G00 X0 Y0\nG53 G00 X0\nG43.4 H1\nG01 X10. F100.\nG49\nM30\n",
        &Options::default(),
    );
    // In G54 (X100 Y50), X0 is machine 100; G53 X0 is machine 0 = work −100.
    assert_moves(
        &xyz(&s),
        &[
            (2, 'R', [0.0, 0.0, 0.0]),
            (3, 'R', [-100.0, 0.0, 0.0]),
            (5, 'F', [10.0, 0.0, 0.0]),
        ],
    );
    let tcp: Vec<bool> = s
        .iter()
        .filter_map(|s| match &s.event {
            Event::Move(m) => Some(m.state.tcp),
            _ => None,
        })
        .collect();
    assert_eq!(tcp, [false, false, true]);
    let off = s.iter().find_map(|s| match &s.event {
        Event::Move(m) => Some(m.state.offset[0]),
        _ => None,
    });
    assert_eq!(off, Some(100.0));
}

#[test]
fn errors() {
    for (text, line, what) in [
        ("G68.2 X0 Y0 Z0 I0 J45. K0\n", 1, "G68.2"),
        ("GOTO 55\n", 1, "N55"),
        ("WHILE [1 EQ 1] DO 1\nG00 X1.\n", 1, "END 1"),
        ("G65 P9999\n", 1, "O9999"),
        ("#1=1/0\n", 1, "division"),
        ("G01 X10.\n", 1, "feed"),
        ("G02 X10. Y0 R2. F10.\n", 1, "too small"),
        ("G00 X1. X2.\n", 1, "two X"),
        ("G00 G01 X1.\n", 1, "same modal group"),
    ] {
        let e = read_all(text, Family::Fanuc, &axes(), &Options::default(), "e.nc").unwrap_err();
        assert_eq!(e.line, line, "{text:?}: {e}");
        assert!(e.message.contains(what), "{text:?}: {e}");
    }
    // M99 at the end of a main program starts it again: the block limit ends it.
    let options = Options {
        max_executed_blocks: 1000,
        ..Options::default()
    };
    let e = read_all("G00 X1.\nM99\n", Family::Fanuc, &axes(), &options, "e.nc").unwrap_err();
    assert!(e.message.contains("1000 blocks"), "{e}");
    // An M-code of the machine is a warning with its line, and passes on.
    let (s, report) = read_all(
        "M50\nM30\n",
        Family::Fanuc,
        &axes(),
        &Options::default(),
        "w.nc",
    )
    .unwrap();
    assert_eq!(report.warnings.len(), 1);
    assert_eq!(report.warnings[0].line, 1);
    assert!(s.iter().any(|s| s.event == Event::MCode(50)));
}
