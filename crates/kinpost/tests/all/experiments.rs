//! The papers' grinding experiments on the virtual MTS1600, as
//! `examples/grinding-experiments/run.sh` and `examples/rotor37/run.sh` run
//! them: the part the program grinds, measured against the surface, with
//! the expected depths and regions computed here from the geometry.

use std::path::Path;

use crate::common::{root, run_in, temp_dir};

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// `kinpost ARGS` in `dir`, which must exit with `code`.
fn kinpost(dir: &Path, args: &[&str], code: i32) {
    let o = run_in(dir, args);
    assert_eq!(
        o.status.code(),
        Some(code),
        "kinpost {args:?}:\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
}

fn path(p: &str) -> String {
    root().join(p).to_string_lossy().into_owned()
}

/// The points of a CL file's GOTOs (x, y, z), in order.
fn gotos(cl: &str) -> Vec<[f64; 3]> {
    cl.lines()
        .filter_map(|l| l.strip_prefix("GOTO/"))
        .map(|l| {
            let v: Vec<f64> = l
                .split(',')
                .take(3)
                .map(|s| s.trim().parse().unwrap())
                .collect();
            [v[0], v[1], v[2]]
        })
        .collect()
}

/// Qiao et al. 2022 §4.1: the program of Figure 28 (the NX CL of Figure
/// 28(a), posted) grinds the 400 × 100 × 7.5 mm blank where and as deep as
/// its path says. The wheel (radius 50, 25 mm wide, its axis along part x)
/// rolls down a quarter circle in the YZ plane to y = 58, z = 0.5: 1 mm
/// into the blank, whose top is z = 1.5. The depth profile across y is the
/// lower envelope of the wheel's circles along the path's chords,
/// computed here by sampling; the ground region is the belt's 25 mm times
/// the span of y where it is deeper than the tolerance.
#[test]
fn qiao_flat_part_is_ground_where_the_program_says() {
    let dir = temp_dir("exp-flat");
    let cl = std::fs::read_to_string(root().join("examples/flat-part.cls")).unwrap();
    kinpost(
        &dir,
        &[
            "post",
            &path("examples/flat-part.cls"),
            "-m",
            "mts1600",
            "-o",
            "flat.mpf",
            "-q",
        ],
        0,
    );
    kinpost(
        &dir,
        &[
            "sim",
            "flat.mpf",
            "-m",
            "mts1600",
            "--stock",
            "box:-452,0,-6,-52,100,1.5",
            "--tool",
            "wheel:50,25",
            "--resolution",
            "0.05",
            "--design",
            &path("examples/grinding-experiments/blank-top.json"),
            "--json",
            "sim.json",
            "-q",
        ],
        3,
    );
    // The path: the feed moves from the second GOTO on (the first two are
    // rapids above the blank).
    let points = gotos(&cl);
    let feed = &points[1..];
    let (r, top, tol) = (50.0, 1.5, 0.01);
    let depth = |y: f64| -> f64 {
        let mut lowest = f64::INFINITY;
        for w in feed.windows(2) {
            for s in 0..=2000 {
                let t = s as f64 / 2000.0;
                let (yc, zc) = (
                    w[0][1] + t * (w[1][1] - w[0][1]),
                    w[0][2] + t * (w[1][2] - w[0][2]) + r,
                );
                let dy = y - yc;
                if dy.abs() < r {
                    lowest = lowest.min(zc - (r * r - dy * dy).sqrt());
                }
            }
        }
        (top - lowest).max(0.0)
    };
    let (mut volume, mut span) = (0.0, (f64::INFINITY, f64::NEG_INFINITY));
    let dy = 0.005;
    for i in 0..(40.0 / dy) as usize {
        let y = 40.0 + (i as f64 + 0.5) * dy;
        let d = depth(y);
        volume += 25.0 * d * dy;
        if d > tol {
            span = (span.0.min(y), span.1.max(y));
        }
    }
    let report = json(&dir.join("sim.json"));
    let removal = &report["removal"];
    let design = &removal["design"];
    // The deepest point: 1 mm at y = 58 (the rays nearest y = 58 are
    // 0.025 mm off it, 6e-6 mm higher on the wheel), on the last feed block.
    let deepest = &design["gouge_max"];
    let d = -deepest["deviation_mm"].as_f64().unwrap();
    assert!((d - 1.0).abs() < 1e-5, "deepest {d}");
    let at: Vec<f64> = (0..3).map(|i| deepest["at"][i].as_f64().unwrap()).collect();
    assert!((at[1] - 58.0).abs() <= 0.025 + 1e-9, "{at:?}");
    assert!(at[0] > -416.0 - 12.5 && at[0] < -416.0 + 12.5, "{at:?}");
    let mpf = std::fs::read_to_string(dir.join("flat.mpf")).unwrap();
    let lines: Vec<&str> = mpf.lines().collect();
    let last_feed = lines.iter().rposition(|l| l.starts_with("X=")).unwrap() + 1;
    assert_eq!(deepest["line"].as_u64(), Some(last_feed as u64));
    // One ground region: the belt's width times the span deeper than the
    // tolerance (within the ray spacing at each end).
    let regions = design["gouge_regions"].as_array().unwrap();
    assert_eq!(regions.len(), 1, "{regions:?}");
    let area = regions[0]["area_mm2"].as_f64().unwrap();
    let expected = 25.0 * (span.1 - span.0);
    assert!(
        (area - expected).abs() < 25.0 * 0.1 + 0.05 * (span.1 - span.0),
        "area {area}, expected {expected} (y {span:?})"
    );
    let removed = removal["removed_volume_mm3"].as_f64().unwrap();
    assert!(
        (removed - volume).abs() < 0.01 * volume,
        "removed {removed} mm³, expected {volume}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// The deepest point of each gouge region seen along Z (the traces'
/// floors), by the x of the trace: (x, depth, line).
fn traces(report: &serde_json::Value) -> Vec<(f64, f64, u64)> {
    let mut t: Vec<(f64, f64, u64)> = report["removal"]["design"]["gouge_regions"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| {
            (
                r["at"][0].as_f64().unwrap(),
                -r["deviation_mm"].as_f64().unwrap(),
                r["line"].as_u64().unwrap(),
            )
        })
        .collect();
    t.sort_by(|a, b| a.0.total_cmp(&b.0));
    t
}

/// Posts examples/grinding-experiments/two-traces.cls (with `post_extra`)
/// to `NAME.mpf` in `dir` and grinds it as run.sh does, with `sim_extra`:
/// the test block, the 25 mm wheel, 0.1 mm rays, compared with the block's
/// top (exit code 3: the traces are below it). Returns the JSON report.
fn grind_traces(
    dir: &Path,
    name: &str,
    post_extra: &[&str],
    sim_extra: &[&str],
) -> serde_json::Value {
    let (program, report) = (format!("{name}.mpf"), format!("{name}.json"));
    let cl = path("examples/grinding-experiments/two-traces.cls");
    let mut args = vec!["post", cl.as_str(), "-m", "mts1600", "-o", &program, "-q"];
    args.extend_from_slice(post_extra);
    kinpost(dir, &args, 0);
    let top = path("examples/grinding-experiments/block-top.json");
    let mut args = vec![
        "sim",
        &program,
        "-m",
        "mts1600",
        "--stock",
        "box:-452,60,-80,-52,160,0",
        "--tool",
        "wheel:50,25",
        "--resolution",
        "0.1",
        "--design",
        &top,
        "--json",
        &report,
        "-q",
    ];
    args.extend_from_slice(sim_extra);
    kinpost(dir, &args, 3);
    json(&dir.join(&report))
}

/// Qi (thesis) §4.2–4.3: a trace with the wheel fully retracted (H1 = 3600,
/// the upper stop) and one with it fully dropped (H1 = 3000, the lower
/// stop), both 20 mm deep in the CL. Compensated, both traces are 20 mm
/// deep; posted as the maker's post does (the wheel assumed where it is at
/// H1 = 3475), each is off by the wheel's offset at its pressure, and they
/// differ by the stroke between the stops (Qi measured 51.075 mm). The
/// offsets are computed here from the machine file's linkage, Qi (thesis)
/// eq. 2.35: z = L·sin α, L = 250 mm, α from the H1 calibration.
#[test]
fn qi_two_traces_agree_with_compensation_and_differ_by_the_offset_without() {
    let dir = temp_dir("exp-traces");
    let comp = traces(&grind_traces(&dir, "comp", &[], &[]));
    let raw = traces(&grind_traces(
        &dir,
        "raw",
        &["--no-pressure-compensation"],
        &[],
    ));
    let alpha = |h1: f64| -> f64 {
        // The machine file's table: (3000, −6.73°), (3250, −5°), (3600, 5°).
        let t = [(3000.0, -6.73), (3250.0, -5.0), (3600.0, 5.0)];
        let h1 = h1.clamp(3000.0, 3600.0);
        let k = if h1 <= 3250.0 { 0 } else { 1 };
        let (a, b) = (t[k], t[k + 1]);
        (a.1 + (b.1 - a.1) * (h1 - a.0) / (b.0 - a.0)).to_radians()
    };
    let lift = |h1: f64| 250.0 * (alpha(h1).sin() - alpha(3475.0).sin());
    assert_eq!(comp.len(), 2, "{comp:?}");
    assert_eq!(raw.len(), 2, "{raw:?}");
    // Sorted by x: the trace at x = −300 (H1 = 3600) first. The NC's 0.001
    // mm rounding bounds the compensated depth.
    for (x, depth, _) in &comp {
        assert!(
            (depth - 20.0).abs() < 0.001,
            "compensated trace at {x}: {depth}"
        );
    }
    assert!(comp[0].2 < comp[1].2, "each trace names its own block");
    for ((x, depth, _), h1) in raw.iter().zip([3600.0, 3000.0]) {
        let expected = 20.0 - lift(h1);
        assert!(
            (depth - expected).abs() < 0.001,
            "uncompensated trace at {x} (H1 {h1}): {depth}, expected {expected}"
        );
    }
    let stroke = raw[1].1 - raw[0].1;
    assert!((stroke - (lift(3600.0) - lift(3000.0))).abs() < 0.002);
    assert!((stroke - 51.075).abs() < 0.02, "stroke {stroke}");
    std::fs::remove_dir_all(&dir).ok();
}

/// The process model grinds Qi's traces by Preston's law at the force the
/// pressure word gives: on a flat, h = K_p·v_belt·F / (v_f·W), with the
/// belt speed from the spindle (3000 rpm on the 50 mm wheel), the 600
/// mm/min feed and the 25 mm belt. The MTS1600's process file gives 300 N
/// at the lower stop and none at the upper one (the wheel retracted).
#[test]
fn qi_two_traces_by_the_process_model_have_prestons_depth() {
    let dir = temp_dir("exp-process");
    let process_file = root().join("crates/stock/process/mts1600.toml");
    let report = grind_traces(
        &dir,
        "t",
        &[],
        &["--process", process_file.to_str().unwrap()],
    );
    let model = kinpost_stock::ProcessModel::from_toml(
        &std::fs::read_to_string(&process_file).unwrap(),
        "mts1600.toml",
    )
    .unwrap();
    let force = |h1: f64| -> f64 {
        let t = &model.force.newtons;
        let (a, b) = (t[0], t[t.len() - 1]);
        let h1 = h1.clamp(a[0], b[0]);
        a[1] + (b[1] - a[1]) * (h1 - a[0]) / (b[0] - a[0])
    };
    assert_eq!(model.force.newtons.len(), 2, "a two-point force table");
    let belt = 3000.0 * std::f64::consts::TAU / 60.0 * 50.0;
    let preston = |f: f64| model.wheel.preston_mm2_per_n * belt * f / (600.0 / 60.0 * 25.0);
    let t = traces(&report);
    let expected: Vec<(f64, f64)> = [(-300.0, 3600.0), (-200.0, 3000.0)]
        .into_iter()
        .map(|(x, h1)| (x, preston(force(h1))))
        .filter(|(_, d)| *d > 0.01)
        .collect();
    assert_eq!(t.len(), expected.len(), "{t:?}");
    for ((x, depth, _), (ex, ed)) in t.iter().zip(&expected) {
        assert!((x - ex).abs() < 12.5, "trace at {x}, expected at {ex}");
        assert!(
            (depth - ed).abs() < 1e-6,
            "trace at {x}: {depth}, expected {ed}"
        );
    }
    let ground = &report["removal"]["grinding"]["blocks"];
    assert_eq!(ground.as_array().unwrap().len(), expected.len());
    std::fs::remove_dir_all(&dir).ok();
}
