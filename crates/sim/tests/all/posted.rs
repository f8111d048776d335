//! Programs posted by kinpost (the post library, run here) for every
//! built-in machine in every built-in dialect replay onto the CL they were
//! posted from within the output rounding; a copy with one axis word
//! pushed past its limit is reported at exactly that line.

use kinpost_machine::{Kinematics, Machine, builtin};
use kinpost_nc::Dialect;
use kinpost_nc::interp::{Event, Family, read_all};
use kinpost_post::{DEFAULT_LINTOL_MM, PostOptions, post};
use kinpost_sim::{ClPath, SimOptions, simulate};

/// Joint values `t` of the way between two corners inside the travel (25 %
/// and 60 % of each range; rotary ranges cut to ±150°; ±100 mm / ±60°
/// where there are none).
fn joints(m: &Machine, t: f64) -> Vec<f64> {
    let f = 0.25 + 0.35 * t;
    m.axes
        .iter()
        .map(|a| match (a.fixed, a.limits) {
            (Some(v), _) => v,
            (None, Some([lo, hi])) if a.is_rotary() => {
                lo.max(-150.0) + (hi.min(150.0) - lo.max(-150.0)) * f
            }
            (None, Some([lo, hi])) => lo.max(-400.0) + (hi.min(400.0) - lo.max(-400.0)) * f,
            (None, None) if a.is_rotary() => -60.0 + 120.0 * f,
            (None, None) => -100.0 + 200.0 * f,
        })
        .collect()
}

/// Twelve CL points through the machine's forward kinematics (6 and 9
/// decimals), a rapid to the first and feeds on.
fn job(m: &Machine) -> String {
    let kin = Kinematics::new(m);
    let mut cl = String::from("PARTNO/SIM\nLOAD/TOOL,1\nSPINDL/2000,RPM,CLW\nRAPID\n");
    for k in 0..12 {
        let p = kin.fk(&joints(m, k as f64 / 11.0));
        if k == 1 {
            cl.push_str("FEDRAT/MMPM,600\n");
        }
        cl.push_str(&format!(
            "GOTO/{:.6},{:.6},{:.6},{:.9},{:.9},{:.9}\n",
            p.point.x, p.point.y, p.point.z, p.axis.x, p.axis.y, p.axis.z
        ));
    }
    cl.push_str("SPINDL/OFF\nEND-OF-PATH\n");
    cl
}

/// The program kinpost posts for `cl`; `lintol_mm`: the linearization
/// tolerance (0: one block per CL point).
fn posted(
    m: &Machine,
    dialect: &Dialect,
    cl: &str,
    lintol_mm: f64,
) -> (String, kinpost_post::summary::Summary) {
    let mut out = Vec::new();
    let options = PostOptions {
        lintol_mm: Some(lintol_mm),
        ..PostOptions::default()
    };
    let summary = post(cl.as_bytes(), m, dialect, &mut out, &options)
        .unwrap_or_else(|e| panic!("{}/{}: {e}", m.name, dialect.name()));
    (String::from_utf8(out).unwrap(), summary)
}

#[test]
fn posted_programs_replay_onto_their_cl() {
    for name in builtin::names() {
        let m = builtin::load(name).unwrap().unwrap();
        let cl = job(&m);
        for dn in Dialect::builtin_names() {
            let d = Dialect::builtin(dn).unwrap();
            let family = Family::of_dialect(&d).unwrap();
            let options = SimOptions {
                collisions: false,
                ..SimOptions::default()
            };
            let replay = |text: &str| {
                let path = ClPath::read(cl.as_bytes(), "job.cls").unwrap();
                simulate(text, family, "job", &m, &options, Some(path), &mut |_| {})
                    .unwrap_or_else(|e| panic!("{name}/{dn}: {e}\n{text}"))
            };
            // One block per CL point: every block end is a CL point, within
            // the output rounding (the closed-loop tolerance the post derives
            // from its decimals) and the CL's 6 and 9 decimals.
            let (text, summary) = posted(&m, &d, &cl, 0.0);
            let r = replay(&text);
            let cmp = r.cl.as_ref().unwrap();
            let ends = cmp
                .position_at_block_ends
                .as_ref()
                .unwrap_or_else(|| panic!("{name}/{dn}: {r:?}\n{text}"))
                .value;
            let axis = cmp.axis_at_block_ends.as_ref().unwrap().value;
            assert!(
                ends <= summary.tolerance_mm + 1e-6,
                "{name}/{dn}: {ends} mm at block ends\n{cmp:?}\n{text}"
            );
            assert!(
                axis <= summary.tolerance_rad + 1e-8,
                "{name}/{dn}: {axis} rad\n{cmp:?}"
            );
            assert!(r.overtravel.is_empty(), "{name}/{dn}: {:?}", r.overtravel);
            // Linearized (the post's default): inside the blocks too, the
            // tool point stays within the linearization tolerance of the CL
            // segment, plus the rounding.
            let (text, summary) = posted(&m, &d, &cl, DEFAULT_LINTOL_MM);
            let r = replay(&text);
            let along = r.max_position_error_mm.unwrap();
            assert!(
                along <= DEFAULT_LINTOL_MM + summary.tolerance_mm + 1e-6,
                "{name}/{dn}: {along} mm along the path\n{:?}",
                r.cl
            );
            assert!(
                r.cl.unwrap().samples > r.blocks,
                "{name}/{dn}: sampled inside blocks"
            );
        }
    }
}

/// `line` with the value of axis word `axis` replaced by `value`
/// (G-code and Heidenhain words: `X12.5`, `X=12.5`, `X+12.500`).
fn push_word(line: &str, axis: &str, value: f64, heidenhain: bool) -> String {
    let b = line.as_bytes();
    for (i, _) in line.match_indices(axis) {
        let before_ok = i == 0 || !b[i - 1].is_ascii_alphanumeric();
        let mut j = i + axis.len();
        if j < b.len() && b[j] == b'=' {
            j += 1;
        }
        let start = j;
        while j < b.len() && (b[j].is_ascii_digit() || b"+-.".contains(&b[j])) {
            j += 1;
        }
        if before_ok && j > start {
            let v = if heidenhain {
                format!("{value:+.3}")
            } else {
                format!("{value:.3}")
            };
            return format!("{}{v}{}", &line[..start], &line[j..]);
        }
    }
    panic!("no {axis} word in `{line}`");
}

/// `line` of a CSV table with column `axis` set to `value`.
fn push_column(header: &str, line: &str, axis: &str, value: f64) -> String {
    let k = header.split(',').position(|c| c == axis).unwrap();
    let mut cols: Vec<String> = line.split(',').map(str::to_string).collect();
    cols[k] = format!("{value:.6}");
    cols.join(",")
}

#[test]
fn an_axis_word_past_its_limit_is_reported_at_its_line_only() {
    for name in builtin::names() {
        let m = builtin::load(name).unwrap().unwrap();
        // The first free linear axis with limits.
        let Some(i) = m
            .axes
            .iter()
            .position(|a| !a.is_rotary() && a.fixed.is_none() && a.limits.is_some())
        else {
            continue;
        };
        let axis = m.axes[i].name.clone();
        let hi = m.axes[i].limits.unwrap()[1];
        let cl = job(&m);
        for dn in Dialect::builtin_names() {
            let d = Dialect::builtin(dn).unwrap();
            let (text, _) = posted(&m, &d, &cl, DEFAULT_LINTOL_MM);
            let family = Family::of_dialect(&d).unwrap();
            let axes = kinpost_post::axis_specs(&m);
            let (steps, _) = read_all(&text, family, &axes, &Default::default(), "job").unwrap();
            let lines: Vec<usize> = steps
                .iter()
                .filter(|s| matches!(s.event, Event::Move(_)))
                .map(|s| s.line)
                .collect();
            // The fourth motion block from the end (the job moves every
            // free axis in every block).
            let target = lines[lines.len() - 4];
            let mut rows: Vec<String> = text.lines().map(str::to_string).collect();
            let pushed = hi + 5.0;
            rows[target - 1] = if family == Family::Csv {
                push_column(&rows[0], &rows[target - 1], &axis, pushed)
            } else {
                push_word(
                    &rows[target - 1],
                    &axis,
                    pushed,
                    family == Family::Heidenhain,
                )
            };
            let text = rows.join("\n") + "\n";
            let options = SimOptions {
                collisions: false,
                ..SimOptions::default()
            };
            let r = simulate(&text, family, "job", &m, &options, None, &mut |_| {})
                .unwrap_or_else(|e| panic!("{name}/{dn}: {e}"));
            let found: Vec<(usize, &str)> = r
                .overtravel
                .iter()
                .map(|o| (o.at.line, o.axis.as_str()))
                .collect();
            assert_eq!(found, [(target, axis.as_str())], "{name}/{dn}\n{text}");
            let o = &r.overtravel[0];
            assert!((o.excess - 5.0).abs() < 1e-9, "{name}/{dn}: {o:?}");
            assert!(r.violated());
        }
    }
}

/// Tool-centre-point output (X Y Z the tool point; the controller solves
/// the linear axes): replayed by solving them the same way, the program
/// lies on its CL within the output rounding, at the block ends and
/// between them (the tool point moves straight, as the CL's). The csv
/// table has no TCP switch and is left out.
#[test]
fn tcp_programs_replay_onto_their_cl() {
    for name in builtin::names() {
        let m = builtin::load(name).unwrap().unwrap();
        let cl = job(&m);
        for dn in Dialect::builtin_names().iter().filter(|d| **d != "csv") {
            let d = Dialect::builtin(dn).unwrap();
            let mut out = Vec::new();
            let options = PostOptions {
                output: Some(kinpost_machine::OutputMode::Tcp),
                ..PostOptions::default()
            };
            let summary = post(cl.as_bytes(), &m, &d, &mut out, &options)
                .unwrap_or_else(|e| panic!("{name}/{dn}: {e}"));
            let text = String::from_utf8(out).unwrap();
            let family = Family::of_dialect(&d).unwrap();
            let path = ClPath::read(cl.as_bytes(), "job.cls").unwrap();
            let sim = SimOptions {
                collisions: false,
                ..SimOptions::default()
            };
            let r = simulate(&text, family, "job", &m, &sim, Some(path), &mut |_| {})
                .unwrap_or_else(|e| panic!("{name}/{dn}: {e}\n{text}"));
            let cmp = r.cl.as_ref().unwrap();
            let ends = cmp.position_at_block_ends.as_ref().unwrap().value;
            let along = cmp.position.as_ref().unwrap().value;
            let axis = cmp.axis_at_block_ends.as_ref().unwrap().value;
            // X Y Z are written with the output's decimals: half a unit in
            // each, on top of the closed-loop tolerance.
            let rounding = summary.tolerance_mm + 1e-3;
            assert!(ends <= rounding, "{name}/{dn}: {ends} mm\n{cmp:?}\n{text}");
            assert!(along <= rounding, "{name}/{dn}: {along} mm along\n{cmp:?}");
            assert!(
                axis <= summary.tolerance_rad + 1e-8,
                "{name}/{dn}: {axis} rad"
            );
            assert!(r.overtravel.is_empty(), "{name}/{dn}: {:?}", r.overtravel);
        }
    }
}
