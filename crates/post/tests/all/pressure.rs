//! The grinding-pressure axis H1 (Qi (thesis), chapters 2–4):
//!
//! - machines made here, not in the repository (random chains, linkage
//!   planes, link lengths and calibrations, or measured offsets), posting CL
//!   with several pressures: every block's forward kinematics, with the wheel
//!   offset of the block's pressure computed here by its own formula, puts
//!   the contact point on the CL point; tilted poses throughout;
//! - at the reference pressure the output is that of the machine without a
//!   pressure section, and with `--no-pressure-compensation` that of the
//!   reference at every pressure (the pressure words aside);
//! - the verification of Qi (thesis) §4.3 (eq. 4.1–4.8).

use crate::common;

use crate::rng::{Rng, Shape, random_body, singular_allowance, vec_toml};
use kinpost_post::machine::{Kinematics, Machine, Pose, builtin, machine_from_toml};
use kinpost_post::nc::{Dialect, read_program};
use kinpost_post::{PostError, PostOptions, post};
use nalgebra::Vector3;
use proptest::prelude::*;

/// A multiple of 0.5 in `lo..hi` (written exactly by every dialect with
/// at least one decimal).
fn half(rng: &mut Rng, lo: f64, hi: f64) -> f64 {
    (rng.range(lo, hi) * 2.0).round() / 2.0
}

/// The wheel model of a generated machine, as this test computes it.
#[derive(Debug, Clone)]
enum Model {
    Linkage { length: f64, rows: Vec<[f64; 2]> },
    Offsets(Vec<[f64; 3]>),
}

/// Piecewise-linear interpolation of column `col`, ends held (written
/// here independently of the machine crate).
fn lerp<const N: usize>(rows: &[[f64; N]], x: f64, col: usize) -> f64 {
    if x <= rows[0][0] {
        return rows[0][col];
    }
    for w in rows.windows(2) {
        if x <= w[1][0] {
            let t = (x - w[0][0]) / (w[1][0] - w[0][0]);
            return w[0][col] + t * (w[1][col] - w[0][col]);
        }
    }
    rows[rows.len() - 1][col]
}

impl Model {
    /// The wheel offset along the plane directions at `p`, against
    /// `reference`: Qi (thesis) eq. 2.35, B = L·(cos α, sin α).
    fn offset(&self, reference: f64, p: f64) -> [f64; 2] {
        match self {
            Model::Linkage { length, rows } => {
                let a = lerp(rows, p, 1).to_radians();
                let r = lerp(rows, reference, 1).to_radians();
                [length * (a.cos() - r.cos()), length * (a.sin() - r.sin())]
            }
            Model::Offsets(rows) => [
                lerp(rows, p, 1) - lerp(rows, reference, 1),
                lerp(rows, p, 2) - lerp(rows, reference, 2),
            ],
        }
    }

    fn range(&self) -> [f64; 2] {
        match self {
            Model::Linkage { rows, .. } => [rows[0][0], rows[rows.len() - 1][0]],
            Model::Offsets(rows) => [rows[0][0], rows[rows.len() - 1][0]],
        }
    }

    fn toml(&self) -> String {
        let table = |rows: Vec<String>| format!("[{}]", rows.join(", "));
        match self {
            Model::Linkage { length, rows } => format!(
                "link_length = {length:.17}\nalpha_deg = {}\n",
                table(
                    rows.iter()
                        .map(|r| format!("[{:.17}, {:.17}]", r[0], r[1]))
                        .collect()
                )
            ),
            Model::Offsets(rows) => format!(
                "offsets = {}\n",
                table(
                    rows.iter()
                        .map(|r| format!("[{:.17}, {:.17}, {:.17}]", r[0], r[1], r[2]))
                        .collect()
                )
            ),
        }
    }
}

/// A generated machine with a pressure axis, and what the test knows of it.
struct Generated {
    /// Everything but `[tool]` and `[pressure]`.
    body: String,
    tool_point: Vector3<f64>,
    tool_axis: Vector3<f64>,
    word: String,
    reference: f64,
    plane: [Vector3<f64>; 2],
    plane_names: [String; 2],
    model: Model,
}

impl Generated {
    /// The machine file with its pressure section.
    fn with_pressure(&self) -> String {
        format!(
            "{}[tool]\npoint = {}\naxis = {}\n[pressure]\nname = \"{}\"\nreference = {}\nplane = [\"{}\", \"{}\"]\n{}",
            self.body,
            vec_toml(&self.tool_point),
            vec_toml(&self.tool_axis),
            self.word,
            self.reference,
            self.plane_names[0],
            self.plane_names[1],
            self.model.toml()
        )
    }

    /// The same machine without a pressure axis, its tool point moved by
    /// the wheel offset at `pressure` (the reference: not moved), as this
    /// test computes it.
    fn at(&self, pressure: Option<f64>) -> Machine {
        let [d1, d2] = pressure.map_or([0.0, 0.0], |p| self.model.offset(self.reference, p));
        let point = self.tool_point + self.plane[0] * d1 + self.plane[1] * d2;
        let toml = format!(
            "{}[tool]\npoint = {}\naxis = {}\n",
            self.body,
            vec_toml(&point),
            vec_toml(&self.tool_axis)
        );
        machine_from_toml(&toml, "at-pressure.toml").expect("generated machine is valid")
    }
}

/// A random serial machine (3 linear, 2 rotary axes in random chain order
/// and sides, non-intersecting rotary lines, a tilted part frame) whose
/// pressure plane is spanned by two of its linear axes, made perpendicular.
fn random_machine(rng: &mut Rng) -> Generated {
    let e1 = rng.unit();
    let e2 = {
        let v = rng.unit();
        let v = v - e1 * e1.dot(&v);
        if v.norm() < 0.2 {
            e1.cross(&Vector3::new(0.3, -0.5, 0.81)).normalize()
        } else {
            v.normalize()
        }
    };
    let e3 = loop {
        let v = rng.unit();
        if nalgebra::Matrix3::from_columns(&[e1, e2, v])
            .determinant()
            .abs()
            > 0.3
        {
            break v;
        }
    };
    // Which linear axes span the plane, and in which order.
    let names = ["X", "Y", "Z"];
    let slots = match (rng.next() * 3.0) as usize {
        0 => [0, 1, 2],
        1 => [1, 2, 0],
        _ => [2, 0, 1],
    };
    let mut dirs = [Vector3::zeros(); 3];
    dirs[slots[0]] = e1;
    dirs[slots[1]] = e2;
    dirs[slots[2]] = e3;
    let shape = Shape {
        name: "random-pressure",
        linear: dirs,
        limits: false,
        linear_first: false,
    };
    let body = random_body(rng, &shape);
    // The calibration: 2 to 5 rows between pressure 0 and 6000.
    let rows = 2 + (rng.next() * 4.0) as usize;
    let mut pressures: Vec<f64> = (0..rows).map(|_| half(rng, 0.0, 6000.0)).collect();
    pressures.sort_by(f64::total_cmp);
    pressures.dedup();
    if pressures.len() < 2 {
        pressures = vec![1000.0, 4000.0];
    }
    let model = if rng.next() < 0.6 {
        Model::Linkage {
            length: rng.range(50.0, 400.0),
            rows: pressures
                .iter()
                .map(|&p| [p, rng.range(-30.0, 30.0)])
                .collect(),
        }
    } else {
        Model::Offsets(
            pressures
                .iter()
                .map(|&p| [p, rng.range(-5.0, 5.0), rng.range(-60.0, 60.0)])
                .collect(),
        )
    };
    let [lo, hi] = model.range();
    Generated {
        body,
        tool_point: Vector3::new(
            rng.range(-200.0, 200.0),
            rng.range(-200.0, 200.0),
            rng.range(-200.0, 200.0),
        ),
        tool_axis: rng.unit(),
        word: ["H1", "P", "Q7"][(rng.next() * 3.0) as usize].to_string(),
        reference: half(rng, lo, hi).clamp(lo, hi),
        plane: [e1, e2],
        plane_names: [names[slots[0]].to_string(), names[slots[1]].to_string()],
        model,
    }
}

fn angle(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
}

fn post_text(
    cl: &str,
    machine: &Machine,
    dialect: &str,
    options: &PostOptions,
) -> Result<(String, kinpost_post::Summary), PostError> {
    let dialect = Dialect::builtin(dialect).unwrap();
    let mut out = Vec::new();
    // These tests pair every block with its CL point: no linearization
    // (tests/all/planning.rs covers it), unless a test asks for it.
    let options = PostOptions {
        lintol_mm: options.lintol_mm.or(Some(0.0)),
        ..options.clone()
    };
    let summary = post(cl.as_bytes(), machine, &dialect, &mut out, &options)?;
    Ok((String::from_utf8(out).unwrap(), summary))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    #[test]
    fn random_machines_at_several_pressures(seed in 1u64..u64::MAX) {
        posts_at_several_pressures(seed)?;
    }
}

/// Two pressures that Sinumerik writes as the same whole value (4507.5 and
/// 4508.5): the csv program moves back onto the point, the Sinumerik
/// program needs not (found by the property test).
#[test]
fn seed_7369548716153890273() {
    posts_at_several_pressures(7369548716153890273).unwrap();
}

/// A branch that moves 1.47° for a 0.01° turn of the tool axis near a fold
/// it does not pass (found by the property test with many more cases; it
/// was taken for a flip and reconfigured).
#[test]
fn seed_5518296535352054306() {
    posts_at_several_pressures(5518296535352054306).unwrap();
}

fn posts_at_several_pressures(seed: u64) -> Result<(), TestCaseError> {
    let mut rng = Rng(seed);
    let g = random_machine(&mut rng);
    let toml = g.with_pressure();
    let machine = machine_from_toml(&toml, "random.toml")
        .map_err(|e| TestCaseError::fail(format!("{e}\n{toml}")))?;
    let [lo, hi] = g.model.range();
    // A random walk through joint space at random pressures (some
    // outside the calibration), written as CL: the poses come from the
    // machine at the reference; the post must reach them at any pressure.
    let reference = Kinematics::new(&g.at(None));
    let mut q: Vec<f64> = (0..5).map(|_| rng.range(-60.0, 60.0)).collect();
    // Rotary axes well away from home: tilted poses.
    for (v, a) in q.iter_mut().zip(&machine.axes) {
        if a.is_rotary() {
            *v = rng.range(20.0, 60.0).copysign(*v);
        }
    }
    // (A pressure below 0 is refused as an option, as `PRESSURE/` values
    // below 0 are clamped above: both are the machine's pressure range.)
    let default = (rng.next() < 0.5).then(|| half(&mut rng, lo - 100.0, hi + 100.0).max(0.0));
    let mut pressure = default;
    let mut cl = String::from("FEDRAT/MMPM,500\n");
    // Per CL line: the pose and the pressure in force.
    let mut want: Vec<Option<(Pose, Option<f64>)>> = vec![None, None];
    let mut tilted = 0;
    for k in 0..40 {
        if k % 7 == 3 {
            let p = half(&mut rng, lo - 300.0, hi + 300.0).max(0.0);
            let word = match k % 3 {
                0 => format!("{},", g.word),
                1 => format!("{},", g.word.to_lowercase()),
                _ => String::new(),
            };
            cl.push_str(&format!("PRESSURE/{word}{p}\n"));
            want.push(None);
            pressure = Some(p);
        }
        for v in q.iter_mut() {
            *v += rng.range(-3.0, 3.0);
        }
        let pose = reference.fk(&q);
        tilted += usize::from(angle(&pose.axis, &reference.fk(&[0.0; 5]).axis) > 0.1);
        cl.push_str(&format!(
            "GOTO/{:.10},{:.10},{:.10},{:.12},{:.12},{:.12}\n",
            pose.point.x, pose.point.y, pose.point.z, pose.axis.x, pose.axis.y, pose.axis.z
        ));
        want.push(Some((pose, pressure)));
    }
    // Rarely (about one machine in 3,000) the two rotations happen to bring
    // the tool axis back near home all along the walk: not a tilted job,
    // another machine instead.
    prop_assume!(tilted > 0, "the poses must be tilted");
    let options = PostOptions {
        pressure: default,
        ..Default::default()
    };
    let (csv, summary) = post_text(&cl, &machine, "csv", &options)
        .map_err(|e| TestCaseError::fail(format!("{e}\n{toml}\n{cl}")))?;
    prop_assert!(
        summary.planning.reconfigurations.is_empty(),
        "{:?}\n{toml}\n{cl}",
        summary.planning
    );
    let mut rows = csv.lines();
    let header: Vec<&str> = rows.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let mut seen = 0;
    let mut cache: Vec<(Option<f64>, Kinematics)> = Vec::new();
    // What each block reaches, in order, and whether it is a move back
    // (for the NC read back below).
    let mut reached: Vec<(Pose, bool)> = Vec::new();
    let mut previous: Option<usize> = None;
    for row in rows {
        let f: Vec<&str> = row.split(',').collect();
        // A block the post inserted (no linearization here): at a change
        // of pressure, the move back onto the last point with the wheel
        // where the new pressure puts it.
        let cl_line: Option<usize> = f[col("line")].parse().ok();
        let line = cl_line.or(previous).expect("a block after a CL point");
        let (pose, in_force) = want[line].expect("a GOTO line");
        previous = Some(line);
        reached.push((pose, cl_line.is_none()));
        // The pressure column: the one in force, empty when none (that of
        // the next point for a move back).
        let written = match f[col(&g.word)] {
            "" => None,
            v => Some(v.parse::<f64>().unwrap()),
        };
        let p = match cl_line {
            Some(_) => {
                prop_assert_eq!(written, in_force, "line {}", line);
                in_force
            }
            None => {
                prop_assert!(
                    written != in_force,
                    "a move back without a change, line {}",
                    line
                );
                written
            }
        };
        let values: Vec<f64> = machine
            .axes
            .iter()
            .map(|a| f[col(&a.name)].parse().unwrap())
            .collect();
        if !cache.iter().any(|(k, _)| *k == p) {
            cache.push((p, Kinematics::new(&g.at(p))));
        }
        let kin = &cache.iter().find(|(k, _)| *k == p).unwrap().1;
        let got = kin.fk(&values);
        let dp = (got.point - pose.point).norm();
        let da = angle(&got.axis, &pose.axis);
        // The CL itself is rounded to 1e-10 mm / 1e-12.
        prop_assert!(
            dp <= summary.tolerance_mm + 1e-8,
            "line {line}: {dp} mm\n{toml}"
        );
        let cone = singular_allowance(&summary, line);
        prop_assert!(
            da <= summary.tolerance_rad + cone + 1e-9,
            "line {line}: {da} rad\n{toml}"
        );
        // The axes moved by exactly the (turned) wheel offset: through
        // the machine at the reference they miss by its length.
        let [d1, d2] = p.map_or([0.0, 0.0], |p| g.model.offset(g.reference, p));
        let miss = (reference.fk(&values).point - pose.point).norm();
        let offset = (g.plane[0] * d1 + g.plane[1] * d2).norm();
        prop_assert!(
            (miss - offset).abs() <= summary.tolerance_mm + 1e-8,
            "line {line}: {miss} vs offset {offset}"
        );
        seen += usize::from(cl_line.is_some());
    }
    prop_assert_eq!(seen, 40);
    // Pressures outside the calibration are warned about.
    let outside = cl
        .lines()
        .filter_map(|l| l.strip_prefix("PRESSURE/"))
        .map(|l| l.rsplit(',').next().unwrap().parse::<f64>().unwrap())
        .chain(default)
        .filter(|&p| p < lo || p > hi)
        .count();
    let warned = summary
        .warnings
        .iter()
        .filter(|w| w.message.contains("calibration"))
        .count();
    prop_assert_eq!(warned, outside);

    // The Sinumerik program read back: the pressure words set each
    // block's pressure, and the blocks land on the CL at it.
    let (nc, summary) = post_text(&cl, &machine, "sinumerik", &options)
        .map_err(|e| TestCaseError::fail(format!("{e}\n{toml}")))?;
    let axes = kinpost_post::axis_specs(&machine);
    let blocks = read_program(&Dialect::builtin("sinumerik").unwrap(), &axes, "r.mpf", &nc)
        .map_err(|e| TestCaseError::fail(e.to_string()))?;
    // Sinumerik writes whole pressures: a change it writes as none (4507.5
    // and 4508.5 both as 4508) needs no move back, which the csv program,
    // with decimals, has.
    let mut want = reached.iter();
    let mut written_before = None;
    for b in &blocks {
        let mut next = want.next();
        if let Some((_, true)) = next
            && b.axes[5] == written_before
        {
            next = want.next();
        }
        let Some(&(pose, _)) = next else {
            return Err(TestCaseError::fail(format!(
                "NC line {:?}: no CL pose left",
                b.line
            )));
        };
        written_before = b.axes[5];
        let values: Vec<f64> = b.axes[..5].iter().map(|v| v.unwrap()).collect();
        // Sinumerik writes whole pressures: the wheel is where the
        // written value puts it.
        let kin = Kinematics::new(&g.at(b.axes[5]));
        let got = kin.fk(&values);
        let dp = (got.point - pose.point).norm();
        prop_assert!(
            dp <= summary.tolerance_mm + 1e-8,
            "NC line {:?}: {} mm",
            b.line,
            dp
        );
    }
    prop_assert!(
        want.next().is_none(),
        "CL poses the NC program does not reach"
    );
    Ok(())
}

/// The mts1600 source without its `[pressure]` section.
fn mts1600_without_pressure() -> Machine {
    let src = builtin::source("mts1600").unwrap();
    let cut = src
        .find("\n# Grinding pressure H1")
        .expect("the pressure section");
    let m = machine_from_toml(&src[..cut], "mts1600-no-pressure.toml").unwrap();
    assert!(m.pressure.is_none());
    m
}

/// `text` without the lines that are the pressure word alone.
fn without_pressure_lines(text: &str) -> String {
    text.lines()
        .filter(|l| !l.starts_with("H1="))
        .map(|l| format!("{l}\n"))
        .collect()
}

/// A CSV without its H1 column.
fn without_pressure_column(csv: &str) -> String {
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let k = header
        .iter()
        .position(|h| *h == "H1")
        .expect("an H1 column");
    csv.lines()
        .map(|l| {
            let mut f: Vec<&str> = l.split(',').collect();
            f.remove(k);
            format!("{}\n", f.join(","))
        })
        .collect()
}

#[test]
fn at_the_reference_the_output_is_that_of_the_machine_without_pressure() {
    let with = builtin::load("mts1600").unwrap().unwrap();
    let without = mts1600_without_pressure();
    // A tilted job (B from −24° to +12°) and the flat part of Qiao et al. 2022.
    let flat = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/flat-part.cls"
    ))
    .unwrap();
    for cl in [common::job(&with), flat] {
        for dialect in Dialect::builtin_names() {
            let options = PostOptions::default();
            let (a, _) = post_text(&cl, &with, dialect, &options).unwrap();
            let (b, _) = post_text(&cl, &without, dialect, &options).unwrap();
            // No pressure programmed: no pressure word, same bytes; the
            // table has its (empty) pressure column.
            if *dialect == "csv" {
                assert_eq!(without_pressure_column(&a), b);
                assert!(a.lines().skip(1).all(|l| l.contains(",,")), "{a}");
            } else {
                assert_eq!(a, b, "{dialect}");
            }
        }
        // The reference programmed, by the CL or the command line: the same
        // program plus the pressure word.
        let programmed = cl.replacen("RAPID\n", "PRESSURE/H1,3475\nRAPID\n", 1);
        assert_ne!(programmed, cl);
        let (b, _) = post_text(&cl, &without, "sinumerik", &PostOptions::default()).unwrap();
        for (cl, pressure) in [(&programmed, None), (&cl, Some(3475.0))] {
            let options = PostOptions {
                pressure,
                ..Default::default()
            };
            let (a, _) = post_text(cl, &with, "sinumerik", &options).unwrap();
            assert_eq!(a.matches("\nH1=3475\n").count(), 1, "{a}");
            assert_eq!(without_pressure_lines(&a), b);
        }
    }
}

#[test]
fn without_compensation_every_pressure_gives_the_reference_program() {
    let machine = builtin::load("mts1600").unwrap().unwrap();
    let cl = common::job(&machine);
    for dialect in ["sinumerik", "csv"] {
        let (reference, _) = post_text(&cl, &machine, dialect, &PostOptions::default()).unwrap();
        for h1 in [2000.0, 3000.0, 3250.0, 3475.0, 3600.0, 4000.0] {
            let off = PostOptions {
                pressure: Some(h1),
                no_pressure_compensation: true,
                ..Default::default()
            };
            let (nc, summary) = post_text(&cl, &machine, dialect, &off).unwrap();
            // The pressure word is written: the program sets the pressure it
            // grinds at, as the maker's post does; the axes ignore it.
            if dialect == "csv" {
                assert_eq!(
                    without_pressure_column(&nc),
                    without_pressure_column(&reference)
                );
                assert!(nc.contains(&format!(",{h1},")), "{nc}");
            } else {
                assert_eq!(without_pressure_lines(&nc), reference, "H1={h1}");
                assert!(nc.contains(&format!("\nH1={h1}\n")), "{nc}");
            }
            // ... and says so, once, where the wheel is off.
            let warned = summary
                .warnings
                .iter()
                .filter(|w| w.message.contains("not compensated"))
                .count();
            assert_eq!(warned, usize::from(h1 != 3475.0), "H1={h1}");
            // With compensation the axes differ wherever the wheel moved.
            let on = PostOptions {
                pressure: Some(h1),
                ..Default::default()
            };
            let (compensated, _) = post_text(&cl, &machine, dialect, &on).unwrap();
            assert_eq!(compensated == nc, h1 == 3475.0, "H1={h1}");
        }
    }
}

#[test]
fn tilted_mts1600_job_reads_back_onto_the_cl_at_every_pressure() {
    let machine = builtin::load("mts1600").unwrap().unwrap();
    let kin_ref = Kinematics::new(&machine);
    let home = kin_ref.fk(&machine.home_joints()).axis;
    let job = common::job(&machine);
    // The job's poses, and a CL that changes the pressure between them.
    let mut cl = String::new();
    let mut poses = Vec::new();
    // What the blocks reach, in order: before a feed move at another
    // pressure, the move back onto the last point at the new one.
    let mut reached: Vec<(Pose, f64)> = Vec::new();
    let mut rapid = false;
    let pressures = [3000.0, 3100.0, 3475.0, 3600.0, 2500.0];
    for (k, line) in job.lines().enumerate() {
        if line.trim() == "RAPID" {
            rapid = true;
        }
        if let Some(v) = line.strip_prefix("GOTO/") {
            let h1 = pressures[poses.len() % pressures.len()];
            cl.push_str(&format!("PRESSURE/H1,{h1}\n"));
            let v: Vec<f64> = v.split(',').map(|x| x.parse().unwrap()).collect();
            let pose = Pose {
                point: Vector3::new(v[0], v[1], v[2]),
                axis: Vector3::new(v[3], v[4], v[5]).normalize(),
                reference: None,
            };
            if let Some(&(last, h0)) = reached.last()
                && h0 != h1
                && !rapid
            {
                reached.push((last, h1));
            }
            reached.push((pose, h1));
            poses.push((pose, h1, k));
            rapid = false;
        }
        cl.push_str(line);
        cl.push('\n');
    }
    assert!(
        poses
            .iter()
            .filter(|(p, ..)| angle(&p.axis, &home) > 0.1)
            .count()
            >= 5
    );
    for dialect in ["sinumerik", "csv"] {
        let (nc, summary) = post_text(&cl, &machine, dialect, &PostOptions::default()).unwrap();
        let d = Dialect::builtin(dialect).unwrap();
        let blocks = read_program(&d, &kinpost_post::axis_specs(&machine), "job", &nc).unwrap();
        let blocks = &blocks[blocks.len() - reached.len()..];
        for (b, (want, h1)) in blocks.iter().zip(&reached) {
            assert_eq!(b.axes[6], Some(*h1), "{dialect} line {:?}", b.line);
            let q: Vec<f64> = b.axes[..6].iter().map(|v| v.unwrap_or(0.0)).collect();
            let got = Kinematics::new(&mts1600_at(*h1)).fk(&q);
            let dp = (got.point - want.point).norm();
            // The CL itself is rounded to 4 / 7 decimals.
            assert!(
                dp <= summary.tolerance_mm + 1e-4,
                "{dialect} H1={h1}: {dp} mm"
            );
            assert!(angle(&got.axis, &want.axis) <= summary.tolerance_rad + 1e-6);
        }
    }
}

/// mts1600 with its wheel where pressure `h1` puts it (the linkage of the
/// mts1600 file, L = 250 mm, α from its calibration, plane Y Z with home
/// directions −y and +z), as a machine without a pressure axis.
fn mts1600_at(h1: f64) -> Machine {
    let machine = builtin::load("mts1600").unwrap().unwrap();
    let alpha = |h: f64| lerp(&[[3000.0, -6.73], [3250.0, -5.0], [3600.0, 5.0]], h, 1).to_radians();
    let (a, r) = (alpha(h1), alpha(3475.0));
    let mut at = machine;
    at.pressure = None;
    at.tool.point += Vector3::new(
        0.0,
        -250.0 * (a.cos() - r.cos()),
        250.0 * (a.sin() - r.sin()),
    );
    at
}

#[test]
fn a_pressure_change_between_two_points_keeps_the_contact_point_on_the_cl() {
    // The wheel drops by tens of millimetres from the reference to 3000:
    // the axes bring the contact point back onto the first point before
    // the cut to the second, and the blocks the linearization inserts
    // follow the CL segment at the pressure they are written with.
    let machine = builtin::load("mts1600").unwrap().unwrap();
    let cl = "FEDRAT/MMPM,300\nGOTO/-416,70,10,0.2,-0.1,0.9746794\nPRESSURE/H1,3000\n\
              GOTO/-406,67,10.5,0.3,-0.2,0.9327379\n";
    let lintol = 0.002;
    let options = PostOptions {
        lintol_mm: Some(lintol),
        ..Default::default()
    };
    let (csv, summary) = post_text(cl, &machine, "csv", &options).unwrap();
    let (a, b) = (
        Vector3::new(-416.0, 70.0, 10.0),
        Vector3::new(-406.0, 67.0, 10.5),
    );
    let rows: Vec<Vec<&str>> = csv
        .lines()
        .skip(1)
        .map(|r| r.split(',').collect())
        .collect();
    assert!(rows.len() > 3, "{csv}");
    for f in &rows {
        let h1 = f[8].parse::<f64>().unwrap_or(3475.0);
        let q: Vec<f64> = f[2..8].iter().map(|v| v.parse().unwrap()).collect();
        let p = Kinematics::new(&mts1600_at(h1)).fk(&q).point;
        let t = ((p - a).dot(&(b - a)) / (b - a).norm_squared()).clamp(0.0, 1.0);
        let off = (a + (b - a) * t - p).norm();
        assert!(
            off <= lintol + summary.tolerance_mm + 1e-4,
            "{off} mm off the CL segment at H1={h1}: {f:?}\n{csv}"
        );
    }
}

/// The verification experiment of Qi (thesis) §4.3, numerically. As we read
/// the damaged text (subscripts and operators shuffled, Δ and ° lost):
///
/// ```text
/// (4.1) Y2 = Y1 + a·cos 45°    (4.2) Z2 = Z1 + a·sin 45°    start of the trace
/// (4.3) Y3 = Y1 − b·cos 45°    (4.4) Z3 = Z1 − b·sin 45°    end of the trace
/// (4.5) Y4 = Y2 + ΔY           (4.6) Z4 = Z2 + ΔZ           start, wheel dropped
/// (4.7) Y5 = Y3 + ΔY           (4.8) Z5 = Z3 + ΔZ           end, wheel dropped
/// ```
///
/// (printed: "2 1Y =Y a cos(45 )+", "3 1Z =Z b sin(45 )−", "4 2Z =Z Z+",
/// "5 3Y =Y + Y"). The first trace is ground with the wheel fully retracted
/// (upper stop), the second with it fully dropped (lower stop) and the
/// offset compensated (Qi (thesis) §4.2, §4.3): the start and end points differ
/// by exactly the computed ΔY, ΔZ.
#[test]
fn qi_section_4_3_two_traces_at_the_stops() {
    let mts = builtin::load("mts1600").unwrap().unwrap();
    // The same machine with the offsets the thesis measured between the
    // stops (§2.7, §4.3: 1.12 mm in Y, 51.075 mm in Z; the wheel drops, and
    // moves to −Y below H1 = 3250, §2.6).
    let src = builtin::source("mts1600").unwrap();
    let cut = src.find("link_length = 250").unwrap();
    let measured = format!(
        "{}offsets = [[3000, -1.12, -51.075], [3600, 0, 0]]\n",
        &src[..cut]
    );
    let measured = machine_from_toml(&measured, "mts1600-measured.toml").unwrap();
    // ΔY, ΔZ: the Y and Z axes carry the head (home directions e₁, e₂), so
    // they move back by the wheel's move from the upper to the lower stop.
    let (up, down) = (5f64.to_radians(), (-6.73f64).to_radians());
    let linkage = [
        -250.0 * (down.cos() - up.cos()),
        -250.0 * (down.sin() - up.sin()),
    ];
    let thesis = [1.12, 51.075];
    assert!((linkage[1] - 51.075).abs() < 0.1, "{linkage:?}");
    for (machine, [dy, dz]) in [(&mts, linkage), (&measured, thesis)] {
        // The contact point: near Figure 28's first block of Qiao et al. 2022 (Z lower,
        // for the travel of Z with the wheel dropped), B = 0 as
        // in the experiment; a, b: distances to the edges of the part.
        let (x, y1, z1, a, b) = (459.0, 8.807, 300.0, 12.0, 17.5);
        let c45 = 45f64.to_radians().cos();
        let s45 = 45f64.to_radians().sin();
        let (y2, z2) = (y1 + a * c45, z1 + a * s45); // (4.1), (4.2)
        let (y3, z3) = (y1 - b * c45, z1 - b * s45); // (4.3), (4.4)
        // The trace on the part: where the retracted wheel touches it.
        let upper = Kinematics::new(&machine.at_pressure(3600.0));
        let at = |y: f64, z: f64| {
            let p = upper.fk(&[x, 0.0, y, z, 0.0, 0.0]);
            format!(
                "GOTO/{:.9},{:.9},{:.9},0,0,1\n",
                p.point.x, p.point.y, p.point.z
            )
        };
        let trace = format!("RAPID\n{}FEDRAT/MMPM,250\n{}", at(y2, z2), at(y3, z3));
        let cl = format!("PRESSURE/H1,3600\n{trace}PRESSURE/H1,3000\n{trace}");
        let (csv, _) = post_text(&cl, machine, "csv", &PostOptions::default()).unwrap();
        let rows: Vec<Vec<f64>> = csv
            .lines()
            .skip(1)
            .map(|r| {
                r.split(',')
                    .skip(2)
                    .take(7)
                    .map(|v| v.parse().unwrap())
                    .collect()
            })
            .collect();
        assert_eq!(rows.len(), 4);
        // X A Y Z B C H1
        let yz = |r: &Vec<f64>| (r[2], r[3]);
        let close = |a: f64, b: f64| (a - b).abs() < 2e-6;
        let ((ya, za), (yb, zb)) = (yz(&rows[0]), yz(&rows[1]));
        assert!(close(ya, y2) && close(za, z2) && close(yb, y3) && close(zb, z3));
        let ((y4, z4), (y5, z5)) = (yz(&rows[2]), yz(&rows[3]));
        assert!(
            close(y4, y2 + dy) && close(z4, z2 + dz),
            "(4.5), (4.6): {rows:?}"
        );
        assert!(
            close(y5, y3 + dy) && close(z5, z3 + dz),
            "(4.7), (4.8): {rows:?}"
        );
        // Nothing else moves: X, A, B are those of the first trace.
        for k in [0, 1, 4] {
            assert!(close(rows[2][k], rows[0][k]) && close(rows[3][k], rows[1][k]));
        }
        assert_eq!((rows[0][6], rows[2][6]), (3600.0, 3000.0));
    }
}

#[test]
fn pressure_mistakes_are_located() {
    let machine = builtin::load("mts1600").unwrap().unwrap();
    let cl = "RAPID\nGOTO/-416,70.5,16.53,0,0,1\nPRESSURE/H2,3000\nGOTO/-416,70.5,13\n";
    let e = post_text(cl, &machine, "sinumerik", &PostOptions::default()).unwrap_err();
    let PostError::Program(located) = &e else {
        panic!("{e}")
    };
    assert!(matches!(
        located.error,
        kinpost_post::ProgramError::PressureWord { .. }
    ));
    let d = e.diagnostic().unwrap();
    assert_eq!(d.line, 3);
    assert!(
        d.message
            .contains("PRESSURE names `H2`, but the pressure word of machine `mts1600` is `H1`"),
        "{d}"
    );
    // A dialect without a pressure word: an error at the statement, not a
    // program that silently grinds at another pressure.
    let cl =
        "RAPID\nGOTO/-416,70.5,16.53,0,0,1\nPRESSURE/3000\nFEDRAT/MMPM,250\nGOTO/-416,70.5,13\n";
    let e = post_text(cl, &machine, "fanuc", &PostOptions::default()).unwrap_err();
    let PostError::Program(located) = &e else {
        panic!("{e}")
    };
    assert!(matches!(
        located.error,
        kinpost_post::ProgramError::Pressure(kinpost_post::PressureError::NoPressureWord { .. })
    ));
    let d = e.diagnostic().unwrap();
    assert_eq!(d.line, 3);
    assert!(
        d.message
            .contains("dialect `fanuc` cannot write the pressure word `H1`"),
        "{d}"
    );
    // ... and for --pressure, a setup error.
    let options = PostOptions {
        pressure: Some(3000.0),
        ..Default::default()
    };
    let e = post_text(cl, &machine, "heidenhain", &options).unwrap_err();
    assert!(matches!(e, PostError::Setup(_)), "{e}");
    // Tool-centre-point output cannot compensate; joint output can.
    let tcp = PostOptions {
        output: Some(kinpost_post::machine::OutputMode::Tcp),
        ..Default::default()
    };
    let e = post_text(cl, &machine, "sinumerik", &tcp).unwrap_err();
    assert!(
        e.to_string()
            .contains("tool-centre-point output cannot compensate"),
        "{e}"
    );
    // A machine without a pressure axis: PRESSURE is a warning, --pressure
    // an error.
    let plain = mts1600_without_pressure();
    let (_, summary) = post_text(cl, &plain, "sinumerik", &PostOptions::default()).unwrap();
    assert!(
        summary
            .warnings
            .iter()
            .any(|w| w.line == 3 && w.message.contains("no pressure axis"))
    );
    let e = post_text(cl, &plain, "sinumerik", &options).unwrap_err();
    assert!(e.to_string().contains("has no pressure axis"), "{e}");
    // Outside the calibration: a warning at the statement, the stop's offset.
    let low = cl.replace("3000", "2000");
    let (nc, summary) = post_text(&low, &machine, "sinumerik", &PostOptions::default()).unwrap();
    let w = summary
        .warnings
        .iter()
        .find(|w| w.message.contains("calibration"))
        .unwrap();
    assert_eq!(w.line, 3);
    assert!(
        w.message
            .contains("H1 = 2000 is below the machine's calibration (3000 .. 3600)")
    );
    let (at_stop, _) = post_text(cl, &machine, "sinumerik", &PostOptions::default()).unwrap();
    assert_eq!(nc.replace("H1=2000", "H1=3000"), at_stop);
}

#[test]
fn pressure_golden_program() {
    // The tilted mts1600 job with the wheel at the lower stop for the
    // first cutting moves, then at 3300, and back at the reference for the
    // last one.
    let machine = builtin::load("mts1600").unwrap().unwrap();
    let job = common::job(&machine).replacen("FEDRAT/", "PRESSURE/H1,3000\nFEDRAT/", 1);
    let mut lines: Vec<&str> = job.lines().collect();
    let last = lines.iter().rposition(|l| l.starts_with("GOTO/")).unwrap();
    lines.insert(last, "PRESSURE/3475");
    lines.insert(last - 3, "PRESSURE/H1,3300");
    let cl = lines.join("\n") + "\n";
    for dialect in ["sinumerik", "csv"] {
        let options = PostOptions {
            cl_file: "mts1600-pressure.cls".into(),
            date: "2026-11-23".into(),
            ..Default::default()
        };
        let (nc, summary) = post_text(&cl, &machine, dialect, &options).unwrap();
        assert!(summary.max_position_error_mm <= summary.tolerance_mm);
        insta::assert_snapshot!(format!("pressure__mts1600__{dialect}"), nc);
    }
}
