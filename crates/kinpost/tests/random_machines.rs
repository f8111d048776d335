//! Any machine written to DESIGN.md §2 and any CL path of `GOTO/x,y,z,i,j,k`
//! posts with `--dialect csv` to blocks whose forward kinematics reproduce
//! the CL within the closed-loop tolerance. Machines, paths and the reading
//! of the CSV are all made here, independently of the post.

use kinpost::machine::{Kinematics, machine_from_toml};
use kinpost::{PostOptions, post};
use nalgebra::Vector3;
use proptest::prelude::*;

/// A small deterministic generator (xorshift64*), seeded by proptest.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }
    fn unit(&mut self) -> Vector3<f64> {
        loop {
            let v = Vector3::new(
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
            );
            if v.norm() > 0.2 && v.norm() <= 1.0 {
                return v.normalize();
            }
        }
    }
}

fn vec_toml(v: &Vector3<f64>) -> String {
    format!("[{:.17}, {:.17}, {:.17}]", v.x, v.y, v.z)
}

/// A random serial machine: 3 linear and 2 rotary axes in random chain order
/// and sides, non-intersecting rotary lines, a tilted part frame.
fn random_machine(rng: &mut Rng) -> String {
    let lin = loop {
        let l = [rng.unit(), rng.unit(), rng.unit()];
        if nalgebra::Matrix3::from_columns(&l).determinant().abs() > 0.3 {
            break l;
        }
    };
    let rot = loop {
        let r = [rng.unit(), rng.unit()];
        if r[0].cross(&r[1]).norm() > 0.3 {
            break r;
        }
    };
    let mut axes: Vec<String> = Vec::new();
    for (k, d) in lin.iter().enumerate() {
        let side = if rng.next() < 0.5 {
            "tool"
        } else {
            "workpiece"
        };
        axes.push(format!(
            "[[axis]]\nname = \"{}\"\nkind = \"linear\"\nside = \"{side}\"\ndirection = {}\n",
            ["X", "Y", "Z"][k],
            vec_toml(d)
        ));
    }
    for (k, d) in rot.iter().enumerate() {
        let side = if rng.next() < 0.5 {
            "tool"
        } else {
            "workpiece"
        };
        let p = Vector3::new(
            rng.range(-300.0, 300.0),
            rng.range(-300.0, 300.0),
            rng.range(-300.0, 300.0),
        );
        let limits = if rng.next() < 0.5 {
            "limits = [-400, 400]\n"
        } else {
            ""
        };
        axes.push(format!(
            "[[axis]]\nname = \"{}\"\nkind = \"rotary\"\nside = \"{side}\"\ndirection = {}\npoint = {}\n{limits}",
            ["A", "B"][k],
            vec_toml(d),
            vec_toml(&p)
        ));
    }
    // Random chain order (Fisher–Yates).
    for i in (1..axes.len()).rev() {
        let j = (rng.next() * (i + 1) as f64) as usize;
        axes.swap(i, j.min(i));
    }
    let x = rng.unit();
    let z = (rng.unit() - x * x.dot(&rng.unit())).normalize();
    let z = (z - x * x.dot(&z)).normalize();
    let origin = Vector3::new(
        rng.range(-100.0, 100.0),
        rng.range(-100.0, 100.0),
        rng.range(-100.0, 100.0),
    );
    let tool = Vector3::new(
        rng.range(-200.0, 200.0),
        rng.range(-200.0, 200.0),
        rng.range(-200.0, 200.0),
    );
    format!(
        "name = \"random\"\n{}\n[workpiece]\norigin = {}\nx = {}\nz = {}\n[tool]\npoint = {}\naxis = {}\n",
        axes.join("\n"),
        vec_toml(&origin),
        vec_toml(&x),
        vec_toml(&z),
        vec_toml(&tool),
        vec_toml(&rng.unit())
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]
    #[test]
    fn random_machines_and_paths_post_within_tolerance(seed in 1u64..u64::MAX) {
        let mut rng = Rng(seed);
        let toml = random_machine(&mut rng);
        let machine = machine_from_toml(&toml, "random.toml").expect("generated machine is valid");
        let kin = Kinematics::new(&machine);
        // A random walk through joint space, written as CL poses.
        let mut q = vec![0.0; 5];
        for v in q.iter_mut() {
            *v = rng.range(-60.0, 60.0);
        }
        let mut cl = String::from("FEDRAT/MMPM,500\n");
        let mut poses = Vec::new();
        for _ in 0..40 {
            for v in q.iter_mut() {
                *v += rng.range(-3.0, 3.0);
            }
            let p = kin.fk(&q);
            cl.push_str(&format!(
                "GOTO/{:.10},{:.10},{:.10},{:.12},{:.12},{:.12}\n",
                p.point.x, p.point.y, p.point.z, p.axis.x, p.axis.y, p.axis.z
            ));
            poses.push(p);
        }
        let dialect = kinpost::nc::Dialect::builtin("csv").unwrap();
        let mut out = Vec::new();
        // Linearization off: a linear axis carried by a rotary one can make
        // the straight CL segment between two reachable poses pass through a
        // configuration where the linear axes lose a direction, which these
        // chains do at random; tests/planning.rs covers linearization on
        // machines whose linear axes are not carried by rotary axes.
        let options = PostOptions { lintol_mm: Some(0.0), ..Default::default() };
        let summary = post(cl.as_bytes(), &machine, &dialect, &mut out, &options)
            .map_err(|e| TestCaseError::fail(format!("{e}\n{toml}")))?;
        let csv = String::from_utf8(out).unwrap();
        let mut rows = csv.lines();
        let header: Vec<&str> = rows.next().unwrap().split(',').collect();
        let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
        let mut seen = 0;
        for row in rows {
            let f: Vec<&str> = row.split(',').collect();
            // Blocks inserted by the linearization have no CL line; the
            // planning tests check them.
            if f[col("line")].is_empty() {
                continue;
            }
            let line: usize = f[col("line")].parse().unwrap();
            let want = &poses[line - 2];
            let values: Vec<f64> = machine.axes.iter().map(|a| f[col(&a.name)].parse().unwrap()).collect();
            let got = kin.fk(&values);
            let dp = (got.point - want.point).norm();
            let da = got.axis.cross(&want.axis).norm().atan2(got.axis.dot(&want.axis));
            // The CL itself is rounded to 1e-10 mm / 1e-12.
            prop_assert!(dp <= summary.tolerance_mm + 1e-8, "line {line}: {dp} mm\n{toml}");
            prop_assert!(da <= summary.tolerance_rad + 1e-9, "line {line}: {da} rad\n{toml}");
            seen += 1;
        }
        prop_assert_eq!(seen, 40);
    }
}
