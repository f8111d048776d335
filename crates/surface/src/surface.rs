//! Tensor-product cubic B-spline surfaces: fitting to a grid (interpolation
//! as Li (B-spline grinding) does, or least squares), evaluation with first and
//! second derivatives, and the local geometry.

use nalgebra::{Isometry3, Point3, Vector3};

use crate::basis::{DEGREE, basis_ders, find_span};
use crate::fit1d::{Ends, Fit1d, FitError, uniform_params};
use crate::geometry::{Degenerate, Derivatives, LocalGeometry};
use crate::grid::Grid;

/// How data points get their parameters.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Parameterisation {
    /// u_i = i / (m − 1), v_j = j / (n − 1) (Li (B-spline grinding), §2).
    Uniform,
    /// Cumulative chord length along each grid line, normalised to [0, 1]
    /// and averaged over the lines (The NURBS Book §9.2.5).
    ChordLength,
    /// As chord length with the square root of each chord (Lee 1989),
    /// steadier on unevenly spaced data.
    Centripetal,
}

impl Parameterisation {
    /// The name used on the command line and in surface files.
    pub fn name(self) -> &'static str {
        match self {
            Parameterisation::Uniform => "uniform",
            Parameterisation::ChordLength => "chord-length",
            Parameterisation::Centripetal => "centripetal",
        }
    }
}

/// Interpolation through every point, or least squares with a given net.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// Through every data point: an (m+2)×(n+2) control net.
    Interpolation(Ends),
    /// Least squares with a control net of `rows × cols` points
    /// (4 ≤ rows ≤ m, 4 ≤ cols ≤ n).
    Approximation {
        /// Control points along u.
        rows: usize,
        /// Control points along v.
        cols: usize,
    },
}

/// What a fit is asked to do.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FitOptions {
    /// Interpolation or least squares.
    pub method: Method,
    /// How the data points get their parameters.
    pub parameterisation: Parameterisation,
}

impl Default for FitOptions {
    fn default() -> Self {
        FitOptions {
            method: Method::Interpolation(Ends::Natural),
            parameterisation: Parameterisation::Uniform,
        }
    }
}

/// Why a grid cannot be fitted, naming the direction.
#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceFitError {
    /// `"u (along the grid's columns: row index)"` or similar.
    pub direction: &'static str,
    /// What went wrong.
    pub error: FitError,
}

impl std::fmt::Display for SurfaceFitError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "direction {}: {}", self.direction, self.error)
    }
}

impl std::error::Error for SurfaceFitError {}

const U_DIRECTION: &str = "u (the grid's row index)";
const V_DIRECTION: &str = "v (the grid's column index)";

/// The data a surface was fitted to, kept for residuals and plots.
#[derive(Debug, Clone, PartialEq)]
pub struct FitData {
    /// Parameters of the grid rows (u) and columns (v).
    pub u: Vec<f64>,
    /// See `u`.
    pub v: Vec<f64>,
    /// The grid, row-major (`rows = u.len()`, `cols = v.len()`).
    pub points: Vec<[f64; 3]>,
}

/// A cubic tensor-product B-spline surface.
#[derive(Debug, Clone, PartialEq)]
pub struct Surface {
    pub(crate) knots_u: Vec<f64>,
    pub(crate) knots_v: Vec<f64>,
    /// Control net size: `rows` along u, `cols` along v.
    pub(crate) rows: usize,
    pub(crate) cols: usize,
    /// Row-major: point (a, b) at `a * cols + b`.
    pub(crate) control: Vec<[f64; 3]>,
    pub(crate) method: Option<Method>,
    pub(crate) parameterisation: Option<Parameterisation>,
    pub(crate) data: Option<FitData>,
}

/// Largest and root-mean-square distance between the surface and the data
/// points at their parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Residual {
    /// The largest, mm.
    pub max: f64,
    /// The root mean square, mm.
    pub rms: f64,
    /// Grid row and column of the largest.
    pub at: (usize, usize),
}

fn params_for(
    lines: usize,
    len: usize,
    point: impl Fn(usize, usize) -> [f64; 3],
    kind: Parameterisation,
) -> Vec<f64> {
    if kind == Parameterisation::Uniform || len < 2 {
        return uniform_params(len);
    }
    let mut sum = vec![0.0; len];
    let mut used = 0usize;
    let mut t = vec![0.0; len];
    for line in 0..lines {
        t[0] = 0.0;
        for k in 1..len {
            let (a, b) = (point(line, k - 1), point(line, k));
            let d = ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt();
            let d = if kind == Parameterisation::Centripetal {
                d.sqrt()
            } else {
                d
            };
            t[k] = t[k - 1] + d;
        }
        let total = t[len - 1];
        if total > 0.0 && total.is_finite() {
            used += 1;
            for k in 0..len {
                sum[k] += t[k] / total;
            }
        }
    }
    if used == 0 {
        return uniform_params(len);
    }
    let mut out: Vec<f64> = sum.iter().map(|s| s / used as f64).collect();
    // Exact ends, whatever the rounding of the average.
    out[0] = 0.0;
    out[len - 1] = 1.0;
    out
}

impl Surface {
    /// Fits a surface to `grid` (rows along u, columns along v).
    pub fn fit(grid: &Grid, options: &FitOptions) -> Result<Surface, SurfaceFitError> {
        let (m, n) = (grid.rows, grid.cols);
        let at = |i: usize, j: usize| grid.points[i * n + j];
        let pu = params_for(n, m, |line, k| at(k, line), options.parameterisation);
        let pv = params_for(m, n, at, options.parameterisation);
        let err_u = |error| SurfaceFitError {
            direction: U_DIRECTION,
            error,
        };
        let err_v = |error| SurfaceFitError {
            direction: V_DIRECTION,
            error,
        };
        let (fu, fv) = match options.method {
            Method::Interpolation(ends) => (
                Fit1d::interpolation(&pu, ends).map_err(err_u)?,
                Fit1d::interpolation(&pv, ends).map_err(err_v)?,
            ),
            Method::Approximation { rows, cols } => (
                Fit1d::approximation(&pu, rows).map_err(err_u)?,
                Fit1d::approximation(&pv, cols).map_err(err_v)?,
            ),
        };
        let (rows, cols) = (fu.n_ctrl(), fv.n_ctrl());
        // Along v for every grid row, then along u for every column of
        // those intermediate control points: the tensor product of the two
        // one-direction fits (both linear maps), as Li (B-spline grinding) §2 does.
        let mut inter = vec![[0.0; 3]; m * cols];
        let mut out = Vec::with_capacity(cols.max(rows));
        for i in 0..m {
            fv.solve(&grid.points[i * n..(i + 1) * n], &mut out);
            inter[i * cols..(i + 1) * cols].copy_from_slice(&out);
        }
        let mut control = vec![[0.0; 3]; rows * cols];
        let mut column = vec![[0.0; 3]; m];
        for b in 0..cols {
            for i in 0..m {
                column[i] = inter[i * cols + b];
            }
            fu.solve(&column, &mut out);
            for a in 0..rows {
                control[a * cols + b] = out[a];
            }
        }
        Ok(Surface {
            knots_u: fu.knots().to_vec(),
            knots_v: fv.knots().to_vec(),
            rows,
            cols,
            control,
            method: Some(options.method),
            parameterisation: Some(options.parameterisation),
            data: Some(FitData {
                u: pu,
                v: pv,
                points: grid.points.clone(),
            }),
        })
    }

    /// A surface from its knots and control net (row-major, `rows × cols`).
    /// Returns `None` unless the sizes agree, the knots are finite and
    /// non-decreasing with non-empty domains, and the points are finite.
    pub fn from_parts(
        knots_u: Vec<f64>,
        knots_v: Vec<f64>,
        rows: usize,
        cols: usize,
        control: Vec<[f64; 3]>,
    ) -> Option<Surface> {
        let s = Surface {
            knots_u,
            knots_v,
            rows,
            cols,
            control,
            method: None,
            parameterisation: None,
            data: None,
        };
        s.check().ok().map(|()| s)
    }

    /// Checks the invariants evaluation relies on; the message says what
    /// is wrong.
    pub(crate) fn check(&self) -> Result<(), String> {
        for (name, knots, n) in [
            ("knots_u", &self.knots_u, self.rows),
            ("knots_v", &self.knots_v, self.cols),
        ] {
            if n < DEGREE + 1 {
                return Err(format!(
                    "a cubic needs at least 4 control points per direction, {name} is for {n}"
                ));
            }
            if knots.len() != n + DEGREE + 1 {
                return Err(format!(
                    "{name} has {} knots; {n} control points need {}",
                    knots.len(),
                    n + DEGREE + 1
                ));
            }
            if let Some(k) = knots.iter().position(|k| !k.is_finite()) {
                return Err(format!("{name}[{k}] is not a finite number"));
            }
            if let Some(k) = (1..knots.len()).find(|&k| knots[k] < knots[k - 1]) {
                return Err(format!("{name} decrease at index {k}"));
            }
            if !(knots[DEGREE] < knots[n]) {
                return Err(format!("{name} give an empty parameter domain"));
            }
            if let Some(k) =
                (0..knots.len() - DEGREE - 1).find(|&k| knots[k] == knots[k + DEGREE + 1])
            {
                return Err(format!(
                    "{name}: knot {} repeats more than {} times",
                    knots[k],
                    DEGREE + 1
                ));
            }
        }
        if self.control.len() != self.rows * self.cols {
            return Err(format!(
                "{} control points for a {} × {} net",
                self.control.len(),
                self.rows,
                self.cols
            ));
        }
        if let Some(k) = self
            .control
            .iter()
            .position(|p| !p.iter().all(|c| c.is_finite()))
        {
            return Err(format!("control point {k} is not finite"));
        }
        Ok(())
    }

    /// The surface moved rigidly by `placement` (a work offset: the part
    /// frame of a machine). A B-spline is affine invariant, so moving its
    /// control points moves every point of it (Piegl & Tiller, The NURBS
    /// Book, §3.4); the knots and the fit data's parameters stay, the data
    /// points move with the surface.
    pub fn transformed(&self, placement: &Isometry3<f64>) -> Surface {
        let moved = |p: &[f64; 3]| -> [f64; 3] { (placement * Point3::from(*p)).coords.into() };
        Surface {
            control: self.control.iter().map(moved).collect(),
            data: self.data.as_ref().map(|d| FitData {
                u: d.u.clone(),
                v: d.v.clone(),
                points: d.points.iter().map(moved).collect(),
            }),
            ..self.clone()
        }
    }

    /// Control net size (along u, along v).
    pub fn net_size(&self) -> (usize, usize) {
        (self.rows, self.cols)
    }

    /// Control points, row-major.
    pub fn control_points(&self) -> &[[f64; 3]] {
        &self.control
    }

    /// The knot vector along u.
    pub fn knots_u(&self) -> &[f64] {
        &self.knots_u
    }

    /// The knot vector along v.
    pub fn knots_v(&self) -> &[f64] {
        &self.knots_v
    }

    /// How the surface was fitted, if known.
    pub fn method(&self) -> Option<Method> {
        self.method
    }

    /// How the data points got their parameters, if known.
    pub fn parameterisation(&self) -> Option<Parameterisation> {
        self.parameterisation
    }

    /// The data it was fitted to, if kept.
    pub fn data(&self) -> Option<&FitData> {
        self.data.as_ref()
    }

    /// The parameter domain along u.
    pub fn u_range(&self) -> (f64, f64) {
        (self.knots_u[DEGREE], self.knots_u[self.rows])
    }

    /// The parameter domain along v.
    pub fn v_range(&self) -> (f64, f64) {
        (self.knots_v[DEGREE], self.knots_v[self.cols])
    }

    /// Point and derivatives up to second order at (u, v), clamped to the
    /// domain.
    pub fn derivatives(&self, u: f64, v: f64) -> Derivatives {
        let (u0, u1) = self.u_range();
        let (v0, v1) = self.v_range();
        let u = u.clamp(u0, u1);
        let v = v.clamp(v0, v1);
        let su = find_span(&self.knots_u, self.rows, u);
        let sv = find_span(&self.knots_v, self.cols, v);
        let bu = basis_ders::<3>(&self.knots_u, su, u);
        let bv = basis_ders::<3>(&self.knots_v, sv, v);
        // Contract along v first: for each of the 4 rows of the local net,
        // the value and two derivatives along v.
        let mut t = [[[0.0f64; 3]; 3]; 4];
        for (r, row) in t.iter_mut().enumerate() {
            let base = (su - DEGREE + r) * self.cols + (sv - DEGREE);
            for c in 0..4 {
                let p = &self.control[base + c];
                for (k, acc) in row.iter_mut().enumerate() {
                    let w = bv[k][c];
                    acc[0] += w * p[0];
                    acc[1] += w * p[1];
                    acc[2] += w * p[2];
                }
            }
        }
        let comb = |ku: usize, kv: usize| {
            let mut s = Vector3::zeros();
            for (r, row) in t.iter().enumerate() {
                let w = bu[ku][r];
                s += w * Vector3::from(row[kv]);
            }
            s
        };
        Derivatives {
            point: comb(0, 0),
            du: comb(1, 0),
            dv: comb(0, 1),
            duu: comb(2, 0),
            duv: comb(1, 1),
            dvv: comb(0, 2),
        }
    }

    /// The surface point at (u, v).
    pub fn point(&self, u: f64, v: f64) -> Vector3<f64> {
        self.derivatives(u, v).point
    }

    /// Normal, curvatures and principal directions at (u, v).
    pub fn geometry(&self, u: f64, v: f64) -> Result<LocalGeometry, Degenerate> {
        LocalGeometry::from_derivatives(&self.derivatives(u, v))
    }

    /// Distances between the surface and its data points, if it has them.
    pub fn residual(&self) -> Option<Residual> {
        let data = self.data.as_ref()?;
        let n = data.v.len();
        let mut r = Residual {
            max: 0.0,
            rms: 0.0,
            at: (0, 0),
        };
        let mut sum = 0.0;
        for (i, &u) in data.u.iter().enumerate() {
            for (j, &v) in data.v.iter().enumerate() {
                let d = (self.point(u, v) - Vector3::from(data.points[i * n + j])).norm();
                sum += d * d;
                if d > r.max {
                    r.max = d;
                    r.at = (i, j);
                }
            }
        }
        r.rms = (sum / data.points.len() as f64).sqrt();
        Some(r)
    }
}
