//! `kinpost sim` end to end: the built binary on the program of Qiao et al.
//! 2022 Figure 28(b) and on small programs, checking exit codes (0 clean,
//! 1 bad input, 2 usage, 3 violated), the summary, the JSON report and the
//! block table, and that the outputs are written all or nothing.

use std::path::{Path, PathBuf};
use std::process::Output;

use crate::common::{self, root, run_in};

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[track_caller]
fn assert_exit(o: &Output, code: i32) {
    assert_eq!(o.status.code(), Some(code), "stderr:\n{}", stderr(o));
}

fn temp_dir(name: &str) -> PathBuf {
    common::temp_dir(&format!("sim-cli-{name}"))
}

#[test]
fn figure_28b_report_and_block_table() {
    let dir = temp_dir("fig28");
    let program = root().join("data/qiao2022/figure28b-verbatim.mpf");
    let cl = root().join("data/qiao2022/figure28a-verbatim.cls");
    let o = run_in(
        &dir,
        &[
            "sim",
            program.to_str().unwrap(),
            "--machine",
            "mts1600",
            "--cl",
            cl.to_str().unwrap(),
            "--no-pressure-offset",
            "--json",
            "report.json",
            "--blocks",
            "blocks.csv",
        ],
    );
    // N140 Z640. is past the Z travel of the machine file: exit 3.
    assert_exit(&o, 3);
    let err = stderr(&o);
    assert!(err.contains("line 9 (N140): Z reaches 640"), "{err}");
    assert!(err.contains("$A_IN[5] = 0"), "{err}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("report.json")).unwrap()).unwrap();
    assert_eq!(json["blocks"], 15);
    assert_eq!(json["overtravel"][0]["line"], 9);
    assert_eq!(json["overtravel"][0]["axis"], "Z");
    assert!(json["max_position_error_mm"].as_f64().unwrap() < 0.001);
    assert!(json["duration_s"].as_f64().unwrap() > 12.0);
    assert_eq!(json["collisions"].as_array().unwrap().len(), 0);
    let csv = std::fs::read_to_string(dir.join("blocks.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().collect();
    assert_eq!(rows[0], "line,motion,X,A,Y,Z,B,C,feed,H1");
    assert_eq!(rows.len(), 16);
    assert_eq!(
        rows[5],
        "18,feed,459.000000,0.000000,8.807000,361.368000,0.000000,0.000000,4980.000000,3000.000"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn clean_program_exits_0_and_errors_keep_their_codes() {
    let dir = temp_dir("codes");
    std::fs::write(
        dir.join("ok.ngc"),
        "G21 G90\nG0 X0 Y0 Z100 A0 C0\nG1 X10 A20 F500\nM2\n",
    )
    .unwrap();
    let o = run_in(&dir, &["sim", "ok.ngc", "-m", "trunnion-ac", "--json", "-"]);
    assert_exit(&o, 0);
    let json: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(json["blocks"], 2);
    assert!(stderr(&o).contains("2 blocks"), "{}", stderr(&o));
    // A bad input is 1, with the line shown.
    std::fs::write(dir.join("bad.ngc"), "G21\nG1 X10 F100\nG5.2 X1\nM2\n").unwrap();
    let o = run_in(&dir, &["sim", "bad.ngc", "-m", "trunnion-ac"]);
    assert_exit(&o, 1);
    assert!(stderr(&o).contains("bad.ngc:3"), "{}", stderr(&o));
    // A bad option value is 2.
    let o = run_in(
        &dir,
        &["sim", "ok.ngc", "-m", "trunnion-ac", "--input", "X"],
    );
    assert_exit(&o, 2);
    // An extension that names no language: the machine's dialect reads it.
    std::fs::write(dir.join("ok.txt"), "G0 X0\n").unwrap();
    let o = run_in(&dir, &["sim", "ok.txt", "-m", "trunnion-ac"]);
    assert_exit(&o, 0);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn outputs_are_all_or_nothing() {
    let dir = temp_dir("atomic");
    std::fs::write(dir.join("ok.ngc"), "G21 G90\nG0 X0 Y0 Z100 A0 C0\nM2\n").unwrap();
    // The JSON cannot be written (no such folder): the block table is not
    // written either.
    let o = run_in(
        &dir,
        &[
            "sim",
            "ok.ngc",
            "-m",
            "trunnion-ac",
            "--json",
            "missing/report.json",
            "--blocks",
            "blocks.csv",
        ],
    );
    assert_exit(&o, 1);
    assert!(!dir.join("blocks.csv").exists());
    // A program with an error writes neither.
    std::fs::write(dir.join("bad.ngc"), "G21\nG5.2 X1\n").unwrap();
    let o = run_in(
        &dir,
        &[
            "sim",
            "bad.ngc",
            "-m",
            "trunnion-ac",
            "--json",
            "r.json",
            "--blocks",
            "b.csv",
        ],
    );
    assert_exit(&o, 1);
    assert!(!dir.join("r.json").exists() && !dir.join("b.csv").exists());
    std::fs::remove_dir_all(&dir).ok();
}

/// A 3-axis program for the material-removal tests: a 4 mm end mill
/// plunges 0.3 mm into the top of a 40 × 40 × 10 mm box at feed (line 3),
/// cuts a slot 30 mm long (line 4), then plunges 5 mm at rapid (line 7).
const SLOT: &str = "G21 G90 G17\nG0 X5 Y10 Z20\nG1 Z9.7 F100\nG1 X35 F500\nG0 Z20\nG0 X20 Y30\nG0 Z5\nG0 Z20\nM2\n";

/// A closed box as an ASCII STL (12 triangles, outward normals).
fn box_stl(lo: [f64; 3], hi: [f64; 3]) -> String {
    let c = |i: usize| {
        [
            if i & 1 == 0 { lo[0] } else { hi[0] },
            if i & 2 == 0 { lo[1] } else { hi[1] },
            if i & 4 == 0 { lo[2] } else { hi[2] },
        ]
    };
    // Faces as corner indices, counter-clockwise seen from outside.
    let faces = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let mut s = String::from("solid box\n");
    for f in faces {
        for t in [[f[0], f[1], f[2]], [f[0], f[2], f[3]]] {
            s += "facet normal 0 0 0\nouter loop\n";
            for i in t {
                let p = c(i);
                s += &format!("vertex {} {} {}\n", p[0], p[1], p[2]);
            }
            s += "endloop\nendfacet\n";
        }
    }
    s + "endsolid box\n"
}

fn free3() -> String {
    root()
        .join("crates/post/tests/machines/free3.toml")
        .to_string_lossy()
        .into_owned()
}

/// The slot and the plunge: the volume a flat end mill sweeps (the slot
/// and the plunge's cylinder, within the resolution), the
/// rapid plunge an error at its line, and against the uncut box as the
/// design the deepest gouge (the plunge's 5 mm) and the slot's 0.3 mm
/// named by their lines; the part's STL, PLY and SVG are written.
#[test]
fn a_slot_and_a_rapid_plunge_are_cut_and_compared_with_the_design() {
    let dir = temp_dir("removal");
    std::fs::write(dir.join("slot.ngc"), SLOT).unwrap();
    std::fs::write(dir.join("box.stl"), box_stl([0.0; 3], [40.0, 40.0, 10.0])).unwrap();
    let o = run_in(
        &dir,
        &[
            "sim",
            "slot.ngc",
            "--machine",
            &free3(),
            "--stock",
            "box:0,0,0,40,40,10",
            "--tool",
            "flat:4",
            "--resolution",
            "0.1",
            "--design",
            "box.stl",
            "--json",
            "report.json",
        ],
    );
    assert_exit(&o, 3);
    let err = stderr(&o);
    assert!(
        err.contains("error: line 7: a rapid removes material"),
        "{err}"
    );
    assert!(err.contains("error: line 7: gouge of 5.0"), "{err}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("report.json")).unwrap()).unwrap();
    let r = &json["removal"];
    assert_eq!(r["stock"], "box:0,0,0,40,40,10");
    assert_eq!(r["resolution_mm"], 0.1);
    // The slot (4 × 0.3 × 30 and two half discs at its ends) and the
    // plunge (π · 2² · 5).
    let pi = std::f64::consts::PI;
    let want = 4.0 * 0.3 * 30.0 + pi * 4.0 * 0.3 + pi * 4.0 * 5.0;
    let got = r["removed_volume_mm3"].as_f64().unwrap();
    assert!((got - want).abs() < 0.02 * want, "{got} against {want}");
    let rapid = r["rapid_cuts"].as_array().unwrap();
    assert_eq!(rapid.len(), 1, "{r}");
    assert_eq!(rapid[0]["line"], 7);
    assert_eq!(json["rapid_into_stock"], serde_json::json!([rapid[0]]));
    // The retracts from the slot and from the plunge start inside the
    // stock's box: warnings, with the plunge.
    let boxed: Vec<&serde_json::Value> = r["rapids_in_stock_box"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| &a["line"])
        .collect();
    assert_eq!(boxed, [5, 7, 8]);
    assert!(
        err.contains("warning: line 5: a rapid enters the stock's bounding box"),
        "{err}"
    );
    let d = &r["design"];
    assert!(
        (d["gouge_max_mm"].as_f64().unwrap() - 5.0).abs() < 1e-9,
        "{d}"
    );
    assert_eq!(d["gouge_max"]["line"], 7);
    // Two regions: the plunge's 5 mm (line 7) and the slot's 0.3 mm (one
    // region, named by the feed block of its deepest point: line 3 or 4).
    let regions = d["gouge_regions"].as_array().unwrap();
    assert_eq!(regions.len(), 2, "{regions:?}");
    assert_eq!(regions[0]["line"], 7);
    assert!(
        [3, 4].contains(&regions[1]["line"].as_u64().unwrap())
            && (regions[1]["deviation_mm"].as_f64().unwrap() + 0.3).abs() < 1e-9,
        "{regions:?}"
    );
    assert_eq!(d["residual_max_mm"], 0.0);
    // The part as STL, PLY and SVG (at 1 mm: the files stay small).
    let o = run_in(
        &dir,
        &[
            "sim",
            "slot.ngc",
            "--machine",
            &free3(),
            "--stock",
            "box:0,0,0,40,40,10",
            "--tool",
            "flat:4",
            "--resolution",
            "1",
            "--design",
            "box.stl",
            "--stl-out",
            "part.stl",
            "--ply-out",
            "part.ply",
            "--svg-out",
            "map.svg",
        ],
    );
    assert_exit(&o, 3);
    let stl = std::fs::read(dir.join("part.stl")).unwrap();
    let triangles = u32::from_le_bytes(stl[80..84].try_into().unwrap()) as usize;
    assert!(triangles > 12 && stl.len() == 84 + 50 * triangles);
    assert!(
        std::fs::read(dir.join("part.ply"))
            .unwrap()
            .starts_with(b"ply\n")
    );
    let svg = std::fs::read_to_string(dir.join("map.svg")).unwrap();
    assert!(svg.contains("<svg"));
    std::fs::remove_dir_all(&dir).ok();
}

/// A stock grown from the design by 0.2 mm, and a program that cuts
/// nothing: a residual of 0.2 mm, no gouge, exit 0.
#[test]
fn an_allowance_left_is_a_residual() {
    let dir = temp_dir("allowance");
    std::fs::write(dir.join("air.ngc"), "G0 X-20 Y-20 Z30\nG1 X60 F800\nM2\n").unwrap();
    std::fs::write(dir.join("box.stl"), box_stl([0.0; 3], [40.0, 40.0, 10.0])).unwrap();
    let o = run_in(
        &dir,
        &[
            "sim",
            "air.ngc",
            "--machine",
            &free3(),
            "--stock",
            "design+0.2",
            "--tool",
            "ball:6",
            "--resolution",
            "0.1",
            "--design",
            "box.stl",
            "--difftol",
            "0.05",
            "--json",
            "-",
        ],
    );
    assert_exit(&o, 0);
    let json: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let r = &json["removal"];
    assert_eq!(r["stock"], "design+0.2");
    assert_eq!(r["removed_volume_mm3"], 0.0);
    let d = &r["design"];
    assert_eq!(d["gouge_max_mm"], 0.0);
    let residual = d["residual_max_mm"].as_f64().unwrap();
    assert!((residual - 0.2).abs() < 0.1 + 1e-9, "{d}");
    std::fs::remove_dir_all(&dir).ok();
}

/// The removal options: a tool without a stock and a stock without a tool
/// are usage errors, as are a bad tool, a bad box and `design+` without a
/// design; nothing is written.
#[test]
fn removal_options_are_checked() {
    let dir = temp_dir("removal-options");
    std::fs::write(dir.join("slot.ngc"), SLOT).unwrap();
    let machine = free3();
    for (extra, want) in [
        (&["--stock", "box:0,0,0,40,40,10"][..], "--tool"),
        (&["--tool", "flat:4"][..], "--stock"),
        (
            &["--stock", "box:0,0,0,40,40,10", "--tool", "cone:4"][..],
            "unknown tool kind",
        ),
        (
            &["--stock", "box:0,0,0,40,40,10", "--tool", "flat:-4"][..],
            "--tool flat:-4",
        ),
        (
            &["--stock", "box:0,0,40,40,10", "--tool", "flat:4"][..],
            "six numbers",
        ),
        (
            &["--stock", "design+0.2", "--tool", "flat:4"][..],
            "needs --design",
        ),
        (
            &[
                "--stock",
                "box:0,0,0,40,40,10",
                "--tool",
                "flat:4",
                "--process",
                "p.toml",
            ][..],
            "--process grinds with the belt's contact wheel",
        ),
    ] {
        let mut args = vec!["sim", "slot.ngc", "--machine", &machine, "--json", "r.json"];
        args.extend_from_slice(extra);
        let o = run_in(&dir, &args);
        assert_exit(&o, 2);
        assert!(stderr(&o).contains(want), "{extra:?}: {}", stderr(&o));
        assert!(!dir.join("r.json").exists());
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// A design surface's options: the side and region only with a surface
/// file, a region inside its domain, DEPTH only for a surface; each a usage
/// error naming what is wrong, nothing written.
#[test]
fn design_surface_options_are_checked() {
    let dir = temp_dir("design-surface-options");
    std::fs::write(dir.join("slot.ngc"), SLOT).unwrap();
    std::fs::write(dir.join("box.stl"), box_stl([0.0; 3], [40.0, 40.0, 10.0])).unwrap();
    let top = root().join("examples/grinding-experiments/block-top.json");
    let top = top.to_str().unwrap();
    let machine = free3();
    let stock = ["--stock", "box:0,0,0,40,40,10", "--tool", "flat:4"];
    for (extra, want) in [
        (
            &["--design", "box.stl", "--design-side", "-"][..],
            "--design-side",
        ),
        (
            &["--design", "box.stl", "--design-region", "0,1,0,1"][..],
            "--design-region",
        ),
        (
            &["--design", top, "--design-region", "0,1,0"][..],
            "four numbers",
        ),
        (
            &["--design", top, "--design-region", "0,1.5,0,1"][..],
            "fractions of the parameter domain",
        ),
        (
            &["--design", top, "--design-side", "up"][..],
            "invalid value",
        ),
    ] {
        let mut args = vec!["sim", "slot.ngc", "--machine", &machine, "--json", "r.json"];
        args.extend_from_slice(&stock);
        args.extend_from_slice(extra);
        let o = run_in(&dir, &args);
        assert_exit(&o, 2);
        assert!(stderr(&o).contains(want), "{extra:?}: {}", stderr(&o));
        assert!(!dir.join("r.json").exists());
    }
    for (stock_spec, design, want) in [
        ("design+0.1,2", "box.stl", "DEPTH is for a design surface"),
        ("design+-0.1", top, "0 or more"),
        ("design+0.1,2,3", top, "design+ALLOWANCE[,DEPTH]"),
    ] {
        let o = run_in(
            &dir,
            &[
                "sim",
                "slot.ngc",
                "--machine",
                &machine,
                "--json",
                "r.json",
                "--stock",
                stock_spec,
                "--tool",
                "flat:4",
                "--design",
                design,
            ],
        );
        assert_exit(&o, 2);
        assert!(stderr(&o).contains(want), "{stock_spec}: {}", stderr(&o));
        assert!(!dir.join("r.json").exists());
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// A straight wheel pass 0.1 mm deep from at Y50 (in
/// `pieces` GOTOs) across a flat blank (-440..-200, 0..100, -10..0),
/// posted for `mts1600` with `post_extra`, replayed with the 25 × 25 mm
/// contact wheel, the blank as stock and design, and `sim_extra`: the JSON
/// report.
fn wheel_pass(
    name: &str,
    head: &str,
    pieces: u32,
    post_extra: &[&str],
    sim_extra: &[&str],
) -> serde_json::Value {
    let dir = temp_dir(name);
    let mut cl = format!("TOOL PATH/WHEEL,TOOL,W\nFEDRAT/MMPM,500\n{head}");
    let goto = |x: f64, z: f64| format!("GOTO/{x:.4},50.0000,{z:.4},0,0,1,1,0,0\n");
    cl += &goto(-420.0, 20.0);
    for k in 0..=pieces {
        cl += &goto(-420.0 + 200.0 * f64::from(k) / f64::from(pieces), -0.1);
    }
    cl += &goto(-220.0, 20.0);
    std::fs::write(dir.join("pass.cls"), cl).unwrap();
    std::fs::write(
        dir.join("blank.stl"),
        box_stl([-440.0, 0.0, -10.0], [-200.0, 100.0, 0.0]),
    )
    .unwrap();
    let mut post = vec!["post", "pass.cls", "--machine", "mts1600", "-o", "pass.mpf"];
    post.extend_from_slice(post_extra);
    assert_exit(&run_in(&dir, &post), 0);
    let mut sim = vec![
        "sim",
        "pass.mpf",
        "--machine",
        "mts1600",
        "--no-collisions",
        "--stock",
        "box:-440,0,-10,-200,100,0",
        "--tool",
        "wheel:25,25",
        "--resolution",
        "0.1",
        "--design",
        "blank.stl",
        "--json",
        "-",
    ];
    sim.extend_from_slice(sim_extra);
    let o = run_in(&dir, &sim);
    // (The pass gouges the blank as design: exit code 3.)
    assert_exit(&o, 3);
    std::fs::remove_dir_all(&dir).ok();
    serde_json::from_slice(&o.stdout).unwrap()
}

/// Five axes and the belt's contact wheel: a straight pass 0.1 mm deep
/// across a flat blank in 40 blocks, posted for `mts1600` and replayed
/// with the wheel (radius 25 mm, width 25 mm; its axis is the feed
/// direction × the tool axis, from the machine's tool reference): the
/// volume ground is the closed form's, width × (length × depth + the
/// circular segment of the wheel's ends), and against the blank as the
/// design the deepest gouge is the pass's depth.
#[test]
fn a_wheel_pass_grinds_its_closed_form_volume() {
    let json = wheel_pass("wheel", "", 40, &[], &[]);
    let r = &json["removal"];
    let (radius, depth, length, width) = (25.0f64, 0.1f64, 200.0, 25.0);
    let segment = radius * radius * ((radius - depth) / radius).acos()
        - (radius - depth) * (2.0 * radius * depth - depth * depth).sqrt();
    let want = width * (length * depth + segment);
    let got = r["removed_volume_mm3"].as_f64().unwrap();
    assert!((got - want).abs() < 0.01 * want, "{got} against {want}");
    assert!(r["rapid_cuts"].as_array().unwrap().is_empty(), "{r}");
    let gouge = r["design"]["gouge_max_mm"].as_f64().unwrap();
    assert!((gouge - depth).abs() < 1e-6, "{gouge}");
}

/// The belt-grinding process model on the same pass in one block, with
/// the belt turning (3000 rpm) and H1 = 3300 (150 N on the force table of
/// `crates/stock/process/mts1600.toml`): every point of the pass loses
/// Preston's depth h = K_p · v_belt · F / (v_f · W) (Qi (thesis), §4.2;
/// the module doc of `kinpost_stock::process`), so the volume ground is
/// W · L · h, whatever the wheel's position, and the design comparison
/// finds the pass's depth.
#[test]
fn the_process_model_grinds_prestons_depth() {
    let process = root().join("crates/stock/process/mts1600.toml");
    let json = wheel_pass(
        "process",
        "SPINDL/RPM,3000,CLW\n",
        1,
        &["--pressure", "3300"],
        &["--process", process.to_str().unwrap()],
    );
    let r = &json["removal"];
    // K_p = 2.5e-6 mm²/N, 3000 rpm on a 25 mm wheel, 150 N, 500 mm/min,
    // a 25 mm belt, a 200 mm pass.
    let belt = 2.0 * std::f64::consts::PI * 3000.0 / 60.0 * 25.0;
    let h = 2.5e-6 * belt * 150.0 / (500.0 / 60.0 * 25.0);
    let want = 25.0 * 200.0 * h;
    let g = &r["grinding"];
    let ground = g["removed_volume_mm3"].as_f64().unwrap();
    assert!(
        (ground - want).abs() < 0.01 * want,
        "{ground} against {want}"
    );
    let total = r["removed_volume_mm3"].as_f64().unwrap();
    assert!((total - want).abs() < 0.01 * want, "{total} against {want}");
    let pass = g["blocks"]
        .as_array()
        .unwrap()
        .iter()
        .find(|b| b["force_n"] == 150.0)
        .expect("the pass is ground at 150 N");
    assert!((pass["pass_depth_mm"].as_f64().unwrap() - h).abs() < 1e-9);
    let gouge = r["design"]["gouge_max_mm"].as_f64().unwrap();
    assert!((gouge - h).abs() < 1e-3 * h, "{gouge} against {h}");
}

/// The largest deviation from the CL `cl` of `program` in `dialect`,
/// replayed on `free3` (`sim --cl`, which must find nothing else).
fn cl_deviation(dir: &Path, program: &str, cl: &str, dialect: &str) -> f64 {
    let o = run_in(
        dir,
        &[
            "sim",
            program,
            "--machine",
            &free3(),
            "--dialect",
            dialect,
            "--cl",
            cl,
            "--json",
            "r.json",
        ],
    );
    assert_exit(&o, 0);
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("r.json")).unwrap()).unwrap();
    json["max_position_error_mm"].as_f64().unwrap()
}

/// Heidenhain's native arcs (CC, C with DR±) posted by kinpost and replayed
/// by its Heidenhain interpreter follow the CL's circles: the deviation
/// along the path, sampled inside every arc, is the output rounding, and
/// with the senses swapped it is not.
#[test]
fn heidenhain_arcs_replay_on_their_cl_circles() {
    let dir = temp_dir("heidenhain-arcs");
    let cl = "PARTNO/ARCS\nLOAD/TOOL,1\nRAPID\nGOTO/10,0,5,0,0,1\nFEDRAT/MMPM,300\n\
              CIRCLE/0,0,5,0,0,1,10\nGOTO/0,10,5\nCIRCLE/0,0,5,0,0,-1,10\nGOTO/10,0,5\n\
              CIRCLE/5,0,5,0,0,1,5\nGOTO/0,0,5\nGOTO/10,0,8\nFINI\n";
    std::fs::write(dir.join("arcs.cls"), cl).unwrap();
    let o = run_in(
        &dir,
        &[
            "post",
            "arcs.cls",
            "--machine",
            &free3(),
            "--dialect",
            "heidenhain",
            "-o",
            "arcs.h",
        ],
    );
    assert_exit(&o, 0);
    let program = std::fs::read_to_string(dir.join("arcs.h")).unwrap();
    // Two centres: (0, 0) for the first two arcs, (5, 0) for the third.
    assert_eq!(program.matches(" CC ").count(), 2, "{program}");
    let sim = |file: &str| cl_deviation(&dir, file, "arcs.cls", "heidenhain");
    assert!(sim("arcs.h") < 0.001);
    let swapped = program
        .replace("DR+", "DR?")
        .replace("DR-", "DR+")
        .replace("DR?", "DR-");
    std::fs::write(dir.join("swapped.h"), swapped).unwrap();
    assert!(sim("swapped.h") > 1.0);
    std::fs::remove_dir_all(&dir).ok();
}

/// Native canned cycles of every dialect that writes them (G81…G89,
/// Sinumerik MCALL CYCLE8x, Heidenhain CYCL DEF 200/201/207), posted by
/// kinpost from a CL with every kind of cycle and replayed by its own
/// interpreters, follow the CL's holes; with the depth of one cycle
/// changed, they do not.
#[test]
fn native_cycles_replay_on_their_cl_holes() {
    let dir = temp_dir("native-cycles");
    let cl =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../post/tests/cl/every-cycle.cls");
    std::fs::copy(cl, dir.join("holes.cls")).unwrap();
    for (dialect, marker, deeper) in [
        ("linuxcnc", "G81", ("Z-5 R2", "Z-6 R2")),
        ("fanuc", "G81", ("Z-5. R2.", "Z-6. R2.")),
        ("sinumerik", "MCALL CYCLE81", ("2, -5)", "2, -6)")),
        ("heidenhain", "CYCL DEF 200", ("Q201=-5 ", "Q201=-6 ")),
    ] {
        let o = run_in(
            &dir,
            &[
                "post",
                "holes.cls",
                "--machine",
                &free3(),
                "--dialect",
                dialect,
                "-o",
                "holes.nc",
            ],
        );
        assert_exit(&o, 0);
        let program = std::fs::read_to_string(dir.join("holes.nc")).unwrap();
        assert!(program.contains(marker), "{dialect}:\n{program}");
        let sim = |file: &str| cl_deviation(&dir, file, "holes.cls", dialect);
        let error = sim("holes.nc");
        assert!(error < 0.001, "{dialect}: {error} mm\n{program}");
        assert!(program.contains(deeper.0), "{dialect}:\n{program}");
        std::fs::write(
            dir.join("deeper.nc"),
            program.replacen(deeper.0, deeper.1, 1),
        )
        .unwrap();
        let error = sim("deeper.nc");
        assert!(error > 0.9, "{dialect}: {error} mm");
    }
    std::fs::remove_dir_all(&dir).ok();
}
