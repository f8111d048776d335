//! Collisions along the replayed path on `mts1600` (its solids: the table
//! flange, the fixtures of the flat-part test, the belt head, the arm and
//! the wheel): a rapid through the fixture is a collision at the block that
//! touches, naming both solids; a feed that stops short of it inside the
//! warning clearance is a near miss, a warning.

use kinpost_collide::{Motion, World};
use kinpost_machine::builtin;
use kinpost_nc::interp::Family;
use kinpost_sim::{SimOptions, SimReport, simulate};

fn run(text: &str) -> SimReport {
    let m = builtin::load("mts1600").unwrap().unwrap();
    simulate(
        text,
        Family::LinuxCnc,
        "c.ngc",
        &m,
        &SimOptions::default(),
        None,
        &mut |_| {},
    )
    .unwrap_or_else(|e| panic!("{e}"))
}

/// Whether the wheel touches anything at B (X, Y, Z of Qiao et al.
/// Figure 28's first point), by the world alone.
fn wheel_touches(b: f64) -> bool {
    let m = builtin::load("mts1600").unwrap().unwrap();
    let world = World::new(&m).unwrap();
    let mut q = m.home_joints();
    for (axis, v) in [("X", 459.0), ("Y", 8.807), ("Z", 361.368), ("B", b)] {
        q[m.axis_index(axis).unwrap()] = v;
    }
    world
        .check_pose(&q, Motion::Feed)
        .iter()
        .any(|c| c.kind.is_error() && c.solids.iter().any(|s| &**s == "wheel"))
}

const START: &str = "G21 G90 G94\nG1 X459 Y8.807 Z361.368 A0 B0 C0 F5000\n";

fn names(c: &kinpost_sim::Contact) -> [&str; 2] {
    [c.solids[0].as_str(), c.solids[1].as_str()]
}

#[test]
fn a_rapid_through_the_fixture_is_a_collision_at_its_block() {
    // X 80 puts the right fixture under the wheel (and is past the X
    // travel: reported too).
    let r = run(&format!("{START}G0 X80\nG0 X459\nM2\n"));
    // Every collision starts in line 3, the rapid that goes in; the one
    // back out (line 4) is the same contact, not a new one.
    assert!(!r.collisions.is_empty());
    assert!(
        r.collisions
            .iter()
            .all(|c| c.at.line == 3 && c.last_block == 3),
        "{:?}",
        r.collisions
    );
    assert!(
        r.collisions
            .iter()
            .any(|c| names(c) == ["wheel", "right-upper-jaw"] && c.kind == "collision")
    );
    assert!(r.violated());
}

#[test]
fn tilting_the_wheel_into_the_jaw_is_a_collision_inside_the_block() {
    let r = run(&format!("{START}G1 B10\nG1 B0\nM2\n"));
    assert!(r.overtravel.is_empty());
    let found: Vec<(usize, [&str; 2], &str)> = r
        .collisions
        .iter()
        .map(|c| (c.at.line, names(c), c.kind))
        .collect();
    assert_eq!(found, [(3, ["wheel", "left-upper-jaw"], "collision")]);
    let c = &r.collisions[0];
    // It touches between B 0 and B 4.52 (single poses), well before the
    // block's end at B 10.
    assert!(c.fraction > 0.0 && c.fraction < 0.452, "{c:?}");
    assert!(c.penetration_mm.is_some_and(|p| p > 0.0), "{c:?}");
}

#[test]
fn stopping_short_inside_the_warning_clearance_is_a_near_miss() {
    // The B at which the wheel first touches (the left fixture's upper
    // jaw), by bisection on single poses.
    let (mut clear, mut hit) = (0.0, 4.52);
    assert!(!wheel_touches(clear) && wheel_touches(hit));
    while hit - clear > 1e-7 {
        let mid = 0.5 * (clear + hit);
        if wheel_touches(mid) {
            hit = mid;
        } else {
            clear = mid;
        }
    }
    // 0.02° short of touching: the wheel's points move less than 0.2 mm
    // (0.02° at the half metre the wheel lies from the B line at most):
    // inside the 2 mm warning clearance, outside the 0 mm error clearance.
    let r = run(&format!("{START}G1 B{:.6}\nM2\n", clear - 0.02));
    assert!(r.collisions.is_empty(), "{:?}", r.collisions);
    let found: Vec<(usize, [&str; 2], &str)> = r
        .near_misses
        .iter()
        .map(|c| (c.at.line, names(c), c.kind))
        .collect();
    assert_eq!(found, [(3, ["wheel", "left-upper-jaw"], "near_miss")]);
    let d = r.near_misses[0].distance_mm;
    assert!(d > 0.0 && d <= 0.2, "{d}");
    assert!(!r.violated(), "{:?}", r.overtravel);
}

/// A ball on the tool passing a post: the nearest approach is in the
/// middle of the block (11 mm between the axes, 1 mm between the
/// surfaces), well after the first pose inside the 3 mm warning
/// clearance: the near miss reports the nearest distance, not the
/// distance where the sweep first came within the clearance.
#[test]
fn a_near_miss_reports_the_nearest_approach_along_the_block() {
    let src = r#"
name = "pass-by"
[[axis]]
name = "X"
kind = "linear"
side = "tool"
direction = [1, 0, 0]
[[axis]]
name = "Y"
kind = "linear"
side = "tool"
direction = [0, 1, 0]
[[axis]]
name = "Z"
kind = "linear"
side = "tool"
direction = [0, 0, 1]
[workpiece]
origin = [0, 0, 0]
x = [1, 0, 0]
z = [0, 0, 1]
[tool]
point = [0, 0, 0]
axis = [0, 0, 1]
[[solid]]
name = "ball"
on = "tool"
sphere = { radius = 5 }
[[solid]]
name = "post"
on = "base"
cylinder = { radius = 5, height = 100 }
origin = [0, 20, -50]
[collision]
warning_clearance = 3
error_clearance = 0
"#;
    let m = kinpost_machine::machine_from_toml(src, "pass-by.toml").unwrap();
    let r = simulate(
        "G21 G90 G94\nG1 X-50 Y9 Z0 F1000\nG1 X50\nM2\n",
        Family::LinuxCnc,
        "p.ngc",
        &m,
        &SimOptions::default(),
        None,
        &mut |_| {},
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert!(r.collisions.is_empty(), "{:?}", r.collisions);
    assert_eq!(r.near_misses.len(), 1, "{:?}", r.near_misses);
    let c = &r.near_misses[0];
    assert_eq!((c.at.line, names(c)), (3, ["ball", "post"]));
    // (The post is a 48-sided prism up to 0.21 % of its radius larger
    // than the cylinder.)
    assert!((c.distance_mm - 1.0).abs() < 0.02, "{}", c.distance_mm);
    // It first came within the clearance about 6.9 mm before the axis.
    assert!(c.fraction < 0.5, "{}", c.fraction);
}
