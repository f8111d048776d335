//! Each statement form real CAM systems write, as the events it gives (the
//! forms are those of the files in `data/cl` and of the CAM systems'
//! documentation; see `docs/cl-statements.md`).

use std::f64::consts::{FRAC_PI_2, PI};

use kinpost_cl::{
    Circle, ClEvent, ClReader, CutcomSide, Cycle, CycleKind, Diagnostic, Dwell, Feed, FeedUnit,
    Frame, Motion, Plane, Severity, SpindleDir, SpindleSpeed, Statement, ToolData, Units,
};

fn reader(cl: &str) -> ClReader<&[u8]> {
    ClReader::new(cl.as_bytes(), "t.cls").with_default_axis([0.0, 0.0, 1.0])
}

fn read_with(mut r: ClReader<&[u8]>) -> (Vec<Statement>, Vec<Diagnostic>) {
    let mut out = Vec::new();
    while let Some(s) = r.next_statement().unwrap_or_else(|e| panic!("{e}")) {
        out.push(s);
    }
    (out, r.take_warnings())
}

/// The events of `cl`; no warning allowed.
fn events(cl: &str) -> Vec<ClEvent> {
    let (s, w) = read_with(reader(cl));
    assert!(w.is_empty(), "{w:#?}");
    s.into_iter().map(|s| s.event).collect()
}

fn error(cl: &str) -> Diagnostic {
    error_with(reader(cl))
}

fn error_with(mut r: ClReader<&[u8]>) -> Diagnostic {
    loop {
        match r.next_statement() {
            Ok(Some(_)) => {}
            Ok(None) => panic!("no error"),
            Err(e) => {
                assert_eq!(e.severity, Severity::Error);
                return e;
            }
        }
    }
}

fn goto(point: [f64; 3]) -> ClEvent {
    ClEvent::Goto {
        point,
        axis: [0.0, 0.0, 1.0],
        reference: None,
        motion: Motion::Feed,
    }
}

fn circles(e: &[ClEvent]) -> Vec<Circle> {
    e.iter()
        .filter_map(|e| match e {
            ClEvent::Circle(c) => Some((**c).clone()),
            _ => None,
        })
        .collect()
}

fn close(a: [f64; 3], b: [f64; 3]) -> bool {
    (0..3).all(|k| (a[k] - b[k]).abs() < 1e-12)
}

#[test]
fn the_reader_converts_lengths_to_mm_by_one_multiplication() {
    // 3 inches are 3 × 25.4 as f64 multiplies them (76.19999999999999).
    let (s, _) = read_with(reader("UNITS/INCHES\nGOTO/3,0,0\n"));
    assert_eq!(s[1].event, goto([3.0 * 25.4, 0., 0.]));
}

#[test]
fn nx_circle_axis_is_clockwise_and_its_extra_values_are_kept() {
    // NX writes the axis 0,0,-1 and turns clockwise about it, i.e.
    // counter-clockwise about +Z: from (0,10) about the origin the tool goes
    // through (-7.07, 7.07) to (-10, 0), a quarter turn.
    let e = events(
        "GOTO/0,10,5,0,0,1\nCIRCLE/0,0,5,0.0000000,0.0000000,-1.0000000,10.0000,0.0600,0.5000,25.0000,1.0000\nGOTO/-10,0,5\n",
    );
    let c = &circles(&e)[0];
    assert_eq!(c.axis, [0.0, 0.0, 1.0]);
    assert_eq!(c.radius_mm, 10.0);
    assert_eq!(c.turns, 1);
    assert_eq!(c.tolerance_mm, Some(0.06));
    assert_eq!(c.tool_diameter_mm, Some(25.0));
    assert_eq!(c.tool_corner_radius_mm, Some(1.0));
    let arc = c.arc([0., 10., 5.], [-10., 0., 5.]).unwrap();
    assert!((arc.sweep_rad() - FRAC_PI_2).abs() < 1e-12);
    assert!(close(arc.tangent_at(0.0), [-1., 0., 0.]));
    assert_eq!(e[2], goto([-10., 0., 5.]));
}

#[test]
fn nx_helix_times() {
    let e = events("GOTO/4,0,3,0,0,1\nCIRCLE/0,0,0,0,0,-1,4,0.06,0.5,10,0,TIMES,2\nGOTO/4,0,0\n");
    let c = &circles(&e)[0];
    assert_eq!(c.turns, 2);
    let arc = c.arc([4., 0., 3.], [4., 0., 0.]).unwrap();
    assert!((arc.sweep_rad() - 4.0 * PI).abs() < 1e-12);
    assert_eq!(arc.rise_mm(), -3.0);
    for times in ["0", "1001"] {
        let e = error(&format!(
            "GOTO/4,0,3,0,0,1\nCIRCLE/0,0,0,0,0,-1,4,0.06,0.5,10,0,TIMES,{times}\nGOTO/4,0,0\n"
        ));
        assert_eq!(e.message, "TIMES must be 1 to 1000");
    }
}

#[test]
fn creo_circle_is_right_handed_and_continued() {
    // Creo's documentation: 0,0,-1 is clockwise in XY.
    let e = events(
        "GOTO / 0.0000000000, 1.5000000000, -1.5000000000\nCIRCLE / 0.0000000000, 0.0000000000, -1.5000000000,  $\n0.0000000000, 0.0000000000, -1.0000000000,  1.5000000000\nGOTO / 1.5000000000, 0.0000000000, -1.5000000000\n",
    );
    let c = &circles(&e)[0];
    assert_eq!(
        (c.axis, c.radius_mm, c.tolerance_mm),
        ([0., 0., -1.], 1.5, None)
    );
    let arc = c.arc([0., 1.5, -1.5], [1.5, 0., -1.5]).unwrap();
    assert!((arc.sweep_rad() - FRAC_PI_2).abs() < 1e-12);
}

#[test]
fn solidworks_circle_has_no_radius() {
    let e = events(
        "GOTO/173.434439,39.349867,-4.\nCIRCLE/174.20718,39.556922,-4.,0,0,1.\nGOTO/173.80718,38.864102,-4.\n",
    );
    let c = &circles(&e)[0];
    // The radius is the current point's distance from the axis.
    assert!((c.radius_mm - 0.8).abs() < 1e-5, "{}", c.radius_mm);
    assert_eq!(c.tolerance_mm, None);
    assert_eq!(
        error("GOTO/1,1,0\nCIRCLE/1,1,5,0,0,1\nGOTO/2,1,0\n").message,
        "the current point is on the circle's axis: the arc has no radius"
    );
}

#[test]
fn creo_further_points_and_arcs_through_them() {
    // A full circle in three arcs of the same CIRCLE (NIST's Pro/E files):
    // the circle is given again, on the line of each further point.
    let (s, w) = read_with(reader(
        "GOTO / 7.4300, 5.8500, 1.8000\nCIRCLE / 7.4550, 5.8500, 1.8000,  $\n0.0000, 0.0000, 1.0000,  0.0250\nGOTO / 7.4675, 5.8283, 1.8000\n       7.4675, 5.8717, 1.8000\n       7.4300, 5.8500, 1.8000\nGOTO / 1, 2, 3\n       4, 5, 6\n",
    ));
    assert!(w.is_empty());
    let lines: Vec<(usize, &str)> = s
        .iter()
        .map(|s| {
            (
                s.line,
                match s.event {
                    ClEvent::Circle(_) => "circle",
                    ClEvent::Goto { .. } => "goto",
                    _ => "other",
                },
            )
        })
        .collect();
    assert_eq!(
        lines,
        [
            (1, "goto"),
            (2, "circle"),
            (4, "goto"),
            (5, "circle"),
            (5, "goto"),
            (6, "circle"),
            (6, "goto"),
            (7, "goto"),
            (8, "goto"),
        ]
    );
    // Each piece is a third of the circle.
    let mut at = [7.43, 5.85, 1.8];
    let mut total = 0.0;
    for pair in s.windows(2) {
        if let (ClEvent::Circle(c), ClEvent::Goto { point, .. }) = (&pair[0].event, &pair[1].event)
        {
            let arc = c.arc(at, *point).unwrap();
            total += arc.sweep_rad();
            at = *point;
        }
    }
    assert!((total - 2.0 * PI).abs() < 1e-3, "{total}");
    // A point that misses the circle is an error on its line.
    let e = error("GOTO/1,0,0\nCIRCLE/0,0,0,0,0,1,1\nGOTO/0,1,0\n  0,2,0\n");
    assert_eq!((e.line, e.column), (4, 3));
}

#[test]
fn nx_nurbs_starts_at_the_current_point() {
    // A degree-1 curve in NX's form: the current point and two CNTRL
    // points, two knots written (0.5 and 1).
    let e = events(
        "GOTO/0,0,0,0,0,1\nNURBS/\nKNOT/0.5000000,1.0000000\nCNTRL/1,0,0\nCNTRL/1,1,0\nPAINT/COLOR,31\nGOTO/1,1,0\n",
    );
    let ClEvent::Nurbs(c) = &e[1] else {
        panic!("{e:?}")
    };
    assert_eq!(c.degree(), 1);
    assert_eq!(c.knots(), [0., 0., 0.5, 1., 1.]);
    assert_eq!(c.points(), [[0., 0., 0.], [1., 0., 0.], [1., 1., 0.]]);
    assert!(close(c.point_at(0.25), [0.5, 0., 0.]));
    assert!(close(c.point_at(0.75), [1., 0.5, 0.]));
    // The line after the records is read as it would be without them.
    assert_eq!(e[2], goto([1., 1., 0.]));
    assert_eq!(e.len(), 3);
    // Cubic with weights, records over several lines, in inches.
    let e = events(
        "UNITS/INCHES\nGOTO/0,0,0,0,0,1\nNURBS/\nKNOT/0.25,0.5\nKNOT/1\nCNTRL/1,0,0,2\nCNTRL/2,0,0\nCNTRL/3,1,0\nCNTRL/4,1,0\nCNTRL/5,0,0\nFINI\n",
    );
    let ClEvent::Nurbs(c) = &e[2] else {
        panic!("{e:?}")
    };
    assert_eq!(c.degree(), 3);
    assert_eq!(c.knots(), [0., 0., 0., 0., 0.25, 0.5, 1., 1., 1., 1.]);
    assert_eq!(c.weights(), [1., 2., 1., 1., 1., 1.]);
    assert_eq!(c.points()[5], [127., 0., 0.]);
    assert_eq!(c.point_at(1.0), [127., 0., 0.]);
    assert_eq!(e[3], ClEvent::Fini);
}

/// The cycle an event carries.
fn cycle(e: &ClEvent) -> Cycle {
    match e {
        ClEvent::Cycle(c) => (**c).clone(),
        _ => panic!("{e:?}"),
    }
}

#[test]
fn cycles_in_three_dialects() {
    let base = Cycle {
        kind: CycleKind::Drill,
        depth_mm: None,
        feed_start_mm: None,
        retract_mm: None,
        peck_mm: None,
        next_peck_mm: None,
        dwell: None,
        feed: None,
        pitch_mm: None,
        back_off_mm: None,
        full_retract_every: None,
    };
    // NX: the kind may take two words.
    let e =
        events("CYCLE/DRILL,DEEP,RAPTO,3.0000,FEDTO,-20.0000,STEP,4,2,MMPM,250.0000\nCYCLE/OFF\n");
    assert_eq!(
        cycle(&e[0]),
        Cycle {
            kind: CycleKind::Deep,
            depth_mm: Some(20.0),
            feed_start_mm: Some(3.0),
            peck_mm: Some(4.0),
            next_peck_mm: Some(2.0),
            feed: Some(Feed {
                value: 250.0,
                unit: FeedUnit::Mmpm
            }),
            ..base.clone()
        }
    );
    assert_eq!(e[1], ClEvent::CycleOff);
    // Creo couplets: CLEAR less RAPTO is where the feed starts; RETURN.
    let e = events(
        "UNITS / INCHES\nCYCLE / BRKCHP, DEPTH, 0.5, STEP, 0.1, IPM, 4.0, CLEAR, 0.2, RAPTO, 0.1, RETURN, 1.0, REV, 2\n",
    );
    let c = cycle(&e[1]);
    assert_eq!(c.kind, CycleKind::BreakChip);
    assert!((c.depth_mm.unwrap() - 12.7).abs() < 1e-12);
    assert!((c.feed_start_mm.unwrap() - 2.54).abs() < 1e-12);
    assert!((c.retract_mm.unwrap() - 25.4).abs() < 1e-12);
    assert!((c.feed.unwrap().value - 101.6).abs() < 1e-12);
    assert_eq!(c.dwell, Some(Dwell::Revolutions(2.0)));
    // Creo's chip breaking: back off 0.05 in after each peck, leave the
    // hole after every third.
    let e = events(
        "UNITS / INCHES\nCYCLE / BRKCHP, DEPTH, 0.5, STEP, 0.1, IPM, 4.0, CLEAR, 0.2, BACK, 0.05, TIMES, 3\n",
    );
    let c = cycle(&e[1]);
    assert!((c.back_off_mm.unwrap() - 1.27).abs() < 1e-12);
    assert_eq!(c.full_retract_every, Some(3));
    assert!(
        error("CYCLE/BRKCHP,DEPTH,1,TIMES,2.5\n")
            .message
            .contains("number of pecks (TIMES)")
    );
    // SOLIDWORKS CAM: INIT first; DWELL 0 is no dwell.
    let e = events(
        "CYCLE/INIT\nCYCLE/TAP,FEDTO,12.,PITCH,1.25,MMPR,1.25,RAPTO,3.,RTRCTO,25.,DWELL,0.5\n",
    );
    let c = cycle(&e[0]);
    assert_eq!(
        (c.kind, c.pitch_mm, c.dwell),
        (CycleKind::Tap, Some(1.25), Some(Dwell::Seconds(0.5)))
    );
    assert_eq!(
        c.feed,
        Some(Feed {
            value: 1.25,
            unit: FeedUnit::Mmpr
        })
    );
    // Another kind word is kept as written.
    let e = events("CYCLE/MILL,FEDTO,1\n");
    assert_eq!(cycle(&e[0]).kind, CycleKind::Other("MILL".into()));
    assert!(
        error("CYCLE/DRILL,FEDTO,1,SPEED,2\n")
            .message
            .contains("unknown word `SPEED`")
    );
    assert!(
        error("CYCLE/DRILL,FEDTO\n")
            .message
            .contains("without its value")
    );
    assert!(
        error("CYCLE/OFF,1\n")
            .message
            .contains("number where a keyword")
    );
    assert!(error("CYCLE/DRILL,MMPM,0\n").message.contains("positive"));
}

#[test]
fn positional_cycles_in_apts_fixed_order() {
    // CATIA V5: `CYCLE/DRILL, depth, clearance` (its file approaches to
    // 5 mm above the hole point before the cycle), the feed of FEDRAT.
    let e = events("CYCLE/DRILL,    3.000000,    5.000000\nCYCLE/OFF\n");
    let c = cycle(&e[0]);
    assert_eq!(
        (c.kind, c.depth_mm, c.feed_start_mm, c.feed),
        (CycleKind::Drill, Some(3.0), Some(5.0), None)
    );
    // APT: depth, feed unit, feed, rapid plane; inch values in mm.
    let e = events("UNITS/INCHES\nCYCLE/BORE, 0.5, IPM, 4.0, 0.1\n");
    let c = cycle(&e[1]);
    assert_eq!(c.kind, CycleKind::Bore);
    assert!((c.depth_mm.unwrap() - 12.7).abs() < 1e-12);
    assert!((c.feed_start_mm.unwrap() - 2.54).abs() < 1e-12);
    assert!((c.feed.unwrap().value - 101.6).abs() < 1e-12);
    // Other orders and kinds are errors that say what is read.
    for bad in [
        "CYCLE/DRILL,5,100,MMPM\n",
        "CYCLE/DRILL,5\n",
        "CYCLE/DRILL,5,FOO,1,2\n",
        "CYCLE/DRILL,5,MMPM,100\n",
    ] {
        let m = error(bad).message;
        assert!(m.contains("depth, clearance"), "{bad}: {m}");
    }
    assert!(
        error("CYCLE/DRILL,5,MMPM,0,2\n")
            .message
            .contains("positive")
    );
    let m = error("CYCLE/DEEP,5,2\n").message;
    assert!(
        m.contains("read for DRILL, FACE, BORE, REAM and CSINK only"),
        "{m}"
    );
}

#[test]
fn from_gohome_and_program_stops() {
    let e = events(
        "FROM/297.5,-393,483,0,0,1\nRAPID\nGOTO/297.5,-393,471\nGOHOME/297.5,-393,483\nFROM/1,2,3\nGOHOME\nSTOP\nOPSTOP\nEND\nDELAY/2.5\nDELAY/3,REV\nDWELL/1\n",
    );
    assert_eq!(
        e[0],
        ClEvent::From {
            point: [297.5, -393., 483.],
            axis: Some([0., 0., 1.])
        }
    );
    assert_eq!(
        e[2],
        ClEvent::GoHome {
            point: Some([297.5, -393., 483.]),
            axis: None
        }
    );
    assert_eq!(
        e[4],
        ClEvent::GoHome {
            point: Some([1., 2., 3.]),
            axis: None
        }
    );
    assert_eq!(
        e[5..],
        [
            ClEvent::Stop,
            ClEvent::OptionalStop,
            ClEvent::End,
            ClEvent::Dwell(Dwell::Seconds(2.5)),
            ClEvent::Dwell(Dwell::Revolutions(3.0)),
            ClEvent::Dwell(Dwell::Seconds(1.0)),
        ]
    );
    // FROM sets the current point (a CIRCLE may start there) and the axis.
    let e = events("FROM/10,0,0,0,0,1\nCIRCLE/0,0,0,0,0,1,10\nGOTO/0,10,0\n");
    assert_eq!(circles(&e).len(), 1);
    assert_eq!(
        events("GOHOME\n"),
        [ClEvent::GoHome {
            point: None,
            axis: None
        }]
    );
    // A stop with the operator's instruction (CATIA V5): the instruction
    // as a comment, then the stop.
    assert_eq!(
        events("STOP/(INSTALL TEST STRIP)\nOPSTOP/CHECK\nSTOP\n"),
        [
            ClEvent::Comment("INSTALL TEST STRIP".into()),
            ClEvent::Stop,
            ClEvent::Comment("CHECK".into()),
            ClEvent::OptionalStop,
            ClEvent::Stop,
        ]
    );
    assert!(error("END/1\n").message.contains("takes no arguments"));
    assert!(error("DELAY/-1\n").message.contains("negative"));
}

#[test]
fn cutcom_forms() {
    let c = |side, plane, register| ClEvent::CutterCompensation {
        side,
        plane,
        register,
    };
    assert_eq!(
        events("CUTCOM/LEFT,XYPLAN\nCUTCOM/RIGHT,YZPLAN,12\nCUTCOM/OFF\nCUTCOM/LEFT\n"),
        [
            c(CutcomSide::Left, Some(Plane::Xy), None),
            c(CutcomSide::Right, Some(Plane::Yz), Some(12)),
            c(CutcomSide::Off, None, None),
            c(CutcomSide::Left, None, None),
        ]
    );
    assert!(
        error("CUTCOM/XYPLAN\n")
            .message
            .contains("CUTCOM/LEFT|RIGHT|OFF")
    );
}

#[test]
fn tools_in_nx_apt_and_creo_forms() {
    let e = events(
        "LOAD/TOOL,2,ADJUST,2 \nLOADTL / 1\nLOADTL/3,ADJUST,7\nSELECT/TOOL,2\nTLDATA/DRILL,MILL,63.0000,0.0000,239.0000,178.0000,35.0000\nCUTTER/12.,0,6.,3.605164,31.,0,63.\nUNITS/INCHES\nTLDATA/MILL,0.7500,0.1200,4.0000,0.0000,0.0000\n",
    );
    assert_eq!(
        e[..4],
        [
            ClEvent::LoadTool {
                number: 2,
                adjust: Some(2)
            },
            ClEvent::LoadTool {
                number: 1,
                adjust: None
            },
            ClEvent::LoadTool {
                number: 3,
                adjust: Some(7)
            },
            ClEvent::SelectTool { number: 2 },
        ]
    );
    assert_eq!(
        e[4],
        ClEvent::ToolData(Box::new(ToolData {
            kind: "DRILL".into(),
            words: vec!["MILL".into()],
            values: vec![63.0, 0.0, 239.0, 178.0, 35.0],
            diameter_mm: Some(63.0),
            corner_radius_mm: None,
            length_mm: None,
        }))
    );
    let ClEvent::ToolData(cutter) = &e[5] else {
        panic!()
    };
    assert_eq!(
        (
            cutter.diameter_mm,
            cutter.corner_radius_mm,
            cutter.length_mm
        ),
        (Some(12.0), Some(0.0), Some(63.0))
    );
    let ClEvent::ToolData(mill) = &e[7] else {
        panic!()
    };
    // Values as written, the lengths in mm.
    assert_eq!(mill.values, [0.75, 0.12, 4.0, 0.0, 0.0]);
    assert!((mill.diameter_mm.unwrap() - 19.05).abs() < 1e-12);
    assert!((mill.length_mm.unwrap() - 101.6).abs() < 1e-12);
    assert!((mill.corner_radius_mm.unwrap() - 3.048).abs() < 1e-12);
    assert!(
        error("CUTTER/MILL,1\n")
            .message
            .contains("CUTTER takes numbers")
    );
}

#[test]
fn spindle_forms() {
    let s = |speed, dir, range, max_rpm| ClEvent::Spindle {
        speed,
        dir,
        range,
        max_rpm,
    };
    assert_eq!(
        events(
            "SPINDL / RPM, 9000.000000,  CLW\nSPINDL/200,SMM,CCLW,MAXRPM,4000\nSPINDL/100,SFM,RANGE,2\nSPINDL/OFF\n"
        ),
        [
            s(SpindleSpeed::Rpm(9000.0), SpindleDir::Clockwise, None, None),
            s(
                SpindleSpeed::SurfaceMetresPerMinute(200.0),
                SpindleDir::CounterClockwise,
                None,
                Some(4000.0)
            ),
            s(
                SpindleSpeed::SurfaceMetresPerMinute(30.48),
                SpindleDir::Clockwise,
                Some(2),
                None
            ),
            ClEvent::SpindleOff,
        ]
    );
}

#[test]
fn machine_names_setups_and_the_rest() {
    assert_eq!(
        events(
            "MACHIN / UNCX01, 1\nMACHIN / MILL, M0001\nOPNAME/'ROUGH 1'\nCLAMP/AAXIS,ON\nCLAMP/OFF,AAXIS\nORIGIN/1,2,3\nTMARK\nSETUP/START,1\nSETUP/END,1\nPPRINT/hello\n"
        ),
        [
            ClEvent::Machine {
                name: "UNCX01".into(),
                args: vec!["1".into()]
            },
            ClEvent::Machine {
                name: "MILL".into(),
                args: vec!["M0001".into()]
            },
            ClEvent::OperationName("ROUGH 1".into()),
            ClEvent::Clamp {
                on: true,
                words: vec!["AAXIS".into()]
            },
            ClEvent::Clamp {
                on: false,
                words: vec!["AAXIS".into()]
            },
            ClEvent::Origin([1., 2., 3.]),
            ClEvent::TapeMark,
            ClEvent::Setup {
                start: true,
                number: 1
            },
            ClEvent::Setup {
                start: false,
                number: 1
            },
            ClEvent::Comment("hello".into()),
        ]
    );
}

#[test]
fn creo_comments_continue_with_a_dollar() {
    assert_eq!(
        events(
            "$$*          Pro/CLfile  Version 8.0 - 8.0.3.0\n$$-> CSYS / 1.0000000000, 0.0000000000,  $\n            0.0000000000, 1.0000000000,  $\n            0.0\n$$-> END / \n$$ price 5$\n"
        ),
        [
            ClEvent::Comment("*          Pro/CLfile  Version 8.0 - 8.0.3.0".into()),
            ClEvent::Comment(
                "-> CSYS / 1.0000000000, 0.0000000000, 0.0000000000, 1.0000000000, 0.0".into()
            ),
            ClEvent::Comment("-> END /".into()),
            ClEvent::Comment("price 5$".into()),
        ]
    );
    // A continued comment that the file ends in is still a comment.
    assert_eq!(events("$$ a,  $\n"), [ClEvent::Comment("a,".into())]);
}

#[test]
fn nx_information_listing_header_and_footer_are_skipped() {
    let (s, w) = read_with(reader(
        "\nInformation listing created by\tphill\nDate\t18-Dec-2021 21:07:42\nCurrent work part\tC:\\part.prt\nNode name\tlaptop\n\nTOOL PATH/CAVITY_MILL,TOOL,MILL\nEND-OF-PATH\nTool Path Listing has 3 lines.\n",
    ));
    assert!(w.is_empty(), "{w:#?}");
    assert_eq!(s.len(), 2);
    assert_eq!(s[0].line, 7);
    // Outside the header these words are unknown statements.
    let (_, w) = read_with(reader("Date\t18-Dec-2021\n"));
    assert_eq!(w.len(), 1);
}

#[test]
fn frames_of_msys_and_csys() {
    let e = events(
        "MSYS/393,-297.5,3,0,1,0,-1,0,0\nCSYS/-0.000025,-1.,0,-96.912553,1.,-0.000025,0,733.700278,0,0,1.,0\n",
    );
    let ClEvent::MachineSystem { frame: Some(m), .. } = &e[0] else {
        panic!()
    };
    assert_eq!(m.z, [0., 0., 1.]);
    assert_eq!(m.to_outer([1., 0., 0.]), [393., -296.5, 3.]);
    let ClEvent::CoordinateSystem(c) = &e[1] else {
        panic!()
    };
    assert_eq!(c.origin, [-96.912553, 733.700278, 0.]);
    assert_eq!(c.x, [-0.000025, -1., 0.]);
    assert!(!c.is_identity(1e-6));
    // In inches the origin is converted, the directions are not.
    let e = events("UNITS/INCHES\nCSYS/1,0,0,1,0,1,0,2,0,0,1,3\n");
    let ClEvent::CoordinateSystem(c) = &e[1] else {
        panic!()
    };
    assert!(close(c.origin, [25.4, 50.8, 76.2]));
    assert_eq!(
        (c.x, c.y, c.z),
        (Frame::IDENTITY.x, Frame::IDENTITY.y, Frame::IDENTITY.z)
    );
}

#[test]
fn units_given_or_declared() {
    // --units inch: lengths and feeds in mm.
    let r = reader("GOTO/1,2,3\nFEDRAT/10\nFEDRAT/IPM,10\n").with_units(Some(Units::Inch));
    let (s, _) = read_with(r);
    let e: Vec<ClEvent> = s.into_iter().map(|s| s.event).collect();
    let ClEvent::Goto { point, .. } = e[0] else {
        panic!()
    };
    assert!(close(point, [25.4, 50.8, 76.2]));
    assert_eq!(
        e[1..],
        [
            ClEvent::Feedrate {
                value: 254.0,
                unit: FeedUnit::Mmpm
            },
            ClEvent::Feedrate {
                value: 254.0,
                unit: FeedUnit::Mmpm
            }
        ]
    );
    // --units mm with an inch feed: the feed is converted, no error.
    let r = reader("FEDRAT/IPR,0.01\n").with_units(Some(Units::Mm));
    let (s, _) = read_with(r);
    assert_eq!(
        s[0].event,
        ClEvent::Feedrate {
            value: 0.254,
            unit: FeedUnit::Mmpr
        }
    );
    // A contradiction is an error.
    let e = error_with(reader("UNITS/MM\n").with_units(Some(Units::Inch)));
    assert!(e.message.contains("`--units inch` was given"), "{e}");
    // An inch feed of a cycle in an undeclared file too.
    let e = error("CYCLE/DRILL,FEDTO,1,IPM,5\n");
    assert!(e.message.contains("`--units inch`"), "{e}");
    // Declared inches: a CIRCLE is converted as the points are.
    let e = events("UNITS/INCHES\nGOTO/1,0,0,0,0,1\nCIRCLE/0,0,0,0,0,1,1\nGOTO/0,1,0\n");
    let c = &circles(&e)[0];
    assert_eq!((c.centre, c.radius_mm), ([0., 0., 0.], 25.4));
}

/// CATIA V5's tool change (`TOOLNO`, `TPRINT`, `LOADTL/n,m` with its
/// compensation number) and its `REWIND` before `END`.
#[test]
fn catia_tool_change_and_rewind() {
    let got = events(
        "TOOLNO/2,   10.000000\nTPRINT/T1 PointeurD10\nLOADTL/2\nLOADTL/2,1\nTOOLNO/1,TURN\nREWIND/0\nEND\n",
    );
    assert_eq!(got.len(), 5, "{got:?}");
    match &got[0] {
        ClEvent::ToolData(t) => assert_eq!(t.diameter_mm, Some(10.0)),
        other => panic!("{other:?}"),
    }
    assert_eq!(
        got[1..],
        [
            ClEvent::Comment("T1 PointeurD10".into()),
            ClEvent::LoadTool {
                number: 2,
                adjust: None
            },
            ClEvent::LoadTool {
                number: 2,
                adjust: Some(1)
            },
            ClEvent::End,
        ]
    );
}
