//! A small deterministic generator for the property tests that build
//! random machines (seeded by proptest), TOML for the vectors they write,
//! and what those tests allow the post at singular points.

use nalgebra::Vector3;

/// xorshift64*.
pub struct Rng(pub u64);

impl Rng {
    /// Uniform in [0, 1).
    pub fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }

    /// A random unit vector.
    pub fn unit(&mut self) -> Vector3<f64> {
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

/// A vector as a TOML array, to the last bit.
pub fn vec_toml(v: &Vector3<f64>) -> String {
    format!("[{:.17}, {:.17}, {:.17}]", v.x, v.y, v.z)
}

/// Three random unit directions for linear axes that span space well
/// (|det| > 0.3).
pub fn spanning_directions(rng: &mut Rng) -> [Vector3<f64>; 3] {
    loop {
        let l = [rng.unit(), rng.unit(), rng.unit()];
        if nalgebra::Matrix3::from_columns(&l).determinant().abs() > 0.3 {
            return l;
        }
    }
}

/// How a random serial machine is built ([`random_body`]).
pub struct Shape<'a> {
    /// The machine's name.
    pub name: &'a str,
    /// Directions of the linear axes X, Y, Z.
    pub linear: [Vector3<f64>; 3],
    /// A rotary axis gets ±400° limits half of the time (else it turns
    /// without end).
    pub limits: bool,
    /// The linear axes come first in the chain, as on every real machine
    /// (no rotary axis carries a linear one: they keep spanning space);
    /// else the chain order is random.
    pub linear_first: bool,
}

/// A random serial machine of `shape` with a `[tool]` table whose point
/// is within `reach` mm of the flange on every coordinate and whose axis is
/// random: the whole machine file, the test machine of the property tests.
pub fn random_machine(rng: &mut Rng, shape: &Shape, reach: f64) -> String {
    let body = random_body(rng, shape);
    let tool = Vector3::new(
        rng.range(-reach, reach),
        rng.range(-reach, reach),
        rng.range(-reach, reach),
    );
    format!(
        "{body}[tool]\npoint = {}\naxis = {}\n",
        vec_toml(&tool),
        vec_toml(&rng.unit())
    )
}

/// The axes and part frame of a random serial machine (see [`Shape`]):
/// linear axes X, Y, Z along `shape.linear`, rotary axes A, B in
/// non-parallel random directions on random (non-intersecting) lines, each
/// axis on a random side, and a tilted part frame. The `[tool]` table is
/// left to the caller.
pub fn random_body(rng: &mut Rng, shape: &Shape) -> String {
    let (name, linear, limits) = (shape.name, shape.linear, shape.limits);
    let rot = loop {
        let r = [rng.unit(), rng.unit()];
        if r[0].cross(&r[1]).norm() > 0.3 {
            break r;
        }
    };
    let side = |rng: &mut Rng| {
        if rng.next() < 0.5 {
            "tool"
        } else {
            "workpiece"
        }
    };
    let mut axes: Vec<String> = Vec::new();
    for (k, d) in linear.iter().enumerate() {
        axes.push(format!(
            "[[axis]]\nname = \"{}\"\nkind = \"linear\"\nside = \"{}\"\ndirection = {}\n",
            ["X", "Y", "Z"][k],
            side(rng),
            vec_toml(d)
        ));
    }
    for (k, d) in rot.iter().enumerate() {
        let side = side(rng);
        let p = Vector3::new(
            rng.range(-300.0, 300.0),
            rng.range(-300.0, 300.0),
            rng.range(-300.0, 300.0),
        );
        let limits = if limits && rng.next() < 0.5 {
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
    for i in (1..axes.len()).rev().filter(|_| !shape.linear_first) {
        let j = (rng.next() * (i + 1) as f64) as usize;
        axes.swap(i, j.min(i));
    }
    let x = rng.unit();
    let z = rng.unit();
    let z = (z - x * x.dot(&z)).normalize();
    let origin = Vector3::new(
        rng.range(-100.0, 100.0),
        rng.range(-100.0, 100.0),
        rng.range(-100.0, 100.0),
    );
    format!(
        "name = \"{name}\"\n{}\n[workpiece]\norigin = {}\nx = {}\nz = {}\n",
        axes.join("\n"),
        vec_toml(&origin),
        vec_toml(&x),
        vec_toml(&z)
    )
}

/// How far beyond the check's tolerance the post may turn the tool axis off
/// the CL at CL line `line`: inside the singular cone it holds the free angle
/// and points the nearest axis it can, off by no more than the (default)
/// cone, and it reports every such point in a stretch; elsewhere nothing.
pub fn singular_allowance(summary: &kinpost_post::Summary, line: usize) -> f64 {
    let held = summary
        .planning
        .singular_stretches
        .iter()
        .any(|s| (s.first_line..=s.last_line).contains(&line));
    if held {
        kinpost_post::DEFAULT_SINGULAR_CONE_DEG.to_radians()
    } else {
        0.0
    }
}
