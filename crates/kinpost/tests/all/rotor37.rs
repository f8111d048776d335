//! examples/rotor37 end to end on a reduced grid (every 3rd point along the
//! chord): the commands of `examples/rotor37/run.sh`, run by the built
//! binary. The blade fits, the path keeps the requested scallop, the
//! program posts on the mts1600 as a 6-axis program whose closed-loop check
//! holds, and the virtual machine grinds the blade from design + 0.1 mm to
//! the design without a gouge.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn kinpost(args: &[&str]) -> Output {
    let o = Command::new(env!("CARGO_BIN_EXE_kinpost"))
        .args(args)
        .current_dir(root())
        .output()
        .expect("run kinpost");
    assert!(
        o.status.success(),
        "kinpost {args:?}:\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// The work offset of examples/rotor37: `kinpost path` and `kinpost
/// surface place` take the same options.
const PLACE: [&str; 4] = ["--rotate", "z:180", "--translate", "-100,-10,20"];

/// Steps 1 and 2 of examples/rotor37/run.sh on the reduced grid in `dir`:
/// `s.json` (the surface), `s.cls` (the path) and `path.json` (its report),
/// which is returned; the fit's summary line is checked.
fn reduced_blade_path(dir: &Path) -> serde_json::Value {
    let p = |name: &str| dir.join(name).to_string_lossy().into_owned();
    let o = kinpost(&[
        "surface",
        "fit",
        "data/nasa-rotors/rotor37geometry.dat",
        "--blade-side",
        "1",
        "--params",
        "chord-length",
        "--every",
        "1,3",
        "-o",
        &p("s.json"),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("13 × 34 points → 15 × 36 control points"),
        "{err}"
    );
    let (surface, cl, svg, report) = (p("s.json"), p("s.cls"), p("path.svg"), p("path.json"));
    let mut args = vec![
        "path",
        &surface,
        "--tool",
        "wheel:radius=20,width=2",
        "--direction",
        "v",
        "--side",
        "-",
        "--scallop",
        "0.01",
        "--chordtol",
        "0.003",
        "--region",
        "0,0.9,0.05,0.95",
        "--feed",
        "1200",
        "--pressure",
        "H1=3000",
        "-o",
        &cl,
        "--svg",
        &svg,
        "--json",
        &report,
    ];
    args.extend(PLACE);
    kinpost(&args);
    json(&dir.join("path.json"))
}

#[test]
fn rotor37_side1_reduced_grid_posts_on_mts1600() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).to_string_lossy().into_owned();
    let report = reduced_blade_path(dir.path());
    let scallop = report["scallop_max_mm"].as_f64().unwrap();
    assert!(scallop > 0.0 && scallop <= 0.01, "scallop {scallop}");
    for g in report["gaps"].as_array().unwrap() {
        assert!(g["scallop_mm"].as_f64().unwrap() <= 0.01);
    }
    assert!(report["chord_error_max_mm"].as_f64().unwrap() <= 0.003);
    assert!(report["passes"].as_u64().unwrap() > 5);
    let cl = std::fs::read_to_string(dir.path().join("s.cls")).unwrap();
    assert!(cl.contains("\nPRESSURE/H1,3000.000\n"));

    kinpost(&[
        "post",
        &p("s.cls"),
        "--machine",
        "mts1600",
        "--dialect",
        "csv",
        "-o",
        &p("s.csv"),
        "--json",
        &p("post.json"),
    ]);
    let summary = json(&dir.path().join("post.json"));
    let max = summary["max_position_error_mm"].as_f64().unwrap();
    let tol = summary["tolerance_mm"].as_f64().unwrap();
    assert!(max <= tol, "closed loop {max} > {tol}");
    assert!(
        summary["max_axis_error_rad"].as_f64().unwrap()
            <= summary["tolerance_rad"].as_f64().unwrap()
    );
    // The only tolerated warning is about PRESSURE while the machine has no
    // pressure axis.
    for w in summary["warnings"].as_array().unwrap() {
        assert!(w["message"].as_str().unwrap().contains("PRESSURE"), "{w}");
    }
    // A 6-axis program: C follows the feed direction.
    let csv = std::fs::read_to_string(dir.path().join("s.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let c = header.iter().position(|h| *h == "C").unwrap();
    // Blocks the linearization inserted have an empty line column.
    let cs: Vec<f64> = lines
        .filter(|l| !l.starts_with(','))
        .map(|l| l.split(',').nth(c).unwrap().parse().unwrap())
        .collect();
    let (lo, hi) = cs
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(*v), b.max(*v)));
    assert!(hi - lo > 5.0, "C from {lo} to {hi}");
    assert_eq!(
        cs.len() as u64,
        summary["cl_points"].as_u64().unwrap(),
        "one block with a CL line per CL point"
    );
}

/// The Rotor 67 file (stream surfaces in blocks of eight values, feet)
/// reads as 14 stream surfaces of the blade from JLE = 16 to JTE = 85, both
/// sides (it gave an error a line before).
#[test]
fn rotor67_reads_both_blade_sides() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).to_string_lossy().into_owned();
    for side in ["1", "2"] {
        let o = kinpost(&[
            "surface",
            "fit",
            "data/nasa-rotors/rotor67geometry.dat",
            "--blade-side",
            side,
            "-o",
            &p(&format!("r67_{side}.json")),
        ]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{err}");
        assert!(err.contains("14 × 70 points"), "{err}");
    }
}

/// examples/rotor37 step 4 on the reduced grid: the blade side 0.1 mm proud
/// (`design+0.1`), ground by the posted program on the virtual mts1600 and
/// compared with the design surface placed as the path placed the CL: no
/// gouge beyond the 0.01 mm tolerance (the 2 mm wheel's edge interference
/// and the chords stay inside it, both reported by the path), material
/// left at most the path's scallop plus the ray spacing, no collision.
#[test]
fn rotor37_side1_ground_from_design_plus_0_1_has_no_gouge() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).to_string_lossy().into_owned();
    let path = reduced_blade_path(dir.path());
    let scallop = path["scallop_max_mm"].as_f64().unwrap();
    let edge = path["wheel_edge_interference_max_mm"].as_f64().unwrap();
    let chord = path["chord_error_max_mm"].as_f64().unwrap();
    assert!(
        edge + chord < 0.01,
        "the path keeps its own gouge {edge} + {chord} inside 0.01"
    );
    kinpost(&[
        "post",
        &p("s.cls"),
        "-m",
        "mts1600",
        "-o",
        &p("s.mpf"),
        "-q",
    ]);
    let mut placed = vec!["surface", "place"];
    let s_json = p("s.json");
    let placed_json = p("placed.json");
    placed.push(&s_json);
    placed.extend(PLACE);
    placed.extend(["-o", &placed_json]);
    kinpost(&placed);
    let resolution = 0.1;
    let report_json = p("sim.json");
    let mpf = p("s.mpf");
    kinpost(&[
        "sim",
        &mpf,
        "-m",
        "mts1600",
        "--stock",
        "design+0.1",
        "--design",
        &placed_json,
        "--design-side",
        "-",
        "--design-region",
        "0,0.9,0.05,0.95",
        "--tool",
        "wheel:20,2",
        "--resolution",
        "0.1",
        "--json",
        &report_json,
        "-q",
    ]);
    let report = json(Path::new(&report_json));
    assert_eq!(report["collisions"].as_array().unwrap().len(), 0);
    assert_eq!(report["overtravel"].as_array().unwrap().len(), 0);
    let design = &report["removal"]["design"];
    assert_eq!(design["gouge_max_mm"].as_f64(), Some(0.0));
    assert_eq!(design["residual_max_mm"].as_f64(), Some(0.0));
    let range = &design["deviation_range_mm"];
    let (lo, hi) = (range[0].as_f64().unwrap(), range[1].as_f64().unwrap());
    assert!(lo >= -0.01, "deepest {lo}");
    assert!(
        hi <= scallop + resolution,
        "material left {hi} (scallop {scallop})"
    );
    // Every ray that sees the design measured it: the whole region, none
    // of it still 0.1 mm proud.
    assert!(hi < 0.1 - 0.01, "{hi}");
    assert!(design["measured"].as_u64().unwrap() > 10_000);
}
