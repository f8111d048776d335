//! LinuxCNC's own G-code interpreter as a client of the `linuxcnc` dialect.
//!
//! Each job is posted twice, with `--dialect linuxcnc` and `--dialect csv`.
//! The `.ngc` program is run through `rs274 -g FILE` (the standalone
//! interpreter of Debian's `linuxcnc-uspace`, no ini, tool table or var file
//! needed; it prints one canonical call per line, e.g.
//! `   33 N..... STRAIGHT_FEED(459.0000, 8.8069, 350.1234, 0.0000, -20.0005, 0.0000)`
//! with X Y Z A B C in program units (mm under our `G21`), 4 decimals; it
//! exits 1 and names the error on standard error for a program it rejects).
//! It creates `$HOME/.tool.mmap`, so each run gets its own `HOME`.
//! The program must parse cleanly, and every STRAIGHT_TRAVERSE /
//! STRAIGHT_FEED must equal the CSV row of the same block within the output
//! decimals, with the feed rate in force for feed moves.
//!
//! Where `rs274` is missing the tests print `SKIPPED: ...` and pass;
//! `.ci/run` installs it (`apt-get install linuxcnc-uspace`).

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use kinpost_post::machine::{Kinematics, Machine, builtin, machine_from_toml};
use kinpost_post::nc::Dialect;
use kinpost_post::{PostOptions, post};

/// The axis letters rs274 prints, in its order.
const RS274_AXES: [&str; 6] = ["X", "Y", "Z", "A", "B", "C"];

/// `rs274` from `$RS274`, the `PATH`, or where Debian's package puts it.
fn rs274() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("RS274") {
        return Some(PathBuf::from(p));
    }
    let on_path = std::env::var_os("PATH")
        .map(|paths| {
            std::env::split_paths(&paths)
                .map(|d| d.join("rs274"))
                .collect::<Vec<_>>()
        })
        .unwrap_or_default();
    on_path
        .into_iter()
        .chain([
            PathBuf::from("/usr/bin/rs274"),
            PathBuf::from("/usr/lib/linuxcnc/bin/rs274"),
        ])
        .find(|p| p.is_file())
}

/// The interpreter, or `None` after a visible skip message.
fn interpreter(test: &str) -> Option<PathBuf> {
    let found = rs274();
    if found.is_none() {
        eprintln!(
            "SKIPPED: {test}: rs274 (LinuxCNC's standalone interpreter) not found on PATH or in \
             /usr/bin; install it with `apt-get install --no-install-recommends linuxcnc-uspace` \
             (or set RS274=/path/to/rs274)"
        );
    }
    found
}

fn example(name: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples")
        .join(name);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn post_text(machine: &Machine, dialect: &str, cl: &str, cl_file: &str) -> String {
    let dialect = Dialect::builtin(dialect).unwrap();
    let mut out = Vec::new();
    let options = PostOptions {
        cl_file: cl_file.into(),
        ..PostOptions::default()
    };
    post(cl.as_bytes(), machine, &dialect, &mut out, &options)
        .unwrap_or_else(|e| panic!("{cl_file} on {} ({}): {e}", machine.name, dialect.name()));
    String::from_utf8(out).unwrap()
}

/// One move of the interpreter.
#[derive(Debug)]
struct Move {
    feed: bool,
    /// X Y Z A B C.
    at: [f64; 6],
    /// Feed rate in force.
    rate: f64,
    /// Value of analog output 0 (`M68 E0 Q…`) in force, if set.
    aux: Option<f64>,
}

/// Runs rs274 on `program`; panics unless it parses cleanly.
fn interpret(rs274: &Path, program: &str, label: &str) -> Vec<Move> {
    run(rs274, program, label).unwrap_or_else(|e| panic!("{e}"))
}

/// Runs rs274 on `program`: its moves, or why the program is not clean.
fn run(rs274: &Path, program: &str, label: &str) -> Result<Vec<Move>, String> {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("job.ngc");
    std::fs::write(&file, program).unwrap();
    let out = Command::new(rs274)
        .arg("-g")
        .arg(&file)
        .current_dir(dir.path())
        // rs274 keeps its tool table in `$HOME/.tool.mmap`, truncated and
        // mapped shared at start: parallel runs sharing it die of SIGBUS.
        .env("HOME", dir.path())
        .stdin(Stdio::null())
        .output()
        .unwrap_or_else(|e| panic!("cannot run {}: {e}", rs274.display()));
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    let context = || format!("{label}\n--- rs274 stderr\n{stderr}\n--- program\n{program}");
    if !out.status.success() {
        return Err(format!(
            "rs274 rejected the program ({}): {}",
            out.status,
            context()
        ));
    }
    // A clean run prints only `executing` on standard error.
    if !stderr
        .lines()
        .all(|l| l.trim().is_empty() || l.trim() == "executing")
    {
        return Err(format!("rs274 complained: {}", context()));
    }
    if !stdout.contains("PROGRAM_END()") {
        return Err(format!(
            "no PROGRAM_END: {}\n--- stdout\n{stdout}",
            context()
        ));
    }
    let mut moves = Vec::new();
    let mut rate = 0.0;
    let mut aux = None;
    for line in stdout.lines() {
        // `   33 N..... NAME(args)`
        let Some(call) = line.split_whitespace().nth(2) else {
            continue;
        };
        let call = &line[line.find(call).unwrap()..];
        let Some((name, args)) = call.split_once('(') else {
            continue;
        };
        let args = args.trim_end_matches(')');
        let numbers = || -> Vec<f64> {
            args.split(',')
                .map(|v| {
                    v.trim()
                        .parse()
                        .unwrap_or_else(|_| panic!("rs274 line: {line}"))
                })
                .collect()
        };
        match name {
            "SET_FEED_RATE" => rate = numbers()[0],
            "SET_AUX_OUTPUT_VALUE" => {
                let v = numbers();
                if v[0] == 0.0 {
                    aux = Some(v[1]);
                }
            }
            "STRAIGHT_TRAVERSE" | "STRAIGHT_FEED" => {
                let v = numbers();
                assert!(v.len() >= 6, "rs274 line: {line}");
                moves.push(Move {
                    feed: name == "STRAIGHT_FEED",
                    at: [v[0], v[1], v[2], v[3], v[4], v[5]],
                    rate,
                    aux,
                });
            }
            "ARC_FEED" | "STRAIGHT_PROBE" | "RIGID_TAP" => {
                return Err(format!("unexpected {name}: {}", context()));
            }
            _ => {}
        }
    }
    Ok(moves)
}

/// One CSV row: motion, X Y Z A B C (0 where the machine lacks the axis),
/// feed.
struct Row {
    feed: bool,
    at: [f64; 6],
    rate: Option<f64>,
    text: String,
}

fn csv_rows(machine: &Machine, csv: &str) -> Vec<Row> {
    for a in &machine.axes {
        assert!(
            RS274_AXES.contains(&a.name.as_str()),
            "{}: axis {} is not one of rs274's X Y Z A B C",
            machine.name,
            a.name
        );
    }
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let column = |name: &str| header.iter().position(|h| *h == name);
    let slots: Vec<Option<usize>> = RS274_AXES.iter().map(|a| column(a)).collect();
    let motion = column("motion").unwrap();
    let feed = column("feed").unwrap();
    lines
        .map(|line| {
            let f: Vec<&str> = line.split(',').collect();
            let num = |s: &str| -> f64 { s.parse().unwrap_or_else(|_| panic!("{line}")) };
            let mut at = [0.0; 6];
            for (k, slot) in slots.iter().enumerate() {
                if let Some(c) = slot {
                    at[k] = num(f[*c]);
                }
            }
            Row {
                feed: f[motion] == "feed",
                at,
                rate: (!f[feed].is_empty()).then(|| num(f[feed])),
                text: line.to_string(),
            }
        })
        .collect()
}

/// Posts `cl` for `machine` in both dialects and compares. Returns the
/// number of moves compared.
fn compare(rs274: &Path, machine: &Machine, cl: &str, cl_file: &str) -> usize {
    let label = format!("{cl_file} on {}", machine.name);
    let ngc = post_text(machine, "linuxcnc", cl, cl_file);
    let csv = post_text(machine, "csv", cl, cl_file);
    let linuxcnc = Dialect::builtin("linuxcnc").unwrap();
    let csv_dialect = Dialect::builtin("csv").unwrap();
    // Half a unit of the last decimal of each side (both round the same
    // exact value), plus float noise.
    let decimals = |d: &Dialect, rotary: bool| {
        let spec = if rotary {
            kinpost_post::nc::AxisSpec::rotary("A")
        } else {
            kinpost_post::nc::AxisSpec::linear("X")
        };
        d.word_format(&spec).number.decimals
    };
    let half = |d: u8| 0.5 * 10f64.powi(-i32::from(d));
    let tol = |k: usize| {
        let rotary = k >= 3;
        half(decimals(&linuxcnc, rotary)) + half(decimals(&csv_dialect, rotary)) + 1e-9
    };
    let feed_tol = half(linuxcnc.feed_format().word.number.decimals)
        + half(csv_dialect.feed_format().word.number.decimals)
        + 1e-9;

    let moves = interpret(rs274, &ngc, &label);
    let rows = csv_rows(machine, &csv);
    let near = |a: &[f64; 6], b: &[f64; 6]| (0..6).all(|k| (a[k] - b[k]).abs() <= tol(k));
    let mut m = 0;
    let mut last = [0.0; 6];
    for row in &rows {
        match moves.get(m) {
            Some(mv) if near(&mv.at, &row.at) => {
                assert_eq!(
                    mv.feed, row.feed,
                    "{label}: motion differs: rs274 {mv:?}, csv {}",
                    row.text
                );
                if mv.feed {
                    let want = row.rate.expect("feed rows have a feed");
                    assert!(
                        (mv.rate - want).abs() <= feed_tol,
                        "{label}: feed rate {} for csv {}",
                        mv.rate,
                        row.text
                    );
                }
                last = mv.at;
                m += 1;
            }
            // A block that moves nothing as written is left out of the program.
            _ if near(&last, &row.at) => {}
            other => panic!(
                "{label}: csv row {} has no rs274 move (next rs274 move: {other:?})\n--- ngc\n{ngc}",
                row.text
            ),
        }
    }
    assert_eq!(
        m,
        moves.len(),
        "{label}: rs274 has moves the csv lacks: {:?}",
        &moves[m..]
    );
    assert!(m > 0, "{label}: no moves");
    m
}

/// A CL program through the given joint values: FK of each, with tool
/// change, spindle, coolant and comments (parentheses and commas) around.
fn cl_through(machine: &Machine, joints: &[Vec<f64>]) -> String {
    let kin = Kinematics::new(machine);
    let mut cl = String::from(
        "PARTNO/RS274 (CHECK), JOB\nTOOL PATH/FIVE AXIS,TOOL,MILL-D10\nLOAD/TOOL,1\n\
         SPINDL/3000,RPM,CLW\nCOOLNT/ON\nPPRINT/MSG, NOT A MESSAGE (NESTED (PARENS))\nRAPID\n",
    );
    for (k, q) in joints.iter().enumerate() {
        let p = kin.fk(q);
        if k == 1 {
            cl.push_str("FEDRAT/MMPM,250\n");
        }
        if k == joints.len() / 2 {
            cl.push_str("FEDRAT/MMPM,400.5\n");
        }
        cl.push_str(&format!(
            "GOTO/{:.6},{:.6},{:.6},{:.9},{:.9},{:.9}\n",
            p.point.x, p.point.y, p.point.z, p.axis.x, p.axis.y, p.axis.z
        ));
    }
    cl.push_str("COOLNT/OFF\nSPINDL/OFF\nEND\nFINI\n");
    cl
}

/// An axis and the values it sweeps from and to.
type Range = (&'static str, f64, f64);

/// A smooth 5-axis sweep through the machine's travel, named by axis:
/// `(name, from, to)`; other axes stay at 0 (fixed ones at their value).
fn sweep(machine: &Machine, ranges: &[Range], n: usize) -> Vec<Vec<f64>> {
    (0..n)
        .map(|k| {
            let t = k as f64 / (n - 1) as f64;
            machine
                .axes
                .iter()
                .map(|a| {
                    if let Some(f) = a.fixed {
                        return f;
                    }
                    ranges.iter().find(|(name, _, _)| *name == a.name).map_or(
                        0.0,
                        |(_, from, to)| {
                            // Not linear in t: every block differs in every axis.
                            from + (to - from) * (t + 0.15 * (std::f64::consts::PI * t).sin())
                        },
                    )
                })
                .collect()
        })
        .collect()
}

/// The built-in mts1600. Its machine file has its own header and footer in
/// Sinumerik code (`R32=15000`, `A=DC(0)`); the post writes them for its
/// default dialect only, so rs274 sees the `linuxcnc` dialect's own.
fn mts1600() -> Machine {
    builtin::load("mts1600").unwrap().unwrap()
}

#[test]
fn mts1600_five_axis_example() {
    let Some(rs274) = interpreter("mts1600_five_axis_example") else {
        return;
    };
    let n = compare(
        &rs274,
        &mts1600(),
        &example("five-axis.cls"),
        "five-axis.cls",
    );
    eprintln!("rs274: mts1600 five-axis.cls: {n} moves equal the csv output");
}

#[test]
fn mts1600_qiao_flat_part() {
    let Some(rs274) = interpreter("mts1600_qiao_flat_part") else {
        return;
    };
    let n = compare(
        &rs274,
        &mts1600(),
        &example("flat-part.cls"),
        "flat-part.cls",
    );
    eprintln!("rs274: mts1600 flat-part.cls: {n} moves equal the csv output");
}

#[test]
fn mts1600_sweep() {
    let Some(rs274) = interpreter("mts1600_sweep") else {
        return;
    };
    let m = mts1600();
    let joints = sweep(
        &m,
        &[
            ("X", 300.0, 700.0),
            ("A", -30.0, 200.0),
            ("Y", -50.0, 20.0),
            ("Z", 300.0, 380.0),
            ("B", -40.0, 35.0),
        ],
        41,
    );
    let n = compare(&rs274, &m, &cl_through(&m, &joints), "sweep.cls");
    eprintln!("rs274: mts1600 sweep: {n} moves equal the csv output");
}

/// An A/C trunnion table (table/table) with offset rotation lines, as
/// LinuxCNC's `xyzac-trt-kins` describes it: A about X through
/// (0, y_r + D_y, z_r + D_z), C about Z through (x_r, y_r).
const TRUNNION_AC: &str = r#"
name = "test-trunnion-ac"
description = "A/C trunnion table with offset rotation lines (rs274 test)"

[[axis]]
name = "X"
kind = "linear"
side = "tool"
direction = [1, 0, 0]
limits = [-500, 500]

[[axis]]
name = "Y"
kind = "linear"
side = "tool"
direction = [0, 1, 0]
limits = [-400, 400]

[[axis]]
name = "Z"
kind = "linear"
side = "tool"
direction = [0, 0, 1]
limits = [-400, 500]

[[axis]]
name = "A"
kind = "rotary"
side = "workpiece"
direction = [1, 0, 0]
point = [0, 12.5, -80]
limits = [-100, 100]

[[axis]]
name = "C"
kind = "rotary"
side = "workpiece"
direction = [0, 0, 1]
point = [7.5, 10, 0]
limits = [-400, 400]

[workpiece]
origin = [0, 0, 0]
x = [1, 0, 0]
z = [0, 0, 1]

[tool]
point = [0, 0, 0]
axis = [0, 0, 1]
"#;

#[test]
fn trunnion_ac_test_machine() {
    let Some(rs274) = interpreter("trunnion_ac_test_machine") else {
        return;
    };
    let m = machine_from_toml(TRUNNION_AC, "test-trunnion-ac.toml").unwrap();
    let joints = sweep(
        &m,
        &[
            ("X", -60.0, 80.0),
            ("Y", 40.0, -30.0),
            ("Z", 50.0, 10.0),
            ("A", -20.0, 70.0),
            ("C", -150.0, 250.0),
        ],
        41,
    );
    let n = compare(&rs274, &m, &cl_through(&m, &joints), "trunnion.cls");
    eprintln!("rs274: test-trunnion-ac: {n} moves equal the csv output");
}

/// The built-in reference machines of the issue (when they are built in).
#[test]
fn builtin_reference_machines() {
    let Some(rs274) = interpreter("builtin_reference_machines") else {
        return;
    };
    let jobs: [(&str, &[Range]); 2] = [
        (
            "trunnion-ac",
            &[
                ("X", -60.0, 80.0),
                ("Y", 40.0, -30.0),
                ("Z", 50.0, 10.0),
                ("A", -20.0, 70.0),
                ("C", -150.0, 250.0),
            ],
        ),
        (
            "table-head-bc",
            &[
                ("X", -60.0, 80.0),
                ("Y", 40.0, -30.0),
                ("Z", 150.0, 60.0),
                ("B", -40.0, 60.0),
                ("C", -150.0, 250.0),
            ],
        ),
    ];
    for (name, ranges) in jobs {
        let Some(machine) = builtin::load(name) else {
            eprintln!("SKIPPED: built-in machine `{name}` does not exist (yet)");
            continue;
        };
        let m = machine.unwrap_or_else(|e| panic!("built-in {name}: {e}"));
        let joints = sweep(&m, ranges, 41);
        let n = compare(&rs274, &m, &cl_through(&m, &joints), "sweep.cls");
        eprintln!("rs274: {name}: {n} moves equal the csv output");
    }
}

/// The interpreter does reject what it should: a nested comment and a word
/// it does not know, so a clean parse above means something.
#[test]
fn rs274_rejects_bad_programs() {
    let Some(rs274) = interpreter("rs274_rejects_bad_programs") else {
        return;
    };
    for bad in [
        "%\n(a (nested) comment)\nM2\n%\n",
        "%\nG0 X1 H2=3\nM2\n%\n",
        "%\nG0 X1\n",
        "%\nG0 X1 E1.5\nM2\n%\n",
    ] {
        assert!(run(&rs274, bad, "bad").is_err(), "rs274 accepted {bad:?}");
    }
}

/// rs274 reads lines of at most 253 bytes with the newline (`LINELEN` 255),
/// the dialect's `max_line_length`: a longer CL comment or PARTNO is
/// shortened to fit, and the program runs.
#[test]
fn long_comments_and_names_fit_the_line_length() {
    let Some(rs274) = interpreter("long_comments_and_names_fit_the_line_length") else {
        return;
    };
    let max = Dialect::builtin("linuxcnc")
        .unwrap()
        .block_format()
        .max_line_length
        .unwrap();
    let comment = |n: usize| format!("%\n({})\nG0 X1\nM2\n%\n", "c".repeat(n));
    assert!(run(&rs274, &comment(max - 3), "longest line").is_ok());
    assert!(run(&rs274, &comment(max - 2), "one byte more").is_err());

    let cl = format!(
        "PARTNO/{}\n$$ {}\n$$ {}\nTOOL PATH/T,TOOL,E\nRAPID\nGOTO/0,0,50,0,0,1\nFEDRAT/100\nGOTO/0,0,10\n",
        "P".repeat(300),
        "c".repeat(253),
        "ü".repeat(200)
    );
    let machine = builtin::load("trunnion-ac").unwrap().unwrap();
    compare(&rs274, &machine, &cl, "long.cls");
    let ngc = post_text(&machine, "linuxcnc", &cl, "long.cls");
    assert!(ngc.lines().all(|l| l.len() < max), "{ngc}");
    assert!(ngc.contains(&format!("(PROGRAM: {})\n", "P".repeat(max - 12))));
}

/// Inverse-time feed (`G93`): the program parses, and the time LinuxCNC
/// gives every feed block (its move length over the feed rate its canon
/// derives from F) equals the CL segment length over the CL feed rate
/// within 0.1 %.
#[test]
fn inverse_time_block_times_are_the_cl_times() {
    let Some(rs274) = interpreter("inverse_time_block_times_are_the_cl_times") else {
        return;
    };
    let cl = example("five-axis.cls");
    let machine = mts1600();
    let dialect = Dialect::builtin("linuxcnc").unwrap();
    let mut out = Vec::new();
    let options = PostOptions {
        feed_mode: Some(kinpost_post::FeedMode::InverseTime),
        ..PostOptions::default()
    };
    post(cl.as_bytes(), &machine, &dialect, &mut out, &options).unwrap();
    let program = String::from_utf8(out).unwrap();
    assert!(
        program.contains("\nG93\n") && program.contains("\nG94\n"),
        "{program}"
    );
    let moves = interpret(&rs274, &program, "five-axis.cls, G93");

    // CL points and the feed rate in force (the example uses one FEDRAT).
    let mut points = Vec::new();
    let mut feed = 0.0;
    for l in cl.lines() {
        if let Some(f) = l.strip_prefix("FEDRAT/MMPM,") {
            feed = f.parse::<f64>().unwrap();
        }
        if let Some(v) = l.strip_prefix("GOTO/") {
            let v: Vec<f64> = v.split(',').map(|x| x.parse().unwrap()).collect();
            points.push([v[0], v[1], v[2]]);
        }
    }
    // Which blocks reach a CL point: the same run in the csv dialect marks
    // the blocks the linearization inserted with an empty line.
    let csv_dialect = Dialect::builtin("csv").unwrap();
    let mut csv = Vec::new();
    post(cl.as_bytes(), &machine, &csv_dialect, &mut csv, &options).unwrap();
    let reaches_cl: Vec<bool> = String::from_utf8(csv)
        .unwrap()
        .lines()
        .skip(1)
        .map(|row| !row.starts_with(','))
        .collect();
    assert_eq!(moves.len(), reaches_cl.len());
    assert_eq!(reaches_cl.iter().filter(|r| **r).count(), points.len());
    assert!(
        moves.len() > points.len(),
        "the example's rotary moves need linearization"
    );
    let d = |a: &[f64], b: &[f64]| {
        a.iter()
            .zip(b)
            .map(|(x, y)| (x - y).powi(2))
            .sum::<f64>()
            .sqrt()
    };
    // The blocks from one CL point to the next take, together, the CL
    // segment length over the feed rate.
    let mut checked = 0;
    let mut point = 0;
    let mut time = 0.0;
    for k in 1..moves.len() {
        if moves[k].feed {
            // LinuxCNC's move length: the XYZ distance, or the ABC one for a
            // move of the rotary axes alone.
            let xyz = d(&moves[k].at[..3], &moves[k - 1].at[..3]);
            let length = if xyz > 1e-6 {
                xyz
            } else {
                d(&moves[k].at[3..], &moves[k - 1].at[3..])
            };
            time += length / moves[k].rate;
        }
        if !reaches_cl[k] {
            continue;
        }
        point += 1;
        if moves[k].feed {
            let want = d(&points[point], &points[point - 1]) / feed;
            assert!(
                (time - want).abs() <= 1e-3 * want,
                "CL point {point}: LinuxCNC time {time} min, CL time {want} min"
            );
            checked += 1;
        }
        time = 0.0;
    }
    assert!(checked > 20, "{checked}");
}

/// The grinding pressure through an analog output (the `[pressure]` example
/// of docs/dialects.md for LinuxCNC, `M68 E0 Q…`): rs274 sets the output before
/// the moves that grind at that pressure, and the moves are the CSV rows of
/// the compensated program.
#[test]
fn pressure_word_as_an_analog_output() {
    let Some(rs274) = interpreter("pressure_word_as_an_analog_output") else {
        return;
    };
    let machine = mts1600();
    let mut cl = String::new();
    let mut gotos = 0;
    for line in example("five-axis.cls").lines() {
        if line.starts_with("GOTO/") {
            match gotos {
                0 => cl.push_str("PRESSURE/H1,3600\n"),
                10 => cl.push_str("PRESSURE/3400\n"),
                20 => cl.push_str("PRESSURE/H1,3500\n"),
                _ => {}
            }
            gotos += 1;
        }
        cl.push_str(line);
        cl.push('\n');
    }
    let source = format!(
        "{}\n[pressure]\nprefix = \"M68 E0 Q\"\n",
        Dialect::builtin_source("linuxcnc").unwrap()
    );
    let linuxcnc = Dialect::from_toml(&source, "linuxcnc-pressure.toml").unwrap();
    let mut ngc = Vec::new();
    post(
        cl.as_bytes(),
        &machine,
        &linuxcnc,
        &mut ngc,
        &PostOptions::default(),
    )
    .unwrap();
    let ngc = String::from_utf8(ngc).unwrap();
    let csv = post_text(&machine, "csv", &cl, "pressure.cls");
    let moves = interpret(&rs274, &ngc, "pressure through M68");
    let rows: Vec<Vec<&str>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    // Every block moves (the path never stands still): one move per row.
    assert_eq!(moves.len(), rows.len(), "{ngc}");
    for (m, row) in moves.iter().zip(&rows) {
        // line, motion, X A Y Z B C H1 feed; rs274: X Y Z A B C.
        let v = |k: usize| row[k].parse::<f64>().unwrap();
        let want = [v(2), v(4), v(5), v(3), v(6), 0.0];
        for (got, want) in m.at.iter().zip(want) {
            assert!(
                (got - want).abs() <= 0.5e-4 + 0.5e-6 + 1e-9,
                "{m:?} vs {row:?}"
            );
        }
        assert_eq!(m.aux, Some(v(8)), "{m:?} vs {row:?}");
    }
    assert_eq!(ngc.matches("M68 E0 Q").count(), 3, "{ngc}");
}
