//! The reader on the real CL files in the repository's `data/` folder.

use std::fs::File;
use std::io::BufReader;
use std::path::PathBuf;

use kinpost_cl::{
    ClEvent, ClReader, Cycle, CycleKind, Diagnostic, Feed, FeedUnit, Frame, Motion, Severity,
    Statement, Units, Vec3,
};

fn data(path: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../data")
        .join(path)
}

fn open(path: &str) -> ClReader<BufReader<File>> {
    let file = data(path);
    let f = File::open(&file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    ClReader::new(BufReader::new(f), path)
}

/// Reads until the end or the first error.
fn read_all<R: std::io::BufRead>(
    mut r: ClReader<R>,
) -> (Vec<Statement>, Vec<Diagnostic>, Option<Diagnostic>) {
    let mut statements = Vec::new();
    loop {
        match r.next_statement() {
            Ok(Some(s)) => statements.push(s),
            Ok(None) => return (statements, r.take_warnings(), None),
            Err(e) => return (statements, r.take_warnings(), Some(e)),
        }
    }
}

#[test]
fn seed_figure_28a() {
    let (statements, warnings, error) = read_all(open("qiao2022/figure28a-verbatim.cls"));
    assert_eq!(error, None);

    let gotos: Vec<_> = statements
        .iter()
        .filter_map(|s| match &s.event {
            ClEvent::Goto {
                point,
                axis,
                motion,
                ..
            } => Some((s.line, *point, *axis, *motion)),
            _ => None,
        })
        .collect();
    assert_eq!(gotos.len(), 14);
    assert!(gotos[..2].iter().all(|g| g.3 == Motion::Rapid));
    assert!(gotos[2..].iter().all(|g| g.3 == Motion::Feed));
    assert!(gotos.iter().all(|g| g.2 == [0.0, 0.0, 1.0]));
    assert_eq!(gotos[0].0, 9);
    assert_eq!(gotos[0].1, [-416.0, 70.5, 16.53]);
    assert_eq!(gotos[2].1, [-416.0, 70.3931, 11.3684]);
    assert_eq!(
        gotos[13],
        (26, [-416.0, 58.0, 0.5], [0.0, 0.0, 1.0], Motion::Feed)
    );

    // The feed rate is set once, before the first feed move.
    let feeds: Vec<_> = statements
        .iter()
        .filter(|s| matches!(s.event, ClEvent::Feedrate { .. }))
        .collect();
    assert_eq!(feeds.len(), 1);
    assert_eq!(
        feeds[0].event,
        ClEvent::Feedrate {
            value: 250.0,
            unit: FeedUnit::Mmpm
        }
    );
    assert!(feeds[0].line < gotos[2].0);

    assert_eq!(
        statements[0].event,
        ClEvent::ToolPath {
            name: "平板件测试".into(),
            words: vec!["TOOL".into(), "代砂轮".into()],
        }
    );
    assert!(statements.iter().any(|s| s.event
        == ClEvent::MachineSystem {
            origin: [226.8083, 392.8435, 0.0],
            x: Some([1.0, 0.0, 0.0]),
            y: None,
            frame: None,
        }));
    assert!(
        statements
            .iter()
            .any(|s| s.event == ClEvent::Comment("centerline data".into()))
    );

    assert_eq!(warnings.len(), 2, "{warnings:#?}");
    assert!(warnings.iter().all(|w| w.severity == Severity::Warning));
    assert_eq!((warnings[0].line, warnings[0].column), (2, 1));
    assert!(warnings[0].message.contains("`TLDDATA`"));
    assert!(warnings[0].message.contains("did you mean `TLDATA`"));
    assert_eq!(warnings[1].line, 3);
    assert!(
        warnings[1]
            .message
            .starts_with("MSYS has 6 values, expected 3 or 9; ")
    );
    assert!(warnings[1].source_line.starts_with("MSYS/226.8083"));
}

#[test]
fn apt_first_moves_are_rapid_then_feed() {
    let (statements, _, _) =
        read_all(open("cl/solidworks/boss.apt").with_default_axis([0.0, 0.0, 1.0]));
    let moves: Vec<_> = statements
        .iter()
        .filter_map(|s| match s.event {
            ClEvent::Goto { point, motion, .. } => Some((point, motion)),
            _ => None,
        })
        .take(4)
        .collect();
    assert_eq!(
        moves,
        vec![
            ([89.2375, 5.7625, 25.0], Motion::Rapid),
            ([89.2375, 5.7625, 2.5], Motion::Rapid),
            ([89.2375, 5.7625, -3.0], Motion::Feed),
            ([89.2375, 33.799705, -3.0], Motion::Feed),
        ]
    );
}

/// Reads a whole file; panics at an error or a warning.
fn clean(reader: ClReader<BufReader<File>>) -> Vec<Statement> {
    let (statements, warnings, error) = read_all(reader);
    assert_eq!(error, None);
    assert!(warnings.is_empty(), "{warnings:#?}");
    statements
}

/// SOLIDWORKS CAM APT files never give a tool axis: without a default
/// axis the first GOTO is an error that says what to do.
#[test]
fn apt_files_need_a_default_axis() {
    let (_, _, error) = read_all(open("cl/solidworks/boss.apt"));
    let e = error.expect("GOTO without a tool axis");
    assert!(e.message.contains("before any tool axis"), "{e}");
    assert_eq!((e.line, e.column), (15, 6));
}

fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn unit(a: Vec3) -> Vec3 {
    let n = dot(a, a).sqrt();
    [a[0] / n, a[1] / n, a[2] / n]
}

/// The direction convention of every CAM system's `CIRCLE`, checked on the
/// geometry of real files alone: where the straight move into an arc is
/// tangent to the circle (seen along the axis: perpendicular to the radius
/// at the start, within 0.5°), a tool path goes on the way it came, so the
/// arc's direction at its start is the move's. (A tool path may also turn
/// back there, a cusp: SOLIDWORKS CAM does at 10 of 1719 such junctions of
/// its files, so up to 1 % is allowed.) The NX files (whose axis is the
/// reverse of the right-hand rule) and the Creo and SOLIDWORKS CAM files
/// (right-hand rule) must all pass, each with many such junctions; with
/// the NX axis read the other way round every one of its junctions would
/// turn back.
#[test]
fn arcs_turn_the_way_the_tool_comes_in() {
    for (path, units, min_tangent) in [
        ("cl/nx/APT_Project2.txt", Some(Units::Inch), 74),
        ("cl/nx/APT_SimpleMillPlane_ZIG.txt", None, 15),
        ("cl/nx/APT_Zig_Zag_Smoothed.txt", None, 35),
        ("cl/creo/profilfraesen_2.ncl.1", None, 15),
        ("cl/solidworks/boss.apt", None, 500),
        ("cl/solidworks/Teste-Metrologia.apt", None, 10),
    ] {
        let reader = open(path)
            .with_default_axis([0.0, 0.0, 1.0])
            .with_units(units);
        let statements = clean(reader);
        let (mut points, mut circle) = (Vec::<Vec3>::new(), None);
        let (mut tangent, mut arcs, mut back) = (0, 0, 0);
        for s in &statements {
            match &s.event {
                ClEvent::Circle(c) => circle = Some((c.clone(), s.line)),
                ClEvent::Goto { point, .. } => {
                    if let Some((c, line)) = circle.take() {
                        arcs += 1;
                        let start = *points.last().unwrap();
                        let arc = c.arc(start, *point).unwrap();
                        // The radius as written (or as measured) fits.
                        assert!(
                            (arc.radius_mm() - c.radius_mm).abs() < 0.01,
                            "{path}:{line}"
                        );
                        if points.len() >= 2 {
                            let before = points[points.len() - 2];
                            if dot(sub(start, before), sub(start, before)) > 1e-6 {
                                // Seen along the axis (a helix also rises).
                                let axis = arc.axis();
                                let flat = |v: Vec3| {
                                    let h = dot(v, axis);
                                    [v[0] - h * axis[0], v[1] - h * axis[1], v[2] - h * axis[2]]
                                };
                                let incoming = flat(unit(sub(start, before)));
                                let radial = unit(sub(start, arc.centre()));
                                if dot(incoming, incoming) > 0.25
                                    && dot(unit(incoming), radial).abs() < 0.0087
                                {
                                    tangent += 1;
                                    let along =
                                        dot(unit(incoming), unit(flat(arc.tangent_at(0.0))));
                                    if along < 0.999 {
                                        assert!(along < -0.999, "{path}:{line}: {along}");
                                        eprintln!("{path}:{line}: a cusp");
                                        back += 1;
                                    }
                                }
                            }
                        }
                    }
                    points.push(*point);
                }
                _ => {}
            }
        }
        assert!(
            arcs > 0 && tangent >= min_tangent && back * 100 <= tangent,
            "{path}: {tangent} tangent junctions of {arcs} arcs, {back} turning back"
        );
    }
}

/// NX inch files without UNITS: an error that names `--units` at the first
/// inch feed, and in inches with it (every length times 25.4).
#[test]
fn nx_inch_file_without_units() {
    let path = "cl/nx/APT_Project2.txt";
    let (statements, warnings, error) = read_all(open(path));
    let e = error.expect("an inch feed in an undeclared file");
    assert_eq!((e.line, e.column, e.width), (21, 8, 3));
    assert!(e.message.contains("`--units inch`"), "{e}");
    assert!(warnings.is_empty(), "{warnings:#?}");
    // The header NX writes is no statement: the operation comes first.
    assert!(
        matches!(&statements[0].event, ClEvent::ToolPath { name, .. } if name == "CAVITY_MILL")
    );

    let statements = clean(open(path).with_units(Some(Units::Inch)));
    let first_goto = statements
        .iter()
        .find_map(|s| match s.event {
            ClEvent::Goto { point, .. } => Some(point),
            _ => None,
        })
        .unwrap();
    // GOTO/2.3600,2.2749,3.5300,0,0,1 on line 16 (a rapid above the part).
    let written = [2.36, 2.2749, 3.53];
    for k in 0..3 {
        assert!(
            (first_goto[k] - written[k] * 25.4).abs() < 1e-9,
            "{first_goto:?}"
        );
    }
    let feed = statements
        .iter()
        .find_map(|s| match s.event {
            ClEvent::Feedrate { value, unit } => Some((value, unit)),
            _ => None,
        })
        .unwrap();
    assert_eq!(feed, (254.0, FeedUnit::Mmpm));
    assert_eq!(
        statements
            .iter()
            .filter(|s| matches!(
                s.event,
                ClEvent::LoadTool {
                    adjust: Some(_),
                    ..
                }
            ))
            .count(),
        4
    );
}

/// SOLIDWORKS CAM cycles: the couplets, in mm.
#[test]
fn solidworks_cycles() {
    let statements =
        clean(open("cl/solidworks/Sacrifice-Board.apt").with_default_axis([0.0, 0.0, 1.0]));
    let cycles: Vec<&Cycle> = statements
        .iter()
        .filter_map(|s| match &s.event {
            ClEvent::Cycle(c) => Some(&**c),
            _ => None,
        })
        .collect();
    assert_eq!(cycles.len(), 4);
    // Line 17: CYCLE/DRILL,FEDTO,5.4,MMPM,364.49,RAPTO,3.,RTRCTO,27.5,DWELL,0
    let drill = cycles[0];
    assert_eq!(drill.kind, CycleKind::Drill);
    assert_eq!(drill.depth_mm, Some(5.4));
    assert_eq!(drill.feed_start_mm, Some(3.0));
    assert_eq!(drill.retract_mm, Some(27.5));
    assert_eq!(drill.dwell, None);
    assert_eq!(
        drill.feed,
        Some(Feed {
            value: 364.49,
            unit: FeedUnit::Mmpm
        })
    );
    // Line 38: CYCLE/DEEP2,FEDTO,28.6019,1STPECK,5.,SUBPECK,2.,…: peck drilling.
    let deep = cycles[1];
    assert_eq!(deep.kind, CycleKind::Deep);
    assert_eq!(deep.depth_mm, Some(28.6019));
    assert_eq!((deep.peck_mm, deep.next_peck_mm), (Some(5.0), Some(2.0)));
    let offs = statements
        .iter()
        .filter(|s| s.event == ClEvent::CycleOff)
        .count();
    assert_eq!(offs, 4);
}

/// SOLIDWORKS CAM writes part instances as CSYS frames (after
/// `TRNTYP/WORLD`): the GOTOs are where the instance is, and the frame maps
/// them onto the reference instance's (identity frame) GOTOs. This fixes
/// which way a CSYS matrix reads ([`Frame::from_rows`]).
#[test]
fn solidworks_csys_maps_instances_onto_the_reference() {
    let statements =
        clean(open("cl/solidworks/manufacture3-top.apt").with_default_axis([0.0, 0.0, 1.0]));
    // The first GOTO after each CSYS, with the frame.
    let mut firsts: Vec<(Frame, Vec3)> = Vec::new();
    let mut frame = None;
    for s in &statements {
        match &s.event {
            ClEvent::CoordinateSystem(f) => frame = Some(*f),
            ClEvent::Goto { point, .. } => {
                if let Some(f) = frame.take() {
                    firsts.push((f, *point));
                }
            }
            _ => {}
        }
    }
    // The first setup: an instance in the identity frame, one turned a half
    // turn, one moved along Y.
    let (reference_frame, reference) = firsts[0];
    assert!(reference_frame.is_identity(1e-12));
    for (f, g) in &firsts[1..3] {
        assert!(!f.is_identity(1e-6));
        let p = f.to_outer(*g);
        for k in 0..3 {
            assert!((p[k] - reference[k]).abs() < 1e-5, "{p:?} {reference:?}");
        }
    }
}

/// Creo: `$$->` comments continued with `$`, `MACHIN`, `LOADTL`, and a
/// couplet DEEP cycle continued with `$`.
#[test]
fn creo_drilling() {
    // Creo writes x,y,z GOTOs where the tool axis is the Z axis.
    let statements = clean(open("cl/creo/bohren_1.ncl.8").with_default_axis([0.0, 0.0, 1.0]));
    let events: Vec<&ClEvent> = statements.iter().map(|s| &s.event).collect();
    assert!(events.contains(&&ClEvent::Comment(
        "-> CSYS / 1.0000000000, 0.0000000000, 0.0000000000, 0.0000000000, 0.0000000000, 1.0000000000, 0.0000000000, 0.0000000000, 0.0000000000, 0.0000000000, 1.0000000000, 0.0000000000".into()
    )));
    assert!(events.contains(&&ClEvent::Machine {
        name: "UNCX01".into(),
        args: vec!["1".into()]
    }));
    assert!(events.contains(&&ClEvent::LoadTool {
        number: 1,
        adjust: None
    }));
    let cycle = events
        .iter()
        .find_map(|e| match e {
            ClEvent::Cycle(c) => Some(c),
            _ => None,
        })
        .unwrap();
    assert_eq!(cycle.kind, CycleKind::Deep);
    assert_eq!((cycle.depth_mm, cycle.peck_mm), (Some(3.5), Some(1.0)));
    // CLEAR 1.0 and no RAPTO: the feed starts 1 mm above the hole.
    assert_eq!((cycle.feed_start_mm, cycle.retract_mm), (Some(1.0), None));
    assert_eq!(
        cycle.feed,
        Some(Feed {
            value: 50.0,
            unit: FeedUnit::Mmpm
        })
    );
}
