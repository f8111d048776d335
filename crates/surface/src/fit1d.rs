//! One direction of a tensor-product fit: cubic spline interpolation with a
//! choice of end conditions, and least-squares approximation with a chosen
//! number of control points. Both are linear maps from data values to
//! control points whose matrix depends only on the parameters, so it is
//! factorised once (band LU) and applied to every row or column of a grid.

use crate::banded::{BandLu, BandMatrix};
use crate::basis::{DEGREE, basis_ders, find_span};

/// End conditions of a cubic interpolating spline (the two equations that
/// the m interpolation conditions leave open for m + 2 control points).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Ends {
    /// Zero second derivative at both ends (Li (B-spline grinding), §2).
    Natural,
    /// Continuous third derivative at the second and the second-last data
    /// parameter (the first and last interior knots). Needs 4 points.
    NotAKnot,
    /// End tangents given: the derivative of the parabola through the three
    /// end points (Bessel's end condition; the chord for two points).
    ClampedTangent,
}

impl Ends {
    /// The name used on the command line and in surface files.
    pub fn name(self) -> &'static str {
        match self {
            Ends::Natural => "natural",
            Ends::NotAKnot => "not-a-knot",
            Ends::ClampedTangent => "clamped-tangent",
        }
    }

    /// The fewest data points per direction these ends need.
    pub fn min_points(self) -> usize {
        match self {
            Ends::Natural | Ends::ClampedTangent => 2,
            Ends::NotAKnot => 4,
        }
    }
}

/// Why a direction cannot be fitted.
#[derive(Debug, Clone, PartialEq)]
pub enum FitError {
    /// Too few data points for the fit.
    TooFewPoints {
        /// Points given.
        have: usize,
        /// Points needed.
        need: usize,
    },
    /// Parameters not strictly increasing at this index.
    ParametersNotIncreasing {
        /// The index.
        index: usize,
    },
    /// More control points asked for than the data can determine.
    TooManyControlPoints {
        /// Control points asked for.
        asked: usize,
        /// Data points.
        points: usize,
    },
    /// Fewer than four control points asked for.
    TooFewControlPoints {
        /// Control points asked for.
        asked: usize,
    },
    /// The linear system is singular (should not happen for valid input).
    Singular,
}

impl std::fmt::Display for FitError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            FitError::TooFewPoints { have, need } => {
                write!(f, "{have} data points, this fit needs at least {need}")
            }
            FitError::ParametersNotIncreasing { index } => write!(
                f,
                "the parameters of data points {} and {index} are equal (repeated points?)",
                index - 1
            ),
            FitError::TooManyControlPoints { asked, points } => write!(
                f,
                "{asked} control points asked for, but only {points} data points: at most {points}"
            ),
            FitError::TooFewControlPoints { asked } => {
                write!(
                    f,
                    "{asked} control points asked for: a cubic needs at least 4"
                )
            }
            FitError::Singular => f.write_str("the fitting equations are singular"),
        }
    }
}

/// A factorised one-direction fit.
#[derive(Debug, Clone)]
pub struct Fit1d {
    knots: Vec<f64>,
    n_ctrl: usize,
    params: Vec<f64>,
    kind: Kind,
}

#[derive(Debug, Clone)]
enum Kind {
    Interpolation {
        ends: Ends,
        lu: BandLu,
    },
    /// Normal equations `AᵀA x = Aᵀ d`, factorised; `rows[i]` is the span
    /// and the four basis values of data parameter `i`.
    Approximation {
        lu: BandLu,
        rows: Vec<(usize, [f64; 4])>,
    },
}

fn check_params(params: &[f64], need: usize) -> Result<(), FitError> {
    if params.len() < need {
        return Err(FitError::TooFewPoints {
            have: params.len(),
            need,
        });
    }
    for i in 1..params.len() {
        // `!(a < b)` also catches NaN.
        if !(params[i - 1] < params[i]) {
            return Err(FitError::ParametersNotIncreasing { index: i });
        }
    }
    Ok(())
}

/// The interpolation knot vector (Li (B-spline grinding), §2): the data parameters as
/// knots, the end ones four-fold (open, clamped), so m points give m + 2
/// control points.
pub fn interpolation_knots(params: &[f64]) -> Vec<f64> {
    let (first, last) = (params[0], params[params.len() - 1]);
    let mut knots = vec![first; DEGREE + 1];
    knots.extend_from_slice(&params[1..params.len() - 1]);
    knots.extend(std::iter::repeat_n(last, DEGREE + 1));
    knots
}

/// Knots for a least-squares fit with `n_ctrl` control points to data at
/// `params`, by averaging (The NURBS Book eq. 9.68–9.69), which keeps data
/// in every knot span; for uniform parameters they are uniform.
pub fn approximation_knots(params: &[f64], n_ctrl: usize) -> Vec<f64> {
    let p = DEGREE;
    let m = params.len(); // points 0..m-1
    let (first, last) = (params[0], params[m - 1]);
    let mut knots = vec![first; p + 1];
    let d = m as f64 / (n_ctrl - p) as f64;
    for j in 1..(n_ctrl - p) {
        let jd = j as f64 * d;
        let i = jd.floor() as usize;
        let alpha = jd - i as f64;
        let k = (1.0 - alpha) * params[i - 1] + alpha * params[i.min(m - 1)];
        knots.push(k);
    }
    knots.extend(std::iter::repeat_n(last, p + 1));
    knots
}

impl Fit1d {
    /// Interpolation at `params` (strictly increasing) with `ends`.
    pub fn interpolation(params: &[f64], ends: Ends) -> Result<Fit1d, FitError> {
        check_params(params, ends.min_points())?;
        let m = params.len();
        let n = m + 2;
        let knots = interpolation_knots(params);
        let mut a = BandMatrix::zeros(n, 3, 3);
        // Row order keeps the band narrow: data 0, start condition, data
        // 1 … m−2, end condition, data m−1.
        for (k, &u) in params.iter().enumerate() {
            let row = if k == 0 {
                0
            } else if k == m - 1 {
                n - 1
            } else {
                k + 1
            };
            let span = find_span(&knots, n, u);
            let b = basis_ders::<1>(&knots, span, u);
            for r in 0..4 {
                set_in_band(&mut a, row, span - DEGREE + r, b[0][r]);
            }
        }
        let u0 = params[0];
        let u1 = params[m - 1];
        match ends {
            Ends::Natural | Ends::ClampedTangent => {
                let order = if ends == Ends::Natural { 2 } else { 1 };
                for (row, u) in [(1, u0), (n - 2, u1)] {
                    let span = find_span(&knots, n, u);
                    let b = basis_ders::<3>(&knots, span, u);
                    for r in 0..4 {
                        set_in_band(&mut a, row, span - DEGREE + r, b[order][r]);
                    }
                }
            }
            Ends::NotAKnot => {
                // Third-derivative jump at knots[4] (= params[1]) and at
                // knots[n − 1] (= params[m − 2]) is zero.
                for (row, knot) in [(1, DEGREE + 1), (n - 2, n - 1)] {
                    let u = knots[knot];
                    let left = basis_ders::<4>(&knots, knot - 1, u);
                    let right = basis_ders::<4>(&knots, knot, u);
                    let mut coef = [0.0; 5];
                    for r in 0..4 {
                        coef[r] += left[3][r];
                        coef[r + 1] -= right[3][r];
                    }
                    for (r, c) in coef.iter().enumerate() {
                        set_in_band(&mut a, row, knot - 1 - DEGREE + r, *c);
                    }
                }
            }
        }
        let lu = a.factor().map_err(|_| FitError::Singular)?;
        Ok(Fit1d {
            knots,
            n_ctrl: n,
            params: params.to_vec(),
            kind: Kind::Interpolation { ends, lu },
        })
    }

    /// Least-squares approximation of data at `params` by `n_ctrl` control
    /// points (4 ≤ n_ctrl ≤ number of points).
    pub fn approximation(params: &[f64], n_ctrl: usize) -> Result<Fit1d, FitError> {
        check_params(params, 2)?;
        let m = params.len();
        if n_ctrl < DEGREE + 1 {
            return Err(FitError::TooFewControlPoints { asked: n_ctrl });
        }
        if n_ctrl > m {
            return Err(FitError::TooManyControlPoints {
                asked: n_ctrl,
                points: m,
            });
        }
        let knots = approximation_knots(params, n_ctrl);
        let rows: Vec<(usize, [f64; 4])> = params
            .iter()
            .map(|&u| {
                let span = find_span(&knots, n_ctrl, u);
                (span, basis_ders::<1>(&knots, span, u)[0])
            })
            .collect();
        let mut ata = BandMatrix::zeros(n_ctrl, DEGREE, DEGREE);
        for (span, b) in &rows {
            for r in 0..4 {
                for c in 0..4 {
                    ata.add(span - DEGREE + r, span - DEGREE + c, b[r] * b[c]);
                }
            }
        }
        let lu = ata.factor().map_err(|_| FitError::Singular)?;
        Ok(Fit1d {
            knots,
            n_ctrl,
            params: params.to_vec(),
            kind: Kind::Approximation { lu, rows },
        })
    }

    /// The knot vector of the fitted splines.
    pub fn knots(&self) -> &[f64] {
        &self.knots
    }

    /// The number of control points of the fitted splines.
    pub fn n_ctrl(&self) -> usize {
        self.n_ctrl
    }

    /// The data parameters.
    pub fn params(&self) -> &[f64] {
        &self.params
    }

    /// Control points of the spline through (or nearest to) `data`, one
    /// value per parameter; `out` gets `n_ctrl` values.
    pub fn solve<const N: usize>(&self, data: &[[f64; N]], out: &mut Vec<[f64; N]>) {
        assert_eq!(data.len(), self.params.len(), "one value per parameter");
        out.clear();
        match &self.kind {
            Kind::Interpolation { ends, lu } => {
                let m = data.len();
                let n = self.n_ctrl;
                out.resize(n, [0.0; N]);
                out[0] = data[0];
                out[n - 1] = data[m - 1];
                out[2..m].copy_from_slice(&data[1..m - 1]);
                let (start, end) = match ends {
                    Ends::Natural | Ends::NotAKnot => ([0.0; N], [0.0; N]),
                    Ends::ClampedTangent => (
                        end_tangent(&self.params[..m.min(3)], &data[..m.min(3)]),
                        end_tangent_rev(&self.params[m - m.min(3)..], &data[m - m.min(3)..]),
                    ),
                };
                out[1] = start;
                out[n - 2] = end;
                lu.solve_in_place(out);
            }
            Kind::Approximation { lu, rows } => {
                out.resize(self.n_ctrl, [0.0; N]);
                for ((span, b), d) in rows.iter().zip(data) {
                    for r in 0..4 {
                        for c in 0..N {
                            out[span - DEGREE + r][c] += b[r] * d[c];
                        }
                    }
                }
                lu.solve_in_place(out);
            }
        }
    }
}

/// Sets a band entry; entries the band cannot hold are structurally zero
/// (basis functions that vanish at the point) and must be zero here.
fn set_in_band(a: &mut BandMatrix, row: usize, col: usize, value: f64) {
    let inside = col + 3 >= row && col <= row + 3;
    if inside {
        a.set(row, col, value);
    } else {
        debug_assert!(
            value.abs() < 1e-9,
            "({row}, {col}) = {value} outside the band"
        );
    }
}

/// Derivative at `t[0]` of the parabola through the first three points (the
/// line through two).
fn end_tangent<const N: usize>(t: &[f64], q: &[[f64; N]]) -> [f64; N] {
    let mut d = [0.0; N];
    if t.len() == 2 {
        for c in 0..N {
            d[c] = (q[1][c] - q[0][c]) / (t[1] - t[0]);
        }
        return d;
    }
    let (t0, t1, t2) = (t[0], t[1], t[2]);
    // Derivative of the Lagrange basis polynomials at t0.
    let w0 = (2.0 * t0 - t1 - t2) / ((t0 - t1) * (t0 - t2));
    let w1 = (t0 - t2) / ((t1 - t0) * (t1 - t2));
    let w2 = (t0 - t1) / ((t2 - t0) * (t2 - t1));
    for c in 0..N {
        d[c] = w0 * q[0][c] + w1 * q[1][c] + w2 * q[2][c];
    }
    d
}

/// Derivative at the last parameter of the parabola through the last three
/// points.
fn end_tangent_rev<const N: usize>(t: &[f64], q: &[[f64; N]]) -> [f64; N] {
    let rt: Vec<f64> = t.iter().rev().copied().collect();
    let rq: Vec<[f64; N]> = q.iter().rev().copied().collect();
    end_tangent(&rt, &rq)
}

/// Parameters of `m` points spread uniformly over [0, 1] (Li (B-spline grinding), §2:
/// u_i = i / (m − 1)).
pub fn uniform_params(m: usize) -> Vec<f64> {
    if m == 1 {
        return vec![0.0];
    }
    (0..m).map(|i| i as f64 / (m - 1) as f64).collect()
}

/// Evaluates the spline with `knots` and control points `ctrl` and its
/// derivatives up to order `D − 1` at `u` (used by tests and by the
/// surface's iso-curves).
pub fn eval_curve<const D: usize, const N: usize>(
    knots: &[f64],
    ctrl: &[[f64; N]],
    u: f64,
) -> [[f64; N]; D] {
    let span = find_span(knots, ctrl.len(), u);
    let b = basis_ders::<D>(knots, span, u);
    let mut out = [[0.0; N]; D];
    for (k, row) in b.iter().enumerate() {
        for (r, w) in row.iter().enumerate() {
            let p = &ctrl[span - DEGREE + r];
            for c in 0..N {
                out[k][c] += w * p[c];
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fit(params: &[f64], data: &[f64], ends: Ends) -> (Vec<f64>, Vec<[f64; 1]>) {
        let f = Fit1d::interpolation(params, ends).unwrap();
        let d: Vec<[f64; 1]> = data.iter().map(|&v| [v]).collect();
        let mut out = Vec::new();
        f.solve(&d, &mut out);
        (f.knots().to_vec(), out)
    }

    #[test]
    fn natural_spline_interpolates_and_has_zero_end_curvature() {
        let params = [0.0, 0.1, 0.35, 0.4, 0.7, 1.0];
        let data = [1.0, -2.0, 0.5, 3.0, 2.0, -1.0];
        let (knots, ctrl) = fit(&params, &data, Ends::Natural);
        assert_eq!(ctrl.len(), 8);
        for (u, d) in params.iter().zip(data) {
            let v = eval_curve::<1, 1>(&knots, &ctrl, *u)[0][0];
            assert!((v - d).abs() < 1e-12);
        }
        for u in [0.0, 1.0] {
            let v = eval_curve::<3, 1>(&knots, &ctrl, u);
            assert!(v[2][0].abs() < 1e-9, "C''({u}) = {}", v[2][0]);
        }
    }

    #[test]
    fn natural_spline_of_a_line_is_the_line() {
        // A straight line satisfies the natural conditions, so it is its own
        // interpolant (uniqueness).
        let params = uniform_params(7);
        let data: Vec<f64> = params.iter().map(|u| 3.0 * u - 1.0).collect();
        let (knots, ctrl) = fit(&params, &data, Ends::Natural);
        for k in 0..=50 {
            let u = k as f64 / 50.0;
            let v = eval_curve::<2, 1>(&knots, &ctrl, u);
            assert!((v[0][0] - (3.0 * u - 1.0)).abs() < 1e-12);
            assert!((v[1][0] - 3.0).abs() < 1e-10);
        }
    }

    #[test]
    fn not_a_knot_reproduces_a_cubic() {
        // A cubic polynomial is its own not-a-knot interpolant.
        let f = |u: f64| 2.0 * u * u * u - u * u + 0.5 * u + 3.0;
        let params = [0.0, 0.15, 0.4, 0.45, 0.8, 1.0];
        let data: Vec<f64> = params.iter().map(|&u| f(u)).collect();
        let (knots, ctrl) = fit(&params, &data, Ends::NotAKnot);
        for k in 0..=40 {
            let u = k as f64 / 40.0;
            let v = eval_curve::<1, 1>(&knots, &ctrl, u)[0][0];
            assert!((v - f(u)).abs() < 1e-11, "u {u}: {v} vs {}", f(u));
        }
    }

    #[test]
    fn clamped_tangent_reproduces_a_parabola() {
        // Bessel end tangents are exact for a parabola, so the clamped
        // spline is the parabola itself.
        let f = |u: f64| -4.0 * u * u + u + 2.0;
        let params = [0.0, 0.2, 0.3, 0.65, 1.0];
        let data: Vec<f64> = params.iter().map(|&u| f(u)).collect();
        let (knots, ctrl) = fit(&params, &data, Ends::ClampedTangent);
        for k in 0..=40 {
            let u = k as f64 / 40.0;
            let v = eval_curve::<1, 1>(&knots, &ctrl, u)[0][0];
            assert!((v - f(u)).abs() < 1e-11);
        }
    }

    #[test]
    fn least_squares_reproduces_a_cubic_and_passes_near_noisy_data() {
        let f = |u: f64| u * u * u - 2.0 * u + 1.0;
        let params = uniform_params(40);
        let data: Vec<[f64; 1]> = params.iter().map(|&u| [f(u)]).collect();
        let fit = Fit1d::approximation(&params, 6).unwrap();
        let mut ctrl = Vec::new();
        fit.solve(&data, &mut ctrl);
        assert_eq!(ctrl.len(), 6);
        for &u in &params {
            let v = eval_curve::<1, 1>(fit.knots(), &ctrl, u)[0][0];
            assert!((v - f(u)).abs() < 1e-12);
        }
        // The least-squares residual is orthogonal to every basis function:
        // Aᵀ(A x − d) = 0.
        let noisy: Vec<[f64; 1]> = params
            .iter()
            .enumerate()
            .map(|(i, &u)| [f(u) + 0.01 * ((i * 7919) % 13) as f64 - 0.06])
            .collect();
        fit.solve(&noisy, &mut ctrl);
        let mut grad = vec![0.0; 6];
        for (&u, d) in params.iter().zip(&noisy) {
            let span = find_span(fit.knots(), 6, u);
            let b = basis_ders::<1>(fit.knots(), span, u)[0];
            let r = eval_curve::<1, 1>(fit.knots(), &ctrl, u)[0][0] - d[0];
            for k in 0..4 {
                grad[span - 3 + k] += b[k] * r;
            }
        }
        assert!(grad.iter().all(|g| g.abs() < 1e-12), "{grad:?}");
    }

    #[test]
    fn bad_requests_are_errors() {
        assert_eq!(
            Fit1d::interpolation(&[0.0, 0.5, 1.0], Ends::NotAKnot).unwrap_err(),
            FitError::TooFewPoints { have: 3, need: 4 }
        );
        assert_eq!(
            Fit1d::interpolation(&[0.0, 0.5, 0.5, 1.0], Ends::Natural).unwrap_err(),
            FitError::ParametersNotIncreasing { index: 2 }
        );
        assert_eq!(
            Fit1d::approximation(&uniform_params(5), 6).unwrap_err(),
            FitError::TooManyControlPoints {
                asked: 6,
                points: 5
            }
        );
        assert_eq!(
            Fit1d::approximation(&uniform_params(5), 3).unwrap_err(),
            FitError::TooFewControlPoints { asked: 3 }
        );
    }
}
