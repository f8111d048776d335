//! 6-axis output: on the mts1600, CL points with a reference direction free
//! the C axis (locked at 0 for 5-axis CL, as in Qiao et al. 2022).

use kinpost_post::machine::{Kinematics, builtin};
use kinpost_post::{PostOptions, post};

fn post_csv(cl: &str) -> Result<String, kinpost_post::PostError> {
    let machine = builtin::load("mts1600").unwrap().unwrap();
    let dialect = kinpost_post::nc::Dialect::builtin("csv").unwrap();
    let mut out = Vec::new();
    post(
        cl.as_bytes(),
        &machine,
        &dialect,
        &mut out,
        &PostOptions::default(),
    )?;
    Ok(String::from_utf8(out).unwrap())
}

#[test]
fn references_drive_the_c_axis_and_the_check_covers_them() {
    let machine = builtin::load("mts1600").unwrap().unwrap();
    let six = Kinematics::new(&machine.with_reference_axes_free());
    let mut cl = String::from("FEDRAT/MMPM,300\n");
    let mut joints = Vec::new();
    for k in 0..30 {
        let t = k as f64 / 29.0;
        // X A Y Z B C
        let q = [
            459.0 + 5.0 * t,
            20.0 * t,
            10.0 - 3.0 * t,
            355.0 + t,
            -15.0 + 30.0 * t,
            -60.0 + 100.0 * t,
        ];
        let p = six.fk(&q);
        let r = p.reference.unwrap();
        cl.push_str(&format!(
            "GOTO/{:.6},{:.6},{:.6},{:.9},{:.9},{:.9},{:.9},{:.9},{:.9}\n",
            p.point.x, p.point.y, p.point.z, p.axis.x, p.axis.y, p.axis.z, r.x, r.y, r.z
        ));
        joints.push(q);
    }
    let csv = post_csv(&cl).unwrap();
    let mut rows = csv.lines();
    // The mts1600 has a pressure axis: an (empty) H1 column.
    assert_eq!(rows.next().unwrap(), "line,motion,X,A,Y,Z,B,C,H1,feed");
    // Blocks inserted by the linearization (empty line) are left out.
    let rows: Vec<&str> = rows.filter(|r| !r.starts_with(',')).collect();
    assert_eq!(rows.len(), joints.len());
    for (row, q) in rows.iter().zip(&joints) {
        let f: Vec<f64> = row
            .split(',')
            .skip(2)
            .take(6)
            .map(|v| v.parse().unwrap())
            .collect();
        for k in 0..6 {
            assert!((f[k] - q[k]).abs() < 2e-6, "{row} vs {q:?}");
        }
    }
}

#[test]
fn sinumerik_writes_c_only_in_six_axis_programs() {
    let machine = builtin::load("mts1600").unwrap().unwrap();
    let dialect = kinpost_post::nc::Dialect::builtin("sinumerik").unwrap();
    let run = |cl: &str| {
        let mut out = Vec::new();
        post(
            cl.as_bytes(),
            &machine,
            &dialect,
            &mut out,
            &PostOptions::default(),
        )
        .unwrap();
        String::from_utf8(out).unwrap()
    };
    let five = run("RAPID\nGOTO/-416,70.5,16.53,0,0,1\n");
    assert!(
        five.contains("X=459.000 Y=8.700 Z366.530 B0.000 A=DC(0.000)\n"),
        "{five}"
    );
    // The reference at home is the feed direction +Y; C60 turns it to
    // (−sin 60°, cos 60°, 0).
    let six = run("RAPID\nGOTO/-416,70.5,16.53,0,0,1,-0.8660254038,0.5,0\n");
    assert!(six.contains("B0.000 A=DC(0.000) C60.000"), "{six}");
}

#[test]
fn mixing_five_and_six_axis_points_is_an_error_naming_the_line() {
    // A 6-value GOTO keeps the reference of the last 9-value one (CL reader).
    let csv = post_csv("FEDRAT/250\nGOTO/-416,70.5,16.53,0,0,1,-1,0,0\nGOTO/-416,70.5,10,0,0,1\n")
        .unwrap();
    let c: Vec<&str> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(7).unwrap())
        .collect();
    assert_eq!(c, ["90.000000", "90.000000"], "{csv}");
    let err = post_csv("FEDRAT/250\nGOTO/-416,70.5,16.53,0,0,1\nGOTO/-416,70.5,10,0,0,1,1,0,0\n")
        .unwrap_err()
        .to_string();
    assert!(
        err.contains(":3:1") && err.contains("began without"),
        "{err}"
    );
}

/// The warnings of posting `cl` on built-in machine `machine`: line and
/// message.
fn warnings(machine: &str, cl: &str) -> Vec<(usize, String)> {
    let machine = builtin::load(machine).unwrap().unwrap();
    let dialect = kinpost_post::nc::Dialect::builtin("csv").unwrap();
    let summary = post(
        cl.as_bytes(),
        &machine,
        &dialect,
        std::io::sink(),
        &PostOptions::default(),
    )
    .unwrap();
    summary
        .warnings
        .iter()
        .map(|w| (w.line, w.message.clone()))
        .collect()
}

/// Nine-value GOTOs at poses of `machine`'s forward kinematics at `qs`,
/// each reference turned `skew_deg` towards the tool axis.
fn goto9(machine: &str, qs: &[Vec<f64>], skew_deg: f64) -> String {
    let m = builtin::load(machine).unwrap().unwrap();
    let kin = Kinematics::new(&m.with_reference_axes_free());
    let mut cl = String::from("FEDRAT/MMPM,300\n");
    for q in qs {
        let p = kin.fk(q);
        let a = p.axis;
        // A unit vector normal to the tool axis (the machine's own reference
        // where it has one).
        let normal = p
            .reference
            .unwrap_or_else(|| a.cross(&nalgebra::Vector3::x()).normalize());
        let s = skew_deg.to_radians();
        let r = normal * s.cos() + a * s.sin();
        cl.push_str(&format!(
            "GOTO/{:.6},{:.6},{:.6},{:.9},{:.9},{:.9},{:.9},{:.9},{:.9}\n",
            p.point.x, p.point.y, p.point.z, a.x, a.y, a.z, r.x, r.y, r.z
        ));
    }
    cl
}

#[test]
fn references_off_perpendicular_or_unused_are_remarked_once() {
    // mts1600 (X A Y Z B C), C freed by the references.
    let qs = [
        vec![459.0, 5.0, 10.0, 355.0, -15.0, -60.0],
        vec![460.0, 6.0, 9.0, 356.0, -14.0, -50.0],
    ];
    assert!(warnings("mts1600", &goto9("mts1600", &qs, 0.0)).is_empty());
    assert_eq!(
        warnings("mts1600", &goto9("mts1600", &qs, 30.0)),
        [(
            2,
            "the reference direction is 30.000° off perpendicular to the tool axis: only its part perpendicular to it is used (further ones are not reported)"
                .to_string()
        )]
    );
    // trunnion-ac (X Y Z A C): two rotary axes, nothing turns a reference.
    let qs = [
        vec![10.0, 20.0, -30.0, 20.0, 40.0],
        vec![11.0, 20.0, -30.0, 21.0, 41.0],
    ];
    assert_eq!(
        warnings("trunnion-ac", &goto9("trunnion-ac", &qs, 0.0)),
        [(
            2,
            "reference directions (GOTO values 7 to 9) are ignored: machine `trunnion-ac` has no third rotary axis to turn them (further ones are not reported)"
                .to_string()
        )]
    );
}

#[test]
fn a_cl_file_without_motion_is_remarked() {
    assert_eq!(
        warnings("mts1600", "$$ nothing to do\nFINI\n"),
        [(
            0,
            "the CL file has no motion (no GOTO): the program is its header and footer only"
                .to_string()
        )]
    );
}
