//! Replays whose findings are worked out by hand (or from LinuxCNC's
//! `rs274 -g`, an independent reading of the same program): travel beyond
//! the limits inside arcs and at block ends, machine coordinates through
//! `machine_offset`, run times from feeds, inverse time, rapids and dwells.

use std::process::Command;

use kinpost_machine::{Machine, builtin, machine_from_toml};
use kinpost_nc::interp::Family;
use kinpost_sim::{SimOptions, SimReport, simulate};

fn trunnion() -> Machine {
    builtin::load("trunnion-ac").unwrap().unwrap()
}

fn run(text: &str, m: &Machine) -> SimReport {
    let options = SimOptions {
        collisions: false,
        ..SimOptions::default()
    };
    simulate(
        text,
        Family::LinuxCnc,
        "t.ngc",
        m,
        &options,
        None,
        &mut |_| {},
    )
    .unwrap_or_else(|e| panic!("{e}"))
}

/// trunnion-ac: Y travel ±250, A −30..120 (its machine file).
const ARCS: &str = "G21 G90 G17 G94
G0 X0 Y240 Z100 A0 C0
G3 X-40 Y240 I-20 J0 F1000
G3 X0 Y240 I20 J0
G1 A130
G1 A0
M2
";

#[test]
fn an_arc_that_bulges_past_the_travel_is_found_inside_the_block() {
    let r = run(ARCS, &trunnion());
    let found: Vec<(usize, &str)> = r
        .overtravel
        .iter()
        .map(|o| (o.at.line, o.axis.as_str()))
        .collect();
    // Line 3: the half circle about (-20, 240), radius 20, counter-
    // clockwise from angle 0 to 180°, tops out at Y = 260: 10 mm past 250,
    // though both its ends are at Y 240. Line 4 goes round below (Y 220).
    // Line 5: A130 is 10° past 120; line 6 comes back and is not charged.
    assert_eq!(found, [(3, "Y"), (5, "A")], "{:?}", r.overtravel);
    let (y, a) = (&r.overtravel[0], &r.overtravel[1]);
    assert!((y.value - 260.0).abs() < 1e-9 && (y.excess - 10.0).abs() < 1e-9);
    assert!(y.between_ends);
    assert_eq!(y.limits, [-250.0, 250.0]);
    assert!((a.value - 130.0).abs() < 1e-9 && (a.excess - 10.0).abs() < 1e-9);
    assert!(!a.between_ends);
    assert_eq!((y.at.block, a.at.block), (2, 4));
}

/// The arcs as LinuxCNC's own interpreter reads them: `ARC_FEED(first_end,
/// second_end, first_axis, second_axis, rotation, ...)` gives the centre
/// and the turning sense; the highest Y of a counter-clockwise half turn
/// from angle 0 is centre + radius.
#[test]
fn rs274_agrees_on_the_arc_top() {
    let dir = std::env::temp_dir().join(format!("kinpost-sim-rs274-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("arcs.ngc");
    std::fs::write(&file, ARCS).unwrap();
    let Ok(out) = Command::new("rs274").arg("-g").arg(&file).output() else {
        eprintln!("rs274 is not installed: skipped");
        return;
    };
    let text = String::from_utf8_lossy(&out.stdout);
    let arcs: Vec<Vec<f64>> = text
        .lines()
        .filter_map(|l| l.split_once("ARC_FEED(").map(|(_, r)| r))
        .map(|r| {
            r.trim_end_matches(')')
                .split(',')
                .map(|v| v.trim().parse().unwrap())
                .collect()
        })
        .collect();
    assert_eq!(arcs.len(), 2, "{text}");
    // First arc: start (0, 240), centre (a[2], a[3]), rotation a[4] > 0
    // (counter-clockwise), end (a[0], a[1]) on the other side of the centre.
    let a = &arcs[0];
    let radius = (0.0 - a[2]).hypot(240.0 - a[3]);
    assert!(a[4] > 0.0 && a[0] < a[2]);
    let top = a[3] + radius;
    let r = run(ARCS, &trunnion());
    assert!((r.overtravel[0].value - top).abs() < 1e-9, "{top}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn limits_are_reported_in_machine_coordinates() {
    // The trunnion with X's travel given in machine coordinates: 0..760
    // with the work offset 380 (NC −380..380).
    let src = builtin::source("trunnion-ac").unwrap();
    let at = src.find("limits = [-380, 380]").unwrap();
    let src = format!(
        "{}limits = [0, 760]\nmachine_offset = 380{}",
        &src[..at],
        &src[at + "limits = [-380, 380]".len()..]
    );
    let m = machine_from_toml(&src, "t.toml").unwrap();
    let r = run(
        "G21 G90\nG0 X0 Y0 Z100 A0 C0\nG1 X390 F1000\nG1 X-385\nM2\n",
        &m,
    );
    let found: Vec<(usize, f64, [f64; 2], f64)> = r
        .overtravel
        .iter()
        .map(|o| (o.at.line, o.value, o.limits, o.excess))
        .collect();
    // NC 390 is machine 770, 10 past 760; NC −385 is machine −5.
    assert_eq!(
        found,
        [(3, 770.0, [0.0, 760.0], 10.0), (4, -5.0, [0.0, 760.0], 5.0)]
    );
}

#[test]
fn run_time_from_feeds_inverse_time_rapids_and_dwells() {
    let r = run(
        "G21 G90 G17 G94
G0 X0 Y0 Z100 A0 C0
G1 X30 Y40 F600
G93 G1 X0 Y0 F2
G94 G0 X100
G4 P1.5
G3 X60 Y0 I-20 J0 F1000
G1 A90 F900
M2
",
        &trunnion(),
    );
    // Rapid Z 0 → 100 at the assumed 10 000 mm/min: 0.6 s. 50 mm at
    // 600 mm/min: 5 s. Inverse time F2: 30 s. Rapid X 0 → 100: 0.6 s.
    // Dwell 1.5 s. Half circle of radius 20 (62.83 mm) at 1000 mm/min:
    // 3.7699 s. A 90° alone at 900 degrees/min: 6 s.
    let want = 0.6 + 5.0 + 30.0 + 0.6 + 1.5 + 20.0 * std::f64::consts::PI / 1000.0 * 60.0 + 6.0;
    assert!(
        (r.duration_s - want).abs() < 1e-9,
        "{} {want}",
        r.duration_s
    );
    assert!(r.assumed.iter().any(|a| a.contains("10000 mm/min")));
    assert!(r.overtravel.is_empty(), "{:?}", r.overtravel);
}

#[test]
fn a_locked_axis_moved_by_the_program_is_past_its_travel() {
    // head-head-bc or any machine with an axis locked without a reference:
    // built here by locking A of the trunnion at 0.
    let src = builtin::source("trunnion-ac").unwrap();
    let at = src.find("limits = [-30, 120]").unwrap();
    let src = format!("{}fixed = 0\n{}", &src[..at], &src[at..]);
    let m = machine_from_toml(&src, "t.toml").unwrap();
    let r = run("G21 G90\nG0 X0 Y0 Z100 C0\nG1 A5 F100\nM2\n", &m);
    let found: Vec<(usize, &str, [f64; 2])> = r
        .overtravel
        .iter()
        .map(|o| (o.at.line, o.axis.as_str(), o.limits))
        .collect();
    assert_eq!(found, [(3, "A", [0.0, 0.0])]);
}

/// The CL's arcs are arcs in the comparison: a program that cuts the
/// quarter circle with G3 lies on it; one that cuts its chord with G1 is
/// off it by the sagitta r (1 − cos 45°) at the middle.
#[test]
fn cl_arcs_are_compared_as_arcs() {
    use kinpost_machine::Kinematics;
    use kinpost_sim::ClPath;
    let m = trunnion();
    let kin = Kinematics::new(&m);
    // At A0 C0 the part frame is the machine's moved by b: X Y Z move the
    // tool point by themselves (checked).
    let b = kin.fk(&[0.0; 5]).point;
    let x1 = kin.fk(&[1.0, 0.0, 0.0, 0.0, 0.0]).point - b;
    let y1 = kin.fk(&[0.0, 1.0, 0.0, 0.0, 0.0]).point - b;
    assert!(
        (x1 - nalgebra::Vector3::x()).norm() < 1e-12
            && (y1 - nalgebra::Vector3::y()).norm() < 1e-12
    );
    let cl = format!(
        "GOTO/{:.6},{:.6},{:.6},0,0,1\nCIRCLE/{:.6},{:.6},{:.6},0,0,1,10\nGOTO/{:.6},{:.6},{:.6},0,0,1\n",
        b.x + 10.0,
        b.y,
        b.z,
        b.x,
        b.y,
        b.z,
        b.x,
        b.y + 10.0,
        b.z
    );
    let options = SimOptions {
        collisions: false,
        ..SimOptions::default()
    };
    let dev = |program: &str| {
        let path = ClPath::read(cl.as_bytes(), "arc.cls").unwrap();
        simulate(
            program,
            Family::LinuxCnc,
            "a.ngc",
            &m,
            &options,
            Some(path),
            &mut |_| {},
        )
        .unwrap()
        .max_position_error_mm
        .unwrap()
    };
    let on_arc = dev("G21 G90 G17\nG0 X10 Y0 Z0 A0 C0\nG3 X0 Y10 I-10 J0 F500\nM2\n");
    assert!(on_arc < 1e-4, "{on_arc}");
    let chord = dev("G21 G90 G17\nG0 X10 Y0 Z0 A0 C0\nG1 X0 Y10 F500\nM2\n");
    let sagitta = 10.0 * (1.0 - std::f64::consts::FRAC_1_SQRT_2);
    assert!((chord - sagitta).abs() < 1e-4, "{chord} vs {sagitta}");
}

/// The trunnion's singular direction is the C axis (A = 0: C turns the
/// part about the tool axis). A block that tilts A through 0 passes it
/// (least angle 0, within the machine's 0.5° cone), a warning at its
/// line; the next block (A 10° to 20°) stays clear; consecutive passing
/// blocks are one passage. Not a violation.
#[test]
fn a_tilt_through_the_singular_direction_is_a_singular_passage() {
    let r = run(
        "G21 G90 G94\nG0 X0 Y0 Z100 A-10 C0\nG1 A10 C30 F1000\nG1 A20\nG1 A-0.2 C40\nG1 A0.3 C50\nM2\n",
        &trunnion(),
    );
    let found: Vec<(usize, u64, &str, f64)> = r
        .singular_passages
        .iter()
        .map(|p| (p.at.line, p.last_block, p.axis.as_str(), p.turn_deg))
        .collect();
    assert_eq!(
        found,
        [(3, 2, "C", 30.0), (5, 5, "C", 20.0)],
        "{:?}",
        r.singular_passages
    );
    assert!(r.singular_passages[0].angle_deg < 1e-9);
    // A -0.2° and 0.3° (blocks 4 and 5 of lines 5 and 6): one passage,
    // its least angle 0 where A crosses 0 in line 6.
    assert!(r.singular_passages[1].angle_deg < 1e-9);
    assert!(!r.violated());
    assert!(
        r.summary()
            .contains("warning: line 3: the tool axis passes")
    );
}
