//! Tool-centre-point output: X, Y, Z carry the CL point, the rotary words
//! the same axis values as joint output, and the closed-loop check runs on
//! those semantics.

use crate::common;

use kinpost_post::machine::{Kinematics, OutputMode, builtin};
use kinpost_post::nc::Dialect;
use kinpost_post::{PostError, PostOptions, post};

fn run(machine: &str, dialect: &str, output: OutputMode, cl: &str) -> Result<String, PostError> {
    let machine = builtin::load(machine).unwrap().unwrap();
    let dialect = Dialect::builtin(dialect).unwrap();
    let mut out = Vec::new();
    let options = PostOptions {
        output: Some(output),
        ..Default::default()
    };
    post(cl.as_bytes(), &machine, &dialect, &mut out, &options)?;
    Ok(String::from_utf8(out).unwrap())
}

fn rows(csv: &str) -> Vec<Vec<String>> {
    csv.lines()
        .skip(1)
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect()
}

#[test]
fn tcp_rows_carry_the_cl_point_and_the_joint_rotaries() {
    for name in builtin::names() {
        let machine = builtin::load(name).unwrap().unwrap();
        let kin = Kinematics::new(&machine);
        let cl = common::job(&machine);
        let tcp = rows(&run(name, "csv", OutputMode::Tcp, &cl).unwrap());
        // Joint output inserts linearization blocks (empty line); TCP output
        // leaves the path between points to the controller.
        let joint: Vec<_> = rows(&run(name, "csv", OutputMode::Joint, &cl).unwrap())
            .into_iter()
            .filter(|r| !r[0].is_empty())
            .collect();
        assert_eq!(tcp.len(), 10);
        assert_eq!(joint.len(), 10);
        let col = |axis: &str| 2 + machine.axis_index(axis).unwrap();
        for (k, (t, j)) in tcp.iter().zip(&joint).enumerate() {
            let p = kin.fk(&common::joints(&machine, k as f64 / 9.0));
            // The CL is written with 4 decimals, the CSV with 6.
            for (axis, want) in [("X", p.point.x), ("Y", p.point.y), ("Z", p.point.z)] {
                let got: f64 = t[col(axis)].parse().unwrap();
                assert!((got - want).abs() < 6e-5, "{name} {axis}: {got} vs {want}");
            }
            for (i, a) in machine.axes.iter().enumerate() {
                if a.is_rotary() {
                    assert_eq!(t[2 + i], j[2 + i], "{name} row {k} axis {}", a.name);
                }
            }
        }
    }
}

#[test]
fn every_word_dialect_switches_tcp_on_and_off() {
    let cl = common::job(&builtin::load("trunnion-ac").unwrap().unwrap());
    for (dialect, on, off) in [
        ("sinumerik", "TRAORI", "TRAFOOF"),
        ("fanuc", "G43.4 H3", "G49"),
        ("heidenhain", "FUNCTION TCPM", "FUNCTION RESET TCPM"),
        ("linuxcnc", "M428", "M429"),
    ] {
        let nc = run("trunnion-ac", dialect, OutputMode::Tcp, &cl).unwrap();
        let first_move = nc.find("X").unwrap();
        let on_at = nc
            .find(on)
            .unwrap_or_else(|| panic!("{dialect}: no {on}\n{nc}"));
        let off_at = nc
            .rfind(off)
            .unwrap_or_else(|| panic!("{dialect}: no {off}\n{nc}"));
        assert!(on_at < first_move && off_at > on_at, "{dialect}\n{nc}");
        let joint = run("trunnion-ac", dialect, OutputMode::Joint, &cl).unwrap();
        assert!(
            !joint.contains(on),
            "{dialect}: joint output switched TCP on\n{joint}"
        );
    }
}

#[test]
fn tcp_needs_xyz_axes_and_a_dialect_that_can_switch() {
    let dialect =
        Dialect::from_toml("name = \"plain\"\nextension = \"nc\"\n", "plain.toml").unwrap();
    let machine = builtin::load("mts1600").unwrap().unwrap();
    let options = PostOptions {
        output: Some(OutputMode::Tcp),
        ..Default::default()
    };
    let err = post(
        "RAPID\nGOTO/-416,70.5,16.53,0,0,1\n".as_bytes(),
        &machine,
        &dialect,
        Vec::new(),
        &options,
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("no `tcp_on` template"), "{err}");
}

#[test]
fn inverse_time_needs_a_dialect_that_can_switch() {
    let machine = builtin::load("mts1600").unwrap().unwrap();
    let dialect = Dialect::builtin("heidenhain").unwrap();
    let options = PostOptions {
        feed_mode: Some(kinpost_post::FeedMode::InverseTime),
        ..Default::default()
    };
    let err = post(
        "RAPID\nGOTO/-416,70.5,16.53,0,0,1\n".as_bytes(),
        &machine,
        &dialect,
        Vec::new(),
        &options,
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("no `inverse_time_on` template"), "{err}");
}

#[test]
fn a_heidenhain_speed_change_under_tcpm_resets_it_around_its_tool_call() {
    // The TNC refuses a TOOL CALL while FUNCTION TCPM is active.
    let cl = "RAPID\nGOTO/0,0,50,0,0,1\nFEDRAT/MMPM,500\nGOTO/0,0,10\nSPINDL/4000,RPM,CLW\nGOTO/10,0,10\n";
    let nc = run("trunnion-ac", "heidenhain", OutputMode::Tcp, cl).unwrap();
    let lines: Vec<&str> = nc
        .lines()
        .map(|l| l.split_once(' ').map_or(l, |(_, rest)| rest))
        .collect();
    let call = lines
        .iter()
        .position(|l| l.starts_with("TOOL CALL") && l.contains("S4000"))
        .unwrap_or_else(|| panic!("no speed change\n{nc}"));
    assert_eq!(lines[call - 1], "FUNCTION RESET TCPM", "\n{nc}");
    assert_eq!(lines[call + 1], "M3", "\n{nc}");
    assert!(lines[call + 2].starts_with("FUNCTION TCPM"), "\n{nc}");
    // In joint output there is no TCPM to reset.
    let joint = run("trunnion-ac", "heidenhain", OutputMode::Joint, cl).unwrap();
    assert!(!joint.contains("TCPM"), "{joint}");
}
