//! The program stage on the CL statements beyond `GOTO`: arcs and splines
//! become points within the chord tolerance (checked against the circle
//! and the helix by their own formulas), canned cycles become the moves of
//! their G-code definitions (written out by hand here), stops, dwells, the
//! home move, cutter compensation and surface speeds become commands, and
//! what cannot be posted is a located error.

use kinpost_post::cl::ClReader;
use kinpost_post::machine::builtin;
use kinpost_post::nc::{Dialect, Motion, ProgramInfo, Spindle};
use kinpost_post::plan::PathPoint;
use kinpost_post::program::{Program, ProgramSink};
use kinpost_post::{Command, Config, Pending, PointError, PostError, PostOptions};

/// What the program stage hands on, in order.
#[derive(Debug, Clone, PartialEq)]
enum Out {
    Point {
        p: [f64; 3],
        axis: [f64; 3],
        motion: Motion,
        feed: Option<f64>,
        line: usize,
    },
    Command(Command),
}

#[derive(Default)]
struct Collect(Vec<Out>);

impl ProgramSink for Collect {
    fn start(&mut self, _: &ProgramInfo, _: bool) -> Result<(), PostError> {
        Ok(())
    }
    fn point(&mut self, point: PathPoint, _: &[u8]) -> Result<(), PointError> {
        self.0.push(Out::Point {
            p: point.pose.point.into(),
            axis: point.pose.axis.into(),
            motion: point.motion,
            feed: point.feed,
            line: point.line,
        });
        Ok(())
    }
    fn command(&mut self, pending: Pending) -> Result<(), PostError> {
        self.0.push(Out::Command(pending.command));
        Ok(())
    }
    fn break_segment(&mut self) {}
}

/// The program stage's output of `cl` (lintol `lintol_mm`), or its error.
fn run_with(cl: &str, lintol_mm: f64) -> Result<(Vec<Out>, Vec<String>), PostError> {
    run_options(cl, |o| o.lintol_mm = Some(lintol_mm))
}

/// The program stage's output of `cl` with the options `set` makes.
fn run_options(
    cl: &str,
    set: impl FnOnce(&mut PostOptions),
) -> Result<(Vec<Out>, Vec<String>), PostError> {
    let machine = builtin::load("mts1600").unwrap().unwrap();
    let dialect = Dialect::builtin("linuxcnc").unwrap();
    let mut options = PostOptions {
        cl_file: "t.cls".into(),
        lintol_mm: Some(0.01),
        ..Default::default()
    };
    set(&mut options);
    let config = Config::resolve(&options, &machine, &dialect).unwrap();
    let program = Program::new(&machine, &dialect, &config, Vec::new());
    let mut reader = ClReader::new(cl.as_bytes(), "t.cls");
    let mut sink = Collect::default();
    let report = program.run(&mut reader, &mut sink)?;
    let mut warnings: Vec<String> = report.warnings.iter().map(|w| w.message.clone()).collect();
    warnings.extend(reader.take_warnings().iter().map(|w| w.message.clone()));
    Ok((sink.0, warnings))
}

fn run(cl: &str) -> Vec<Out> {
    run_with(cl, 0.01).unwrap().0
}

fn points(out: &[Out]) -> Vec<([f64; 3], Motion)> {
    out.iter()
        .filter_map(|o| match o {
            Out::Point { p, motion, .. } => Some((*p, *motion)),
            Out::Command(_) => None,
        })
        .collect()
}

/// The commands the program stage hands on, without the markers of the
/// holes of a canned cycle (for the check, never written).
fn commands(out: &[Out]) -> Vec<Command> {
    out.iter()
        .filter_map(|o| match o {
            Out::Command(Command::HoleBegin { .. } | Command::HoleEnd) => None,
            Out::Command(c) => Some(c.clone()),
            Out::Point { .. } => None,
        })
        .collect()
}

fn close(a: [f64; 3], b: [f64; 3]) -> bool {
    (0..3).all(|i| (a[i] - b[i]).abs() < 1e-9)
}

fn error_of(cl: &str) -> String {
    match run_with(cl, 0.01) {
        Err(e) => e.to_string(),
        Ok(_) => panic!("no error for\n{cl}"),
    }
}

/// A quarter arc of radius 10 about (0,0,5), counter-clockwise (APT
/// right-hand rule about +Z): every point on the circle, turning the right
/// way, no chord's sagitta r (1 − cos(δ/2)) above the tolerance, the last
/// one the GOTO itself, all at the GOTO's line.
#[test]
fn a_circle_becomes_points_on_the_arc_within_the_tolerance() {
    let tol = 0.01;
    let cl = "RAPID\nGOTO/10,0,5,0,0,1\nFEDRAT/MMPM,300\nCIRCLE/0,0,5,0,0,1,10\nGOTO/0,10,5\n";
    let out = run_with(cl, tol).unwrap().0;
    let pts = points(&out);
    assert!(pts.len() > 3, "{pts:?}");
    let arc = &pts[1..];
    let mut prev = pts[0].0;
    for (p, motion) in arc {
        assert_eq!(*motion, Motion::Feed);
        let r = (p[0] * p[0] + p[1] * p[1]).sqrt();
        assert!((r - 10.0).abs() < 1e-9, "off the circle: {p:?}");
        assert!((p[2] - 5.0).abs() < 1e-12);
        // Counter-clockwise about +Z: prev × p has a positive z.
        let cross = prev[0] * p[1] - prev[1] * p[0];
        assert!(cross > 0.0);
        let delta = (p[1].atan2(p[0]) - prev[1].atan2(prev[0])).abs();
        assert!(10.0 * (1.0 - (delta / 2.0).cos()) <= tol + 1e-12);
        prev = *p;
    }
    assert_eq!(arc.last().unwrap().0, [0.0, 10.0, 5.0]);
    for o in &out[1..] {
        if let Out::Point { line, axis, .. } = o {
            assert_eq!(*line, 5);
            assert_eq!(*axis, [0.0, 0.0, 1.0]);
        }
    }
    // A finer tolerance needs more points: 2 acos(1 − t/r) per chord.
    let fine = points(&run_with(cl, 0.0001).unwrap().0).len() - 1;
    let expected = (std::f64::consts::FRAC_PI_2 / (2.0 * (1.0 - 0.0001_f64 / 10.0).acos())).ceil();
    assert_eq!(fine as f64, expected);
}

/// A full circle (end = start) and a helix: the helix rises linearly with
/// the angle turned, and ends at the GOTO.
#[test]
fn full_circles_and_helices() {
    let cl = "RAPID\nGOTO/5,0,0,0,0,1\nFEDRAT/MMPM,300\nCIRCLE/0,0,0,0,0,1,5\nGOTO/5,0,0\n";
    let pts = points(&run(cl));
    let angles: Vec<f64> = pts[1..].iter().map(|(p, _)| p[1].atan2(p[0])).collect();
    // It goes all the way round: through every quadrant.
    assert!(angles.iter().any(|a| *a > 1.5 && *a < 1.7));
    assert!(angles.iter().any(|a| a.abs() > 3.0));
    assert!(angles.iter().any(|a| *a < -1.5 && *a > -1.7));
    assert_eq!(pts.last().unwrap().0, [5.0, 0.0, 0.0]);

    let cl = "RAPID\nGOTO/5,0,0,0,0,1\nFEDRAT/MMPM,300\nCIRCLE/0,0,0,0,0,1,5\nGOTO/5,0,-2\n";
    let pts = points(&run(cl));
    let mut turned = 0.0;
    let mut prev = pts[0].0;
    for (p, _) in &pts[1..] {
        let mut d = p[1].atan2(p[0]) - prev[1].atan2(prev[0]);
        if d < 0.0 {
            d += 2.0 * std::f64::consts::PI;
        }
        turned += d;
        // z = −2 · (angle turned) / 2π.
        assert!((p[2] + 2.0 * turned / (2.0 * std::f64::consts::PI)).abs() < 1e-9);
        prev = *p;
    }
    assert!((turned - 2.0 * std::f64::consts::PI).abs() < 1e-9);
}

/// An arc whose end is not on the circle is an error at the GOTO.
#[test]
fn an_end_point_off_the_circle_is_an_error() {
    let e =
        error_of("RAPID\nGOTO/10,0,0,0,0,1\nFEDRAT/MMPM,300\nCIRCLE/0,0,0,0,0,1,10\nGOTO/0,12,0\n");
    assert!(e.contains("CIRCLE"), "{e}");
}

/// G81 as LinuxCNC defines it, with R 3 above the hole, the depth 5
/// below it and a retract to 25 (G98 to the initial level): rapid to
/// above the hole, rapid to R, feed to depth, rapid out. The second hole
/// (1 lower) is reached across at the height the tool is at, then down to
/// its R, and the tool leaves it to 25 above it.
#[test]
fn a_drill_cycle_is_expanded_hole_by_hole() {
    let cl = "RAPID\nGOTO/0,0,25,0,0,1\nFEDRAT/MMPM,500\n\
              CYCLE/DRILL,FEDTO,-5,RAPTO,3,RTRCTO,25,MMPM,100\n\
              GOTO/0,0,0\nGOTO/10,0,-1\nCYCLE/OFF\nRAPID\nGOTO/10,0,50\n";
    let out = run(cl);
    let pts = points(&out);
    let expected = [
        ([0.0, 0.0, 25.0], Motion::Rapid),
        ([0.0, 0.0, 3.0], Motion::Rapid),
        ([0.0, 0.0, -5.0], Motion::Feed),
        ([0.0, 0.0, 25.0], Motion::Rapid),
        ([10.0, 0.0, 25.0], Motion::Rapid),
        ([10.0, 0.0, 2.0], Motion::Rapid),
        ([10.0, 0.0, -6.0], Motion::Feed),
        ([10.0, 0.0, 24.0], Motion::Rapid),
        ([10.0, 0.0, 50.0], Motion::Rapid),
    ];
    assert_eq!(pts.len(), expected.len(), "{pts:?}");
    for (got, want) in pts.iter().zip(&expected) {
        assert!(
            close(got.0, want.0) && got.1 == want.1,
            "{got:?} vs {want:?}"
        );
    }
    // The cycle's own feed, and the FEDRAT again after it.
    let feeds: Vec<Option<f64>> = out
        .iter()
        .filter_map(|o| match o {
            Out::Point {
                motion: Motion::Feed,
                feed,
                ..
            } => Some(*feed),
            _ => None,
        })
        .collect();
    assert_eq!(feeds, [Some(100.0), Some(100.0)]);
}

/// G83 with pecks of 2 from R = 1 to the bottom at −5, with LinuxCNC's
/// 0.254 mm rapid clearance above each previous bottom; and the dwell of a
/// G82.
#[test]
fn peck_cycles_and_dwells() {
    let cl = "RAPID\nGOTO/0,0,10,0,0,1\nFEDRAT/MMPM,500\n\
              CYCLE/DEEP,FEDTO,5,RAPTO,1,STEP,2,MMPM,100\nGOTO/0,0,0\nCYCLE/OFF\n";
    let zs: Vec<(f64, Motion)> = points(&run(cl))[1..]
        .iter()
        .map(|(p, m)| (p[2], *m))
        .collect();
    use Motion::{Feed, Rapid};
    let want = [
        (1.0, Rapid),
        (-1.0, Feed),
        (1.0, Rapid),
        (-1.0 + 0.254, Rapid),
        (-3.0, Feed),
        (1.0, Rapid),
        (-3.0 + 0.254, Rapid),
        (-5.0, Feed),
        (1.0, Rapid),
    ];
    assert_eq!(zs.len(), want.len(), "{zs:?}");
    for (g, w) in zs.iter().zip(&want) {
        assert!((g.0 - w.0).abs() < 1e-9 && g.1 == w.1, "{zs:?}");
    }

    let cl = "RAPID\nGOTO/0,0,10,0,0,1\nFEDRAT/MMPM,500\n\
              CYCLE/DRILL,FEDTO,5,RAPTO,1,DWELL,1.5,MMPM,100\nGOTO/0,0,0\nCYCLE/OFF\n";
    let out = run(cl);
    let dwell_after_bottom = out.windows(2).any(|w| {
        matches!(&w[0], Out::Point { p, .. } if (p[2] + 5.0).abs() < 1e-9)
            && w[1] == Out::Command(Command::Dwell(1.5))
    });
    assert!(dwell_after_bottom, "{out:?}");
}

/// A hole on a tilted axis: the moves run along that axis.
#[test]
fn holes_follow_the_tool_axis() {
    let s = 0.5_f64.sqrt();
    let cl = format!(
        "RAPID\nGOTO/20,0,20,{s},0,{s}\nFEDRAT/MMPM,500\n\
         CYCLE/DRILL,FEDTO,4,RAPTO,2,MMPM,100\nGOTO/0,0,0\nCYCLE/OFF\n"
    );
    let pts = points(&run(&cl));
    // The tool starts 20·√2 above the hole along the axis, on it: down to
    // R (2 along the axis), to −4, back to R.
    let along = |h: f64| [h * s, 0.0, h * s];
    let want = [along(2.0), along(-4.0), along(2.0)];
    assert_eq!(pts.len(), 4, "{pts:?}");
    for (g, w) in pts[1..].iter().zip(&want) {
        assert!(close(g.0, *w), "{pts:?}");
    }
}

/// Tapping reverses the spindle at the bottom and restores it at the top;
/// the feed is the pitch times the speed.
#[test]
fn tapping_reverses_the_spindle() {
    let cl = "SPINDL/500,RPM,CLW\nRAPID\nGOTO/0,0,10,0,0,1\nFEDRAT/MMPM,500\n\
              CYCLE/TAP,FEDTO,6,RAPTO,2,PITCH,1.25\nGOTO/0,0,0\nCYCLE/OFF\n";
    let out = run(cl);
    let cmds = commands(&out);
    assert_eq!(
        cmds,
        [
            Command::Spindle(Spindle::Cw(500.0)),
            Command::Spindle(Spindle::Ccw(500.0)),
            Command::Spindle(Spindle::Cw(500.0)),
        ]
    );
    let feeds: Vec<f64> = out
        .iter()
        .filter_map(|o| match o {
            Out::Point {
                motion: Motion::Feed,
                feed,
                ..
            } => *feed,
            _ => None,
        })
        .collect();
    assert_eq!(feeds, [625.0, 625.0]);
    assert!(
        error_of("RAPID\nGOTO/0,0,10,0,0,1\nCYCLE/TAP,FEDTO,6,RAPTO,2,MMPM,100\nGOTO/0,0,0\n")
            .contains("spindle")
    );
}

/// Stops, dwells, END, in their places.
#[test]
fn stops_and_dwells_are_commands() {
    let cl =
        "RAPID\nGOTO/0,0,10,0,0,1\nSTOP\nOPSTOP\nDELAY/2.5\nSPINDL/600,RPM\nDELAY/3,REV\nEND\n";
    let cmds = commands(&run(cl));
    assert_eq!(
        cmds,
        [
            Command::Stop { optional: false },
            Command::Stop { optional: true },
            Command::Dwell(2.5),
            Command::Spindle(Spindle::Cw(600.0)),
            // 3 revolutions at 600 rpm: 0.3 s.
            Command::Dwell(0.3),
            Command::Spindle(Spindle::Off),
            Command::Coolant(None),
            Command::Stop { optional: false },
        ]
    );
}

/// GOHOME goes back to the FROM point in rapid; with no FROM (and no home
/// in the machine file), an error.
#[test]
fn gohome_returns_to_the_from_point() {
    let cl = "FROM/1,2,30,0,0,1\nFEDRAT/MMPM,100\nGOTO/5,5,0\nGOHOME\n";
    let pts = points(&run(cl));
    assert_eq!(pts.last().unwrap(), &([1.0, 2.0, 30.0], Motion::Rapid));
    assert!(error_of("RAPID\nGOTO/5,5,0,0,0,1\nGOHOME\n").contains("GOHOME"));
}

/// GOHOME with no point and no FROM goes to the machine's home
/// (`[post] home`, NC values): a rapid to the tool pose those values give,
/// written as those values.
#[test]
fn gohome_without_a_point_goes_to_the_machine_home() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/machines/free3.toml");
    let src =
        std::fs::read_to_string(path).unwrap() + "[post]\nhome = { X = 10, Y = 20, Z = 150 }\n";
    let machine = kinpost_post::machine::machine_from_toml(&src, "free3-home.toml").unwrap();
    let dialect = Dialect::builtin("csv").unwrap();
    let options = PostOptions {
        cl_file: "t.cls".into(),
        default_axis: Some([0.0, 0.0, 1.0]),
        ..Default::default()
    };
    let cl = "FEDRAT/MMPM,100\nGOTO/5,5,0\nGOHOME\n";
    let mut out = Vec::new();
    kinpost_post::post(cl.as_bytes(), &machine, &dialect, &mut out, &options).unwrap();
    let text = String::from_utf8(out).unwrap();
    let last = text.lines().last().unwrap();
    assert_eq!(last, "3,rapid,10.000000,20.000000,150.000000,", "{text}");
}

/// A surface speed in rpm from the tool diameter: n = 1000 v / (π d).
#[test]
fn surface_speed_becomes_rpm() {
    let cl = "CUTTER/10\nSPINDL/SMM,100,CLW\n";
    let cmds = commands(&run(cl));
    let Command::Spindle(Spindle::Cw(rpm)) = cmds[0] else {
        panic!("{cmds:?}")
    };
    assert!((rpm - 3183.098861837907).abs() < 1e-9);
    let (out, warnings) = run_with("CUTTER/10\nSPINDL/SMM,100,CLW,MAXRPM,3000\n", 0.01).unwrap();
    assert_eq!(commands(&out), [Command::Spindle(Spindle::Cw(3000.0))]);
    assert!(
        warnings.iter().any(|w| w.contains("MAXRPM")),
        "{warnings:?}"
    );
    assert!(error_of("SPINDL/SMM,100,CLW\n").contains("diameter"));
}

/// CUTCOM: the side and the register (the CL's, else the tool's); OFF only
/// when on; another plane than XY is an error.
#[test]
fn cutter_compensation() {
    let cl =
        "CUTCOM/OFF\nLOAD/TOOL,7\nCUTCOM/LEFT\nCUTCOM/OFF\nCUTCOM/RIGHT,XYPLAN,12\nCUTCOM/OFF\n";
    assert_eq!(
        commands(&run(cl)),
        [
            Command::CutterCompensation(Some((true, 7))),
            Command::CutterCompensation(None),
            Command::CutterCompensation(Some((false, 12))),
            Command::CutterCompensation(None),
        ]
    );
    assert!(error_of("CUTCOM/LEFT,ZXPLAN\n").contains("ZX"));
}

/// CLAMP is a warning with its reason; ORIGIN with an offset an error.
#[test]
fn clamp_warns_and_origin_refuses() {
    let (_, warnings) = run_with("CLAMP/ON,AAXIS\n", 0.01).unwrap();
    assert!(warnings.iter().any(|w| w.contains("CLAMP")), "{warnings:?}");
    assert!(error_of("ORIGIN/10,0,0\n").contains("ORIGIN"));
    assert!(run_with("ORIGIN/0,0,0\n", 0.01).is_ok());
}

/// A cubic NURBS: points on the curve (a quarter-circle-like Bézier here,
/// checked against the Bernstein form), the last the curve's end.
#[test]
fn nurbs_become_points_on_the_curve() {
    let cl = "RAPID\nGOTO/0,0,0,0,0,1\nFEDRAT/MMPM,100\nNURBS/\nKNOT/1\nCNTRL/1,2,0\nCNTRL/3,2,0\nCNTRL/4,0,0\n";
    let pts = points(&run_with(cl, 0.001).unwrap().0);
    assert!(pts.len() > 3, "{pts:?}");
    assert_eq!(pts.last().unwrap().0, [4.0, 0.0, 0.0]);
    // Bézier with control points (0,0) (1,2) (3,2) (4,0): x(t) = 3t + 3t²
    // − 2t³… solve x for t by bisection and compare y.
    let bez = |t: f64| {
        let b = [
            (1.0 - t).powi(3),
            3.0 * t * (1.0 - t).powi(2),
            3.0 * t * t * (1.0 - t),
            t.powi(3),
        ];
        let xs = [0.0, 1.0, 3.0, 4.0];
        let ys = [0.0, 2.0, 2.0, 0.0];
        (
            (0..4).map(|i| b[i] * xs[i]).sum::<f64>(),
            (0..4).map(|i| b[i] * ys[i]).sum::<f64>(),
        )
    };
    for (p, _) in &pts[1..] {
        let (mut lo, mut hi) = (0.0, 1.0);
        for _ in 0..80 {
            let mid = 0.5 * (lo + hi);
            if bez(mid).0 < p[0] {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        assert!((bez(lo).1 - p[1]).abs() < 1e-9, "{p:?}");
    }
}

/// INSERT: verbatim with a warning when it moves an axis or changes a
/// tool; a comment or nothing when asked.
#[test]
fn inserts_that_move_are_warned_about() {
    let moving = [
        "INSERT/Stock Size X293.7 Y100. Z9.",
        "INSERT/G0 Z100",
        "INSERT/X10Y20",
        "INSERT/T5 M6",
        "INSERT/X=12.5",
    ];
    let passive = [
        "INSERT/M08",
        "INSERT/[HOLDER=C40-32ERP412] 6MM CRB 2FL 19 LOC",
        "INSERT/(MSG, CHECK THE CLAMPS)",
        "INSERT/G17 G90",
    ];
    for line in moving {
        let (out, warnings) = run_with(&format!("{line}\n"), 0.01).unwrap();
        assert!(warnings.iter().any(|w| w.contains("INSERT")), "{line}");
        assert!(matches!(commands(&out)[..], [Command::Insert(_)]));
    }
    for line in passive {
        let (_, warnings) = run_with(&format!("{line}\n"), 0.01).unwrap();
        assert!(warnings.is_empty(), "{line}: {warnings:?}");
    }
}

/// Two setups: the second `MSYS` turns the MCS 90° about Z and moves it
/// to (100, 0, 50). `--frame mcs` posts points as written and stops at the
/// second `MSYS`, naming `--frame absolute`; `--frame absolute` maps the
/// points, axes and circles of each setup into the absolute frame (an
/// origin-only `MSYS` moves them; one with a single axis is an error).
#[test]
fn frame_absolute_posts_every_setup_in_the_absolute_frame() {
    let cl = "MSYS/0,0,0,1,0,0,0,1,0\nRAPID\nGOTO/10,0,5,0,0,1\n\
              MSYS/100,0,50,0,1,0,-1,0,0\nRAPID\nGOTO/10,0,5,0,0,1\nFEDRAT/MMPM,200\n\
              GOTO/10,0,0\nCIRCLE/0,0,0,0,0,1,10\nGOTO/0,10,0\n\
              MSYS/-5,0,0\nGOTO/20,0,0,0,0.6,0.8\nFINI\n";
    let e = run_options(cl, |_| {}).unwrap_err().to_string();
    assert!(e.contains("--frame absolute"), "{e}");
    let (out, _) = run_options(cl, |o| o.frame = kinpost_post::FrameMode::Absolute).unwrap();
    let pts = points(&out);
    assert!(close(pts[0].0, [10.0, 0.0, 5.0]), "{pts:?}");
    // (10, 0, 5) in the turned MCS: x along absolute Y.
    assert!(close(pts[1].0, [100.0, 10.0, 55.0]), "{pts:?}");
    assert!(close(pts[2].0, [100.0, 10.0, 50.0]), "{pts:?}");
    // The arc about the MCS origin, (100, 0, 50), from its X to its Y
    // (absolute Y to absolute −X): on the circle all the way.
    let arc: Vec<[f64; 3]> = pts[3..pts.len() - 1].iter().map(|p| p.0).collect();
    for p in &arc {
        let r = (p[0] - 100.0).hypot(p[1]);
        assert!(
            (r - 10.0).abs() < 0.011 && (p[2] - 50.0).abs() < 1e-9,
            "{p:?}"
        );
    }
    assert!(close(*arc.last().unwrap(), [90.0, 0.0, 50.0]), "{arc:?}");
    // An origin alone: moved, not turned; the axis as written.
    let Some(Out::Point { p, axis, .. }) = out.last() else {
        panic!()
    };
    assert!(
        close(*p, [15.0, 0.0, 0.0]) && close(*axis, [0.0, 0.6, 0.8]),
        "{p:?} {axis:?}"
    );
    let half = "MSYS/0,0,0,1,0,0\nGOTO/1,2,3,0,0,1\nFINI\n";
    let e = run_options(half, |o| o.frame = kinpost_post::FrameMode::Absolute)
        .unwrap_err()
        .to_string();
    assert!(e.contains("no complete frame"), "{e}");
}
