//! The command under hostile or unlucky input: nothing from outside
//! becomes code, templates stop, outputs are all or nothing (signals
//! included), values are range-checked, readers stay linear, every input
//! error is located.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn kinpost(dir: &Path, args: &[&str]) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_kinpost"));
    c.args(args).current_dir(dir);
    c
}

fn run(dir: &Path, args: &[&str]) -> Output {
    kinpost(dir, args).output().expect("run kinpost")
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

fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// A short CL file for `trunnion-ac`.
const CL: &str =
    "TOOL PATH/P1,TOOL,T1\nSPINDL/1200,CLW\nFEDRAT/MMPM,500\nGOTO/0,0,0,0,0,1\nGOTO/10,0,0,0,0,1\n";

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// Whether a line of a program (block number and blanks skipped) starts
/// with the code the tests try to inject.
fn injected(program: &str) -> Option<&str> {
    program.lines().find(|l| {
        let code = l.trim_start_matches(|c: char| c.is_ascii_digit() || c == ' ' || c == 'N');
        code.starts_with("G0 Z-100") || code.starts_with("G00 Z-100") || code.starts_with(";.cls")
    })
}

#[test]
fn a_line_break_in_the_cl_file_name_is_no_block() {
    let dir = tempfile::tempdir().unwrap();
    let name = "part\nG0 Z-100\n;.cls";
    write(dir.path(), name, CL);
    for dialect in ["sinumerik", "linuxcnc", "heidenhain", "fanuc"] {
        let o = run(
            dir.path(),
            &["post", name, "-m", "trunnion-ac", "-d", dialect, "-q"],
        );
        assert_exit(&o, 0);
        let program = stdout(&o);
        assert_eq!(injected(&program), None, "{dialect}:\n{program}");
        assert!(
            program.contains("part G0 Z-100 ;.cls"),
            "{dialect}:\n{program}"
        );
    }
}

#[test]
fn control_characters_in_partno_and_tool_path_stay_out_of_the_header() {
    let dir = tempfile::tempdir().unwrap();
    for first in [
        "PARTNO NAME\u{0}\u{c}\u{b}\u{1b}G00 Z-100 X",
        "TOOL PATH/NAME\u{1b}\u{c}G00 Z-100\u{1b},TOOL,T1",
    ] {
        write(
            dir.path(),
            "p.cls",
            &format!("{first}\n{}", &CL[CL.find('\n').unwrap() + 1..]),
        );
        for dialect in ["sinumerik", "linuxcnc", "heidenhain", "fanuc"] {
            let o = run(
                dir.path(),
                &["post", "p.cls", "-m", "trunnion-ac", "-d", dialect, "-q"],
            );
            assert_exit(&o, 0);
            let program = stdout(&o);
            assert!(
                !program.bytes().any(|b| b < 0x20 && b != b'\n'),
                "{dialect}: {program:?}"
            );
        }
    }
}

/// A dialect file whose header runs without end, or doubles a string, is
/// refused at load, at its line, in seconds, and leaves no temporary file.
#[test]
fn runaway_templates_are_refused_with_their_place() {
    let dir = tempfile::tempdir().unwrap();
    let base = std::fs::read_to_string(root().join("crates/nc/dialects/sinumerik.toml")).unwrap();
    let loops =
        "{% for a in range(100000) %}{% for b in range(100000) %}{{ a }}{% endfor %}{% endfor %}";
    let doubling = "{% set ns = namespace(s='0123456789') %}{% for i in range(40) %}{% set ns.s = ns.s ~ ns.s %}{% endfor %}{{ ns.s }}";
    for (k, t) in [loops, doubling].into_iter().enumerate() {
        let dialect = base.replacen("G90 G71 G17 G64\n", &format!("G90 G71 G17 G64\n{t}\n"), 1);
        write(dir.path(), "mine.toml", &dialect);
        write(dir.path(), "p.cls", CL);
        let started = Instant::now();
        let o = run(
            dir.path(),
            &[
                "post",
                "p.cls",
                "-m",
                "trunnion-ac",
                "-d",
                "./mine.toml",
                "-o",
                "p.mpf",
            ],
        );
        assert!(started.elapsed() < Duration::from_secs(20), "{k}");
        assert_exit(&o, 1);
        let err = stderr(&o);
        assert!(err.contains("mine.toml:"), "{err}");
        assert!(err.contains("rendered with sample values"), "{err}");
        assert_eq!(listing(dir.path()), ["mine.toml", "p.cls"]);
        let o = run(dir.path(), &["dialect", "check", "mine.toml"]);
        assert_exit(&o, 1);
        assert!(stderr(&o).contains("mine.toml:"), "{}", stderr(&o));
        // A machine file whose header does the same is not valid.
        let machine =
            std::fs::read_to_string(root().join("crates/machine/machines/trunnion-ac.toml"))
                .unwrap()
                .replacen("[post]\n", &format!("[post]\nheader = '''\n{t}\n'''\n"), 1);
        write(dir.path(), "m.toml", &machine);
        let o = run(dir.path(), &["machine", "check", "m.toml"]);
        assert_exit(&o, 1);
        assert!(stderr(&o).contains("m.toml:"), "{}", stderr(&o));
        std::fs::remove_file(dir.path().join("m.toml")).unwrap();
    }
    let o = run(dir.path(), &["dialect", "check", "sinumerik"]);
    assert_exit(&o, 0);
}

#[test]
fn a_failed_output_leaves_no_other_output() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "p.cls", CL);
    let o = run(
        dir.path(),
        &[
            "post",
            "p.cls",
            "-m",
            "trunnion-ac",
            "-o",
            "x.mpf",
            "--json",
            "/dev/full",
        ],
    );
    assert_exit(&o, 1);
    assert_eq!(listing(dir.path()), ["p.cls"]);
    // The same for `path`.
    let pts = dir.path().join("pts.csv");
    let mut text = String::new();
    for i in 0..5 {
        for j in 0..5 {
            text.push_str(&format!(
                "{i},{j},{},{},0\n",
                f64::from(i) * 10.0,
                f64::from(j) * 10.0
            ));
        }
    }
    std::fs::write(&pts, text).unwrap();
    let o = run(dir.path(), &["surface", "fit", "pts.csv", "-o", "s.json"]);
    assert_exit(&o, 0);
    let o = run(
        dir.path(),
        &[
            "path",
            "s.json",
            "--tool",
            "wheel:radius=50,width=20",
            "--stepover",
            "5",
            "--feed",
            "600",
            "-o",
            "p2.cls",
            "--svg",
            "/dev/full",
        ],
    );
    assert_exit(&o, 1);
    assert_eq!(listing(dir.path()), ["p.cls", "pts.csv", "s.json"]);
}

#[cfg(unix)]
#[test]
fn two_links_to_one_new_file_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "p.cls", CL);
    std::os::unix::fs::symlink("new.mpf", dir.path().join("a.lnk")).unwrap();
    std::os::unix::fs::symlink("new.mpf", dir.path().join("b.lnk")).unwrap();
    let o = run(
        dir.path(),
        &[
            "post",
            "p.cls",
            "-m",
            "trunnion-ac",
            "-o",
            "a.lnk",
            "--json",
            "b.lnk",
        ],
    );
    assert_exit(&o, 2);
    assert!(stderr(&o).contains("same file"), "{}", stderr(&o));
    assert!(!dir.path().join("new.mpf").exists());
}

#[cfg(unix)]
#[test]
fn standard_input_that_is_the_output_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let cl = write(dir.path(), "f.cls", CL);
    let o = kinpost(
        dir.path(),
        &["post", "-", "-m", "trunnion-ac", "-o", "f.cls"],
    )
    .stdin(std::fs::File::open(&cl).unwrap())
    .output()
    .unwrap();
    assert_exit(&o, 2);
    assert!(stderr(&o).contains("standard input"), "{}", stderr(&o));
    assert_eq!(std::fs::read_to_string(&cl).unwrap(), CL);
}

/// SIGINT, SIGTERM and SIGHUP in the middle of a post remove its staged
/// files; the exit code is 128 + the signal.
#[cfg(unix)]
#[test]
fn a_signal_leaves_no_temporary_file() {
    for (signal, number) in [("INT", 2), ("TERM", 15), ("HUP", 1)] {
        let dir = tempfile::tempdir().unwrap();
        let mut child = kinpost(
            dir.path(),
            &[
                "post",
                "-",
                "-m",
                "trunnion-ac",
                "-o",
                "out.mpf",
                "--json",
                "out.json",
            ],
        )
        .stdin(Stdio::piped())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
        let mut input = child.stdin.take().unwrap();
        input.write_all(b"FEDRAT/MMPM,500\n").unwrap();
        for i in 0..20_000 {
            writeln!(input, "GOTO/{}.0,0,0,0,0,1", i % 100).unwrap();
        }
        input.flush().unwrap();
        // Both outputs are staged while the post waits for more input.
        let started = Instant::now();
        while listing(dir.path()).len() < 2 {
            assert!(
                started.elapsed() < Duration::from_secs(20),
                "{signal}: nothing staged"
            );
            std::thread::sleep(Duration::from_millis(20));
        }
        let killed = Command::new("kill")
            .args([format!("-{signal}"), child.id().to_string()])
            .status()
            .unwrap();
        assert!(killed.success());
        let o = child.wait_with_output().unwrap();
        drop(input);
        assert_eq!(
            o.status.code(),
            Some(128 + number),
            "{signal}: {}",
            stderr(&o)
        );
        assert_eq!(listing(dir.path()), Vec::<String>::new(), "{signal}");
    }
}

#[test]
fn spindle_speeds_out_of_range_are_errors_with_their_line() {
    let dir = tempfile::tempdir().unwrap();
    for speed in ["0.4", "1e308"] {
        write(
            dir.path(),
            "p.cls",
            &CL.replace("SPINDL/1200", &format!("SPINDL/{speed}")),
        );
        for dialect in ["sinumerik", "linuxcnc", "heidenhain", "fanuc"] {
            let o = run(
                dir.path(),
                &[
                    "post",
                    "p.cls",
                    "-m",
                    "trunnion-ac",
                    "-d",
                    dialect,
                    "-o",
                    "p.nc",
                ],
            );
            assert_exit(&o, 1);
            let err = stderr(&o);
            assert!(err.contains("p.cls:2:"), "{dialect} {speed}: {err}");
            assert!(err.contains("spindle speed"), "{dialect} {speed}: {err}");
            assert_eq!(listing(dir.path()), ["p.cls"]);
        }
    }
}

/// Standard output is spooled, not held in memory, and a failed run
/// prints no part of its program.
#[test]
fn a_failed_run_prints_nothing_on_standard_output() {
    let dir = tempfile::tempdir().unwrap();
    write(
        dir.path(),
        "p.cls",
        &format!("{CL}GOTO/0,0,0,0.8660254,0,0.5\nGOTO/0,0,0,0,0,-1\n"),
    );
    let o = run(dir.path(), &["post", "p.cls", "-m", "trunnion-ac", "-q"]);
    assert_exit(&o, 1);
    assert!(o.stdout.is_empty(), "{}", stdout(&o));
}

/// A carriage return inside a line (in PARTNO, or a whole file with CR
/// line ends) is an error at its place: never a file read as one line,
/// never an empty program with exit 0.
#[test]
fn carriage_returns_inside_lines_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    for cl in [
        "PARTNO NAME\rG00 Z-100\nFEDRAT/MMPM,500\nGOTO/0,0,0,0,0,1\n".to_string(),
        CL.replace('\n', "\r"),
        format!("$$ made on a Mac\r{}", CL.replace('\n', "\r")),
    ] {
        write(dir.path(), "p.cls", &cl);
        let o = run(
            dir.path(),
            &["post", "p.cls", "-m", "trunnion-ac", "-o", "p.mpf"],
        );
        assert_exit(&o, 1);
        let err = stderr(&o);
        assert!(err.contains("p.cls:1:"), "{err}");
        assert!(err.contains("carriage return"), "{err}");
        assert_eq!(listing(dir.path()), ["p.cls"]);
    }
}

/// A small wavy surface fitted in `dir` (`s.json`).
fn fitted_surface(dir: &Path) {
    let mut text = String::new();
    for i in 0..8 {
        for j in 0..8 {
            let (x, y) = (f64::from(i) * 10.0, f64::from(j) * 8.0);
            let z = 3.0 * (f64::from(i) / 3.0).sin() + 2.0 * (f64::from(j) / 4.0).cos();
            text.push_str(&format!("{i},{j},{x},{y},{z:.4}\n"));
        }
    }
    write(dir, "pts.csv", &text);
    assert_exit(&run(dir, &["surface", "fit", "pts.csv", "-o", "s.json"]), 0);
}

/// Options that would ask for billions of CL points or passes are refused
/// before the work, with the count they would need.
#[test]
fn path_options_too_fine_are_refused_up_front() {
    let dir = tempfile::tempdir().unwrap();
    fitted_surface(dir.path());
    let base = [
        "path",
        "s.json",
        "--tool",
        "wheel:radius=50,width=20",
        "--feed",
        "600",
        "-o",
        "p.cls",
    ];
    for (extra, code, says) in [
        (
            &["--stepover", "5", "--max-angle", "1e-9"][..],
            1,
            "CL points",
        ),
        (&["--stepover", "1e-9"][..], 1, "passes"),
        (&["--stepover", "5", "--chordtol", "1e-12"][..], 2, "1e-6"),
        (&["--scallop", "1e-12"][..], 2, "1e-6"),
    ] {
        let args: Vec<&str> = base.iter().chain(extra).copied().collect();
        let started = Instant::now();
        let o = run(dir.path(), &args);
        assert!(started.elapsed() < Duration::from_secs(30), "{extra:?}");
        assert_exit(&o, code);
        assert!(stderr(&o).contains(says), "{extra:?}: {}", stderr(&o));
        assert!(!dir.path().join("p.cls").exists());
    }
}

/// One long line of a points file is read in linear time (it was
/// quadratic: a 2 MB line took 12 s, 8 MB over 3 minutes).
#[test]
fn a_long_points_line_is_read_in_linear_time() {
    let dir = tempfile::tempdir().unwrap();
    let line: String = "0,0,1,2,3,".repeat(800_000);
    write(dir.path(), "long.csv", &format!("{line}\n"));
    let started = Instant::now();
    let o = run(dir.path(), &["surface", "fit", "long.csv", "-o", "s.json"]);
    assert!(started.elapsed() < Duration::from_secs(30));
    assert_exit(&o, 1);
    // The error does not echo the 8 MB line.
    assert!(o.stderr.len() < 4000, "{}", o.stderr.len());
}

/// Bytes that are not UTF-8 in a machine, dialect, points or surface file
/// are an error at the file, line and column of the first.
#[test]
fn invalid_utf8_is_located_in_every_input_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write(d, "p.cls", CL);
    let machine = std::fs::read(root().join("crates/machine/machines/trunnion-ac.toml")).unwrap();
    let mut bad = b"# caf\xe9\n".to_vec();
    bad.extend_from_slice(&machine);
    std::fs::write(d.join("m.toml"), &bad).unwrap();
    let dialect = std::fs::read(root().join("crates/nc/dialects/sinumerik.toml")).unwrap();
    let mut bad = b"# caf\xe9\n".to_vec();
    bad.extend_from_slice(&dialect);
    std::fs::write(d.join("d.toml"), &bad).unwrap();
    std::fs::write(d.join("pts.csv"), b"0,0,1,2,3\n0,1,1,2,\xff\n").unwrap();
    std::fs::write(d.join("s.json"), b"{\n \"knots\": \"\xfe\"}\n").unwrap();
    for (args, at) in [
        (&["machine", "check", "m.toml"][..], "m.toml:1:6"),
        (&["post", "p.cls", "-m", "m.toml"][..], "m.toml:1:6"),
        (&["dialect", "check", "d.toml"][..], "d.toml:1:6"),
        (
            &["post", "p.cls", "-m", "trunnion-ac", "-d", "d.toml"][..],
            "d.toml:1:6",
        ),
        (
            &["surface", "fit", "pts.csv", "-o", "f.json"][..],
            "pts.csv:2:9",
        ),
        (
            &["surface", "eval", "s.json", "--uv", "0.5,0.5"][..],
            "s.json:2:12",
        ),
    ] {
        let o = run(d, args);
        assert_exit(&o, 1);
        let err = stderr(&o);
        assert!(err.contains(at), "{args:?}: {err}");
        assert!(err.contains("UTF-8"), "{args:?}: {err}");
    }
}

/// A relative `[post] dialect` path is the machine file's neighbour, from
/// any folder; a built-in name wins over a file of that name only when it
/// is a plain name, and the run says so.
#[test]
fn names_resolve_the_same_from_any_folder() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::create_dir(d.join("cell")).unwrap();
    let dialect = std::fs::read_to_string(root().join("crates/nc/dialects/sinumerik.toml"))
        .unwrap()
        .replace("; POSTED BY KINPOST", "; MY CELL POST");
    write(&d.join("cell"), "mine.toml", &dialect);
    let machine =
        std::fs::read_to_string(root().join("crates/machine/machines/trunnion-ac.toml")).unwrap();
    let machine = match machine.find("dialect = ") {
        Some(at) => {
            let end = at + machine[at..].find('\n').unwrap();
            format!(
                "{}dialect = \"./mine.toml\"{}",
                &machine[..at],
                &machine[end..]
            )
        }
        None => panic!("trunnion-ac has a [post] dialect"),
    };
    write(&d.join("cell"), "m.toml", &machine);
    write(d, "p.cls", CL);
    let from_top = run(d, &["post", "p.cls", "-m", "cell/m.toml", "-q"]);
    assert_exit(&from_top, 0);
    assert!(
        stdout(&from_top).contains("; MY CELL POST"),
        "{}",
        stdout(&from_top)
    );
    let from_cell = run(&d.join("cell"), &["post", "../p.cls", "-m", "m.toml", "-q"]);
    assert_exit(&from_cell, 0);
    assert_eq!(
        stdout(&from_top),
        stdout(&from_cell).replace("../p.cls", "p.cls")
    );
    // A file named like a built-in in the current folder: the built-in,
    // with a note; `./NAME` reads the file.
    write(d, "sinumerik", &dialect);
    let o = run(
        d,
        &[
            "post",
            "p.cls",
            "-m",
            "trunnion-ac",
            "-d",
            "sinumerik",
            "-q",
        ],
    );
    assert_exit(&o, 0);
    assert!(!stdout(&o).contains("; MY CELL POST"));
    assert!(stderr(&o).contains("built-in dialect"), "{}", stderr(&o));
    let o = run(
        d,
        &[
            "post",
            "p.cls",
            "-m",
            "trunnion-ac",
            "-d",
            "./sinumerik",
            "-q",
        ],
    );
    assert_exit(&o, 0);
    assert!(stdout(&o).contains("; MY CELL POST"));
}

/// A huge token is not echoed whole, neither on standard error nor in the
/// JSON summary.
#[test]
fn a_huge_token_is_not_echoed_whole() {
    let dir = tempfile::tempdir().unwrap();
    let token = "X".repeat(500_000);
    write(dir.path(), "p.cls", &format!("{token}/1\n{CL}"));
    let o = run(
        dir.path(),
        &[
            "post",
            "p.cls",
            "-m",
            "trunnion-ac",
            "-o",
            "p.mpf",
            "--json",
            "p.json",
        ],
    );
    assert_exit(&o, 0);
    assert!(o.stderr.len() < 5000, "{}", o.stderr.len());
    let json = std::fs::read_to_string(dir.path().join("p.json")).unwrap();
    assert!(json.len() < 20_000, "{}", json.len());
}

/// A pressure too large to write is an error at its CL line, shown in a
/// few characters (not 309 digits).
#[test]
fn pressures_that_cannot_be_written_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    for p in ["1e308", "1e30"] {
        write(
            dir.path(),
            "p.cls",
            &format!(
                "PRESSURE/H1,{p}\nFEDRAT/MMPM,250\nGOTO/-416.0000,70.5000,16.5300,0.0000000,0.0000000,1.0000000\nGOTO/-416.0000,70.5000,13.0000\n"
            ),
        );
        let o = run(
            dir.path(),
            &["post", "p.cls", "-m", "mts1600", "-o", "p.mpf"],
        );
        assert_exit(&o, 1);
        let err = stderr(&o);
        assert!(err.contains("cannot write H1"), "{err}");
        assert!(err.contains("p.cls:"), "{err}");
        assert!(err.len() < 2000, "{err}");
        assert_eq!(listing(dir.path()), ["p.cls"]);
    }
}

/// A machine file of 300 000 `[[axis]]` tables (15 MB) is refused by its
/// size before it is parsed; one of a few hundred tables at its tenth.
#[test]
fn machine_files_with_many_axis_tables_are_refused_early() {
    let dir = tempfile::tempdir().unwrap();
    let table = |i: usize| {
        format!(
            "[[axis]]\nname = \"X{i}\"\nkind = \"linear\"\nside = \"tool\"\ndirection = [1, 0, 0]\n"
        )
    };
    let many: String = std::iter::once("name = \"m\"\n".to_string())
        .chain((0..300_000).map(table))
        .collect();
    write(dir.path(), "many.toml", &many);
    let started = Instant::now();
    let o = run(dir.path(), &["machine", "check", "many.toml"]);
    assert!(started.elapsed() < Duration::from_secs(20));
    assert_exit(&o, 1);
    assert!(stderr(&o).contains("many.toml:1:1"), "{}", stderr(&o));
    let few: String = std::iter::once("name = \"m\"\n".to_string())
        .chain((0..500).map(table))
        .collect();
    write(dir.path(), "few.toml", &few);
    let o = run(dir.path(), &["machine", "check", "few.toml"]);
    assert_exit(&o, 1);
    assert!(stderr(&o).contains("at most 9 axes"), "{}", stderr(&o));
    assert!(stderr(&o).contains("few.toml:48:"), "{}", stderr(&o));
}
