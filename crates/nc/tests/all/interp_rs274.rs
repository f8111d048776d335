//! The interpreter against LinuxCNC's own: every motion of a program as
//! `rs274 -g` prints it (STRAIGHT_TRAVERSE, STRAIGHT_FEED, ARC_FEED with
//! their end points, arc centres and turns, in program coordinates)
//! equals the interpreter's moves, on LinuxCNC's 5-axis sample programs
//! (`data/linuxcnc/`) and on hand-written programs for every feature.
//!
//! `rs274` is Debian's `linuxcnc-uspace`; where it is missing the tests say
//! SKIPPED, unless the environment variable `CI` is set: then they fail.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use kinpost_nc::ArcPlane;
use kinpost_nc::AxisSpec;
use kinpost_nc::interp::{Event, Family, MotionKind, Options, read_all};

fn rs274() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("RS274") {
        return Some(PathBuf::from(p));
    }
    let path = std::env::var_os("PATH").unwrap_or_default();
    std::env::split_paths(&path)
        .map(|d| d.join("rs274"))
        .chain([PathBuf::from("/usr/bin/rs274")])
        .find(|p| p.is_file())
}

/// The interpreter, or `None` after a visible skip (a failure under CI).
fn interpreter(test: &str) -> Option<PathBuf> {
    let found = rs274();
    if found.is_none() {
        assert!(
            std::env::var_os("CI").is_none(),
            "{test}: rs274 is missing and CI is set (apt-get install linuxcnc-uspace)"
        );
        eprintln!("SKIPPED: {test}: rs274 not found (apt-get install linuxcnc-uspace)");
    }
    found
}

/// One motion: kind, X Y Z A B C, arc centre (X Y Z) and turns.
#[derive(Debug, Clone, PartialEq)]
struct Motion {
    kind: char,
    at: [f64; 6],
    centre: Option<[f64; 3]>,
    rotation: i32,
    feed: f64,
    /// The interpreter's feed is inverse time (rs274 prints mm/min).
    inverse_time: bool,
    line: usize,
}

fn run_rs274(rs274: &Path, program: &str, label: &str) -> Vec<Motion> {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("p.ngc");
    std::fs::write(&file, program).unwrap();
    // Tool lengths are the machine's: the interpreter reports the offset
    // number and applies no length, so rs274 gets a table of zero lengths.
    let table = dir.path().join("zero.tbl");
    let tools: String = (0..100).map(|t| format!("T{t} P{t} Z0 D0\n")).collect();
    std::fs::write(&table, tools).unwrap();
    let out = Command::new(rs274)
        .arg("-t")
        .arg(&table)
        .arg("-g")
        .arg(&file)
        .current_dir(dir.path())
        .env("HOME", dir.path())
        .stdin(Stdio::null())
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success()
            && stderr
                .lines()
                .all(|l| l.trim().is_empty() || l.trim() == "executing"),
        "{label}: rs274 rejected the program: {stderr}"
    );
    let mut moves = Vec::new();
    let mut plane = ArcPlane::Xy;
    let mut feed = 0.0;
    // rs274 prints program units: inch after G20.
    let mut unit = 1.0;
    for line in stdout.lines() {
        let Some(call) = line.split_whitespace().nth(2) else {
            continue;
        };
        let call = &line[line.find(call).unwrap()..];
        let Some((name, args)) = call.split_once('(') else {
            continue;
        };
        let args = args.trim_end_matches(')');
        let nums = || -> Vec<f64> { args.split(',').map(|v| v.trim().parse().unwrap()).collect() };
        match name {
            "SELECT_PLANE" => {
                plane = match args {
                    "CANON_PLANE_XY" => ArcPlane::Xy,
                    "CANON_PLANE_XZ" => ArcPlane::Zx,
                    "CANON_PLANE_YZ" => ArcPlane::Yz,
                    other => panic!("plane {other}"),
                }
            }
            "USE_LENGTH_UNITS" => unit = if args.contains("INCHES") { 25.4 } else { 1.0 },
            "SET_FEED_RATE" => feed = nums()[0],
            "STRAIGHT_TRAVERSE" | "STRAIGHT_FEED" => {
                let v = nums();
                moves.push(Motion {
                    kind: if name == "STRAIGHT_FEED" { 'F' } else { 'R' },
                    at: [v[0] * unit, v[1] * unit, v[2] * unit, v[3], v[4], v[5]],
                    centre: None,
                    rotation: 0,
                    feed: feed * unit,
                    inverse_time: false,
                    line: 0,
                });
            }
            "ARC_FEED" => {
                let v = nums();
                // first end, second end, first centre, second centre,
                // rotation, axis end, a, b, c.
                let (mut at, mut c) = ([0.0; 6], [f64::NAN; 3]);
                let [fa, sa, na] = match plane {
                    ArcPlane::Xy => [0, 1, 2],
                    ArcPlane::Zx => [2, 0, 1],
                    ArcPlane::Yz => [1, 2, 0],
                };
                at[fa] = v[0] * unit;
                at[sa] = v[1] * unit;
                at[na] = v[5] * unit;
                at[3] = v[6];
                at[4] = v[7];
                at[5] = v[8];
                c[fa] = v[2] * unit;
                c[sa] = v[3] * unit;
                moves.push(Motion {
                    kind: 'A',
                    at,
                    centre: Some(c),
                    rotation: v[4] as i32,
                    feed: feed * unit,
                    inverse_time: false,
                    line: 0,
                });
                let _ = na;
            }
            "STRAIGHT_PROBE" | "RIGID_TAP" | "NURBS_FEED" => panic!("{label}: unexpected {name}"),
            _ => {}
        }
    }
    moves
}

fn axes() -> Vec<AxisSpec> {
    ["X", "Y", "Z"]
        .iter()
        .map(|n| AxisSpec::linear(n))
        .chain(["A", "B", "C"].iter().map(|n| AxisSpec::rotary(n)))
        .collect()
}

fn ours(program: &str, options: &Options, label: &str) -> Vec<Motion> {
    let (steps, _) = read_all(program, Family::LinuxCnc, &axes(), options, label)
        .unwrap_or_else(|e| panic!("{label}: {e}"));
    steps
        .iter()
        .filter_map(|s| match &s.event {
            Event::Move(m) => {
                let mut at = [0.0; 6];
                at.copy_from_slice(m.axes());
                let (kind, centre, rotation) = match &m.kind {
                    MotionKind::Rapid => ('R', None, 0),
                    MotionKind::Linear => ('F', None, 0),
                    MotionKind::Arc(a) => {
                        let turns = a.turns as i32 + 1;
                        (
                            'A',
                            Some(a.centre_mm),
                            if a.clockwise { -turns } else { turns },
                        )
                    }
                };
                Some(Motion {
                    kind,
                    at,
                    centre,
                    rotation,
                    feed: m.feed,
                    inverse_time: m.feed_mode == kinpost_nc::interp::FeedMode::InverseTime,
                    line: s.line,
                })
            }
            _ => None,
        })
        .collect()
}

/// Consecutive moves to the same point are one (rs274 leaves some
/// zero-length moves out that the interpreter makes, and the other way
/// round).
fn collapse(moves: Vec<Motion>) -> Vec<Motion> {
    let mut out: Vec<Motion> = Vec::new();
    // Both start at 0 on every axis.
    let mut last = [0.0; 6];
    for m in moves {
        if m.kind != 'A' && last.iter().zip(&m.at).all(|(a, b)| (a - b).abs() < 1e-9) {
            continue;
        }
        last = m.at;
        out.push(m);
    }
    out
}

/// rs274 prints 4 decimals.
const PRINTED: f64 = 0.5e-4 + 1e-9;

fn compare(
    rs274: &Path,
    program: &str,
    ngc_for_rs274: &str,
    options: &Options,
    label: &str,
) -> usize {
    let want = collapse(run_rs274(rs274, ngc_for_rs274, label));
    let got = collapse(ours(program, options, label));
    let mut prev = [0.0; 6];
    for (k, (w, g)) in want.iter().zip(&got).enumerate() {
        // Inverse time: rs274 turns F into the rate of this move (its XYZ
        // length, or its ABC length for a rotary move, times F).
        let feed = if g.inverse_time && g.kind != 'A' {
            let d = |r: std::ops::Range<usize>| {
                r.map(|i| (g.at[i] - prev[i]).powi(2)).sum::<f64>().sqrt()
            };
            let xyz = d(0..3);
            g.feed * if xyz > 1e-6 { xyz } else { d(3..6) }
        } else {
            g.feed
        };
        prev = g.at;
        let ok = w.kind == g.kind
            && w.at
                .iter()
                .zip(&g.at)
                .all(|(a, b)| (a - b).abs() <= PRINTED * a.abs().max(1.0))
            && w.rotation == g.rotation
            && match (w.centre, g.centre) {
                // rs274 gives the centre in the plane only (NaN elsewhere).
                (Some(a), Some(b)) => (0..3)
                    .all(|i| a[i].is_nan() || (a[i] - b[i]).abs() <= PRINTED * a[i].abs().max(1.0)),
                (None, None) => true,
                _ => false,
            }
            && (w.kind == 'R'
                || (g.inverse_time && g.kind == 'A')
                || (w.feed - feed).abs() <= 1e-3 * w.feed.max(1.0));
        assert!(
            ok,
            "{label}: move {k} differs:\n  rs274 {w:?}\n  ours  {g:?} (line {})",
            g.line
        );
    }
    assert_eq!(
        want.len(),
        got.len(),
        "{label}: rs274 has {} moves, the interpreter {}; next: {:?} / {:?}",
        want.len(),
        got.len(),
        want.get(got.len()),
        got.get(want.len())
    );
    want.len()
}

fn data(name: &str) -> String {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../data/linuxcnc")
        .join(name);
    std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// M428/M429 are remapped M-codes of the sample configurations: rs274
/// alone does not know them, so they are stripped for it; the interpreter
/// reads them as the TCP switches (Options::tcp_mcodes).
fn strip_remaps(text: &str) -> String {
    text.lines()
        .map(|l| {
            let t = l.trim_start().to_ascii_lowercase();
            if t.starts_with("m428") || t.starts_with("m429") {
                ""
            } else {
                l
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
        + "\n"
}

#[test]
fn linuxcnc_sample_programs() {
    let Some(rs274) = interpreter("linuxcnc_sample_programs") else {
        return;
    };
    let mut options = Options {
        tcp_mcodes: Some((428, 429)),
        ..Options::default()
    };
    for name in ["boat-xyzac.ngc", "boat-xyzbc.ngc", "impeller-7bl-xyzac.ngc"] {
        let text = data(name);
        let n = compare(&rs274, &text, &strip_remaps(&text), &options, name);
        eprintln!("{name}: {n} moves equal rs274's");
        assert!(n > 100);
    }
    // The XYZAB demo reads HAL pins: rs274 has no HAL, so it gets numbers in
    // their place and the interpreter the same numbers as inputs.
    let text = data("xyzab-tdr-demo.ngc");
    let pins = [
        ("xyzab_tdr_kins.x-rot-point", 10.5),
        ("xyzab_tdr_kins.x-offset", -2.25),
        ("xyzab_tdr_kins.z-rot-point", 40.0),
        ("xyzab_tdr_kins.z-offset", 5.5),
    ];
    let mut for_rs274 = strip_remaps(&text);
    for (pin, v) in pins {
        for_rs274 = for_rs274.replace(&format!("#<_hal[{pin}]>"), &format!("[{v}]"));
        options
            .inputs
            .insert(format!("_HAL[{}]", pin.to_uppercase()), v);
    }
    let n = compare(&rs274, &text, &for_rs274, &options, "xyzab-tdr-demo.ngc");
    assert!(n > 20);
}

/// Hand-written programs, one feature each; each is compared with rs274.
const PROGRAMS: &[(&str, &str)] = &[
    (
        "arcs in every plane, R and IJK, full circles, helices with P",
        "G21 G90 G17 G0 X0 Y0 Z0 F300\n\
         G2 X10 Y0 I5 J0\nG3 X0 Y0 R5\nG2 X0 Y0 I5 J0\nG3 X10 Y10 R-10\nG2 X10 Y10 I-5 J-5 Z-3 P3\n\
         G18 G0 X0 Y0 Z0\nG2 X0 Z10 I0 K5\nG3 X5 Z5 R5\nG2 X5 Z5 K-2 Y2 P2\n\
         G19 G0 X0 Y0 Z0\nG3 Y5 Z0 J2.5 K0\nG2 Y0 Z5 R-4\nG3 Y0 Z5 J0 K-3 X4\n\
         G17 G0 X10 Y10 Z0\nG90.1 G2 X20 Y10 I15 J10\nG91.1 G91 G3 X-5 Y5 I0 J5\nG90\nM2\n",
    ),
    (
        "canned cycles G81 G82 G83 G73 G85 G86 G89 G84 with G98 / G99, L repeats in G91",
        "G21 G90 G17 G0 X0 Y0 Z10 M3 S1000 F50\n\
         G98 G81 X10 Y10 Z-5 R2\nX20\nY20\nG99 G81 X30 Y10 Z-5 R2\nG98 G82 X40 Z-3 R2 P1.5\n\
         G83 X50 Z-7 R1 Q3\nG73 X60 Z-7.5 R1 Q2\nG99 G85 X70 Z-3 R2\nG98 G85 X75 Z-3 R2\n\
         G86 X80 Z-3 R2 P0.5\nG89 X90 Z-3 R2 P0.5\nG99 G84 X95 Z-3 R2\nG80\n\
         G0 Z1\nG91 G98 G81 X5 Y0 Z-4 R-1 L3\nG99 G81 X0 Y5 Z-4 R-1 L2\nG90 G80\nG0 Z-2\nG81 X0 Y0 Z-8 R1\nG80\n\
         G18 G0 X0 Y0 Z0\nG81 Z10 X5 Y-5 R-1\nG19 G0 X0 Y0 Z0\nG98 G81 Y3 Z4 X-6 R-1\nG80\nM2\n",
    ),
    (
        "O-word control flow: while, do-while, repeat, if/elseif/else, break, continue, subs with arguments and return values",
        "G21 G90 G0 X0 Y0 Z0 F100\n\
         o100 sub\n  G1 X[#1] Y[#2]\n  o100 return [#1 + #2]\no100 endsub\n\
         o200 sub\n  #<r> = #1\n  o201 if [#<r> GT 10]\n    o200 return [10]\n  o201 endif\n  G1 Z[#<r>]\no200 endsub\n\
         #1 = 0\no1 while [#1 LT 5]\n  G1 X[#1 * 2] Y[#1 ** 2]\n  #1 = [#1 + 1]\no1 endwhile\n\
         #2 = 0\no2 do\n  G1 Z[-#2]\n  #2 = [#2 + 0.5]\no2 while [#2 LE 2]\n\
         o3 repeat [3]\n  G91 G1 X1\n  G90\no3 endrepeat\n\
         #3 = 7\no4 if [#3 LT 5]\n  G1 Y1\no4 elseif [#3 LT 10]\n  G1 Y2\no4 else\n  G1 Y3\no4 endif\n\
         #4 = 0\no5 while [1]\n  #4 = [#4 + 1]\n  o6 if [#4 EQ 2]\n    o5 continue\n  o6 endif\n  G1 X[#4]\n  o7 if [#4 GE 4]\n    o5 break\n  o7 endif\no5 endwhile\n\
         o100 call [3] [4]\nG1 X#<_value>\no200 call [15]\no200 call [2.5]\nG1 Y[#<_value_returned>]\nM2\n",
    ),
    (
        "named and global parameters, expressions and functions, G91, G20",
        "G21 G90 G0 X0 Y0 Z0 F100\n\
         #<len> = 12.5\n#<_glob> = [#<len> / 2]\n#10 = [SIN[30] * 4 + COS[60] * 2]\n\
         G1 X#<len> Y#<_glob> Z#10\nG1 X[ATAN[1]/[1]] Y[SQRT[16] + ABS[-2]] Z[FIX[2.7] + FUP[2.2]]\n\
         G1 X[ROUND[2.5] + 10 MOD 3] Y[EXP[0] + LN[1]] Z[2 ** 3]\nG1 X[[1 EQ 1] + [2 GT 1] + [1 AND 0] + [0 OR 1] + [1 XOR 1]]\n\
         G91 G1 X1 Y-2 Z0.5\nX1\nG90\nG20 G1 X1 Y1 Z0.1 F10\nG91 X0.5\nG90 G21 X0 Y0 Z0 F100\n\
         #<_one> = 1\nG1 X#<_x> Y[#<_y> + #<_one>]\nM2\n",
    ),
    (
        "work offsets: G10 L2 / L20, G54..G59.3, G53, G92, G92.1, G28 via a point",
        "G21 G90 G0 X0 Y0 Z0\n\
         G10 L2 P1 X10 Y20 Z5\nG10 L2 P2 X-5\nG54 G0 X1 Y1 Z1\nG55 G0 X1\nG53 G0 X0 Y0 Z0\nG54\nG10 L20 P1 X100\nG0 X101 Y2\n\
         G92 X0 Y0\nG0 X1 Y1\nG92.1\nG0 X1 Y1\nG59.3 G0 X3\nG54\nG28 X5 Y5\nG0 X1 Z1\nG28\nM2\n",
    ),
    (
        "inverse time and feed per revolution, rotary axes, tool change and length, coolant, dwell",
        "G21 G90 G17 G0 X0 Y0 Z0 A0 B0 C0\nT2 M6\nG43 H2\nM3 S2000\nM8\nG4 P0.5\n\
         G93 G1 X10 A30 F2\nG1 Y10 C-45 F4.5\nG2 X0 Y0 I-5 J-5 F3\nG94 G1 X5 F200\nG95 G1 X6 F0.1\nG94 F300\n\
         G0 A-370.5 B12.25\nG1 A720 F1000\nG91 G1 C-30\nG90 G49\nM9 M5\nM2\n",
    ),
];

#[test]
fn hand_written_programs() {
    let Some(rs274) = interpreter("hand_written_programs") else {
        return;
    };
    for (label, program) in PROGRAMS {
        let n = compare(&rs274, program, program, &Options::default(), label);
        assert!(n > 3, "{label}");
        eprintln!("{label}: {n} moves equal rs274's");
    }
}
