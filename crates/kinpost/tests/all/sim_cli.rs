//! `kinpost sim` end to end: the built binary on the program of Qiao et al.
//! 2022 Figure 28(b) and on small programs, checking exit codes (0 clean,
//! 1 bad input, 2 usage, 3 violated), the summary, the JSON report and the
//! block table, and that the outputs are written all or nothing.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn run_in(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_kinpost"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run kinpost")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[track_caller]
fn assert_exit(o: &Output, code: i32) {
    assert_eq!(o.status.code(), Some(code), "stderr:\n{}", stderr(o));
}

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("kinpost-sim-cli-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
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
