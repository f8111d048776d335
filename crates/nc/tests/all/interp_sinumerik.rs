//! The Sinumerik interpreter on the program of Qiao et al. 2022, Figure
//! 28(b), exactly as printed, and on hand-written programs whose expected
//! axis values are worked out by hand in the comments (rules: SINUMERIK
//! 840D sl programming manuals "Fundamentals" and "Job planning", the
//! sections named in `crates/nc/src/interp/sinumerik.rs`).

use std::path::Path;

use kinpost_nc::AxisSpec;
use kinpost_nc::interp::{Event, Family, FeedMode, MotionKind, Options, Step, StopKind, read_all};

/// The MTS1600 belt grinder's axes in machine order (X A Y Z B C, C locked)
/// and its pressure word H1 (`crates/machine/machines/mts1600.toml`).
fn mts1600() -> Vec<AxisSpec> {
    vec![
        AxisSpec::linear("X"),
        AxisSpec::endless("A"),
        AxisSpec::linear("Y"),
        AxisSpec::linear("Z"),
        AxisSpec::rotary("B"),
        AxisSpec::rotary("C").fixed(),
        AxisSpec::pressure_word("H1"),
    ]
}

fn figure28b() -> String {
    let p =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/qiao2022/figure28b-verbatim.mpf");
    std::fs::read_to_string(p).unwrap()
}

/// (line, kind, X A Y Z B C H1, feed) of every move.
fn moves(steps: &[Step]) -> Vec<(usize, MotionKind, Vec<f64>, f64)> {
    steps
        .iter()
        .filter_map(|s| match &s.event {
            Event::Move(m) => Some((s.line, m.kind.clone(), m.axes().to_vec(), m.feed)),
            _ => None,
        })
        .collect()
}

#[test]
fn qiao_figure_28b_as_printed() {
    let (steps, report) = read_all(
        &figure28b(),
        Family::Sinumerik,
        &mts1600(),
        &Options::default(),
        "figure28b.mpf",
    )
    .unwrap_or_else(|e| panic!("{e}"));
    // Both inputs were assumed off, and the run says so.
    assert!(
        report.assumed.iter().any(|a| a.contains("$A_IN[5] = 0")),
        "{:?}",
        report.assumed
    );
    assert!(
        report.assumed.iter().any(|a| a.contains("$A_IN[6] = 0")),
        "{:?}",
        report.assumed
    );
    // U1030 (no U axis on the model) and M20 (the machine's own M function)
    // are warned about at their lines.
    let warned: Vec<(usize, usize)> = report.warnings.iter().map(|w| (w.line, w.column)).collect();
    assert_eq!(warned, [(11, 11), (14, 26)], "{:?}", report.warnings);

    // Hand-read from the figure: X A Y Z B C H1 after each move, feed.
    // The machine starts at 0 on every axis (Options::start).
    let want: Vec<(usize, [f64; 7], f64)> = vec![
        (5, [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0], 5000.0), // N130 G01 B0 F5000
        (9, [0.0, 0.0, 0.0, 640.0, 0.0, 0.0, 0.0], 15000.0), // N140 G01 Z640. F=R32 (R32=15000)
        (10, [0.0, 0.0, 0.0, 640.0, 0.0, 0.0, 0.0], 15000.0), // N150 B0 C0
        (13, [0.0, 0.0, 0.0, 640.0, 0.0, 0.0, 0.0], 15000.0), // N180 G01 B0 A=DC(0)
        (18, [459.0, 0.0, 8.807, 361.368, 0.0, 0.0, 3000.0], 4980.0),
        (19, [459.0, 0.0, 9.126, 359.765, 0.0, 0.0, 3000.0], 4980.0),
        (20, [459.0, 0.0, 9.651, 358.216, 0.0, 0.0, 3000.0], 4980.0),
        (21, [459.0, 0.0, 10.375, 356.750, 0.0, 0.0, 3000.0], 4980.0),
        (22, [459.0, 0.0, 11.283, 355.390, 0.0, 0.0, 3000.0], 4980.0),
        (23, [459.0, 0.0, 12.361, 354.161, 0.0, 0.0, 3000.0], 4980.0),
        (24, [459.0, 0.0, 13.591, 353.083, 0.0, 0.0, 3000.0], 4980.0),
        (25, [459.0, 0.0, 14.950, 352.175, 0.0, 0.0, 3000.0], 4980.0),
        (26, [459.0, 0.0, 16.417, 351.452, 0.0, 0.0, 3000.0], 4980.0),
        (27, [459.0, 0.0, 17.965, 350.926, 0.0, 0.0, 3000.0], 4980.0),
        (28, [459.0, 0.0, 19.568, 350.607, 0.0, 0.0, 3000.0], 4980.0),
    ];
    let got = moves(&steps);
    assert_eq!(got.len(), want.len(), "{got:?}");
    for ((line, kind, axes, feed), (wl, wa, wf)) in got.iter().zip(&want) {
        assert_eq!((*line, kind, *feed), (*wl, &MotionKind::Linear, *wf));
        assert_eq!(axes.as_slice(), wa.as_slice(), "line {line}");
    }
    // The rest of the block's commands, in order.
    let others: Vec<(usize, Event)> = steps
        .iter()
        .filter(|s| !matches!(s.event, Event::Move(_) | Event::Spindle { .. }))
        .map(|s| (s.line, s.event.clone()))
        .collect();
    assert!(others.contains(&(6, Event::ToolSelect { tool: 1 })));
    assert!(others.contains(&(7, Event::ToolChange { tool: 1 })));
    assert!(others.contains(&(
        14,
        Event::Pressure {
            axis: 6,
            value: 3000.0
        }
    )));
    assert!(others.contains(&(14, Event::MCode(20))));
    assert!(others.contains(&(
        15,
        Event::Coolant {
            mist: false,
            flood: true
        }
    )));
    assert!(others.contains(&(17, Event::Dwell { seconds: 3.0 })));
    let spindle: Vec<(usize, Event)> = steps
        .iter()
        .filter(|s| matches!(s.event, Event::Spindle { .. }))
        .map(|s| (s.line, s.event.clone()))
        .collect();
    use kinpost_nc::interp::SpindleDir::*;
    assert_eq!(
        spindle,
        [
            (
                8,
                Event::Spindle {
                    dir: Off,
                    speed: 3000.0
                }
            ),
            (
                14,
                Event::Spindle {
                    dir: Off,
                    speed: 3013.0
                }
            ),
            (
                16,
                Event::Spindle {
                    dir: Ccw,
                    speed: 3013.0
                }
            ),
        ]
    );
}

/// With `--input '$A_IN[5]=1'` the first line jumps forward to `wzw`,
/// which the printed excerpt does not contain: the controller's alarm
/// 14080, at line 2.
#[test]
fn qiao_figure_28b_takes_the_jump_on_input() {
    let mut options = Options::default();
    options.parse_input("$A_IN[5]=1").unwrap();
    let e = read_all(
        &figure28b(),
        Family::Sinumerik,
        &mts1600(),
        &options,
        "figure28b.mpf",
    )
    .unwrap_err();
    assert_eq!((e.line, e.column), (2, 21), "{e}");
    assert!(
        e.message.contains("GOTOF WZW") && e.message.contains("not found"),
        "{e}"
    );
    // The other input takes the second jump.
    let mut options = Options::default();
    options.parse_input("$a_in[6] = 1").unwrap();
    let e = read_all(
        &figure28b(),
        Family::Sinumerik,
        &mts1600(),
        &options,
        "figure28b.mpf",
    )
    .unwrap_err();
    assert_eq!(e.line, 3, "{e}");
    assert!(e.message.contains("GRST"), "{e}");
}

fn xyzac() -> Vec<AxisSpec> {
    vec![
        AxisSpec::linear("X"),
        AxisSpec::linear("Y"),
        AxisSpec::linear("Z"),
        AxisSpec::rotary("A"),
        AxisSpec::endless("C"),
    ]
}

fn run(text: &str) -> Vec<(usize, MotionKind, Vec<f64>, f64)> {
    let (steps, _) = read_all(
        text,
        Family::Sinumerik,
        &xyzac(),
        &Options::default(),
        "t.mpf",
    )
    .unwrap_or_else(|e| panic!("{e}"));
    moves(&steps)
}

fn ends(text: &str) -> Vec<Vec<f64>> {
    run(text).into_iter().map(|m| m.2).collect()
}

fn close(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-9)
}

/// Arithmetic, R parameters, DEF variables, functions ("Job planning",
/// "Arithmetic functions", "Priority of operators").
#[test]
fn arithmetic_and_variables() {
    let got = ends(
        "DEF REAL LEN=10, W\nDEF INT N=7\nR1=2 R2=R1*3+1\nW=LEN/4\n\
         G0 X=R2 Y=W Z=N DIV 2\n\
         G0 X=SQRT(16)+ABS(-1) Y=POT(3) Z=TRUNC(2.7)+ROUND(2.5)\n\
         G0 X=7 MOD 4 Y=SIN(30)*2 Z=ATAN2(1,1)\n\
         G0 X=(1==1)+(2>1) Y=(1 AND 0)+(0 OR 1)+(NOT 0)+(1 XOR 1) Z=R[1]\n\
         N=2.6\nG0 X=N\nM30\n",
    );
    // R2 = 2·3+1 = 7; W = 2.5; 7 DIV 2 = 3
    // √16+|−1| = 5; 3² = 9; trunc 2.7 + round 2.5 = 2 + 3 = 5
    // 7 mod 4 = 3; 2·sin 30° = 1; atan2(1,1) = 45
    // 1+1 = 2; 0+1+1+0 = 2; R1 = 2
    // INT N = round(2.6) = 3
    let want = [
        [7.0, 2.5, 3.0, 0.0, 0.0],
        [5.0, 9.0, 5.0, 0.0, 0.0],
        [3.0, 1.0, 45.0, 0.0, 0.0],
        [2.0, 2.0, 2.0, 0.0, 0.0],
        [3.0, 2.0, 2.0, 0.0, 0.0],
    ];
    assert_eq!(got.len(), want.len(), "{got:?}");
    for (g, w) in got.iter().zip(&want) {
        assert!(close(g, w), "{g:?} != {w:?}");
    }
}

/// Jumps and structured loops ("Job planning", "Program jumps" and
/// "Control structures").
#[test]
fn control_flow() {
    let got = ends(
        "DEF INT I\nR1=0\nG0 X0\n\
         START: R1=R1+1\nIF R1<3 GOTOB START\nG0 X=R1\n\
         IF R1==3\n  G0 Y1\nELSE\n  G0 Y2\nENDIF\n\
         IF R1>5\n  G0 Y3\nELSE\n  G0 Y4\nENDIF\n\
         WHILE R1<5\n  R1=R1+1\nENDWHILE\nG0 Z=R1\n\
         FOR I=1 TO 3\n  G0 X=I*10\nENDFOR\n\
         REPEAT\n  R1=R1-2\nUNTIL R1<0\nG0 Z=R1\n\
         R2=0\nLOOP\n  R2=R2+1\n  IF R2==2 GOTOF OUT\nENDLOOP\nOUT: G0 Y=R2\n\
         GOTOF N90\nG0 X99\nN90 G0 X-1\nM30\n",
    );
    // R1 counts to 3 by the backward jump: X3; R1 == 3 → Y1; not > 5 → Y4;
    // WHILE to 5 → Z5; FOR → X10, X20, X30; REPEAT 5 → 3 → 1 → −1 → Z−1;
    // LOOP leaves at R2 = 2 → Y2; GOTOF N90 skips X99 → X−1.
    let want: [[f64; 5]; 11] = [
        [0.0, 0.0, 0.0, 0.0, 0.0],
        [3.0, 0.0, 0.0, 0.0, 0.0],
        [3.0, 1.0, 0.0, 0.0, 0.0],
        [3.0, 4.0, 0.0, 0.0, 0.0],
        [3.0, 4.0, 5.0, 0.0, 0.0],
        [10.0, 4.0, 5.0, 0.0, 0.0],
        [20.0, 4.0, 5.0, 0.0, 0.0],
        [30.0, 4.0, 5.0, 0.0, 0.0],
        [30.0, 4.0, -1.0, 0.0, 0.0],
        [30.0, 2.0, -1.0, 0.0, 0.0],
        [-1.0, 2.0, -1.0, 0.0, 0.0],
    ];
    assert_eq!(got.len(), want.len(), "{got:?}");
    for (g, w) in got.iter().zip(&want) {
        assert!(close(g, w), "{g:?} != {w:?}");
    }
}

/// Incremental and rotary positioning ("Fundamentals", "Absolute and
/// incremental dimensions", "Absolute dimensions for rotary axes (DC, ACP,
/// ACN)"); C is endless (a modulo axis), A is a tilting axis.
#[test]
fn incremental_and_rotary_words() {
    let (steps, _) = read_all(
        "G90 G0 X10 C350\nG0 X=IC(5) C=DC(10)\nG91 G0 X5 Y=AC(2)\nG90\nC=ACN(20)\nC=ACP(10)\nA=DC(-30)\nA=DC(320)\nG0 C=IC(-725)\nM30\n",
        Family::Sinumerik,
        &xyzac(),
        &Options::default(),
        "r.mpf",
    )
    .unwrap();
    let got: Vec<(Vec<f64>, f64, f64)> = steps
        .iter()
        .filter_map(|s| match &s.event {
            Event::Move(m) => Some((m.axes().to_vec(), m.travel[3], m.travel[4])),
            _ => None,
        })
        .collect();
    // C350 (from 0: directly, +350); DC(10) from 350: +20 the short way;
    // G91 X+5 → 20, Y=AC(2) absolute; ACN(20) from 10: −350; ACP(10) from
    // 20: +350; A=DC(-30) (a tilting axis): −30 from 0 → −30; A=DC(320)
    // from −30 (= 330): −10 → −40; C=IC(−725) from 10: −725 turns, ends at
    // 10 − 725 + 720 = 5.
    let want = [
        ([10.0, 0.0, 0.0, 0.0, 350.0], 0.0, 350.0),
        ([15.0, 0.0, 0.0, 0.0, 10.0], 0.0, 20.0),
        ([20.0, 2.0, 0.0, 0.0, 10.0], 0.0, 0.0),
        ([20.0, 2.0, 0.0, 0.0, 20.0], 0.0, -350.0),
        ([20.0, 2.0, 0.0, 0.0, 10.0], 0.0, 350.0),
        ([20.0, 2.0, 0.0, -30.0, 10.0], -30.0, 0.0),
        ([20.0, 2.0, 0.0, -40.0, 10.0], -10.0, 0.0),
        ([20.0, 2.0, 0.0, -40.0, 5.0], 0.0, -725.0),
    ];
    assert_eq!(got.len(), want.len(), "{got:?}");
    for (g, w) in got.iter().zip(&want) {
        assert!(
            close(&g.0, &w.0) && (g.1 - w.1).abs() < 1e-9 && (g.2 - w.2).abs() < 1e-9,
            "{g:?} != {w:?}"
        );
    }
}

/// Circles: I/J/K centre (incremental), CR= radius (negative: more than a
/// half circle), TURN= full turns, CIP through a point, CT tangential, in
/// G17 and G18 ("Fundamentals", "Circular interpolation").
#[test]
fn circles() {
    let got = run(
        "G17 G90 G0 X0 Y0 Z0\nF100\nG2 X10 Y0 I5 J0\nG3 X0 Y0 CR=5\nG2 X10 Y0 CR=-5\n\
         G3 X10 Y0 I-5 J0 Z-6 TURN=2\nG1 X20\nCIP X30 Y10 I1=25 J1=5+5*SQRT(0.5)-5\n\
         G1 X30 Y20\nCT X40 Y30\nG18 G2 X50 Z-16 K-5 I5\nM30\n",
    );
    let arcs: Vec<(usize, [f64; 3], bool, f64)> = got
        .iter()
        .filter_map(|(line, k, _, _)| match k {
            MotionKind::Arc(a) => Some((*line, a.centre_mm, a.clockwise, a.sweep_deg)),
            _ => None,
        })
        .collect();
    // Line 3: centre (5, 0), CW from (0,0) to (10,0): 180°.
    // Line 4: CR=5 from (10,0) back to (0,0) CCW: centre (5,0), 180°.
    // Line 5: CR=−5 (exactly a half circle either way): 180°.
    // Line 6: full circle about (5,0) plus 2 turns, helix to Z−6: 1080°.
    let expect = [
        (3, [5.0, 0.0, 0.0], true, 180.0),
        (4, [5.0, 0.0, 0.0], false, 180.0),
        (5, [5.0, 0.0, 0.0], true, 180.0),
        (6, [5.0, 0.0, 0.0], false, 1080.0),
    ];
    for (g, w) in arcs.iter().zip(&expect) {
        assert_eq!(g.0, w.0);
        assert!(
            close(&g.1, &w.1) && g.2 == w.2 && (g.3 - w.3).abs() < 1e-9,
            "{g:?} != {w:?}"
        );
    }
    // CIP through (20,0), (25, 5√½) and (30,10): the centre is as far from
    // each of the three points.
    let cip = arcs.iter().find(|a| a.0 == 8).unwrap();
    let pts = [[20.0, 0.0], [25.0, 5.0 * 0.5f64.sqrt()], [30.0, 10.0]];
    let r: Vec<f64> = pts
        .iter()
        .map(|p| (p[0] - cip.1[0]).hypot(p[1] - cip.1[1]))
        .collect();
    assert!(
        (r[0] - r[1]).abs() < 1e-9 && (r[0] - r[2]).abs() < 1e-9,
        "{cip:?} {r:?}"
    );
    // Going (20,0) → (25,3.54) → (30,10) turns left: counter-clockwise.
    assert!(!cip.2);
    // CT from (30,20), arriving there along +Y, to (40,30): centre (40,20),
    // clockwise, a quarter circle (at Z−6).
    let ct = arcs.iter().find(|a| a.0 == 10).unwrap();
    assert!(
        close(&ct.1, &[40.0, 20.0, -6.0]) && ct.2 && (ct.3 - 90.0).abs() < 1e-9,
        "{ct:?}"
    );
    // G18 from (X40, Z−6) (the helix left Z at −6) about (X45, Z−11)
    // (I5 K−5) to (X50, Z−16), at Y30: clockwise, half a circle.
    let g18 = arcs.iter().find(|a| a.0 == 11).unwrap();
    assert!(
        close(&g18.1, &[45.0, 30.0, -11.0]) && g18.2 && (g18.3 - 180.0).abs() < 1e-9,
        "{g18:?}"
    );
}

#[test]
fn cycles_and_mcall() {
    let (steps, _) = read_all(
        "G17 G90 G0 X0 Y0 Z50 F200 S1000 M3\nMCALL CYCLE81(10, 0, 2, -15)\nG0 X10 Y10\nX20\nMCALL\nX30\n\
         CYCLE82(10, 0, 2, , 5, 1.5)\nM30\n",
        Family::Sinumerik,
        &xyzac(),
        &Options::default(),
        "c.mpf",
    )
    .unwrap();
    let got: Vec<(usize, char, [f64; 3])> = steps
        .iter()
        .filter_map(|s| match &s.event {
            Event::Move(m) => Some((
                s.line,
                if m.kind == MotionKind::Rapid {
                    'R'
                } else {
                    'F'
                },
                [m.axes()[0], m.axes()[1], m.axes()[2]],
            )),
            Event::Dwell { seconds } => Some((s.line, 'D', [*seconds, 0.0, 0.0])),
            _ => None,
        })
        .collect();
    // CYCLE81(RTP=10, RFP=0, SDIS=2, DP=−15): at each position G0 to
    // RFP+SDIS = 2, G1 to −15, G0 to RTP = 10. CYCLE82 with DPR=5: depth
    // 0 − 5 = −5, dwell 1.5 s.
    let want = vec![
        (1, 'R', [0.0, 0.0, 50.0]),
        (3, 'R', [10.0, 10.0, 50.0]),
        (3, 'R', [10.0, 10.0, 2.0]),
        (3, 'F', [10.0, 10.0, -15.0]),
        (3, 'R', [10.0, 10.0, 10.0]),
        (4, 'R', [20.0, 10.0, 10.0]),
        (4, 'R', [20.0, 10.0, 2.0]),
        (4, 'F', [20.0, 10.0, -15.0]),
        (4, 'R', [20.0, 10.0, 10.0]),
        (6, 'R', [30.0, 10.0, 10.0]),
        (7, 'R', [30.0, 10.0, 2.0]),
        (7, 'F', [30.0, 10.0, -5.0]),
        (7, 'D', [1.5, 0.0, 0.0]),
        (7, 'R', [30.0, 10.0, 10.0]),
    ];
    assert_eq!(got, want);
}

/// Inch (G70), tool-centre-point on/off, messages, dwell, end.
#[test]
fn units_tcp_messages() {
    let (steps, report) = read_all(
        "G70 G0 X1 Y2\nG71 G0 X1\nTRAORI\nMSG(\"ROUGH \" << 2 << \" OF \" << 3)\nG1 Z=-2.5 F=1000/2\nG93 G1 X2 F4\nTRAFOOF\nM30\nG0 X99\n",
        Family::Sinumerik,
        &xyzac(),
        &Options::default(),
        "u.mpf",
    )
    .unwrap();
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);
    let got = moves(&steps);
    assert!(close(&got[0].2, &[25.4, 50.8, 0.0, 0.0, 0.0]));
    assert!(close(&got[1].2, &[1.0, 50.8, 0.0, 0.0, 0.0]));
    assert_eq!(got[2].3, 500.0);
    assert_eq!(got.len(), 4, "M30 ends the program: X99 is never reached");
    let events: Vec<&Event> = steps.iter().map(|s| &s.event).collect();
    assert!(events.contains(&&Event::Tcp(true)) && events.contains(&&Event::Tcp(false)));
    assert!(events.contains(&&Event::Message("ROUGH 2 OF 3".into())));
    assert!(events.contains(&&Event::Stop(StopKind::End)));
    assert!(events.contains(&&Event::FeedMode(FeedMode::InverseTime)));
    // G4 S30 without a spindle speed is an error; with S1000: 30 rev = 1.8 s.
    let e = read_all(
        "G4 S30\n",
        Family::Sinumerik,
        &xyzac(),
        &Options::default(),
        "d.mpf",
    )
    .unwrap_err();
    assert_eq!(e.line, 1);
    let (steps, _) = read_all(
        "S1000 M3\nG4 S30\n",
        Family::Sinumerik,
        &xyzac(),
        &Options::default(),
        "d.mpf",
    )
    .unwrap();
    assert!(
        steps
            .iter()
            .any(|s| matches!(s.event, Event::Dwell { seconds } if (seconds - 1.8).abs() < 1e-12))
    );
}

/// Errors name the line and column.
#[test]
fn errors_are_located() {
    for (text, line, col, what) in [
        ("G0 X10\nG1 Q=5 X1\n", 2, 4, "Q"),
        ("IF R1==0 GOTOF NOWHERE\n", 1, 10, "NOWHERE"),
        ("G0 X=$P_TOOLR\n", 1, 6, "$P_TOOLR"),
        ("WHILE 1\nG0 X1\n", 1, 1, "ENDWHILE"),
        ("G0 X=1/0\n", 1, 7, "division"),
        ("G2 X10 Y0 CR=1 F10\n", 1, 4, "too small"),
        ("L100\n", 1, 1, "subprogram"),
        ("G0 A=DC(5) X=DC(1)\n", 1, 4, "linear"),
    ] {
        let e = read_all(
            text,
            Family::Sinumerik,
            &xyzac(),
            &Options::default(),
            "e.mpf",
        )
        .unwrap_err();
        assert_eq!((e.line, e.column), (line, col), "{text:?}: {e}");
        assert!(e.message.contains(what), "{text:?}: {e}");
    }
    // An endless loop ends at the limit.
    let options = Options {
        max_executed_blocks: 10_000,
        ..Options::default()
    };
    let e = read_all(
        "LOOP\nG0 X1\nENDLOOP\n",
        Family::Sinumerik,
        &xyzac(),
        &options,
        "l.mpf",
    )
    .unwrap_err();
    assert!(e.message.contains("10000 blocks"), "{e}");
}
