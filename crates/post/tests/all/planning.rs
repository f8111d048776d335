//! Whole-path planning: passing through and near the singular
//! direction of a table/table machine, retract and reconfiguration where
//! the travel forces a flip, and the linearization property over random
//! machines.

use kinpost_post::machine::{Kinematics, Machine, Pose, builtin, machine_from_toml};
use kinpost_post::nc::Dialect;
use kinpost_post::{PostError, PostOptions, Summary, post};
use nalgebra::Vector3;
use proptest::prelude::*;

use crate::rng::{self, Rng, Shape, spanning_directions};

fn post_csv(
    machine: &Machine,
    cl: &str,
    options: &PostOptions,
) -> Result<(String, Summary), PostError> {
    let dialect = Dialect::builtin("csv").unwrap();
    let mut out = Vec::new();
    let summary = post(cl.as_bytes(), machine, &dialect, &mut out, options)?;
    Ok((String::from_utf8(out).unwrap(), summary))
}

/// A row of a csv program: CL line (None for an inserted block), motion,
/// axis values in machine order.
type Row = (Option<usize>, String, Vec<f64>);

/// The rows of a csv program.
fn rows(csv: &str, n: usize) -> Vec<Row> {
    csv.lines()
        .skip(1)
        .map(|r| {
            let f: Vec<&str> = r.split(',').collect();
            (
                f[0].parse().ok(),
                f[1].to_string(),
                f[2..2 + n].iter().map(|v| v.parse().unwrap()).collect(),
            )
        })
        .collect()
}

fn goto(p: &Vector3<f64>, a: &Vector3<f64>) -> String {
    format!(
        "GOTO/{:.6},{:.6},{:.6},{:.12},{:.12},{:.12}\n",
        p.x, p.y, p.z, a.x, a.y, a.z
    )
}

/// A pass along X on the trunnion's table whose tool axis tilts in the XZ
/// plane from +20° to −20°, `offset_deg` beside the pole (the C axis, +Z).
fn pole_pass(offset_deg: f64) -> (String, Vec<Vector3<f64>>) {
    tilted_pass((0..=80).map(|k| (20.0 - 0.5 * f64::from(k), offset_deg)), 0)
}

/// A pass along X on the trunnion's table whose tool axis takes the
/// `tilts` (degrees about Y, then about X) one point a millimetre, at feed
/// but for a rapid to point `rapid_at`.
fn tilted_pass(
    tilts: impl Iterator<Item = (f64, f64)>,
    rapid_at: usize,
) -> (String, Vec<Vector3<f64>>) {
    let mut cl = String::from("FEDRAT/MMPM,1000\n");
    let mut axes = Vec::new();
    for (k, (x, y)) in tilts.enumerate() {
        if k == rapid_at {
            cl.push_str("RAPID\n");
        }
        let (x, y) = (x.to_radians(), y.to_radians());
        let axis = Vector3::new(x.sin() * y.cos(), y.sin(), x.cos() * y.cos()).normalize();
        cl.push_str(&goto(&Vector3::new(-40.0 + k as f64, 15.0, 5.0), &axis));
        axes.push(axis);
    }
    (cl, axes)
}

/// Posts `cl` on `m` with the defaults, without a reconfiguration or a
/// tool axis held off the CL: the rows of the CL points.
fn posts_exactly(m: &Machine, cl: &str) -> (Vec<Row>, Summary) {
    let (csv, summary) = post_csv(m, cl, &PostOptions::default()).unwrap();
    assert!(summary.planning.reconfigurations.is_empty());
    assert!(
        summary.planning.singular_stretches.is_empty(),
        "{:?}",
        summary.planning.singular_stretches
    );
    let cl_rows = rows(&csv, m.axes.len())
        .into_iter()
        .filter(|r| r.0.is_some())
        .collect();
    (cl_rows, summary)
}

#[test]
fn through_the_pole_a_changes_sign_and_c_stays() {
    let m = builtin::load("trunnion-ac").unwrap().unwrap();
    let (ia, ic) = (m.axis_index("A").unwrap(), m.axis_index("C").unwrap());
    let (cl, axes) = pole_pass(0.0);
    let (csv, summary) = post_csv(&m, &cl, &PostOptions::default()).unwrap();
    assert!(summary.planning.reconfigurations.is_empty());
    let cl_rows: Vec<_> = rows(&csv, m.axes.len())
        .into_iter()
        .filter(|r| r.0.is_some())
        .collect();
    assert_eq!(cl_rows.len(), axes.len());
    for k in 1..cl_rows.len() {
        let turn = axes[k].angle(&axes[k - 1]).to_degrees();
        let (a0, a1) = (cl_rows[k - 1].2[ia], cl_rows[k].2[ia]);
        let (c0, c1) = (cl_rows[k - 1].2[ic], cl_rows[k].2[ic]);
        // The tool axis turns by 0.5° per point: A follows it, C does not
        // move (no 180° flip of C, no flip of A).
        assert!(
            (a1 - a0).abs() <= turn + 2e-6,
            "row {k}: A {a0} -> {a1}, turn {turn}"
        );
        assert!((c1 - c0).abs() <= 2e-6, "row {k}: C {c0} -> {c1}");
    }
    // The pole point itself is a singular stretch, with C held.
    assert_eq!(summary.planning.singular_stretches.len(), 1);
    let s = &summary.planning.singular_stretches[0];
    assert_eq!(s.axis, "C");
    assert!(s.max_axis_deviation_deg <= 0.5);
    assert!(summary.max_position_error_mm <= summary.tolerance_mm);
}

/// With A limited to −10° a pass through (or 0.2° beside) the pole cannot
/// go on with A negative: C turns half a turn where the tool axis passes
/// the pole and A stays positive, without a retract. (C turns without end:
/// the inverse kinematics offers both turns of a configuration half a turn
/// from the hint; with the nearest alone, the branch the path needs flipped
/// by a whole turn from point to point with the rounding, and the planner
/// retracted when A reached its limit.)
#[test]
fn through_the_pole_with_a_short_a_c_turns_instead_of_a_retract() {
    let m = trunnion_with_a("[-10, 120]");
    let (ia, ic) = (m.axis_index("A").unwrap(), m.axis_index("C").unwrap());
    assert_eq!(m.axes[ia].limits, Some([-10.0, 120.0]));
    for offset in [0.0, 0.2] {
        let (cl, _) = pole_pass(offset);
        let (csv, summary) = post_csv(&m, &cl, &PostOptions::default()).unwrap();
        assert!(
            summary.planning.reconfigurations.is_empty(),
            "offset {offset}: {:?}",
            summary.planning.reconfigurations
        );
        let all = rows(&csv, m.axes.len());
        assert!(all.iter().all(|r| r.2[ia] >= 0.0), "offset {offset}: A < 0");
        let c_travel: f64 = all
            .windows(2)
            .map(|w| (w[1].2[ic] - w[0].2[ic]).abs())
            .sum();
        assert!(
            (170.0..=180.0 + 1e-3).contains(&c_travel),
            "offset {offset}: C travels {c_travel}°"
        );
    }
}

#[test]
fn near_the_pole_c_turns_no_more_than_the_pass_needs() {
    let m = builtin::load("trunnion-ac").unwrap().unwrap();
    let kin = Kinematics::new(&m);
    let (ia, ic) = (m.axis_index("A").unwrap(), m.axis_index("C").unwrap());
    for offset in [0.2, 1.0] {
        let (cl, axes) = pole_pass(offset);
        let (csv, summary) = post_csv(&m, &cl, &PostOptions::default()).unwrap();
        assert!(summary.planning.reconfigurations.is_empty());
        let all = rows(&csv, m.axes.len());
        let cl_rows: Vec<_> = all.iter().filter(|r| r.0.is_some()).collect();
        assert_eq!(cl_rows.len(), axes.len());
        // Going around the pole turns C by half a turn in all; nothing more.
        let c_travel: f64 = all
            .windows(2)
            .map(|w| (w[1].2[ic] - w[0].2[ic]).abs())
            .sum();
        assert!(
            c_travel <= 180.0 + 1e-3,
            "offset {offset}: C travels {c_travel}°"
        );
        for w in all.windows(2) {
            assert!(
                (w[1].2[ia] - w[0].2[ia]).abs() <= 0.5 + 1e-6,
                "A steps by more than the tilt"
            );
        }
        // Round trip: every CL point is reached, the tool axis within the
        // cone where the stretch holds C, within the check tolerance elsewhere.
        let held: Vec<(usize, usize)> = summary
            .planning
            .singular_stretches
            .iter()
            .map(|s| (s.first_line, s.last_line))
            .collect();
        assert_eq!(held.is_empty(), offset > 0.5, "offset {offset}: {held:?}");
        for (k, row) in cl_rows.iter().enumerate() {
            let got = kin.fk(&row.2);
            let line = row.0.unwrap();
            let angle = got.axis.angle(&axes[k]);
            let in_stretch = held.iter().any(|&(a, b)| (a..=b).contains(&line));
            let limit = if in_stretch {
                0.5f64.to_radians()
            } else {
                summary.tolerance_rad
            };
            assert!(
                angle <= limit + 1e-9,
                "offset {offset} line {line}: {angle} rad"
            );
        }
    }
}

/// The tool axis tilts towards the pole 0.45° beside it, turns at 0.46°
/// from it (inside the 0.5° cone) and tilts away at right angles: the
/// exact C turns by 41° and then 6.5° while the tool axis turns by 0.5°,
/// no faster than at the edge of the cone (0.5° / sin 0.5° = 57°). The
/// corner is written as the CL has it, not with C held between its
/// neighbours (which put its tool axis 0.13° off).
#[test]
fn a_point_in_the_cone_whose_exact_angle_does_not_swing_is_not_held() {
    let m = builtin::load("trunnion-ac").unwrap().unwrap();
    let kin = Kinematics::new(&m);
    let ic = m.axis_index("C").unwrap();
    let tilts = (0..=40)
        .map(|k| (20.1 - 0.5 * f64::from(k), 0.45))
        .chain((1..=40).map(|k| (0.1, 0.45 + 0.5 * f64::from(k))));
    let (cl, axes) = tilted_pass(tilts, 0);
    let (cl_rows, summary) = posts_exactly(&m, &cl);
    assert_eq!(cl_rows.len(), axes.len());
    for (k, row) in cl_rows.iter().enumerate() {
        let angle = kin.fk(&row.2).axis.angle(&axes[k]);
        assert!(
            angle <= summary.tolerance_rad,
            "line {:?}: the tool axis {angle} rad off",
            row.0
        );
    }
    let steps: Vec<f64> = cl_rows
        .windows(2)
        .map(|w| (w[1].2[ic] - w[0].2[ic]).abs())
        .collect();
    assert!(steps.iter().all(|&s| s < 57.0), "{steps:?}");
}

/// A program that starts 0.32° beside the pole and tilts away from it to
/// 40°: A cannot go below −30°, so the cut takes A positive and C about
/// 170°. A second cut, after a rapid, tilts the other way (A positive, C
/// about 0°) and ends where the planner stands when it solves the first
/// point, which lies in the cone: it is solved from the point after it,
/// on the branch of its cut. (Solved nearest the planner's last point, it
/// fell on the other branch, so C was held instead, 0.06° off.)
#[test]
fn a_program_that_starts_in_the_cone_starts_on_the_branch_of_its_cut() {
    let m = builtin::load("trunnion-ac").unwrap().unwrap();
    let kin = Kinematics::new(&m);
    let ia = m.axis_index("A").unwrap();
    let tilts = (0..=80)
        .map(|k| -0.3 - 0.5 * f64::from(k))
        .chain((0..=20).map(|k| 40.0 + 0.5 * f64::from(k)));
    let (cl, axes) = tilted_pass(tilts.map(|y| (0.1, y)), 81);
    let (cl_rows, summary) = posts_exactly(&m, &cl);
    let first = &cl_rows[0];
    assert!(first.2[ia] > 0.0, "{first:?}");
    let angle = kin.fk(&first.2).axis.angle(&axes[0]);
    assert!(angle <= summary.tolerance_rad, "{angle} rad off");
}

/// A rapid to a tool axis that CL rounding put 0.0057° beside the pole:
/// solved exactly it needs C at 90° (the axis leans towards X), a quarter
/// turn from where the cut before it left C; the rapid keeps C where it was
/// and holds it (the axis 0.0057° off, reported as a stretch), as it did
/// before points in the cone were written exactly where they can be.
#[test]
fn a_rapid_a_hair_beside_the_pole_does_not_swing_the_free_angle() {
    let m = builtin::load("trunnion-ac").unwrap().unwrap();
    let ic = m.axis_index("C").unwrap();
    let cl = "FEDRAT/MMPM,1000\n\
              GOTO/0,10,36,0,0,1\n\
              GOTO/4,10,36,0,0,1\n\
              RAPID\n\
              GOTO/4,10,40,0.0001,0,0.9999\n";
    let (csv, summary) = post_csv(&m, cl, &PostOptions::default()).unwrap();
    let all = rows(&csv, m.axes.len());
    assert_eq!(all.len(), 3);
    assert_eq!(all[2].1, "rapid");
    assert_eq!(all[2].2[ic], all[1].2[ic], "C swings in the rapid");
    // (The vertical points before are singular too: C is free there.)
    let s = &summary.planning.singular_stretches;
    let rapid = s
        .iter()
        .find(|s| s.first_line == 5)
        .expect("a stretch at line 5");
    assert!(
        (rapid.max_axis_deviation_deg - 0.0057).abs() < 1e-4,
        "{s:?}"
    );
}

/// One feed move whose tool axis swings by 40° about X and passes the pole
/// of `head-head-bc` (its C axis, +Z) 0.59° away, outside the 0.5° cone:
/// the branch stays (B keeps its sign) and C turns through the pass, one
/// way. The ends' distances to the pole add up to less than the turn and
/// the cone's diameter, and until the arc itself was tested that allowed a
/// branch switch the linearization could not follow ("does not converge":
/// the benchmark path on `head-head-bc`).
#[test]
fn a_swing_just_outside_the_singular_cone_keeps_its_branch() {
    let m = builtin::load("head-head-bc").unwrap().unwrap();
    let (ib, ic) = (m.axis_index("B").unwrap(), m.axis_index("C").unwrap());
    let cl = "FEDRAT/MMPM,2000\n\
              GOTO/-350.0500,59.6002,6.9551,0.3413640,-0.0102954,0.9398748\n\
              GOTO/-400.0000,59.6000,5.0000,-0.3420201,-0.0102979,0.9396362\n";
    let (csv, summary) = post_csv(&m, cl, &PostOptions::default()).unwrap();
    assert!(summary.planning.reconfigurations.is_empty());
    assert!(summary.planning.singular_stretches.is_empty());
    assert!(summary.planning.max_linearization_error_mm <= kinpost_post::DEFAULT_LINTOL_MM + 1e-9);
    let all = rows(&csv, m.axes.len());
    assert!(
        all.len() > 10,
        "the swing is linearized: {} blocks",
        all.len()
    );
    assert!(all.iter().all(|r| r.2[ib] > 0.0), "B changes sign");
    let travel: f64 = all
        .windows(2)
        .map(|w| (w[1].2[ic] - w[0].2[ic]).abs())
        .sum();
    let net = (all[all.len() - 1].2[ic] - all[0].2[ic]).abs();
    assert!(
        (travel - net).abs() < 1e-9 && net < 180.0,
        "C travels {travel}°, net {net}°"
    );
}

/// The built-in A/C trunnion with A's `limits` (TOML) instead of −30..120°.
fn trunnion_with_a(limits: &str) -> Machine {
    let source = builtin::source("trunnion-ac")
        .unwrap()
        .replace("limits = [-30, 120]", &format!("limits = {limits}"));
    machine_from_toml(&source, "trunnion-a.toml").unwrap()
}

/// The built-in A/C trunnion with C turning by ±100° only.
/// The built-in `trunnion-ac` as TOML with `line` added to its C axis.
fn trunnion_ac_with_c(line: &str) -> String {
    builtin::source("trunnion-ac").unwrap().replace(
        "point = [0, 0, 0]          # measured: the table centre (at A = 0)",
        &format!("point = [0, 0, 0]\n{line}"),
    )
}

fn short_c() -> Machine {
    let source = trunnion_ac_with_c("limits = [-100, 100]");
    let m = machine_from_toml(&source, "short-c.toml").unwrap();
    assert_eq!(
        m.axes[m.axis_index("C").unwrap()].limits,
        Some([-100.0, 100.0])
    );
    m
}

/// A C axis whose file gives it ±370° (a head's cables, say) and no `wrap`
/// keeps them: a tool axis turning three times about the part's Z is
/// written inside them, with reconfigurations. Only `wrap = "modulo"`
/// turns it without end.
#[test]
fn limits_of_more_than_a_turn_are_kept_unless_the_axis_is_modulo() {
    let source = trunnion_ac_with_c("limits = [-370, 370]");
    let mut cl = String::from("FEDRAT/MMPM,800\n");
    for k in 0..=216 {
        let phi = (5.0 * k as f64).to_radians();
        let tilt = 25f64.to_radians();
        let axis = Vector3::new(tilt.sin() * phi.cos(), tilt.sin() * phi.sin(), tilt.cos());
        cl.push_str(&goto(
            &Vector3::new(30.0 * phi.cos(), 30.0 * phi.sin(), 10.0),
            &axis,
        ));
    }
    let largest_c = |source: &str| {
        let m = machine_from_toml(source, "c370.toml").unwrap();
        let ic = m.axis_index("C").unwrap();
        assert_eq!(m.axes[ic].limits, Some([-370.0, 370.0]));
        let (csv, summary) = post_csv(&m, &cl, &PostOptions::default()).unwrap();
        let c = rows(&csv, m.axes.len())
            .iter()
            .map(|r| r.2[ic].abs())
            .fold(0.0, f64::max);
        (c, summary.planning.reconfigurations.len())
    };
    let (c, reconfigurations) = largest_c(&source);
    assert!(
        c <= 370.0 + 1e-9 && reconfigurations > 0,
        "C {c}°, {reconfigurations}"
    );
    let modulo = source.replace(
        "limits = [-370, 370]",
        "limits = [-370, 370]\nwrap = \"modulo\"",
    );
    let (c, reconfigurations) = largest_c(&modulo);
    assert!(
        c > 720.0 && reconfigurations == 0,
        "C {c}°, {reconfigurations}"
    );
}

/// A C axis without limits that unwinds (`wrap = "unwind"`) is back at
/// the turn nearest zero at the start of the next segment, however far the
/// last cut turned it (before: only the turns within 210° of the last
/// point were candidates). It unwinds where the rapid ends, in a block of
/// its own: the rapid that leaves the cut keeps its turn.
#[test]
fn an_unwinding_axis_without_limits_unwinds_after_two_turns() {
    let source = trunnion_ac_with_c("wrap = \"unwind\"");
    let m = machine_from_toml(&source, "unwind-c.toml").unwrap();
    let ic = m.axis_index("C").unwrap();
    assert_eq!(m.axes[ic].limits, None);
    let tilt = 20f64.to_radians();
    let at = |phi: f64| {
        let axis = Vector3::new(tilt.sin() * phi.cos(), tilt.sin() * phi.sin(), tilt.cos());
        goto(
            &Vector3::new(40.0 * phi.cos(), 40.0 * phi.sin(), 0.0),
            &axis,
        )
    };
    let mut cl = String::from("FEDRAT/MMPM,500\n");
    for k in 0..=144 {
        cl.push_str(&at((5.0 * k as f64).to_radians()));
    }
    // Retract 50 mm along Z.
    cl.push_str("RAPID\n");
    cl.push_str(&goto(
        &Vector3::new(40.0, 0.0, 50.0),
        &Vector3::new(tilt.sin(), 0.0, tilt.cos()),
    ));
    let (csv, _) = post_csv(&m, &cl, &PostOptions::default()).unwrap();
    let all = rows(&csv, m.axes.len());
    let turned = all.iter().map(|r| r.2[ic].abs()).fold(0.0, f64::max);
    assert!(turned > 600.0, "the cut turns C twice: {turned}°");
    let [.., cut, retract, unwound] = &all[..] else {
        panic!("{csv}")
    };
    assert_eq!(retract.1, "rapid");
    assert_eq!(retract.0, None, "the retract is a block of the post's");
    assert!(
        (retract.2[ic] - cut.2[ic]).abs() < 1e-6,
        "{retract:?} after {cut:?}"
    );
    assert_eq!(unwound.0, Some(146 + 2));
    assert!(
        unwound.2[ic].abs() <= 180.0,
        "C {}° after the rapid",
        unwound.2[ic]
    );
    let kin = Kinematics::new(&m);
    let (a, b) = (kin.fk(&retract.2), kin.fk(&unwound.2));
    assert!((a.point - b.point).norm() < 1e-6 && (a.axis - b.axis).norm() < 1e-9);
    assert!((a.point.z - 50.0).abs() < 1e-6, "{a:?}");
}

/// Tool axis tilted 25° turning about the part's Z by 270°: more than C's
/// range on either A branch.
fn long_turn() -> String {
    turning(0.0, 5.0, 55)
}

/// `count` points on a circle of 30 mm at Z 10, from `start_deg` in steps of
/// `step_deg`, the tool axis tilted 25° towards each point: a tool axis
/// turning about the part's Z (after a rapid, at 800 mm/min).
fn turning(start_deg: f64, step_deg: f64, count: u32) -> String {
    let mut cl = String::from("FEDRAT/MMPM,800\nRAPID\n");
    for k in 0..count {
        let phi = (start_deg + step_deg * f64::from(k)).to_radians();
        let tilt = 25f64.to_radians();
        let axis = Vector3::new(tilt.sin() * phi.cos(), tilt.sin() * phi.sin(), tilt.cos());
        let point = Vector3::new(30.0 * phi.cos(), 30.0 * phi.sin(), 10.0);
        cl.push_str(&goto(&point, &axis));
    }
    cl
}

#[test]
fn a_path_beyond_the_c_range_retracts_and_reconfigures_once() {
    let m = short_c();
    let kin = Kinematics::new(&m);
    let cl = long_turn();
    let (csv, summary) = post_csv(&m, &cl, &PostOptions::default()).unwrap();
    let events = &summary.planning.reconfigurations;
    assert_eq!(events.len(), 1, "{events:?}");
    let event = &events[0];
    assert_eq!(event.retract_mm, 50.0);
    assert_eq!(
        event.uncut_mm, 0.0,
        "the segment is cut after the re-approach"
    );
    // The blocks from the CL point before the event: the point, the
    // retract, the turn above that same point, the approach onto it in the
    // new configuration, then the segment to the event's point, cut.
    let all = rows(&csv, m.axes.len());
    let b = all.iter().position(|r| r.0 == event.previous_line).unwrap();
    let at = all.iter().position(|r| r.0 == Some(event.line)).unwrap();
    let (before, retract, over, again) = (&all[b], &all[b + 1], &all[b + 2], &all[b + 3]);
    assert!(retract.0.is_none() && over.0.is_none() && again.0.is_none());
    assert_eq!(
        (retract.1.as_str(), over.1.as_str(), again.1.as_str()),
        ("rapid", "rapid", "feed")
    );
    let p0 = kin.fk(&before.2);
    let p1 = kin.fk(&retract.2);
    let lift = p1.point - p0.point;
    assert!((lift.norm() - 50.0).abs() < 1e-3, "{lift}");
    assert!(
        lift.normalize().angle(&p0.axis) < 1e-4,
        "the retract follows the tool axis"
    );
    // The same pose in the other configuration.
    let resumed = kin.fk(&again.2);
    assert!((resumed.point - p0.point).norm() < 1e-3);
    assert!(resumed.axis.angle(&p0.axis) < 1e-4);
    let ic = m.axis_index("C").unwrap();
    assert!(
        (again.2[ic] - before.2[ic]).abs() > 90.0,
        "{again:?} {before:?}"
    );
    let approach = resumed.point - kin.fk(&over.2).point;
    assert!((approach.norm() - 50.0).abs() < 1e-3);
    assert!((-approach).normalize().angle(&resumed.axis) < 1e-4);
    // The segment: inserted feed blocks on it, then the event's point.
    let target = kin.fk(&all[at].2);
    for r in &all[b + 4..at] {
        assert!(r.0.is_none() && r.1 == "feed");
        let p = kin.fk(&r.2).point;
        let along = (target.point - p0.point).normalize();
        let off = (p - p0.point) - along * (p - p0.point).dot(&along);
        assert!(off.norm() <= 0.002 + 1e-6, "{}", off.norm());
    }
    assert!(summary.max_position_error_mm <= summary.tolerance_mm);

    // Forbidden: the error names that CL line.
    let options = PostOptions {
        no_reconfigure: true,
        ..Default::default()
    };
    let e = post_csv(&m, &cl, &options).unwrap_err().to_string();
    assert!(e.contains(&format!(":{}:", event.line)), "{e}");
    assert!(e.contains("--no-reconfigure"), "{e}");
}

/// Three turns of the tool axis about the part's Z on a C axis of ±360°:
/// the cheapest reconfiguration would unwind C by two turns, into a
/// setting that cannot reach the point before it (C would be 1° past its
/// travel there), leaving that segment uncut. The planner takes a
/// reconfiguration the tool can resume from instead: every segment is cut.
#[test]
fn the_planner_prefers_a_reconfiguration_that_cuts_every_segment() {
    let source = trunnion_ac_with_c("limits = [-360, 360]");
    let m = machine_from_toml(&source, "c-360.toml").unwrap();
    let cl = turning(1.0, 5.0, 224);
    let (_, summary) = post_csv(&m, &cl, &PostOptions::default()).unwrap();
    let events = &summary.planning.reconfigurations;
    assert!(!events.is_empty());
    for e in events {
        assert_eq!(e.uncut_mm, 0.0, "{e:?}");
    }
    assert!(summary.warnings.is_empty(), "{:?}", summary.warnings);
}

/// Where neither configuration reaches both ends of a segment (C needs
/// 190° there, its travel ends at 185°, and the other A branch is outside
/// A's travel), the re-approach is onto the next point and the segment is
/// reported as not cut, with its length.
#[test]
fn a_segment_no_configuration_can_cut_is_reported_uncut() {
    let source = trunnion_ac_with_c("limits = [-185, 185]")
        .replace("limits = [-30, 120]", "limits = [0, 120]");
    let m = machine_from_toml(&source, "short-c-one-branch.toml").unwrap();
    let cl = turning(0.0, 20.0, 25);
    let (csv, summary) = post_csv(&m, &cl, &PostOptions::default()).unwrap();
    let events = &summary.planning.reconfigurations;
    assert_eq!(events.len(), 1, "{events:?}");
    let event = &events[0];
    // Two points 20° apart on a circle of 30 mm.
    let chord = 2.0 * 30.0 * 10f64.to_radians().sin();
    assert!((event.uncut_mm - chord).abs() < 1e-3, "{event:?}");
    assert!(
        summary.one_line().contains("mm of the path uncut"),
        "{}",
        summary.one_line()
    );
    // A warning at the point, naming the segment.
    let [w] = &summary.warnings[..] else {
        panic!("{:?}", summary.warnings)
    };
    assert_eq!(w.line, event.line);
    let from = format!(
        "from CL line {} to this point",
        event.previous_line.unwrap()
    );
    assert!(w.message.contains(&from), "{w}");
    assert!(w.message.contains("is not cut"), "{w}");
    // The point before, the retract, the turn above the next point, then
    // the next point itself.
    let all = rows(&csv, m.axes.len());
    let at = all.iter().position(|r| r.0 == Some(event.line)).unwrap();
    assert_eq!(all[at - 3].0, event.previous_line);
    assert_eq!(
        (all[at - 2].1.as_str(), all[at - 1].1.as_str()),
        ("rapid", "rapid")
    );
}

#[test]
fn point_by_point_planning_needs_more_reconfigurations() {
    // The whole-path planner starts on the branch that lasts; point by
    // point takes the one nearest zero first.
    let m = short_c();
    let mut cl = String::from("FEDRAT/MMPM,800\nRAPID\n");
    for k in 0..=30 {
        // Azimuth from 0° to −150°: C = 90° → 240° on the A = 20° branch,
        // nearest zero at the start but beyond C's 100° after two points;
        // C = −90° → 60° on the A = −20° branch, inside all along.
        let phi = (-5.0 * k as f64).to_radians();
        let tilt = 20f64.to_radians();
        let axis = Vector3::new(tilt.sin() * phi.cos(), tilt.sin() * phi.sin(), tilt.cos());
        cl.push_str(&goto(&Vector3::new(10.0, 0.0, 5.0), &axis));
    }
    let global = post_csv(&m, &cl, &PostOptions::default()).unwrap().1;
    let nearest = post_csv(
        &m,
        &cl,
        &PostOptions {
            planner: kinpost_post::PlannerMode::Nearest,
            ..Default::default()
        },
    )
    .unwrap()
    .1;
    assert!(global.planning.reconfigurations.is_empty());
    assert!(
        global.planning.reconfigurations.len() < nearest.planning.reconfigurations.len(),
        "global {:?} nearest {:?}",
        global.planning.reconfigurations,
        nearest.planning.reconfigurations
    );
}

/// A random serial machine whose linear axes are not carried by rotary
/// axes (as on every real machine): the linear axes keep spanning space.
fn random_machine(rng: &mut Rng) -> String {
    let shape = Shape {
        name: "random",
        linear: spanning_directions(rng),
        limits: false,
        linear_first: true,
    };
    rng::random_machine(rng, &shape, 100.0)
}

/// Whether the tool axis, interpolated along a great circle between two
/// consecutive poses (as the linearization moves it), passes a direction
/// the machine cannot point (sampled).
fn leaves_the_reachable_directions(kin: &Kinematics, poses: &[Pose]) -> bool {
    let mut out = Vec::new();
    poses.windows(2).any(|w| {
        let (a, b) = (w[0].axis, w[1].axis);
        let theta = a.angle(&b);
        (1..256).any(|k| {
            let t = k as f64 / 256.0;
            let axis = if theta > 1e-12 {
                (a * ((1.0 - t) * theta).sin() + b * (t * theta).sin()) / theta.sin()
            } else {
                a
            };
            let pose = Pose {
                point: w[0].point.lerp(&w[1].point, t),
                axis,
                reference: None,
            };
            kin.ik(&pose, None, &mut out).is_err()
        })
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]
    /// For every pair of consecutive feed blocks, the contact point at the
    /// joint-space midpoint of the values as written lies within the
    /// linearization tolerance (plus the rounding the closed-loop check
    /// allows) of the straight segment between the two blocks' contact
    /// points, which lie on the CL segment.
    #[test]
    fn joint_space_midpoints_stay_on_the_cl_segment(seed in any::<u64>(), lintol in 0.001f64..0.05) {
        let mut rng = Rng(seed | 1);
        let toml = random_machine(&mut rng);
        let m = machine_from_toml(&toml, "random.toml").map_err(|e| TestCaseError::reject(e.to_string()))?;
        if m.axes.iter().filter(|a| !a.is_rotary()).count() != 3 {
            return Err(TestCaseError::reject("degenerate"));
        }
        let kin = Kinematics::new(&m);
        let mut q: Vec<f64> = (0..5).map(|_| rng.range(-50.0, 50.0)).collect();
        let mut cl = String::from("FEDRAT/MMPM,600\n");
        let mut poses = Vec::new();
        for _ in 0..25 {
            for (i, v) in q.iter_mut().enumerate() {
                *v += if m.axes[i].is_rotary() { rng.range(-4.0, 4.0) } else { rng.range(-8.0, 8.0) };
            }
            let p = kin.fk(&q);
            cl += &format!(
                "GOTO/{:.10},{:.10},{:.10},{:.13},{:.13},{:.13}\n",
                p.point.x, p.point.y, p.point.z, p.axis.x, p.axis.y, p.axis.z
            );
            poses.push(p);
        }
        let options = PostOptions { lintol_mm: Some(lintol), ..Default::default() };
        let (csv, summary) = match post_csv(&m, &cl, &options) {
            Ok(r) => r,
            // The joint-space walk may take the tool axis round directions
            // the machine cannot point (two rotary axes at an angle other
            // than 90° reach a band of directions only) where the straight
            // CL segment between two points goes through them: no motion of
            // the machine follows that segment.
            Err(_) if leaves_the_reachable_directions(&kin, &poses) => {
                return Err(TestCaseError::reject("the CL path leaves the reachable directions"));
            }
            Err(e) => return Err(TestCaseError::fail(format!("{e}\n{toml}\n{cl}"))),
        };
        prop_assume!(summary.planning.reconfigurations.is_empty());
        prop_assume!(summary.planning.singular_stretches.is_empty());
        prop_assert!(summary.planning.max_linearization_error_mm <= lintol);
        let all = rows(&csv, m.axes.len());
        let bound = lintol + summary.tolerance_mm + 1e-9;
        for w in all.windows(2) {
            if w[1].1 != "feed" {
                continue;
            }
            let mid: Vec<f64> = w[0].2.iter().zip(&w[1].2).map(|(a, b)| 0.5 * (a + b)).collect();
            let c = kin.fk(&mid).point;
            let (a, b) = (kin.fk(&w[0].2).point, kin.fk(&w[1].2).point);
            let ab = b - a;
            let t = if ab.norm_squared() > 0.0 { ((c - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0) } else { 0.0 };
            let d = (c - (a + ab * t)).norm();
            prop_assert!(d <= bound, "{d} mm > {bound} between {:?} and {:?}\n{toml}", w[0], w[1]);
            for i in 0..m.axes.len() {
                if m.axes[i].is_rotary() {
                    prop_assert!((w[1].2[i] - w[0].2[i]).abs() < 180.0, "a half turn inside a cut");
                }
            }
        }
    }
}

#[test]
fn feed_words_give_the_cl_time_and_slow_down_to_max_velocity() {
    // The trunnion with C limited to 3600°/min; a pass that turns C fast.
    let source = trunnion_ac_with_c("max_velocity = 3600");
    let m = machine_from_toml(&source, "slow-c.toml").unwrap();
    let ic = m.axis_index("C").unwrap();
    let mut cl = String::from("FEDRAT/MMPM,1000\nRAPID\n");
    let tilt = 30f64.to_radians();
    for k in 0..=10 {
        // 10 mm per point at 1000 mm/min: 0.01 min; C turns 9° per point
        // (900°/min), then 45° per point (4500°/min > 3600).
        let phi = if k <= 5 {
            9.0 * k as f64
        } else {
            45.0 + 45.0 * (k - 5) as f64
        };
        let phi = phi.to_radians();
        let axis = Vector3::new(tilt.sin() * phi.cos(), tilt.sin() * phi.sin(), tilt.cos());
        cl.push_str(&goto(&Vector3::new(10.0 * k as f64, 0.0, 0.0), &axis));
    }
    let options = |mode| PostOptions {
        feed_mode: Some(mode),
        lintol_mm: Some(0.0),
        ..Default::default()
    };
    let (csv, summary) = post_csv(&m, &cl, &options(kinpost_post::FeedMode::InverseTime)).unwrap();
    let clamps = &summary.planning.feed_clamps;
    assert_eq!(summary.planning.feed_clamp_count, 5, "{clamps:?}");
    assert!(
        clamps
            .iter()
            .all(|c| c.axis == "C" && c.written_min > c.programmed_min)
    );
    let all = rows(&csv, m.axes.len());
    let feed_col = |csv: &str| -> Vec<f64> {
        csv.lines()
            .skip(1)
            .map(|r| feed_field(csv, r).parse().unwrap_or(f64::NAN))
            .collect()
    };
    let f = feed_col(&csv);
    for k in 2..all.len() {
        let dc = (all[k].2[ic] - all[k - 1].2[ic]).abs();
        let time = 1.0 / f[k];
        // Never faster than the CL asks (0.01 min) nor than C allows.
        assert!(time >= 0.01 * (1.0 - 1e-5), "row {k}: {time}");
        assert!(
            time >= dc / 3600.0 * (1.0 - 1e-5),
            "row {k}: C at {} °/min",
            dc / time
        );
        // And no slower than needed.
        let want = f64::max(0.01, dc / 3600.0);
        assert!(
            (time - want).abs() <= 1e-5 * want + 1e-7,
            "row {k}: {time} vs {want}"
        );
    }
    // dpm: F is the length of the change of all axes over the same time.
    let (csv, _) = post_csv(&m, &cl, &options(kinpost_post::FeedMode::Dpm)).unwrap();
    let all = rows(&csv, m.axes.len());
    let f = feed_col(&csv);
    for k in 2..all.len() {
        let d: f64 = all[k]
            .2
            .iter()
            .zip(&all[k - 1].2)
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>()
            .sqrt();
        let dc = (all[k].2[ic] - all[k - 1].2[ic]).abs();
        let want = f64::max(0.01, dc / 3600.0);
        // The csv values are rounded to 6 decimals; F too.
        assert!(
            (d / f[k] - want).abs() <= 1e-4 * want,
            "row {k}: {} vs {want}",
            d / f[k]
        );
    }
}

/// Posts `cl` on the built-in trunnion to `dialect` without linearization.
fn post_trunnion(
    cl: &str,
    dialect: &str,
    mode: kinpost_post::FeedMode,
) -> Result<String, PostError> {
    let m = builtin::load("trunnion-ac").unwrap().unwrap();
    let dialect = Dialect::builtin(dialect).unwrap();
    let options = PostOptions {
        feed_mode: Some(mode),
        lintol_mm: Some(0.0),
        ..Default::default()
    };
    let mut out = Vec::new();
    post(cl.as_bytes(), &m, &dialect, &mut out, &options)?;
    Ok(String::from_utf8(out).unwrap())
}

#[test]
fn a_block_that_turns_while_the_tool_point_barely_moves_takes_the_turning_time() {
    // A turns 30° while the tool point moves 1e-7 mm (less than the last
    // written decimal): at F1000 the block takes 30° / 1000 °/min, not
    // 1e-7 mm / 1000 mm/min (F ≈ 1e10 in inverse time).
    let cl = "RAPID\nGOTO/0,0,10,0,0,1\nFEDRAT/1000\nGOTO/0,0,10.0000001,0,0.5,0.8660254\n";
    for (mode, want) in [
        (kinpost_post::FeedMode::InverseTime, 1000.0 / 30.0),
        (kinpost_post::FeedMode::Tip, 1000.0),
    ] {
        let csv = post_trunnion(cl, "csv", mode).unwrap();
        let last = csv.lines().last().unwrap();
        let f: f64 = feed_field(&csv, last).parse().unwrap();
        assert!((f - want).abs() < 1e-5, "{mode:?}: {last}");
    }
}

#[test]
fn inverse_time_starts_where_the_start_is_known() {
    // The first feed move and the first after a tool change start where the
    // machine happens to be: no block time, so they are written at the CL
    // feed rate per minute (G94), inverse time (G93) in between. (The CL
    // loads no tool before its first point: the header calls none.)
    let cl = "FEDRAT/MMPM,100\nGOTO/0,0,50,0,0,1\nGOTO/0,0,10\nLOAD/TOOL,2\nGOTO/10,0,10\nGOTO/20,0,10\n";
    let nc = post_trunnion(cl, "fanuc", kinpost_post::FeedMode::InverseTime).unwrap();
    let body: Vec<&str> = nc
        .lines()
        .skip_while(|l| !l.starts_with("G54"))
        .skip(1)
        .take_while(|l| !l.starts_with("M05"))
        .collect();
    assert_eq!(
        body,
        [
            "G01 X0.000 Y0.000 Z50.000 A0.000 C0.000 F100.",
            "G93",
            "Z10.000 F2.5",
            "T2 M06",
            "G43 H2",
            "G94",
            "G01 X10.000 Y0.000 Z10.000 A0.000 C0.000 F100.",
            "G93",
            "X20.000 F10.",
            "G94",
        ],
        "{nc}"
    );
}

#[test]
fn csv_says_which_feeds_are_inverse_time() {
    // The same program in CSV: its feed column holds per-minute feeds where
    // the start is unknown and inverse-time feeds elsewhere; a last column
    // says which.
    let cl = "FEDRAT/MMPM,100\nGOTO/0,0,50,0,0,1\nGOTO/0,0,10\nLOAD/TOOL,2\nGOTO/10,0,10\nGOTO/20,0,10\n";
    let csv = post_trunnion(cl, "csv", kinpost_post::FeedMode::InverseTime).unwrap();
    let rows: Vec<(&str, &str)> = csv
        .lines()
        .map(|l| {
            let fields: Vec<&str> = l.split(',').collect();
            (fields[fields.len() - 2], fields[fields.len() - 1])
        })
        .collect();
    assert_eq!(
        rows,
        [
            ("feed", "feed_mode"),
            ("100.000000", "per-minute"),
            ("2.500000", "inverse-time"),
            ("100.000000", "per-minute"),
            ("10.000000", "inverse-time"),
        ],
        "{csv}"
    );
    // Read back as the CSV dialect reads it.
    let m = kinpost_post::machine::builtin::load("trunnion-ac")
        .unwrap()
        .unwrap();
    let dialect = kinpost_post::nc::Dialect::builtin("csv").unwrap();
    let axes = kinpost_post::axis_specs(&m);
    let program = kinpost_post::nc::read_program(&dialect, &axes, "job.csv", &csv).unwrap();
    assert_eq!(program.len(), 4);
    // Feed per minute: no such column.
    let tip = post_trunnion(cl, "csv", kinpost_post::FeedMode::Tip).unwrap();
    assert!(tip.starts_with("line,motion,X,Y,Z,A,C,feed\n"), "{tip}");
}

#[test]
fn loading_the_tool_in_the_spindle_again_is_no_tool_change() {
    // CAM systems write LOAD/TOOL at the start of every operation, the
    // same tool too: only a different tool is a tool change cycle.
    let cl = "RAPID\nGOTO/0,0,50,0,0,1\nLOAD/TOOL,1\nFEDRAT/MMPM,100\nGOTO/0,0,10\n\
              LOAD/TOOL,2\nGOTO/10,0,10\nLOAD/TOOL,2\nGOTO/20,0,10\nLOAD/TOOL,1\nGOTO/30,0,10\n";
    let nc = post_trunnion(cl, "fanuc", kinpost_post::FeedMode::Tip).unwrap();
    let changes: Vec<&str> = nc.lines().filter(|l| l.contains("M06")).collect();
    assert_eq!(changes, ["T1 M06", "T2 M06", "T1 M06"], "{nc}");
}

#[test]
fn the_same_tool_with_another_length_register_is_loaded_again() {
    // CATIA V5: `LOADTL/2` at the tool change, `LOADTL/2,1` (tool 2, length
    // register 1) at the operation: the program's G43 H follows the CL.
    // The same register again, or the tool again without one, changes
    // nothing.
    let cl = "LOADTL/2\nRAPID\nGOTO/0,0,50,0,0,1\nLOADTL/2,1\nFEDRAT/MMPM,100\nGOTO/0,0,10\n\
              LOADTL/2,1\nGOTO/10,0,10\nLOADTL/2\nGOTO/20,0,10\n";
    let nc = post_trunnion(cl, "linuxcnc", kinpost_post::FeedMode::Tip).unwrap();
    let lines: Vec<&str> = nc
        .lines()
        .filter(|l| l.contains("M6") || l.starts_with("G43"))
        .collect();
    assert_eq!(lines, ["T2 M6", "G43 H2", "T2 M6", "G43 H1"], "{nc}");
}

#[test]
fn a_feed_the_dialect_cannot_write_names_its_cl_line() {
    // Fanuc's feed word has too few decimals for 0.0001 mm/min: F0.
    let cl = "RAPID\nGOTO/0,0,50,0,0,1\nFEDRAT/MMPM,0.0001\nGOTO/0,0,10\n";
    let e = post_trunnion(cl, "fanuc", kinpost_post::FeedMode::Tip).unwrap_err();
    let PostError::Motion(located) = &e else {
        panic!("{e}")
    };
    assert!(matches!(
        located.error,
        kinpost_post::MotionError::FeedRoundsToZero { .. }
    ));
    let d = e.diagnostic().unwrap();
    assert_eq!(d.line, 4);
    assert!(d.message.contains("rounds to 0"), "{}", d.message);
    // Too large to be written: the CL line, once.
    let cl = "RAPID\nGOTO/0,0,50,0,0,1\nFEDRAT/1e13\nGOTO/0,0,10\n";
    let e = post_trunnion(cl, "fanuc", kinpost_post::FeedMode::Tip).unwrap_err();
    let PostError::Block(located) = &e else {
        panic!("{e}")
    };
    assert!(matches!(
        located.error,
        kinpost_post::nc::BlockError::Value { .. }
    ));
    let d = e.diagnostic().unwrap();
    assert_eq!(d.line, 4);
    assert_eq!(
        d.message,
        "cannot write feed = 10000000000000: value is too large to be written"
    );
}

#[test]
fn deciding_point_by_point_keeps_the_branch_it_is_on() {
    // A limited to negative values puts the path on one branch of the
    // closed form; steps of 3° of the tool axis are no flip, whether the
    // planner decides at the end or at every point.
    let m = trunnion_with_a("[-60, 0]");
    let mut cl = String::from("FEDRAT/MMPM,500\nRAPID\n");
    for k in 0..8 {
        let t = (20.0 + 3.0 * k as f64).to_radians();
        cl.push_str(&goto(
            &Vector3::new(k as f64, 0.0, 0.0),
            &Vector3::new(t.sin(), 0.0, t.cos()),
        ));
    }
    for planner in [
        kinpost_post::PlannerMode::Global,
        kinpost_post::PlannerMode::Nearest,
    ] {
        let options = PostOptions {
            planner,
            ..Default::default()
        };
        let (_, summary) = post_csv(&m, &cl, &options).unwrap();
        assert!(
            summary.planning.reconfigurations.is_empty(),
            "{planner:?}: {:?}",
            summary.planning.reconfigurations
        );
    }
}

/// Near the folds of a machine whose tool reaches a band of tool axes,
/// the two branches lie close: the linearization keeps a segment's
/// midpoints on its ends' branch (the joint-space midpoint may be nearer
/// the other one), and the planner switches branch only where the
/// interpolated tool axis reaches a fold. Here it leaves the band between
/// two points and comes back (found by tests/all/pressure.rs; it failed with
/// "does not converge").
#[test]
fn a_path_skirting_the_folds_is_linearized() {
    let summary = posts_fold_fixture("random-pressure.toml", "band-exit.cls", 40);
    assert!(summary.planning.inserted_blocks > 100);
}

/// The tool axis of nutating-off.toml cannot point within 0.2° of the C
/// axis (a fold, not a pole, bounds the band there). cone-crossing.cls
/// tilts it 1° at azimuth 0°, then at 170°: the great circle between
/// passes the C axis at atan(tan 1°·cos 85°) and enters that cone. The
/// machine passes the cone at its rim: the contact point stays within the
/// linearization tolerance, and the summary says how far the tool axis of
/// the inserted blocks lies from the interpolated one (the cone's depth).
#[test]
fn a_segment_through_a_cone_the_machine_cannot_point_passes_at_its_rim() {
    let dir = format!("{}/tests/folds", env!("CARGO_MANIFEST_DIR"));
    let path = format!("{dir}/nutating-off.toml");
    let m = machine_from_toml(&std::fs::read_to_string(&path).unwrap(), &path).unwrap();
    let cl = std::fs::read_to_string(format!("{dir}/cone-crossing.cls")).unwrap();
    let nearest = (1f64.to_radians().tan() * 85f64.to_radians().cos())
        .atan()
        .to_degrees();
    for cone in [None, Some(0.0)] {
        let options = PostOptions {
            singular_cone_deg: cone,
            ..Default::default()
        };
        let (csv, summary) = post_csv(&m, &cl, &options).unwrap();
        let p = &summary.planning;
        assert!(
            (p.max_inserted_axis_deviation_deg - (0.2 - nearest)).abs() < 1e-4,
            "{cone:?}: {p:?}"
        );
        assert_eq!(p.max_inserted_axis_deviation_line, Some(8));
        assert!(p.max_linearization_error_mm <= kinpost_post::DEFAULT_LINTOL_MM);
        assert!(summary.one_line().contains(&format!(
            "an inserted block's tool axis up to {:.4}° off the CL's interpolation (before CL line 8)",
            0.2 - nearest
        )));
        // Every block points where the machine can: 0.2° or more from Z.
        let kin = Kinematics::new(&m);
        for (_, _, q) in rows(&csv, m.axes.len()) {
            let a = kin.fk(&q).axis;
            assert!(a.z.acos().to_degrees() > 0.2 - 1e-6, "{a:?}");
        }
    }
    // Written as joint moves, the segment posts without inserted blocks.
    let options = PostOptions {
        lintol_mm: Some(0.0),
        ..Default::default()
    };
    let (csv, summary) = post_csv(&m, &cl, &options).unwrap();
    assert_eq!(rows(&csv, m.axes.len()).len(), 6);
    assert_eq!(summary.planning.max_inserted_axis_deviation_deg, 0.0);
}

/// Posts a CL file of `tests/folds` on a machine there with the defaults:
/// no reconfiguration, linearized within the tolerance, a block for each of
/// the `points` CL points.
fn posts_fold_fixture(machine: &str, cl: &str, points: usize) -> Summary {
    let dir = format!("{}/tests/folds", env!("CARGO_MANIFEST_DIR"));
    let path = format!("{dir}/{machine}");
    let m = machine_from_toml(&std::fs::read_to_string(&path).unwrap(), &path).unwrap();
    let cl = std::fs::read_to_string(format!("{dir}/{cl}")).unwrap();
    let (csv, summary) = post_csv(&m, &cl, &PostOptions::default()).unwrap();
    assert!(summary.planning.reconfigurations.is_empty());
    assert!(summary.planning.max_linearization_error_mm <= kinpost_post::DEFAULT_LINTOL_MM);
    let all = rows(&csv, m.axes.len());
    assert_eq!(all.iter().filter(|r| r.0.is_some()).count(), points);
    summary
}

/// Between its last two points the tool axis passes the singular cone,
/// their C angles 49° apart. The linearization cuts such a segment into
/// equal pieces at once, but a piece's node in the cone holds C (at the
/// joint-space interpolation) beside nodes outside it whose exact C swings
/// round the pole: halving decides there, holding C over every half with a
/// held end. (Cut into pieces, the segment did not converge.)
#[test]
fn a_segment_through_the_singular_cone_is_halved_not_cut_into_pieces() {
    let summary = posts_fold_fixture("random-tt.toml", "pole-pieces.cls", 23);
    assert!(summary.planning.inserted_blocks > 100);
}

/// Between CL lines 8 and 9 the tool axis passes 0.0007° outside the small
/// hole of a machine whose C turns without end: near the fold the exact C
/// turns by 142° there. The planner's allowance near a fold (the change of
/// the branches' separation) let it take the other turn of C at line 9, a
/// step of 218° that joint interpolation makes the other way round; the
/// linearization found nodes a whole turn apart and did not converge. No
/// step of a cut reaches half a turn, near a fold either.
#[test]
fn near_a_fold_no_rotary_step_reaches_half_a_turn() {
    let summary = posts_fold_fixture("random-tt-modulo.toml", "fold-graze.cls", 60);
    assert!(
        summary.planning.max_rotary_step_deg < 10.0,
        "{:?}",
        summary.planning.max_rotary_step_deg
    );
}

/// Between CL lines 13 and 14 the tool axis passes within 0.0003° of a fold
/// without reaching it: the branches lie within a degree of each other at
/// line 14 but do not meet between the points, so the path keeps its
/// branch. A switch there, allowed as a step below the 1° floor, could not
/// be linearized ("does not converge").
#[test]
fn a_path_passing_a_fold_it_does_not_reach_keeps_its_branch() {
    posts_fold_fixture("near-fold.toml", "near-fold.cls", 25);
}

/// A feed per revolution is written per minute at the spindle speed, and
/// follows it when the speed changes; without a speed it is an error.
#[test]
fn a_feed_per_revolution_follows_the_spindle_speed() {
    let m = builtin::load("trunnion-ac").unwrap().unwrap();
    let options = PostOptions {
        lintol_mm: Some(0.0),
        ..Default::default()
    };
    // (UNITS/MM: an inch feed in a file of undeclared units is an error.)
    let cl = "UNITS/MM\nFEDRAT/MMPM,500\nGOTO/0,0,50,0,0,1\nSPINDL/RPM,2000,CLW\nFEDRAT/MMPR,0.1\n\
              GOTO/0,0,10\nSPINDL/RPM,3000,CLW\nGOTO/0,0,5\nFEDRAT/IPR,0.01\nGOTO/0,0,4\n\
              FEDRAT/300\nGOTO/0,0,1\n";
    let (csv, summary) = post_csv(&m, cl, &options).unwrap();
    assert!(summary.warnings.is_empty(), "{:?}", summary.warnings);
    let feeds: Vec<&str> = csv
        .lines()
        .skip(1)
        .map(|l| l.rsplit(',').next().unwrap())
        .collect();
    assert_eq!(
        feeds,
        [
            "500.000000",
            "200.000000",
            "300.000000",
            "762.000000",
            "300.000000"
        ]
    );
    let e = post_csv(&m, "FEDRAT/MMPR,0.1\nGOTO/0,0,50,0,0,1\n", &options)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("a feed per revolution needs the spindle speed: give SPINDL/rpm before it"),
        "{e}"
    );
    // The spindle stopped: no speed for a feed per revolution, until the
    // next SPINDL gives one.
    let stopped = "SPINDL/RPM,2000,CLW\nFEDRAT/MMPR,0.1\nGOTO/0,0,50,0,0,1\nSPINDL/OFF\n";
    let e = post_csv(&m, &format!("{stopped}GOTO/0,0,40\n"), &options)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("feed move at a feed per revolution with the spindle off (SPINDL/OFF): give SPINDL/rpm before it"),
        "{e}"
    );
    assert!(e.contains(":5:"), "{e}");
    let (csv, _) = post_csv(
        &m,
        &format!("{stopped}SPINDL/RPM,1000,CLW\nGOTO/0,0,40\n"),
        &options,
    )
    .unwrap();
    assert!(csv.trim_end().ends_with(",100.000000"), "{csv}");
}

/// A CL file writes tool axes with 7 decimals. Along the edge of the band a
/// 45° nutating head can point (the tool lying flat), that rounding puts
/// some of them just below the horizontal, beyond the band: each is solved
/// at the nearest axis on the edge, the closed-loop check counts the
/// distance as the CL's own, and the summary says so. 1e-5 below is beyond
/// the rounding of 6 decimals: an error that says how far, and what axis
/// rounding would take it.
#[test]
fn a_flat_tool_axis_rounded_below_the_band_posts_at_the_edge() {
    let m = nutating_45();
    let (csv, summary) = post_csv(&m, &flat_path("-0.0000001"), &PostOptions::default()).unwrap();
    assert_posted_at_the_edge(&m, &csv, &summary, 1e-7);
    let e = post_csv(&m, &flat_path("-0.0000100"), &PostOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("no setting of the rotary axes gives this tool axis: it lies 0.0005730° (1.0e-5 rad) beyond the directions the machine can point (an axis up to 1.0e-6 rad beyond, CL rounding, is taken at the nearest; if the CL rounds its tool axes that coarsely, --axis-rounding 1.1e-5 takes it at the nearest)"),
        "{e}"
    );
}

/// `--axis-rounding` for a CL that writes fewer decimals: the point 1e-5
/// below the fold posts at the edge, checked against it; 2e-4 below is
/// still beyond.
#[test]
fn a_cl_that_rounds_its_tool_axes_more_coarsely_posts_with_its_axis_rounding() {
    // 1e-5 rad below the fold, as rounding to 5 decimals can put it.
    let m = nutating_45();
    let options = PostOptions {
        axis_rounding_rad: Some(1e-4),
        ..PostOptions::default()
    };
    let (csv, summary) = post_csv(&m, &flat_path("-0.0000100"), &options).unwrap();
    assert_posted_at_the_edge(&m, &csv, &summary, 1e-5);
    // The setting is a bound: farther out is still an error.
    let e = post_csv(&m, &flat_path("-0.0002000"), &options)
        .unwrap_err()
        .to_string();
    assert!(e.contains("(2.0e-4 rad) beyond"), "{e}");
    assert!(e.contains("an axis up to 1.0e-4 rad beyond"), "{e}");
}

fn nutating_45() -> Machine {
    let path = format!(
        "{}/../machine/tests/machines/nutating-45.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    machine_from_toml(&std::fs::read_to_string(&path).unwrap(), &path).unwrap()
}

/// A quarter circle of points with the tool lying flat on the 45° nutating
/// head's lower edge, every second tool axis written `below` the horizontal.
fn flat_path(below: &str) -> String {
    let mut cl = String::from("FEDRAT/MMPM,1000\n");
    for k in 0..=10 {
        let phi = (9.0 * f64::from(k)).to_radians();
        let z = if k % 2 == 1 { below } else { "0.0000000" };
        cl += &format!(
            "GOTO/{:.4},{:.4},0.0000,{:.7},{:.7},{z}\n",
            50.0 * phi.cos(),
            50.0 * phi.sin(),
            phi.cos(),
            phi.sin()
        );
    }
    cl
}

/// `flat_path` posted with its axes `gap` below the fold taken at the edge:
/// counted from CL line 3 on, checked against the edge, and every block
/// points the tool flat (or above) and reaches its point.
fn assert_posted_at_the_edge(m: &Machine, csv: &str, summary: &Summary, gap: f64) {
    let p = &summary.planning;
    assert!(p.beyond_reach_blocks >= 1, "{p:?}");
    assert!((p.max_beyond_reach_rad - gap).abs() < 1e-9, "{p:?}");
    assert_eq!(p.first_beyond_reach_line, Some(3));
    assert!(summary.max_axis_error_rad <= summary.tolerance_rad);
    assert!(
        summary.tolerance_rad < 1.1 * gap,
        "{}",
        summary.tolerance_rad
    );
    let kin = Kinematics::new(m);
    for (_, _, q) in rows(csv, m.axes.len()) {
        let pose = kin.fk(&q);
        assert!(pose.axis.z > -1e-8, "{pose:?}");
        assert!(pose.point.z.abs() < 1e-3, "{pose:?}");
    }
}

/// A long feed move with a large turn (50 mm while B tilts 40°, the return
/// move of the benchmark's path) strays about 5 mm from its chord in joint
/// space: it is cut at once into the equal pieces that deviation says it
/// needs (it shrinks like the square of the piece length), not halved down
/// to 64, and every piece stays within the linearization tolerance.
#[test]
fn a_long_turning_move_is_cut_into_the_pieces_it_needs() {
    let m = builtin::load("mts1600").unwrap().unwrap();
    let cl = "FEDRAT/MMPM,2000\n\
              GOTO/-400.0000,60.0000,5.0000,-0.3420201,0.0000000,0.9396926\n\
              GOTO/-350.0000,60.0000,7.0000,0.3420201,0.0000000,0.9396926\n";
    let (csv, summary) = post_csv(&m, cl, &PostOptions::default()).unwrap();
    let kin = Kinematics::new(&m);
    let rows = rows(&csv, m.axes.len());
    let (a, b) = (
        Vector3::new(-400.0, 60.0, 5.0),
        Vector3::new(-350.0, 60.0, 7.0),
    );
    let off_chord = |q0: &[f64], q1: &[f64]| {
        let mid: Vec<f64> = q0.iter().zip(q1).map(|(x, y)| 0.5 * (x + y)).collect();
        let p = kin.fk(&mid).point;
        let t = ((p - a).dot(&(b - a)) / (b - a).norm_squared()).clamp(0.0, 1.0);
        (p - (a + (b - a) * t)).norm()
    };
    let whole = off_chord(&rows[0].2, &rows[rows.len() - 1].2);
    assert!(whole > 4.0 && whole < 6.0, "{whole}");
    let needed = (whole / kinpost_post::DEFAULT_LINTOL_MM).sqrt();
    let pieces = rows.len() - 1;
    assert_eq!(summary.planning.inserted_blocks as usize, pieces - 1);
    assert!(
        (pieces as f64) < 1.1 * needed + 1.0,
        "{pieces} pieces where {needed:.1} are needed"
    );
    for w in rows.windows(2) {
        let d = off_chord(&w[0].2, &w[1].2);
        assert!(d <= kinpost_post::DEFAULT_LINTOL_MM, "{d}");
    }
    // Equal pieces along the CL segment.
    let points: Vec<_> = rows.iter().map(|r| kin.fk(&r.2).point).collect();
    for w in points.windows(2) {
        let step = (w[1] - w[0]).norm();
        assert!(
            (step - (b - a).norm() / pieces as f64).abs() < 1e-3,
            "{step}"
        );
    }
}

/// Inverse-time block times do not depend on the dialect's decimals: a
/// block whose tool point moves less than 1 µm only turns, and takes its
/// rotary change at the feed rate read as degrees per minute, in the csv
/// (6 decimals) as in fanuc (3). A feed block that turns a rotary axis
/// without `max_velocity` faster than 100 turns a minute is warned about.
#[test]
fn inverse_time_feed_words_are_the_same_in_every_dialect() {
    let m = builtin::load("mts1600").unwrap().unwrap();
    // The tool point moves 0.5 µm a point while the axis tilts 1° a point.
    let mut cl = String::from("FEDRAT/MMPM,1000\n");
    for k in 0..6 {
        let b = f64::from(k).to_radians();
        cl += &format!(
            "GOTO/{:.7},60.0000000,5.0000000,{:.7},0.0000000,{:.7}\n",
            -400.0 + 0.0005 * f64::from(k),
            b.sin(),
            b.cos()
        );
    }
    let options = PostOptions {
        feed_mode: Some(kinpost_post::FeedMode::InverseTime),
        lintol_mm: Some(0.0),
        ..Default::default()
    };
    let (csv, summary) = post_csv(&m, &cl, &options).unwrap();
    assert!(summary.warnings.is_empty(), "{:?}", summary.warnings);
    let feeds: Vec<f64> = csv
        .lines()
        .skip(3) // header, the first block (per minute), its first move
        .map(|r| feed_field(&csv, r).parse().unwrap())
        .collect();
    assert_eq!(feeds.len(), 4);
    for f in &feeds {
        // 1° at 1000°/min: 1/1000 min.
        assert!((f - 1000.0).abs() < 1.0, "{feeds:?}");
    }
    let dialect = Dialect::builtin("fanuc").unwrap();
    let mut out = Vec::new();
    post(cl.as_bytes(), &m, &dialect, &mut out, &options).unwrap();
    let fanuc = String::from_utf8(out).unwrap();
    assert_eq!(fanuc.matches("F1000.").count(), 4, "{fanuc}");

    // 0.05 mm while B tilts 30°: by the tool path, B would turn at
    // 600,000°/min.
    let fast = "FEDRAT/MMPM,1000\n\
                GOTO/-400.0000,60.0000,5.0000,0.0000000,0.0000000,1.0000000\n\
                GOTO/-399.9500,60.0000,5.0000,0.5000000,0.0000000,0.8660254\n";
    let options = PostOptions {
        feed_mode: Some(kinpost_post::FeedMode::InverseTime),
        ..Default::default()
    };
    let (_, summary) = post_csv(&m, fast, &options).unwrap();
    assert_eq!(summary.warnings.len(), 1, "{:?}", summary.warnings);
    let w = &summary.warnings[0];
    assert_eq!(w.line, 3);
    assert!(
        w.message
            .contains("(600000°/min): the machine file gives B no max_velocity to hold it to"),
        "{}",
        w.message
    );
}

/// The `feed` field of a CSV row (found by the header: programs with
/// inverse-time feeds have a `feed_mode` column after it).
fn feed_field<'a>(csv: &str, row: &'a str) -> &'a str {
    let header = csv.lines().next().unwrap();
    let k = header.split(',').position(|c| c == "feed").unwrap();
    row.split(',').nth(k).unwrap()
}
