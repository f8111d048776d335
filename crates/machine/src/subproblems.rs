//! Paden–Kahan subproblems for rotations about lines through the origin
//! (directions only: orientation does not depend on where a rotary axis is).
//!
//! Reference: R. M. Murray, Z. Li, S. S. Sastry, *A Mathematical Introduction
//! to Robotic Manipulation* (1994), §3.3.2, subproblems 1 and 2. All angles
//! come from `atan2`, never `acos`, so accuracy holds near singular poses.

use nalgebra::{Matrix3, Vector3};

/// Below this length a projection onto the plane normal to a rotation axis is
/// taken as zero: the vector lies on the axis and the angle is free.
pub const FREE_EPS: f64 = 1e-12;

/// `Some((k, σ))` when `v` is exactly `σ·e_k` (σ = ±1): two components
/// zero and the third ±1, as the axes of most machines are.
pub(crate) fn coordinate_axis(v: &Vector3<f64>) -> Option<(usize, f64)> {
    let zeros = v.iter().filter(|&&c| c == 0.0).count();
    let k = v.iamax();
    (zeros == 2 && v[k].abs() == 1.0).then_some((k, v[k]))
}

/// `g²` of subproblem 2, the squared height of the intersection point
/// `z = a·w1 + b·w2 + g·(w1 × w2)` off the plane of the axes, from
/// `|q off w1|² / |w1 × w2|²` and `b`.
///
/// `z` turns onto `q` about `w1`, so its part off `w1`, `b·(w2 − (w1·w2)·w1)
/// + g·(w1 × w2)` (two orthogonal terms, each of length `|w1 × w2|` per
/// unit), is as long as `q`'s: `|q off w1|² = (b² + g²)·|w1 × w2|²`.
/// Murray, Li and Sastry (§3.3.2) write `g²` from `|z|² = |p|²` instead,
/// `(|p|² − a² − b² − 2ab·w1·w2) / |w1 × w2|²`: near the pole (`q` nearly
/// along `w1`, `g` small) that difference of numbers near 1 loses what `g`
/// is made of: 2.4·10⁻⁹ rad of the tool axis 1·10⁻⁶ ° from the pole;
/// here `g²` is as accurate as `q`'s small components.
#[inline(always)]
fn height_squared(q_off_w1_squared_over_cross2: f64, b: f64) -> f64 {
    q_off_w1_squared_over_cross2 - b * b
}

/// Rotation matrix about unit `w` by `theta` radians (Rodrigues' formula).
#[inline]
pub fn rotation(w: &Vector3<f64>, theta: f64) -> Matrix3<f64> {
    let (s, c) = theta.sin_cos();
    rotation_cs(w, c, s)
}

/// Rotation matrix about unit `w` by the angle whose cosine and sine are
/// `c` and `s` (no trigonometry: for angles that come out of [`sp1_cs`]).
#[inline]
pub fn rotation_cs(w: &Vector3<f64>, c: f64, s: f64) -> Matrix3<f64> {
    let v = 1.0 - c;
    let (x, y, z) = (w.x, w.y, w.z);
    Matrix3::new(
        c + x * x * v,
        x * y * v - z * s,
        x * z * v + y * s,
        y * x * v + z * s,
        c + y * y * v,
        y * z * v - x * s,
        z * x * v - y * s,
        z * y * v + x * s,
        c + z * z * v,
    )
}

/// An angle with its cosine and sine, as subproblem 1 finds them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Angle {
    /// Radians, in (−π, π].
    pub rad: f64,
    /// Its cosine.
    pub cos: f64,
    /// Its sine.
    pub sin: f64,
}

impl Angle {
    /// The rotation about unit `w` by this angle.
    #[inline]
    pub fn rotation(&self, w: &Vector3<f64>) -> Matrix3<f64> {
        rotation_cs(w, self.cos, self.sin)
    }
}

/// Subproblem 1 with the cosine and sine of the solution (see [`sp1`]).
#[inline]
pub fn sp1_cs(w: &Vector3<f64>, u: &Vector3<f64>, v: &Vector3<f64>) -> Option<Angle> {
    sp1_xy(w, u, v).map(|(x, y)| Angle::from_xy(x, y))
}

/// Subproblem 1 before its `atan2`: `(x, y)`, a positive multiple of
/// `(cos θ, sin θ)` (see [`sp1`]). The inverse kinematics takes the angle
/// itself only for the branches it needs.
#[inline]
pub fn sp1_xy(w: &Vector3<f64>, u: &Vector3<f64>, v: &Vector3<f64>) -> Option<(f64, f64)> {
    let up = u - w * w.dot(u);
    let vp = v - w * w.dot(v);
    if up.norm_squared() < FREE_EPS * FREE_EPS || vp.norm_squared() < FREE_EPS * FREE_EPS {
        return None;
    }
    Some((up.dot(&vp), w.dot(&up.cross(&vp))))
}

impl Angle {
    /// The angle of the direction `(x, y)` (not both zero).
    #[inline]
    pub fn from_xy(x: f64, y: f64) -> Angle {
        let (cos, sin) = unit_xy(x, y);
        Angle {
            rad: f64::atan2(y, x),
            cos,
            sin,
        }
    }
}

/// `(x, y)` scaled to unit length: the cosine and sine of its angle.
#[inline]
pub fn unit_xy(x: f64, y: f64) -> (f64, f64) {
    // Both are products of unit-length-scale vectors: no overflow to fear.
    let r = (x * x + y * y).sqrt();
    (x / r, y / r)
}

/// Subproblem 1: the angle `θ` with `rot(w, θ)·u = v`, assuming `w·u = w·v`
/// and `|u| = |v|`. `None` when `u` (or `v`) lies on the axis: every angle
/// is a solution (a singular configuration).
#[inline]
pub fn sp1(w: &Vector3<f64>, u: &Vector3<f64>, v: &Vector3<f64>) -> Option<f64> {
    sp1_cs(w, u, v).map(|a| a.rad)
}

/// One solution of subproblem 2.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sp2Solution {
    /// Angle about the first axis; `None` if free (singular).
    pub theta1: Option<Angle>,
    /// Angle about the second axis; `None` if free (singular).
    pub theta2: Option<Angle>,
}

/// One solution of subproblem 2 before the `atan2`s (see [`sp1_xy`] and
/// [`Sp2::solve_xy`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sp2Xy {
    /// `(x, y)` of the angle about the first axis; `None` if free (singular).
    pub theta1: Option<(f64, f64)>,
    /// `(x, y)` of the angle about the second axis; `None` if free (singular).
    pub theta2: Option<(f64, f64)>,
}

/// Subproblem 2: angles with `rot(w1, θ1)·rot(w2, θ2)·p = q` for unit vectors
/// `p`, `q` and non-parallel unit axes `w1`, `w2`. Returns 0, 1 or 2
/// solutions. `slack` is how far below zero the squared height of the
/// intersection point may be before the orientation counts as unreachable
/// (round-off at the edge of the reachable cone).
pub fn sp2(
    w1: &Vector3<f64>,
    w2: &Vector3<f64>,
    p: &Vector3<f64>,
    q: &Vector3<f64>,
    slack: f64,
) -> ([Sp2Solution; 2], usize) {
    let (xy, n) = Sp2::new(w1, w2, p).solve_xy(q, slack);
    let angle = |t: Option<(f64, f64)>| t.map(|(x, y)| Angle::from_xy(x, y));
    let sol = |s: &Sp2Xy| Sp2Solution {
        theta1: angle(s.theta1),
        theta2: angle(s.theta2),
    };
    ([sol(&xy[0]), sol(&xy[1])], n)
}

/// Subproblem 2 for given axes `w1`, `w2` and vector `p`, with everything
/// that does not depend on `q` worked out once: the inverse kinematics of a
/// machine solves it for one `q` per CL point. Same arithmetic as [`sp2`],
/// hence the same results to the bit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sp2 {
    w1: Vector3<f64>,
    w2: Vector3<f64>,
    w12: f64,
    cross: Vector3<f64>,
    cross2: f64,
    denom: f64,
    w2p: f64,
    /// `p` with its component along `w2` removed (subproblem 1 for `θ2`
    /// turns it), and whether that leaves nothing (`θ2` free).
    p_off_w2: Vector3<f64>,
    p_on_w2: bool,
    /// Axes along coordinate axes (see [`Aligned`]).
    aligned: Option<Aligned>,
}

/// `w1 = σ1·e_i`, `w2 = σ2·e_j` (i ≠ j), hence `w1 × w2 = σ3·e_k`: every
/// dot and cross product of [`Sp2::solve_xy`] with them has one or two
/// non-zero terms, worked out here.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Aligned {
    i: usize,
    j: usize,
    k: usize,
    s1: f64,
    s2: f64,
    s3: f64,
    /// The signs of the cross products' components i and j: `σ1` and `σ2`,
    /// negated when `(i, j, k)` (resp. `(j, k, i)`) is not cyclic.
    t1: f64,
    t2: f64,
    /// The components i and k of `p` off `w2` (its component j is zero).
    po_i: f64,
    po_k: f64,
}

impl Sp2 {
    /// Subproblem 2 for rotations about the unit axes `w1` (outer) and
    /// `w2` (inner) applied to `p`: what every solve shares, worked out once.
    pub fn new(w1: &Vector3<f64>, w2: &Vector3<f64>, p: &Vector3<f64>) -> Sp2 {
        let w12 = w1.dot(w2);
        let cross = w1.cross(w2);
        let w2p = w2.dot(p);
        let p_off_w2 = p - w2 * w2p;
        let aligned = match (coordinate_axis(w1), coordinate_axis(w2)) {
            (Some((i, s1)), Some((j, s2))) if i != j => {
                let k = 3 - i - j;
                let cyclic = j == (i + 1) % 3;
                Some(Aligned {
                    i,
                    j,
                    k,
                    s1,
                    s2,
                    s3: cross[k],
                    t1: if cyclic { s1 } else { -s1 },
                    t2: if cyclic { s2 } else { -s2 },
                    po_i: p_off_w2[i],
                    po_k: p_off_w2[k],
                })
            }
            _ => None,
        };
        Sp2 {
            w1: *w1,
            w2: *w2,
            w12,
            cross,
            cross2: cross.norm_squared(),
            denom: w12 * w12 - 1.0,
            w2p,
            p_off_w2,
            p_on_w2: p_off_w2.norm_squared() < FREE_EPS * FREE_EPS,
            aligned,
        }
    }

    /// The solutions for `q`, as [`sp2`] has them but before the `atan2`s.
    #[inline(always)]
    pub fn solve_xy(&self, q: &Vector3<f64>, slack: f64) -> ([Sp2Xy; 2], usize) {
        let none = Sp2Xy {
            theta1: None,
            theta2: None,
        };
        if let Some(al) = &self.aligned {
            return self.solve_aligned(al, q, slack);
        }
        let (w1, w12) = (&self.w1, self.w12);
        if self.cross2 < 1e-24 {
            return ([none; 2], 0);
        }
        let w1q = w1.dot(q);
        let a = (w12 * self.w2p - w1q) / self.denom;
        let b = (w12 * w1q - self.w2p) / self.denom;
        // Subproblem 1 (see `sp1_xy`) for both angles, sharing the
        // projections that do not depend on the intersection point `z`.
        let q_off_w1 = q - w1 * w1q;
        let q_off2 = q_off_w1.norm_squared();
        let q_on_w1 = q_off2 < FREE_EPS * FREE_EPS;
        let g2 = height_squared(q_off2 / self.cross2, b);
        if g2 < -slack {
            return ([none; 2], 0);
        }
        let g = g2.max(0.0).sqrt();
        if g == 0.0 {
            ([self.at(a, b, 0.0, &q_off_w1, q_on_w1), none], 1)
        } else {
            (
                [
                    self.at(a, b, g, &q_off_w1, q_on_w1),
                    self.at(a, b, -g, &q_off_w1, q_on_w1),
                ],
                2,
            )
        }
    }

    /// [`Sp2::solve_xy`] for axes along coordinate axes: the same
    /// arithmetic without the products with a zero component of `w1`, `w2`
    /// or `w1 × w2` (every sum left has one or two terms), hence the same
    /// values up to the sign of a zero result. With `w1·w2 = 0` and
    /// `|w1 × w2| = 1`: `a = w1·q`, `b = w2·p`, `g² = q_j² + q_k² − b²`
    /// (Murray, Li, Sastry §3.3.2), `z = σ1·a·e_i + σ2·b·e_j + σ3·g·e_k`.
    #[inline(always)]
    fn solve_aligned(&self, al: &Aligned, q: &Vector3<f64>, slack: f64) -> ([Sp2Xy; 2], usize) {
        let none = Sp2Xy {
            theta1: None,
            theta2: None,
        };
        let a = al.s1 * q[al.i];
        let b = self.w2p;
        // q off w1: q with its component i zero.
        let (qj, qk) = (q[al.j], q[al.k]);
        let q_off2 = qj * qj + qk * qk;
        let g2 = height_squared(q_off2, b);
        if g2 < -slack {
            return ([none; 2], 0);
        }
        let g = g2.max(0.0).sqrt();
        let q_on_w1 = q_off2 < FREE_EPS * FREE_EPS;
        let (po_i, po_k) = (al.po_i, al.po_k);
        let (zb, za) = (al.s2 * b, al.s1 * a);
        let solve = |g: f64| {
            // z off w1 is (zb, zg) at (j, k); z off w2 is (za, zg) at (i, k).
            let zg = al.s3 * g;
            let free1 = b * b + g * g < FREE_EPS * FREE_EPS;
            let free2 = a * a + g * g < FREE_EPS * FREE_EPS;
            Sp2Xy {
                // (z off w1 · q off w1, w1 · (z off w1 × q off w1))
                theta1: (!(free1 || q_on_w1))
                    .then_some((zb * qj + zg * qk, al.t1 * (zb * qk - zg * qj))),
                // (p off w2 · z off w2, w2 · (p off w2 × z off w2))
                theta2: (!(self.p_on_w2 || free2))
                    .then_some((po_i * za + po_k * zg, al.t2 * (po_k * za - po_i * zg))),
            }
        };
        if g == 0.0 {
            ([solve(0.0), none], 1)
        } else {
            ([solve(g), solve(-g)], 2)
        }
    }

    /// For axes along coordinate axes, the lengths of the two `(x, y)` of
    /// [`Sp2::solve_xy`] (the same for both solutions): `|θ1| =
    /// √((b² + g²)(q_j² + q_k²))` and `|θ2| = √((p_i² + p_k²)(a² + g²))`,
    /// their components being the products of those pairs. They need
    /// neither `g`'s square root nor `(x, y)` itself, so that `(x, y)` turned
    /// into a cosine and sine does not wait for two square roots in a row.
    /// `None` for other axes.
    #[inline(always)]
    pub fn xy_lengths(&self, q: &Vector3<f64>) -> Option<[f64; 2]> {
        let al = self.aligned.as_ref()?;
        let a = al.s1 * q[al.i];
        let b = self.w2p;
        let (qj, qk) = (q[al.j], q[al.k]);
        let q_off2 = qj * qj + qk * qk;
        let g2 = height_squared(q_off2, b).max(0.0);
        Some([
            ((b * b + g2) * q_off2).sqrt(),
            ((al.po_i * al.po_i + al.po_k * al.po_k) * (a * a + g2)).sqrt(),
        ])
    }

    /// The angles for the intersection point `z = a·w1 + b·w2 + g·(w1 × w2)`.
    #[inline(always)]
    fn at(&self, a: f64, b: f64, g: f64, q_off_w1: &Vector3<f64>, q_on_w1: bool) -> Sp2Xy {
        let (w1, w2) = (&self.w1, &self.w2);
        let z = w1 * a + w2 * b + self.cross * g;
        let z_off_w1 = z - w1 * w1.dot(&z);
        let z_off_w2 = z - w2 * w2.dot(&z);
        let free = |v: &Vector3<f64>| v.norm_squared() < FREE_EPS * FREE_EPS;
        Sp2Xy {
            theta1: (!(free(&z_off_w1) || q_on_w1))
                .then(|| (z_off_w1.dot(q_off_w1), w1.dot(&z_off_w1.cross(q_off_w1)))),
            theta2: (!(self.p_on_w2 || free(&z_off_w2))).then(|| {
                (
                    self.p_off_w2.dot(&z_off_w2),
                    w2.dot(&self.p_off_w2.cross(&z_off_w2)),
                )
            }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn unit() -> impl Strategy<Value = Vector3<f64>> {
        (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64)
            .prop_filter("non-zero", |(x, y, z)| x * x + y * y + z * z > 0.01)
            .prop_map(|(x, y, z)| Vector3::new(x, y, z).normalize())
    }

    #[test]
    fn rotation_is_right_handed() {
        let r = rotation(&Vector3::z(), std::f64::consts::FRAC_PI_2);
        assert!((r * Vector3::x() - Vector3::y()).norm() < 1e-15);
    }

    /// Subproblem 2 as first written, solved from scratch for each `q`
    /// (Murray, Li, Sastry §3.3.2, with `g²` as [`height_squared`] has
    /// it): the precomputed [`Sp2`] must give the same bits.
    fn sp2_from_scratch(
        w1: &Vector3<f64>,
        w2: &Vector3<f64>,
        p: &Vector3<f64>,
        q: &Vector3<f64>,
        slack: f64,
    ) -> ([Sp2Xy; 2], usize) {
        let none = Sp2Xy {
            theta1: None,
            theta2: None,
        };
        let w12 = w1.dot(w2);
        let cross = w1.cross(w2);
        let cross2 = cross.norm_squared();
        if cross2 < 1e-24 {
            return ([none; 2], 0);
        }
        let denom = w12 * w12 - 1.0;
        let a = (w12 * w2.dot(p) - w1.dot(q)) / denom;
        let b = (w12 * w1.dot(q) - w2.dot(p)) / denom;
        let g2 = height_squared((q - w1 * w1.dot(q)).norm_squared() / cross2, b);
        if g2 < -slack {
            return ([none; 2], 0);
        }
        let g = g2.max(0.0).sqrt();
        let solve = |g: f64| {
            let z = w1 * a + w2 * b + cross * g;
            Sp2Xy {
                theta1: sp1_xy(w1, &z, q),
                theta2: sp1_xy(w2, p, &z),
            }
        };
        if g == 0.0 {
            ([solve(0.0), none], 1)
        } else {
            ([solve(g), solve(-g)], 2)
        }
    }

    proptest! {
        #[test]
        fn precomputed_sp2_is_sp2_to_the_bit(
            w1 in unit(), w2 in unit(), p in unit(), q in unit(),
            on_axis in 0usize..4, t1 in -3.1..3.1f64, t2 in -3.1..3.1f64,
        ) {
            // Reachable targets, and the singular cases: p on w2, q on w1.
            let p = if on_axis == 1 { w2 } else { p };
            let q = match on_axis {
                2 => w1,
                3 => rotation(&w1, t1) * rotation(&w2, t2) * p,
                _ => q,
            };
            let fast = Sp2::new(&w1, &w2, &p).solve_xy(&q, 1e-12);
            prop_assert_eq!(fast, sp2_from_scratch(&w1, &w2, &p, &q, 1e-12));
        }

        /// Axes along coordinate axes take the shortcut of
        /// [`Sp2::solve_aligned`]: the same values as from scratch (`==`:
        /// up to the sign of a zero), for reachable, unreachable and
        /// singular targets.
        #[test]
        fn aligned_sp2_is_sp2(
            i in 0usize..3, dj in 1usize..3, s1 in prop_oneof![Just(1.0), Just(-1.0)],
            s2 in prop_oneof![Just(1.0), Just(-1.0)], p in unit(), q in unit(),
            on_axis in 0usize..5, t1 in -3.1..3.1f64, t2 in -3.1..3.1f64,
            quarter in 0usize..4,
        ) {
            let axis = |k: usize, s: f64| {
                let mut v = Vector3::zeros();
                v[k] = s;
                v
            };
            let (w1, w2) = (axis(i, s1), axis((i + dj) % 3, s2));
            let p = if on_axis == 1 { w2 } else { p };
            // Exact quarter turns as well (zeros in the solution).
            let right = std::f64::consts::FRAC_PI_2 * quarter as f64;
            let q = match on_axis {
                2 => w1,
                3 => rotation(&w1, t1) * rotation(&w2, t2) * p,
                4 => rotation(&w1, right) * rotation(&w2, -right) * axis(3 - i - (i + dj) % 3, 1.0),
                _ => q,
            };
            let sp2 = Sp2::new(&w1, &w2, &p);
            prop_assert!(sp2.aligned.is_some());
            let (sols, n) = sp2.solve_xy(&q, 1e-12);
            prop_assert_eq!((sols, n), sp2_from_scratch(&w1, &w2, &p, &q, 1e-12));
            // The lengths known in closed form are those of the solutions,
            // within rounding (relative to the unit scale of p and q).
            let lengths = sp2.xy_lengths(&q).unwrap();
            for s in &sols[..n] {
                for (xy, length) in [s.theta1, s.theta2].iter().zip(lengths) {
                    if let Some((x, y)) = xy {
                        let r = (x * x + y * y).sqrt();
                        prop_assert!((r - length).abs() <= 1e-15, "{} vs {}", r, length);
                    }
                }
            }
        }

        #[test]
        fn sp1_recovers_the_angle(w in unit(), u in unit(), t in -3.1..3.1f64) {
            prop_assume!(w.cross(&u).norm() > 1e-3);
            let v = rotation(&w, t) * u;
            let got = sp1(&w, &u, &v).unwrap();
            prop_assert!((got - t).abs() < 1e-12);
        }

        #[test]
        fn sp2_solutions_satisfy_the_equation_and_contain_the_truth(
            w1 in unit(), w2 in unit(), p in unit(), t1 in -3.1..3.1f64, t2 in -3.1..3.1f64
        ) {
            prop_assume!(w1.cross(&w2).norm() > 1e-3);
            prop_assume!(w2.cross(&p).norm() > 1e-3);
            let q = rotation(&w1, t1) * rotation(&w2, t2) * p;
            prop_assume!(w1.cross(&q).norm() > 1e-3);
            let (sols, n) = sp2(&w1, &w2, &p, &q, 1e-12);
            prop_assert!(n >= 1);
            let mut found = false;
            for s in &sols[..n] {
                let (a, b) = (s.theta1.unwrap().rad, s.theta2.unwrap().rad);
                let m = s.theta1.unwrap().rotation(&w1) * s.theta2.unwrap().rotation(&w2) * p;
                prop_assert!((m - q).norm() < 1e-9, "cos/sin rotation {m} vs {q}");
                let got = rotation(&w1, a) * rotation(&w2, b) * p;
                prop_assert!((got - q).norm() < 1e-9, "{got} vs {q}");
                let d = |x: f64, y: f64| (x - y + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
                if d(a, t1).abs() < 1e-6 && d(b, t2).abs() < 1e-6 { found = true; }
            }
            prop_assert!(found);
        }
    }
}
