//! The `kinpost` command end to end: the built binary run on the examples,
//! checking exit codes, standard output and error, and the files it writes.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

use kinpost_post::machine::machine_from_toml;

/// The repository root.
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn example(name: &str) -> PathBuf {
    root().join("examples").join(name)
}

fn kinpost(args: &[&str]) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_kinpost"));
    c.args(args).current_dir(root());
    c
}

fn run(args: &[&str]) -> Output {
    kinpost(args).output().expect("run kinpost")
}

/// Runs in directory `dir` (outputs named without a directory go there).
fn run_in(dir: &Path, args: &[&str]) -> Output {
    kinpost(args)
        .current_dir(dir)
        .output()
        .expect("run kinpost")
}

/// Runs with `input` on standard input.
fn run_with_stdin(args: &[&str], input: &[u8]) -> Output {
    let mut child = kinpost(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run kinpost");
    child.stdin.take().unwrap().write_all(input).unwrap();
    child.wait_with_output().unwrap()
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[track_caller]
fn assert_exit(o: &Output, code: i32) {
    assert_eq!(
        o.status.code(),
        Some(code),
        "stdout:\n{}\nstderr:\n{}",
        stdout(o),
        stderr(o)
    );
}

/// The names of the files in `dir`.
fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// A CL file asking for B = 60° (the tool axis tilted 60° about Y), outside
/// the ±45.2° of mts1600, on line 3.
const OUT_OF_TRAVEL: &str = "$$ B travel test\nRAPID\nGOTO/0,0,0,0.8660254,0,0.5\n";

const FIGURE_28_BLOCK: &str = "X=459.000 Y=8.807 Z361.368 B0.000 A=DC(0.000)";

#[test]
fn post_flat_part() {
    let o = run(&["post", "examples/flat-part.cls", "--machine", "mts1600"]);
    assert_exit(&o, 0);
    let out = stdout(&o);
    assert!(out.contains(FIGURE_28_BLOCK), "{out}");
    let err = stderr(&o);
    // The two defects of the CL file: TLDDATA and the cut-short MSYS.
    assert!(
        err.contains("warning: unknown statement `TLDDATA`"),
        "{err}"
    );
    assert!(err.contains("flat-part.cls:2:1"), "{err}");
    assert!(err.contains("warning: MSYS"), "{err}");
    assert!(err.contains("flat-part.cls:3:"), "{err}");
    assert!(err.contains("14 CL points, 14 blocks"), "{err}");
}

#[test]
fn same_input_same_output() {
    let a = run(&["post", "examples/flat-part.cls", "-m", "mts1600", "-q"]);
    let b = run(&["post", "examples/flat-part.cls", "-m", "mts1600", "-q"]);
    assert_exit(&a, 0);
    assert_eq!(a.stdout, b.stdout);
}

#[test]
fn post_to_file_with_json_summary() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.mpf");
    let json = dir.path().join("s.json");
    let o = run(&[
        "post",
        example("flat-part.cls").to_str().unwrap(),
        "--machine",
        "mts1600",
        "-o",
        out.to_str().unwrap(),
        "--json",
        json.to_str().unwrap(),
    ]);
    assert_exit(&o, 0);
    // The program goes to the file, not to standard output.
    assert!(stdout(&o).is_empty(), "{}", stdout(&o));
    let program = std::fs::read_to_string(&out).unwrap();
    assert!(program.contains(FIGURE_28_BLOCK), "{program}");
    assert!(program.contains("M30"), "{program}");

    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(summary["cl_points"], 14);
    assert_eq!(summary["blocks"], 14);
    let warnings = summary["warnings"].as_array().unwrap();
    assert_eq!(warnings.len(), 2, "{summary}");
    for w in warnings {
        assert!(w["line"].as_u64().is_some(), "{w}");
        assert!(w["message"].as_str().is_some_and(|m| !m.is_empty()), "{w}");
    }
    assert_eq!(warnings[0]["line"], 2);
    assert_eq!(warnings[1]["line"], 3);
    let position = summary["max_position_error_mm"].as_f64().unwrap();
    assert!((0.0..0.01).contains(&position), "{summary}");
    // The largest error is at a GOTO of the file.
    let worst = summary["max_position_error_line"].as_u64().unwrap() as usize;
    let cl = std::fs::read_to_string(root().join("examples/flat-part.cls")).unwrap();
    assert!(
        cl.lines().nth(worst - 1).unwrap().starts_with("GOTO/"),
        "{summary}"
    );
    assert!(summary["max_axis_error_rad"].as_f64().unwrap() >= 0.0);
    assert!(summary["seconds"].as_f64().unwrap() >= 0.0);

    // Only the two files: no temporary file left behind.
    assert_eq!(listing(dir.path()), ["out.mpf", "s.json"]);
}

#[test]
fn post_from_stdin() {
    let cl = std::fs::read(example("flat-part.cls")).unwrap();
    let o = run_with_stdin(&["post", "-", "--machine", "mts1600"], &cl);
    assert_exit(&o, 0);
    assert!(stdout(&o).contains(FIGURE_28_BLOCK), "{}", stdout(&o));
    // Same program as from the file, apart from the CL name in the header.
    let from_file = run(&["post", "examples/flat-part.cls", "-m", "mts1600", "-q"]);
    let body = |s: &str| -> Vec<String> {
        s.lines()
            .filter(|l| !l.contains("CL:"))
            .map(str::to_string)
            .collect()
    };
    assert_eq!(body(&stdout(&o)), body(&stdout(&from_file)));
    assert!(stderr(&o).contains(":2:1"), "{}", stderr(&o));
}

#[test]
fn point_outside_travel_fails_and_names_line_and_axis() {
    let o = run_with_stdin(&["post", "-", "-m", "mts1600"], OUT_OF_TRAVEL.as_bytes());
    assert_exit(&o, 1);
    assert!(
        stdout(&o).is_empty(),
        "a failed run prints no partial program"
    );
    let err = stderr(&o);
    assert!(err.contains("error:"), "{err}");
    assert!(err.contains(":3:1"), "{err}");
    assert!(err.contains("GOTO/0,0,0,0.8660254,0,0.5"), "{err}");
    assert!(err.contains("B would be 60"), "{err}");
}

#[test]
fn failed_run_leaves_the_existing_output_alone() {
    let dir = tempfile::tempdir().unwrap();
    let cl = dir.path().join("tilted.cls");
    std::fs::write(&cl, OUT_OF_TRAVEL).unwrap();
    let out = dir.path().join("existing.mpf");
    std::fs::write(&out, "; a good program\n").unwrap();
    let json = dir.path().join("s.json");
    let o = run(&[
        "post",
        cl.to_str().unwrap(),
        "-m",
        "mts1600",
        "-o",
        out.to_str().unwrap(),
        "--json",
        json.to_str().unwrap(),
    ]);
    assert_exit(&o, 1);
    let err = stderr(&o);
    assert!(err.contains("tilted.cls:3:1"), "{err}");
    assert!(err.contains('B'), "{err}");
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "; a good program\n");
    // No temporary file, no JSON summary of the failed run.
    assert_eq!(listing(dir.path()), ["existing.mpf", "tilted.cls"]);
}

#[test]
fn bad_cl_syntax_is_located() {
    let dir = tempfile::tempdir().unwrap();
    let cl = dir.path().join("syntax.cls");
    std::fs::write(&cl, "RAPID\nGOTO/1,2,3x,0,0,1\n").unwrap();
    let o = run(&["post", cl.to_str().unwrap(), "-m", "mts1600"]);
    assert_exit(&o, 1);
    let err = stderr(&o);
    assert!(err.contains("error:"), "{err}");
    assert!(err.contains("syntax.cls:2:10"), "{err}");
    assert!(err.contains("GOTO/1,2,3x,0,0,1"), "{err}");
}

#[test]
fn missing_cl_file() {
    let o = run(&["post", "no-such-file.cls", "-m", "mts1600"]);
    assert_exit(&o, 1);
    assert!(stderr(&o).contains("no-such-file.cls"), "{}", stderr(&o));
}

#[test]
fn unknown_machine() {
    let o = run(&[
        "post",
        "examples/flat-part.cls",
        "--machine",
        "no-such-mill",
    ]);
    assert_exit(&o, 1);
    let err = stderr(&o);
    assert!(err.contains("no built-in machine `no-such-mill`"), "{err}");
    assert!(err.contains("mts1600"), "{err}");
}

#[test]
fn usage_errors_exit_2() {
    for args in [
        &[][..],
        &["post"][..],
        &["post", "examples/flat-part.cls"][..],
        &[
            "post",
            "examples/flat-part.cls",
            "-m",
            "mts1600",
            "--frobnicate",
        ][..],
        &["no-such-command"][..],
    ] {
        let o = run(args);
        assert_exit(&o, 2);
        assert!(stdout(&o).is_empty(), "{args:?}");
        assert!(!stderr(&o).is_empty(), "{args:?}");
    }
}

#[test]
fn bad_option_values_are_usage_errors() {
    let o = run(&[
        "post",
        "examples/flat-part.cls",
        "-m",
        "mts1600",
        "--tolerance",
        "0",
    ]);
    assert_exit(&o, 2);
    assert!(stderr(&o).contains("--tolerance"), "{}", stderr(&o));
    // A negative number is a value (not an unknown option), refused alike.
    for (option, message) in [
        ("--tolerance", "--tolerance must be a positive number of mm"),
        ("--lintol", "--lintol must be a distance of 0 or more (mm)"),
    ] {
        let o = run(&[
            "post",
            "examples/flat-part.cls",
            "-m",
            "mts1600",
            option,
            "-1",
        ]);
        assert_exit(&o, 2);
        assert!(stderr(&o).contains(message), "{}", stderr(&o));
    }
    for (args, message) in [
        (
            &["fk", "-m", "mts1600", "X=abc"][..],
            "`abc` is not a number",
        ),
        (&["fk", "-m", "mts1600", "X459"][..], "AXIS=VALUE"),
        (
            &["ik", "-m", "mts1600", "--point", "1,2", "--axis", "0,0,1"][..],
            "expected three numbers",
        ),
        (
            &[
                "post",
                "examples/flat-part.cls",
                "-m",
                "mts1600",
                "--retract",
                "0",
            ][..],
            "--retract",
        ),
        (
            &[
                "post",
                "examples/flat-part.cls",
                "-m",
                "mts1600",
                "--pressure",
                "nan",
            ][..],
            "--pressure",
        ),
        (
            &["wheel", "-m", "mts1600", "--table", "3600:3000:100"][..],
            "STEP must be positive",
        ),
    ] {
        let o = run(args);
        assert_exit(&o, 2);
        assert!(stderr(&o).contains(message), "{args:?}: {}", stderr(&o));
    }
}

/// A 4 × 4 grid of points 10 mm apart, `z = bend·i·j`, as
/// `dir/points.csv`.
fn grid_points(dir: &Path, bend: f64) -> PathBuf {
    let points = dir.join("points.csv");
    let mut csv = String::from("row,col,x,y,z\n");
    for i in 0..4 {
        for j in 0..4 {
            let z = bend * f64::from(i * j);
            csv.push_str(&format!("{i},{j},{},{},{z}\n", 10 * j, 10 * i));
        }
    }
    std::fs::write(&points, csv).unwrap();
    points
}

#[test]
fn bad_surface_and_path_option_values_are_usage_errors() {
    let dir = tempfile::tempdir().unwrap();
    let points = grid_points(dir.path(), 0.0);
    let surface = dir.path().join("s.json");
    let surface = surface.to_str().unwrap();
    let o = run(&["surface", "fit", points.to_str().unwrap(), "-o", surface]);
    assert_exit(&o, 0);
    let path = |extra: &[&'static str]| {
        let mut args = vec!["path", surface, "--tool", "wheel:radius=50,width=2"];
        args.extend_from_slice(extra);
        args
    };
    for (args, message) in [
        (vec!["surface", "eval", surface, "--uv", "1"], "--uv `1`"),
        (vec!["surface", "eval", surface], "nothing to evaluate"),
        (
            vec![
                "surface",
                "fit",
                points.to_str().unwrap(),
                "-o",
                surface,
                "--every",
                "0,1",
            ],
            "--every",
        ),
        (vec!["path", surface, "--tool", "disc"], "--tool `disc`"),
        (path(&["--side", "x"]), "--side"),
        (path(&["--feed", "0"]), "--feed"),
        (path(&["--rotate", "w:90"]), "--rotate"),
        (path(&["--chordtol=-1"]), "s.json: "),
    ] {
        let o = run(&args);
        assert_exit(&o, 2);
        assert!(stderr(&o).contains(message), "{args:?}: {}", stderr(&o));
    }
    // A well-formed value outside what the surface file allows is bad input.
    let o = run(&["surface", "eval", surface, "--uv", "5,5"]);
    assert_exit(&o, 1);
    assert!(stderr(&o).contains("outside the surface's domain"));
}

#[test]
fn every_command_writes_dash_to_standard_output() {
    let dir = tempfile::tempdir().unwrap();
    let points = grid_points(dir.path(), 1.0);
    let points = points.to_str().unwrap();
    let in_dir = |args: &[&str]| run_in(dir.path(), args);
    // The surface as JSON on standard output, the grid in a file.
    let o = in_dir(&["surface", "fit", points, "-o", "-", "--write-grid", "g.csv"]);
    assert_exit(&o, 0);
    let surface: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(surface.is_object());
    std::fs::write(dir.path().join("s.json"), &o.stdout).unwrap();
    let wheel = "wheel:radius=50,width=2";
    for (args, starts) in [
        (&["surface", "plot", "s.json", "--svg", "-"][..], "<svg"),
        (
            &["surface", "eval", "s.json", "--uv", "0.5,0.5", "-o", "-"][..],
            "u,v,",
        ),
        (
            &[
                "path", "s.json", "--tool", wheel, "-o", "p.cls", "--svg", "-",
            ][..],
            "<svg",
        ),
        (
            &[
                "path", "s.json", "--tool", wheel, "-o", "p.cls", "--json", "-",
            ][..],
            "{",
        ),
        (&["wheel", "-m", "mts1600", "--svg", "w.svg"][..], ""),
    ] {
        let o = in_dir(args);
        assert_exit(&o, 0);
        assert!(
            stdout(&o).trim_start().starts_with(starts),
            "{args:?}: {}",
            stdout(&o)
        );
    }
    // Two outputs on standard output, or an output onto an input.
    for (args, message) in [
        (
            &["path", "s.json", "--tool", wheel, "--svg", "-"][..],
            "--svg - would write to standard output, where the CL file (-o) goes",
        ),
        (
            &[
                "path", "s.json", "--tool", wheel, "-o", "p.cls", "--svg", "-", "--json", "-",
            ][..],
            "--json - would write to standard output, where --svg goes",
        ),
        (
            &["wheel", "-m", "mts1600", "--svg", "-"][..],
            "--svg - would write to standard output, where the table goes",
        ),
        (
            &[
                "surface", "eval", "s.json", "--uv", "0.5,0.5", "-o", "s.json",
            ][..],
            "is the surface file",
        ),
        (
            &[
                "path", "s.json", "--tool", wheel, "-o", "p.cls", "--svg", "p.cls",
            ][..],
            "are the same file",
        ),
    ] {
        let o = in_dir(args);
        assert_exit(&o, 2);
        assert!(stderr(&o).contains(message), "{args:?}: {}", stderr(&o));
    }
    assert_eq!(
        listing(dir.path()),
        ["g.csv", "p.cls", "points.csv", "s.json", "w.svg"]
    );
}

#[test]
fn machines_and_machine_show() {
    let o = run(&["machines"]);
    assert_exit(&o, 0);
    assert!(stdout(&o).contains("mts1600"), "{}", stdout(&o));

    let o = run(&["machine", "show", "mts1600"]);
    assert_exit(&o, 0);
    let m = machine_from_toml(&stdout(&o), "shown.toml").unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(m.name, "mts1600");

    let o = run(&["machine", "show", "no-such-mill"]);
    assert_exit(&o, 1);
    assert!(stderr(&o).contains("no-such-mill"), "{}", stderr(&o));
}

#[test]
fn machine_check() {
    let good = root().join("crates/machine/machines/mts1600.toml");
    let o = run(&["machine", "check", good.to_str().unwrap()]);
    assert_exit(&o, 0);
    assert!(stdout(&o).contains("is valid"), "{}", stdout(&o));
    assert!(stdout(&o).contains("5 free: X A Y Z B"), "{}", stdout(&o));
    assert!(!stdout(&o).contains("reaches only"), "{}", stdout(&o));
    assert!(
        stdout(&o).contains(
            "A turns without end (wrap = \"modulo\"); its limits [-360, 360] are not applied"
        ),
        "{}",
        stdout(&o)
    );

    // A nutating head whose tool is 0.2° off its B axis's inclination
    // (45.2° from B): the tool axis makes 0.2° to 90.2° with the C axis.
    let folds = root().join("crates/post/tests/folds/nutating-off.toml");
    let o = run(&["machine", "check", folds.to_str().unwrap()]);
    assert_exit(&o, 0);
    assert!(
        stdout(&o).contains(
            "the tool axis reaches only the directions 0.2000° to 90.2000° from (0.0000000, 0.0000000, 1.0000000)"
        ),
        "{}",
        stdout(&o)
    );

    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.toml");
    let text = std::fs::read_to_string(&good)
        .unwrap()
        .replace("limits = [-45.2, 45.2]", "limits = [45.2, -45.2]");
    std::fs::write(&bad, &text).unwrap();
    let line = text
        .lines()
        .position(|l| l == "limits = [45.2, -45.2]")
        .unwrap()
        + 1;
    let o = run(&["machine", "check", bad.to_str().unwrap()]);
    assert_exit(&o, 1);
    let err = stderr(&o);
    assert!(err.contains("error: limits are reversed"), "{err}");
    assert!(err.contains(&format!("bad.toml:{line}:10")), "{err}");
    assert!(err.contains("limits = [45.2, -45.2]"), "{err}");
    assert!(stdout(&o).is_empty());
}

/// A machine or dialect file that is a pipe (`-m <(…)` in a shell) is
/// read like a file.
#[cfg(target_os = "linux")]
#[test]
fn machine_and_dialect_files_may_be_pipes() {
    let machine = std::fs::read(root().join("crates/machine/machines/mts1600.toml")).unwrap();
    let cl = example("flat-part.cls");
    let o = run_with_stdin(
        &["post", cl.to_str().unwrap(), "-m", "/dev/stdin"],
        &machine,
    );
    assert_exit(&o, 0);
    assert_eq!(
        stdout(&o),
        stdout(&run(&["post", cl.to_str().unwrap(), "-m", "mts1600"]))
    );
    let dialect = stdout(&run(&["dialect", "show", "fanuc"]));
    let o = run_with_stdin(
        &[
            "post",
            cl.to_str().unwrap(),
            "-m",
            "mts1600",
            "-d",
            "/dev/stdin",
        ],
        dialect.as_bytes(),
    );
    assert_exit(&o, 0);
    assert_eq!(
        stdout(&o),
        stdout(&run(&[
            "post",
            cl.to_str().unwrap(),
            "-m",
            "mts1600",
            "-d",
            "fanuc"
        ]))
    );
}

#[test]
fn machine_file_templates_are_checked_at_load() {
    let dir = tempfile::tempdir().unwrap();
    let src = std::fs::read_to_string(root().join("crates/machine/machines/mts1600.toml")).unwrap();
    let bad = src.replace("T{{ tool_number }}", "T{{ tool_numbr }}");
    assert_ne!(bad, src);
    let file = dir.path().join("m.toml");
    std::fs::write(&file, &bad).unwrap();
    let file = file.to_str().unwrap();
    let line = bad.lines().position(|l| l.contains("tool_numbr")).unwrap() + 1;
    let mpf = dir.path().join("p.mpf");
    for args in [
        &["machine", "check", file][..],
        &[
            "post",
            "examples/flat-part.cls",
            "-m",
            file,
            "-o",
            mpf.to_str().unwrap(),
        ][..],
    ] {
        let o = run(args);
        assert_exit(&o, 1);
        let e = stderr(&o);
        assert!(e.contains("unknown variable `tool_numbr`"), "{args:?}: {e}");
        assert!(e.contains(&format!("{file}:{line}:5")), "{args:?}: {e}");
    }
    assert!(!mpf.exists());
    let o = run_with_stdin(&["machine", "check", "-"], bad.as_bytes());
    assert_exit(&o, 1);
    assert!(
        stderr(&o).contains(&format!("<stdin>:{line}:5")),
        "{}",
        stderr(&o)
    );
}

#[test]
fn dialects_and_dialect_show() {
    let o = run(&["dialects"]);
    assert_exit(&o, 0);
    let out = stdout(&o);
    assert!(out.contains("sinumerik"), "{out}");
    assert!(out.contains("csv"), "{out}");

    let o = run(&["dialect", "show", "sinumerik"]);
    assert_exit(&o, 0);
    assert!(
        stdout(&o).contains("name = \"sinumerik\""),
        "{}",
        stdout(&o)
    );

    let o = run(&["dialect", "show", "no-such-dialect"]);
    assert_exit(&o, 1);
    assert!(stderr(&o).contains("no-such-dialect"), "{}", stderr(&o));
}

/// The three numbers after `label` on its line of `out`.
fn triple(out: &str, label: &str) -> [f64; 3] {
    let line = out
        .lines()
        .find(|l| l.split_whitespace().next() == Some(label))
        .unwrap_or_else(|| panic!("no `{label}` line in\n{out}"));
    let v: Vec<f64> = line
        .split_whitespace()
        .skip(1)
        .map(|x| x.parse().unwrap())
        .collect();
    v.try_into().unwrap()
}

#[test]
fn forward_kinematics() {
    let o = run(&[
        "fk",
        "--machine",
        "mts1600",
        "X=459",
        "Y=8.807",
        "Z=361.368",
    ]);
    assert_exit(&o, 0);
    let out = stdout(&o);
    let p = triple(&out, "point");
    for (got, want) in p.iter().zip([-416.0, 70.393, 11.368]) {
        assert!((got - want).abs() < 1e-3, "{out}");
    }
    let a = triple(&out, "axis");
    for (got, want) in a.iter().zip([0.0, 0.0, 1.0]) {
        assert!((got - want).abs() < 1e-9, "{out}");
    }

    let o = run(&["fk", "--machine", "mts1600", "Q=1"]);
    assert_exit(&o, 1);
    assert!(stderr(&o).contains("no axis `Q`"), "{}", stderr(&o));
}

#[test]
fn inverse_kinematics() {
    let o = run(&[
        "ik",
        "--machine",
        "mts1600",
        "--point",
        "-416,70.3931,11.3684",
        "--axis",
        "0,0,1",
    ]);
    assert_exit(&o, 0);
    let out = stdout(&o);
    assert!(out.lines().next().unwrap().contains("branch"), "{out}");
    assert!(
        out.lines()
            .any(|l| l.contains("459.000000") && l.trim_end().ends_with("ok")),
        "{out}"
    );
}

#[test]
fn csv_dialect() {
    let o = run(&[
        "post",
        "examples/flat-part.cls",
        "-m",
        "mts1600",
        "--dialect",
        "csv",
        "-q",
    ]);
    assert_exit(&o, 0);
    let out = stdout(&o);
    let mut lines = out.lines();
    // The mts1600 has a pressure axis: its H1 column is empty while no
    // pressure is programmed.
    assert_eq!(lines.next(), Some("line,motion,X,A,Y,Z,B,C,H1,feed"));
    // One row per block, every row with all ten columns.
    let rows: Vec<&str> = lines.collect();
    assert_eq!(rows.len(), 14, "{out}");
    assert!(rows.iter().all(|r| r.split(',').count() == 10), "{out}");
    assert!(
        rows.iter().all(|r| r.split(',').nth(8) == Some("")),
        "{out}"
    );
    assert!(rows[2].starts_with("15,feed,459.000000,"), "{out}");
}

/// The numeric rows of a `kinpost wheel` table.
fn wheel_rows(out: &str) -> Vec<Vec<f64>> {
    out.lines()
        .filter_map(|l| {
            let v: Option<Vec<f64>> = l
                .split_whitespace()
                .map(|w| w.trim_end_matches('*').parse().ok())
                .collect();
            v.filter(|v| v.len() >= 4)
        })
        .collect()
}

#[test]
fn wheel_table_has_the_stroke_and_the_arc_of_qi_thesis() {
    let o = run(&["wheel", "--machine", "mts1600", "--table", "3000:3600:100"]);
    assert_exit(&o, 0);
    let out = stdout(&o);
    let rows = wheel_rows(&out);
    // H1, alpha, offset Y, offset Z, correction X, Y, Z.
    assert_eq!(rows.len(), 7, "{out}");
    assert!(rows.iter().all(|r| r.len() == 7), "{out}");
    assert_eq!(rows[0][0], 3000.0);
    assert_eq!(rows[6][0], 3600.0);
    assert_eq!((rows[0][1], rows[6][1]), (-6.73, 5.0));
    // Qi (thesis) §2.7: 51.075 mm in Z between the stops.
    let stroke = (rows[6][3] - rows[0][3]).abs();
    assert!((stroke - 51.1).abs() <= 0.1, "{stroke}\n{out}");
    // The Y offset first grows, then shrinks (the arc of Figure 2.23).
    let y: Vec<f64> = rows.iter().map(|r| r[2]).collect();
    let top = y
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))
        .unwrap()
        .0;
    assert!(top > 0 && top < y.len() - 1, "{y:?}");
    assert!(y[..=top].windows(2).all(|w| w[0] < w[1]), "{y:?}");
    assert!(y[top..].windows(2).all(|w| w[0] > w[1]), "{y:?}");
    // The correction puts the wheel back: Y and Z carry the head.
    for r in &rows {
        assert!(r[4].abs() < 1e-4 && (r[5] + r[2]).abs() < 2e-4 && (r[6] + r[3]).abs() < 2e-4);
    }
    assert!(out.contains("51.0866 mm along Z"), "{out}");
}

#[test]
fn wheel_svg_pressures_and_mistakes() {
    let dir = tempfile::tempdir().unwrap();
    let svg = dir.path().join("wheel.svg");
    let o = run(&[
        "wheel",
        "-m",
        "mts1600",
        "--pressure",
        "2500",
        "3475",
        "--pressure",
        "3300",
        "--svg",
        svg.to_str().unwrap(),
    ]);
    assert_exit(&o, 0);
    let rows = wheel_rows(&stdout(&o));
    assert_eq!(
        rows.iter().map(|r| r[0]).collect::<Vec<_>>(),
        [2500.0, 3475.0, 3300.0]
    );
    assert!(stdout(&o).contains("2500*"), "{}", stdout(&o));
    assert_eq!(rows[1][2..4], [0.0, 0.0]);
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.starts_with("<svg") && text.ends_with("</svg>\n"));
    assert!(text.contains("H1=2500") && text.contains("<polyline"));
    // Written all or nothing: no temporary file is left behind.
    assert_eq!(listing(dir.path()), ["wheel.svg"]);

    // Without pressures: the calibration rows and the reference.
    let o = run(&["wheel", "-m", "mts1600"]);
    assert_exit(&o, 0);
    let rows = wheel_rows(&stdout(&o));
    assert_eq!(
        rows.iter().map(|r| r[0]).collect::<Vec<_>>(),
        [3000.0, 3250.0, 3475.0, 3600.0]
    );

    // A machine file of measured offsets, not one of the built-ins.
    let src = kinpost_post::machine::builtin::source("mts1600").unwrap();
    let cut = src.find("link_length = 250").unwrap();
    let file = dir.path().join("measured.toml");
    std::fs::write(
        &file,
        format!(
            "{}offsets = [[3000, -1.12, -51.075], [3600, 0, 0]]\n",
            &src[..cut]
        ),
    )
    .unwrap();
    let o = run(&["wheel", "-m", file.to_str().unwrap(), "--pressure", "3000"]);
    assert_exit(&o, 0);
    assert!(stdout(&o).contains("1.1200 mm along Y, 51.0750 mm along Z"));

    let o = run(&["wheel", "-m", "trunnion-ac"]);
    assert_exit(&o, 1);
    assert!(
        stderr(&o).contains("has no pressure axis"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn post_with_pressure_and_without_compensation() {
    let post = |extra: &[&str]| {
        let mut args = vec!["post", "examples/flat-part.cls", "-m", "mts1600"];
        args.extend_from_slice(extra);
        run(&args)
    };
    // Compensated: the wheel is 35.5 mm lower at H1 = 3000, Z goes up.
    let o = post(&["--pressure", "3000"]);
    assert_exit(&o, 0);
    let out = stdout(&o);
    assert!(out.contains("\nH1=3000\n"), "{out}");
    assert!(!out.contains(FIGURE_28_BLOCK), "{out}");
    assert!(out.contains("X=459.000 Y=10.452 Z396.899"), "{out}");
    // Not compensated: the maker's program, with its pressure word, and a
    // warning saying by how much the wheel is off.
    let o = post(&["--pressure", "3000", "--no-pressure-compensation"]);
    assert_exit(&o, 0);
    assert!(stdout(&o).contains(FIGURE_28_BLOCK), "{}", stdout(&o));
    assert!(stdout(&o).contains("\nH1=3000\n"));
    assert!(stderr(&o).contains("not compensated"), "{}", stderr(&o));
    // A dialect without a pressure word: bad input, nothing written.
    let o = post(&["--pressure", "3000", "--dialect", "fanuc"]);
    assert_exit(&o, 1);
    assert!(stdout(&o).is_empty());
    assert!(
        stderr(&o).contains("cannot write the pressure word `H1`"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn kinematics_at_a_pressure() {
    let reference = triple(
        &stdout(&run(&[
            "fk",
            "-m",
            "mts1600",
            "X=459",
            "Y=8.807",
            "Z=361.368",
        ])),
        "point",
    );
    for args in [
        &[
            "fk",
            "-m",
            "mts1600",
            "X=459",
            "Y=8.807",
            "Z=361.368",
            "H1=3000",
        ][..],
        &[
            "fk",
            "-m",
            "mts1600",
            "--pressure",
            "3000",
            "X=459",
            "Y=8.807",
            "Z=361.368",
        ][..],
    ] {
        let o = run(args);
        assert_exit(&o, 0);
        let p = triple(&stdout(&o), "point");
        // The wheel offset at the lower stop, from H1 = 3475: −y·dY + z·dZ.
        let alpha = |a: f64| a.to_radians();
        let r = alpha(-5.0 + 10.0 * 225.0 / 350.0);
        let (dy, dz) = (
            250.0 * (alpha(-6.73).cos() - r.cos()),
            250.0 * (alpha(-6.73).sin() - r.sin()),
        );
        assert!((p[1] - (reference[1] - dy)).abs() < 1e-5, "{p:?}");
        assert!((p[2] - (reference[2] + dz)).abs() < 1e-5, "{p:?}");
    }
    let o = run(&[
        "ik",
        "-m",
        "mts1600",
        "--pressure",
        "3000",
        "--point",
        "-416,70.3931,11.3684",
        "--axis",
        "0,0,1",
    ]);
    assert_exit(&o, 0);
    assert!(stdout(&o).contains("396.898"), "{}", stdout(&o));
    let o = run(&["fk", "-m", "trunnion-ac", "--pressure", "3000"]);
    assert_exit(&o, 1);
    assert!(
        stderr(&o).contains("has no pressure axis"),
        "{}",
        stderr(&o)
    );
}

/// Standard output of a command that must succeed.
#[track_caller]
fn success(args: &[&str]) -> String {
    let o = run(args);
    assert_exit(&o, 0);
    stdout(&o)
}

#[test]
fn fk_and_ik_turn_an_axis_free_with_reference() {
    // The mts1600's C axis is locked at 0 but free with a reference
    // direction: fk and ik must agree with a copy where C is simply free.
    let dir = tempfile::tempdir().unwrap();
    let src = kinpost_post::machine::builtin::source("mts1600").unwrap();
    let unlocked = src
        .replace("fixed = 0\n", "")
        .replace("free_with_reference = true\n", "");
    assert_ne!(unlocked, src);
    let free = dir.path().join("free.toml");
    std::fs::write(&free, &unlocked).unwrap();
    let run_fk = |m: &str| {
        run(&[
            "fk",
            "-m",
            m,
            "X=459",
            "Y=8.807",
            "Z=361.368",
            "A=0",
            "B=20",
            "C=90",
        ])
    };
    let fk = |m: &str| {
        let o = run_fk(m);
        assert_exit(&o, 0);
        assert!(!stderr(&o).contains("fixed"), "{}", stderr(&o));
        stdout(&o)
    };
    let posed = fk("mts1600");
    assert_eq!(posed, fk(free.to_str().unwrap()));
    let r = triple(&posed, "reference");
    assert!((r[0] + 0.939692621).abs() < 1e-9, "{posed}");

    let ik = |m: &str| {
        success(&[
            "ik",
            "-m",
            m,
            "--point",
            "-444.188385,69.19,16.41578",
            "--axis",
            "0.342020143,0,0.939692621",
            "--reference",
            "-0.939692621,0,0.342020143",
        ])
    };
    let solved = ik("mts1600");
    assert_eq!(solved, ik(free.to_str().unwrap()));
    assert!(
        solved.lines().any(|l| l.contains("90.000000  ok")),
        "{solved}"
    );

    // An axis locked for good is locked at the value fk is given.
    let locked = dir.path().join("locked.toml");
    std::fs::write(&locked, src.replace("free_with_reference = true\n", "")).unwrap();
    let o = run_fk(locked.to_str().unwrap());
    assert_exit(&o, 0);
    assert!(stderr(&o).contains("using 90"), "{}", stderr(&o));
    assert_eq!(triple(&stdout(&o), "point"), triple(&posed, "point"));
}

#[test]
fn outputs_never_replace_inputs_or_each_other() {
    let dir = tempfile::tempdir().unwrap();
    let cl = dir.path().join("part.cls");
    std::fs::copy(example("flat-part.cls"), &cl).unwrap();
    let original = std::fs::read(&cl).unwrap();
    let machine = dir.path().join("m.toml");
    std::fs::write(
        &machine,
        kinpost_post::machine::builtin::source("mts1600").unwrap(),
    )
    .unwrap();
    let link = dir.path().join("link.cls");
    std::fs::hard_link(&cl, &link).unwrap();
    let d = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let (cl, machine) = (d("part.cls"), d("m.toml"));
    for (outputs, message) in [
        (vec!["-o", &cl], "is the CL file"),
        (vec!["--json", &cl], "is the CL file"),
        (vec!["-o", &d("link.cls")], "is the CL file"),
        (vec!["-o", &d("./part.cls")], "is the CL file"),
        (vec!["--json", &machine], "is the machine file"),
        (
            vec!["-o", &d("p.mpf"), "--json", &d("./p.mpf")],
            "are the same file",
        ),
    ] {
        let mut args = vec!["post", &cl, "-m", &machine];
        args.extend(outputs.iter().copied());
        let o = run(&args);
        assert_exit(&o, 2);
        assert!(stderr(&o).contains(message), "{args:?}: {}", stderr(&o));
    }
    assert_eq!(std::fs::read(&cl).unwrap(), original);
    assert_eq!(listing(dir.path()), ["link.cls", "m.toml", "part.cls"]);

    // An output that cannot be created leaves the other one unwritten.
    for outputs in [
        [d("p.mpf"), d("no-dir/p.json")],
        [d("no-dir/p.mpf"), d("p.json")],
    ] {
        let o = run(&[
            "post",
            &cl,
            "-m",
            &machine,
            "-o",
            &outputs[0],
            "--json",
            &outputs[1],
        ]);
        assert_exit(&o, 1);
        assert!(stderr(&o).contains("cannot create"), "{}", stderr(&o));
        assert_eq!(listing(dir.path()), ["link.cls", "m.toml", "part.cls"]);
    }
}

#[test]
fn dash_outputs_are_standard_output() {
    let dir = tempfile::tempdir().unwrap();
    let cl = example("flat-part.cls");
    let cl = cl.to_str().unwrap();
    let in_dir = |args: &[&str]| run_in(dir.path(), args);
    let o = in_dir(&[
        "post", cl, "-m", "mts1600", "-q", "-o", "-", "--json", "s.json",
    ]);
    assert_exit(&o, 0);
    assert!(stdout(&o).contains(FIGURE_28_BLOCK), "{}", stdout(&o));
    assert_eq!(listing(dir.path()), ["s.json"]);

    let o = in_dir(&[
        "post", cl, "-m", "mts1600", "-q", "-o", "p.mpf", "--json", "-",
    ]);
    assert_exit(&o, 0);
    let summary: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(summary["blocks"], 14);
    assert_eq!(listing(dir.path()), ["p.mpf", "s.json"]);

    // Program and summary cannot share standard output.
    for args in [
        &["post", cl, "-m", "mts1600", "--json", "-"][..],
        &["post", cl, "-m", "mts1600", "-o", "-", "--json", "-"][..],
    ] {
        let o = in_dir(args);
        assert_exit(&o, 2);
        assert!(stdout(&o).is_empty());
        assert!(stderr(&o).contains("--json -"), "{}", stderr(&o));
    }
    assert_eq!(listing(dir.path()), ["p.mpf", "s.json"]);
}

#[test]
fn machine_check_reads_standard_input() {
    let src = kinpost_post::machine::builtin::source("mts1600").unwrap();
    let o = run_with_stdin(&["machine", "check", "-"], src.as_bytes());
    assert_exit(&o, 0);
    assert!(
        stdout(&o).starts_with("<stdin>: machine `mts1600` is valid"),
        "{}",
        stdout(&o)
    );
    let bad = src.replace("limits = [-45.2, 45.2]", "limits = [45.2, -45.2]");
    let o = run_with_stdin(&["machine", "check", "-"], bad.as_bytes());
    assert_exit(&o, 1);
    assert!(stderr(&o).contains("--> <stdin>:"), "{}", stderr(&o));
}

#[test]
fn a_closed_standard_output_ends_every_command_quietly() {
    let dir = tempfile::tempdir().unwrap();
    let mpf = dir.path().join("p.mpf");
    for args in [
        &["machines"][..],
        &["machine", "show", "mts1600"][..],
        &["machine", "check", "mts1600"][..],
        &["dialects"][..],
        &["dialect", "show", "sinumerik"][..],
        &["fk", "-m", "mts1600", "X=459"][..],
        &[
            "ik",
            "-m",
            "mts1600",
            "--point",
            "-416,70.3931,11.3684",
            "--axis",
            "0,0,1",
        ][..],
        &["wheel", "-m", "mts1600"][..],
        &["post", "examples/flat-part.cls", "-m", "mts1600"][..],
        &[
            "post",
            "examples/flat-part.cls",
            "-m",
            "mts1600",
            "-o",
            mpf.to_str().unwrap(),
            "--json",
            "-",
        ][..],
    ] {
        // A pipe whose reader is gone before the command writes.
        let (reader, writer) = std::io::pipe().unwrap();
        drop(reader);
        let o = kinpost(args)
            .stdout(writer)
            .stderr(Stdio::piped())
            .output()
            .unwrap();
        assert_exit(&o, 0);
        assert!(!stderr(&o).contains("panicked"), "{args:?}: {}", stderr(&o));
        assert!(!stderr(&o).contains("error"), "{args:?}: {}", stderr(&o));
    }
}

#[test]
fn a_closed_standard_error_loses_the_messages_not_the_run() {
    let dir = tempfile::tempdir().unwrap();
    let mpf = dir.path().join("p.mpf");
    let mpf = mpf.to_str().unwrap();
    // The flat part posts with two warnings and a summary on standard
    // error; the missing file is an error message there.
    for (args, code) in [
        (
            &["post", "examples/flat-part.cls", "-m", "mts1600", "-o", mpf][..],
            0,
        ),
        (&["post", "no-such-file.cls", "-m", "mts1600"][..], 1),
        (&["fk", "-m", "mts1600", "X=459", "A=9999"][..], 0),
    ] {
        let (reader, writer) = std::io::pipe().unwrap();
        drop(reader);
        let o = kinpost(args)
            .stdout(Stdio::null())
            .stderr(writer)
            .output()
            .unwrap();
        assert_exit(&o, code);
    }
    // The program was written all the same.
    let written = std::fs::read_to_string(mpf).unwrap();
    let o = run(&["post", "examples/flat-part.cls", "-m", "mts1600"]);
    assert_eq!(written, stdout(&o));
}

#[test]
fn a_directory_is_named_as_one() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path().to_str().unwrap();
    let flat = "examples/flat-part.cls";
    for (args, message) in [
        (&["post", d, "-m", "mts1600"][..], "CL file"),
        (&["post", flat, "-m", d][..], "machine file"),
        (
            &["post", flat, "-m", "mts1600", "-d", d][..],
            "dialect file",
        ),
        (&["machine", "check", d][..], "machine file"),
    ] {
        let o = run(args);
        assert_exit(&o, 1);
        assert_eq!(
            stderr(&o),
            format!("error: {message} {d} is a directory\n"),
            "{args:?}"
        );
    }
    let o = run(&["post", flat, "-m", "mts1600", "-o", d]);
    assert_exit(&o, 2);
    assert!(stderr(&o).contains("is a directory"), "{}", stderr(&o));
    assert!(listing(dir.path()).is_empty());
}

/// `ik` of a flat tool axis rounded just below the band of a 45° nutating
/// head gives the solutions of the nearest axis and says so; 1e-5 rad
/// below, the error says how far outside the axis lies.
#[test]
fn ik_says_when_it_takes_the_nearest_axis_and_how_far_an_unreachable_one_is() {
    let m = "crates/machine/tests/machines/nutating-45.toml";
    let near = success(&[
        "ik",
        "-m",
        m,
        "--point",
        "50,0,0",
        "--axis",
        "1,0,-0.0000001",
    ]);
    assert!(
        near.contains("ok (the nearest axis the machine can point, 1.0e-7 rad off: CL rounding)"),
        "{near}"
    );
    let o = run(&["ik", "-m", m, "--point", "50,0,0", "--axis", "1,0,-0.00001"]);
    assert_exit(&o, 1);
    assert!(
        stderr(&o).contains("no setting of the rotary axes gives this tool axis: it lies 0.0005730° (1.0e-5 rad) beyond the directions the machine can point (an axis up to 1.0e-6 rad beyond, CL rounding, is taken at the nearest; if the CL rounds its tool axes that coarsely, --axis-rounding 1.0e-5 takes it at the nearest)"),
        "{}",
        stderr(&o)
    );
    // With that axis rounding it is taken at the nearest axis, in `ik` as
    // in `post`.
    let args = ["ik", "-m", m, "--point", "50,0,0", "--axis", "1,0,-0.00001"];
    let coarse = success(&[&args[..], &["--axis-rounding", "1.0e-5"]].concat());
    assert!(
        coarse.contains("ok (the nearest axis the machine can point, 1.0e-5 rad off: CL rounding)"),
        "{coarse}"
    );
    let cl = "FEDRAT/MMPM,1000\nGOTO/50,0,0,1,0,-0.00001\nGOTO/40,10,0,1,0,0\n";
    let post = |extra: &[&str]| {
        run_with_stdin(
            &[&["post", "-", "-m", m][..], extra].concat(),
            cl.as_bytes(),
        )
    };
    assert_exit(&post(&[]), 1);
    let o = post(&["--axis-rounding", "1e-4", "--dialect", "csv"]);
    assert_exit(&o, 0);
    assert!(
        stderr(&o).contains("1 block(s) with a CL tool axis up to 1.0e-5 rad beyond reach"),
        "{}",
        stderr(&o)
    );
    // More than any rounding: a usage error.
    for bad in ["0.01", "-1e-6", "nan"] {
        let o = run(&[&args[..], &["--axis-rounding", bad]].concat());
        assert_exit(&o, 2);
        assert!(
            stderr(&o).contains("--axis-rounding must be an angle from 0 to 1e-3 rad"),
            "{}",
            stderr(&o)
        );
    }
}

/// A modulo axis reaches every angle: `fk` and `ik` do not hold it to its
/// limits (which bound the counter), as `post` does not.
#[test]
fn fk_and_ik_do_not_hold_a_modulo_axis_to_its_limits() {
    let dir = tempfile::tempdir().unwrap();
    let show = stdout(&run(&["machine", "show", "head-head-bc"]));
    let machine = show.replace(
        "limits = [-360, 360]\n# Endless",
        "limits = [0, 1]\n# Endless",
    );
    assert_ne!(machine, show, "head-head-bc's C is modulo with limits ±360");
    let path = dir.path().join("modulo-c.toml");
    std::fs::write(&path, machine).unwrap();
    let m = path.to_str().unwrap();
    let fk = run(&["fk", "-m", m, "C=90", "B=30"]);
    assert_exit(&fk, 0);
    assert!(
        !stderr(&fk).contains("outside the axis limits"),
        "{}",
        stderr(&fk)
    );
    let ik = success(&[
        "ik",
        "-m",
        m,
        "--point",
        "10,20,30",
        "--axis",
        "0,0.5,0.8660254",
    ]);
    assert!(!ik.contains("outside"), "{ik}");
    assert!(ik.lines().skip(1).all(|l| l.ends_with("ok")), "{ik}");
}

/// `fk` and `ik` print a value that rounds to zero without a sign.
#[test]
fn fk_and_ik_print_no_negative_zero() {
    // At C = 90° the tool axis is (−6e-17, 0, 1).
    let fk = success(&["fk", "-m", "head-head-bc", "C=90", "B=0"]);
    assert!(
        fk.contains("axis      0.000000000 0.000000000 1.000000000"),
        "{fk}"
    );
    assert!(!fk.contains("-0.0"), "{fk}");
    let ik = success(&[
        "ik",
        "-m",
        "mts1600",
        "--point",
        "-400,60,5",
        "--axis",
        "0,0,1",
    ]);
    assert!(!ik.contains("-0.000000"), "{ik}");
}

/// CATIA V5's ISO 8859-1 APT source: an error at the first accented byte
/// that names `--encoding latin1`; with it, the comments keep their accents
/// and the positional `CYCLE/DRILL, 3.0, 5.0` holes post as G81. The
/// virtual machine replays the program against the same CL with
/// `--cl-encoding latin1`.
#[test]
fn a_latin1_catia_file_posts_with_its_encoding() {
    let dir = crate::common::temp_dir("latin1");
    let cl = root().join("data/cl/catia/PrepaFlans_Pointage.aptsource");
    let cl = cl.to_str().unwrap();
    let machine = root().join("crates/post/tests/machines/free3.toml");
    let machine = machine.to_str().unwrap();
    let o = run_in(&dir, &["post", cl, "-m", machine, "-d", "linuxcnc"]);
    assert_exit(&o, 1);
    let err = stderr(&o);
    assert!(
        err.contains("invalid UTF-8 (byte 0xE9)") && err.contains("--encoding latin1"),
        "{err}"
    );
    assert!(err.contains("PrepaFlans_Pointage.aptsource:2:9"), "{err}");
    let o = run_in(
        &dir,
        &[
            "post",
            cl,
            "-m",
            machine,
            "-d",
            "linuxcnc",
            "--encoding",
            "latin1",
            "-o",
            "p.ngc",
        ],
    );
    assert_exit(&o, 0);
    let program = std::fs::read_to_string(dir.join("p.ngc")).unwrap();
    assert!(
        program.contains("(Généré le jeudi 30 novembre 2023 08:46:00)"),
        "{program}"
    );
    assert_eq!(program.matches("G99 G81 ").count(), 12, "{program}");
    assert!(
        program.contains("G99 G81 X98 Y100 Z17 R25 F300"),
        "{program}"
    );
    let o = run_in(
        &dir,
        &[
            "sim",
            "p.ngc",
            "-m",
            machine,
            "--cl",
            cl,
            "--cl-encoding",
            "latin1",
            "--json",
            "r.json",
        ],
    );
    assert_exit(&o, 0);
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("r.json")).unwrap()).unwrap();
    assert!(
        report["max_position_error_mm"].as_f64().unwrap() < 0.001,
        "{report}"
    );
    std::fs::remove_dir_all(&dir).ok();
}
