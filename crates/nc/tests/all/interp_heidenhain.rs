//! Heidenhain conversational programs written by hand from the rules of
//! the TNC 640 user's manual (conversational programming): "Path
//! contours — Cartesian coordinates" (L, CC, C, CR), "Path contours —
//! polar coordinates" (LP, CP with IPA and IZ), "Subprograms and program
//! section repeats", "Q parameters" (FN 0 … FN 13, formulas), "FUNCTION
//! TCPM"; and the cycle programming manual, "DRILLING (Cycle 200)". Every
//! expected value is worked out by hand in the comments.

use kinpost_nc::AxisSpec;
use kinpost_nc::interp::{
    CutterComp, Event, Family, MotionKind, Options, Step, StopKind, read_all,
};

fn axes() -> Vec<AxisSpec> {
    vec![
        AxisSpec::linear("X"),
        AxisSpec::linear("Y"),
        AxisSpec::linear("Z"),
        AxisSpec::rotary("B"),
        AxisSpec::endless("C"),
    ]
}

fn steps(text: &str) -> Vec<Step> {
    read_all(
        text,
        Family::Heidenhain,
        &axes(),
        &Options::default(),
        "h.h",
    )
    .unwrap_or_else(|e| panic!("{e}"))
    .0
}

/// (line, kind, X Y Z, arc centre, arc clockwise, sweep) of every move.
type M = (usize, char, [f64; 3], Option<([f64; 3], bool, f64)>);

fn moves(s: &[Step]) -> Vec<M> {
    s.iter()
        .filter_map(|s| match &s.event {
            Event::Move(m) => {
                let (k, arc) = match &m.kind {
                    MotionKind::Rapid => ('R', None),
                    MotionKind::Linear => ('F', None),
                    MotionKind::Arc(a) => ('A', Some((a.centre_mm, a.clockwise, a.sweep_deg))),
                };
                Some((s.line, k, [m.axes()[0], m.axes()[1], m.axes()[2]], arc))
            }
            _ => None,
        })
        .collect()
}

fn near(a: &[f64], b: &[f64]) -> bool {
    a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-9)
}

fn check(got: &[M], want: &[M]) {
    assert_eq!(got.len(), want.len(), "{got:#?}");
    for (g, w) in got.iter().zip(want) {
        let arc_ok = match (g.3, w.3) {
            (Some(a), Some(b)) => near(&a.0, &b.0) && a.1 == b.1 && (a.2 - b.2).abs() < 1e-9,
            (None, None) => true,
            _ => false,
        };
        assert!(
            g.0 == w.0 && g.1 == w.1 && near(&g.2, &w.2) && arc_ok,
            "{g:?} != {w:?}"
        );
    }
}

#[test]
fn contours() {
    let s = steps(
        "0 BEGIN PGM T1 MM\n1 BLK FORM 0.1 Z X+0 Y+0 Z-20\n2 BLK FORM 0.2 X+100 Y+100 Z+0\n3 TOOL CALL 1 Z S2000\n\
         4 L Z+50 R0 FMAX M3\n5 L X+10 Y+0 R0 FMAX\n6 L Z-5 F200\n7 L IX+10 RL\n8 CC X+20 Y+10\n9 C X+30 Y+10 DR+\n\
         10 CR X+40 Y+20 R+10 DR-\n11 CC X+0 Y+0\n12 LP PR+10 PA+90 R0\n13 CP IPA+90 DR+\n14 CP IPA+720 IZ-2 DR+\n\
         15 L Z+50 FMAX M5\n16 END PGM T1 MM\n",
    );
    check(
        &moves(&s),
        &[
            (5, 'R', [0.0, 0.0, 50.0], None),
            (6, 'R', [10.0, 0.0, 50.0], None),
            (7, 'F', [10.0, 0.0, -5.0], None),
            // IX+10 from X10.
            (8, 'F', [20.0, 0.0, -5.0], None),
            // About CC (20,10) from (20,0) to (30,10), DR+ (counter-
            // clockwise): from −90° to 0°, 90°.
            (
                10,
                'A',
                [30.0, 10.0, -5.0],
                Some(([20.0, 10.0, -5.0], false, 90.0)),
            ),
            // CR R+10 DR− from (30,10) to (40,20): the short clockwise arc,
            // centre right of the chord: (40,10), 90°.
            (
                11,
                'A',
                [40.0, 20.0, -5.0],
                Some(([40.0, 10.0, -5.0], true, 90.0)),
            ),
            // LP PR+10 PA+90 about CC (0,0): (0,10).
            (13, 'F', [0.0, 10.0, -5.0], None),
            // CP IPA+90 DR+: to 180°, (−10, 0).
            (
                14,
                'A',
                [-10.0, 0.0, -5.0],
                Some(([0.0, 0.0, -5.0], false, 90.0)),
            ),
            // CP IPA+720 IZ−2: two full turns down 2 mm.
            (
                15,
                'A',
                [-10.0, 0.0, -7.0],
                Some(([0.0, 0.0, -5.0], false, 720.0)),
            ),
            (16, 'R', [-10.0, 0.0, 50.0], None),
        ],
    );
    let ev: Vec<(usize, &Event)> = s.iter().map(|s| (s.line, &s.event)).collect();
    assert!(ev.contains(&(
        3,
        &Event::BlankForm {
            min_mm: [0.0, 0.0, -20.0],
            max_mm: [100.0, 100.0, 0.0]
        }
    )));
    assert!(ev.contains(&(4, &Event::ToolChange { tool: 1 })));
    assert!(ev.contains(&(8, &Event::CutterComp(CutterComp::Left))));
    assert!(ev.contains(&(13, &Event::CutterComp(CutterComp::Off))));
    assert!(ev.contains(&(17, &Event::Stop(StopKind::End))));
    // The feed F200 of line 7 stays in force for the arcs.
    assert!(s.iter().all(|s| match &s.event {
        Event::Move(m) if s.line > 7 && m.kind != MotionKind::Rapid => m.feed == 200.0,
        _ => true,
    }));
}

#[test]
fn q_parameters_and_labels() {
    let s = steps(
        "0 BEGIN PGM Q MM\n1 FN 0: Q1 = +0\n2 LBL 1\n3 FN 1: Q1 = +Q1 + +10\n4 L X+Q1 R0 FMAX\n\
         5 FN 12: IF +Q1 LT +30 GOTO LBL 1\n6 Q2 = 5 * SIN(30) + SQ(3)\n7 L Y+Q2 FMAX\n8 FN 3: Q3 = +Q2 * +2\n\
         9 FN 4: Q4 = +Q3 DIV +4\n10 FN 8: Q5 = +3 LEN +4\n11 FN 13: Q6 = +10 ANG +10\n12 L X+Q4 Y+Q5 Z+Q6 FMAX\n\
         13 LBL 2\n14 L IZ+1 FMAX\n15 CALL LBL 2 REP 2\n16 CALL LBL 5\n17 L X-Q1 FMAX\n18 M30\n\
         19 LBL 5\n20 L Y+1 FMAX\n21 LBL 0\n22 END PGM Q MM\n",
    );
    // Q1 = 10, 20, 30 (the jump back while Q1 < 30). Q2 = 5·sin 30° + 3² =
    // 11.5; Q3 = 23, Q4 = 23 / 4 = 5.75, Q5 = √(3² + 4²) = 5, Q6 = the
    // angle of (10, 10) = 45. The section from LBL 2 runs three times
    // (REP 2): Z 46, 47, 48. The subprogram LBL 5 moves Y to 1; then X −30.
    check(
        &moves(&s),
        &[
            (5, 'R', [10.0, 0.0, 0.0], None),
            (5, 'R', [20.0, 0.0, 0.0], None),
            (5, 'R', [30.0, 0.0, 0.0], None),
            (8, 'R', [30.0, 11.5, 0.0], None),
            (13, 'R', [5.75, 5.0, 45.0], None),
            (15, 'R', [5.75, 5.0, 46.0], None),
            (15, 'R', [5.75, 5.0, 47.0], None),
            (15, 'R', [5.75, 5.0, 48.0], None),
            (21, 'R', [5.75, 1.0, 48.0], None),
            (18, 'R', [-30.0, 1.0, 48.0], None),
        ],
    );
}

#[test]
fn drilling_cycle_200() {
    let s = steps(
        "0 BEGIN PGM C MM\n1 TOOL CALL 1 Z S1000\n2 L Z+100 R0 FMAX M3\n3 CYCL DEF 200 DRILLING ~\n\
         Q200=+2 ;SET-UP CLEARANCE ~\n  Q201=-15 ;DEPTH ~\n  Q206=+150 ;FEED RATE FOR PLNGNG ~\n  Q202=+5 ;PLUNGING DEPTH ~\n\
         Q210=+0 ;DWELL TIME AT TOP ~\n  Q203=+0 ;SURFACE COORDINATE ~\n  Q204=+50 ;2ND SET-UP CLEARANCE ~\n\
         Q211=+0.5 ;DWELL TIME AT DEPTH\n4 L X+10 Y+10 R0 FMAX M99\n5 CYCL CALL POS X+20 Y+10 Z+100\n6 END PGM C MM\n",
    );
    // Surface 0, set-up clearance 2, depth −15 in plunges of 5: down to
    // the clearance 2 at FMAX, feed −5, back to 2, down to −5 + 2 = −3,
    // feed −10, back to 2, down to −8, feed −15, dwell 0.5 s, back to 2,
    // then to the 2nd set-up clearance 0 + 50.
    let hole = |line: usize, x: f64| -> Vec<M> {
        [
            ('R', 2.0),
            ('F', -5.0),
            ('R', 2.0),
            ('R', -3.0),
            ('F', -10.0),
            ('R', 2.0),
            ('R', -8.0),
            ('F', -15.0),
            ('R', 2.0),
            ('R', 50.0),
        ]
        .into_iter()
        .map(|(k, z)| (line, k, [x, 10.0, z], None))
        .collect()
    };
    let mut want = vec![
        (3, 'R', [0.0, 0.0, 100.0], None),
        (13, 'R', [10.0, 10.0, 100.0], None),
    ];
    want.extend(hole(13, 10.0));
    want.push((14, 'R', [20.0, 10.0, 100.0], None));
    want.extend(hole(14, 20.0));
    check(&moves(&s), &want);
    // Plunges at Q206 = 150 mm/min; the dwell at depth.
    assert!(s.iter().all(|s| match &s.event {
        Event::Move(m) if m.kind == MotionKind::Linear => m.feed == 150.0,
        _ => true,
    }));
    assert_eq!(
        s.iter()
            .filter(|s| s.event == Event::Dwell { seconds: 0.5 })
            .count(),
        2
    );
}

#[test]
fn inch_programs_and_tcpm() {
    let s = steps(
        "0 BEGIN PGM I INCH\n1 L X+1 Y+2 R0 FMAX\n2 FUNCTION TCPM F TCP AXIS POS PATHCTRL AXIS\n3 L X+2 F10\n\
         4 FUNCTION RESET TCPM\n5 M128\n6 L C+370 FMAX\n7 M129\n8 END PGM I INCH\n",
    );
    // 1 inch = 25.4 mm; F10 inch/min = 254 mm/min. C+370 on the endless C
    // reads 10 after turning 370.
    let m: Vec<(usize, [f64; 5], f64, bool)> = s
        .iter()
        .filter_map(|s| match &s.event {
            Event::Move(m) => Some((
                s.line,
                [
                    m.axes()[0],
                    m.axes()[1],
                    m.axes()[2],
                    m.axes()[3],
                    m.axes()[4],
                ],
                m.feed,
                m.state.tcp,
            )),
            _ => None,
        })
        .collect();
    assert_eq!(m.len(), 3);
    assert!(near(&m[0].1, &[25.4, 50.8, 0.0, 0.0, 0.0]) && !m[0].3);
    assert!(near(&m[1].1, &[50.8, 50.8, 0.0, 0.0, 0.0]) && m[1].2 == 254.0 && m[1].3);
    assert!(near(&m[2].1, &[50.8, 50.8, 0.0, 0.0, 10.0]) && m[2].3);
    let travel = s.iter().find_map(|s| match &s.event {
        Event::Move(m) if s.line == 7 => Some(m.travel[4]),
        _ => None,
    });
    assert_eq!(travel, Some(370.0));
}

#[test]
fn errors_are_located() {
    for (text, line, col, what) in [
        (
            "0 BEGIN PGM E MM\n1 L X+10 R0 FMAX\n2 RND R2\n",
            3,
            3,
            "RND",
        ),
        ("1 CALL LBL 9\n", 1, 12, "LBL 9"),
        ("1 FN 14: ERROR = 5\n", 1, 3, "error 5"),
        ("1 L X+1 F100\n2 C X+2 Y+1 DR+\n", 2, 3, "CC"),
        ("1 CYCL DEF 208 BORE MILLING\n", 1, 12, "208"),
        ("1 PLANE SPATIAL SPA+0 SPB+0 SPC+0\n", 1, 3, "PLANE"),
        ("1 L X+1 F100\n2 CR X+30 Y+0 R+2 DR-\n", 2, 3, "too small"),
        ("1 LBL 1\n2 CALL LBL 1\n", 2, 3, "nested deeper"),
    ] {
        let e = read_all(
            text,
            Family::Heidenhain,
            &axes(),
            &Options::default(),
            "e.h",
        )
        .unwrap_err();
        assert_eq!((e.line, e.column), (line, col), "{text:?}: {e}");
        assert!(e.message.contains(what), "{text:?}: {e}");
    }
}
