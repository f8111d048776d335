//! Differential geometry of a parametric surface at one point: the unit
//! normal, the first and second fundamental forms, Gaussian and mean
//! curvature, principal curvatures and directions (Li (B-spline grinding) eq. 16;
//! do Carmo, *Differential Geometry of Curves and Surfaces*, §3-3).
//!
//! Sign convention: the normal is `r_u × r_v / |r_u × r_v|`, and a normal
//! curvature is positive where the surface bends towards the normal (a
//! sphere with outward normal has principal curvatures −1/R).

use nalgebra::Vector3;

/// Point and partial derivatives of a surface at (u, v).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Derivatives {
    /// r(u, v).
    pub point: Vector3<f64>,
    /// r_u.
    pub du: Vector3<f64>,
    /// r_v.
    pub dv: Vector3<f64>,
    /// r_uu.
    pub duu: Vector3<f64>,
    /// r_uv.
    pub duv: Vector3<f64>,
    /// r_vv.
    pub dvv: Vector3<f64>,
}

/// Everything about the surface at one point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LocalGeometry {
    /// r(u, v).
    pub point: Vector3<f64>,
    /// Unit normal r_u × r_v / |r_u × r_v|.
    pub normal: Vector3<f64>,
    /// First fundamental form E, F, G.
    pub e: f64,
    /// F.
    pub f: f64,
    /// G.
    pub g: f64,
    /// Second fundamental form L, M, N (with the unit normal).
    pub l: f64,
    /// M.
    pub m: f64,
    /// N.
    pub n: f64,
    /// Gaussian curvature K = (LN − M²) / (EG − F²) (Li, eq. 16).
    pub gaussian: f64,
    /// Mean curvature H = (EN − 2FM + GL) / (2(EG − F²)).
    pub mean: f64,
    /// Principal curvatures, k1 ≥ k2.
    pub k1: f64,
    /// See `k1`.
    pub k2: f64,
    /// Unit principal directions in space (tangent to the surface), for k1
    /// and k2; at an umbilic any orthonormal tangent pair.
    pub dir1: Vector3<f64>,
    /// See `dir1`.
    pub dir2: Vector3<f64>,
}

/// The parametrisation is singular here (r_u × r_v = 0).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Degenerate;

impl LocalGeometry {
    /// The local geometry from the derivatives.
    pub fn from_derivatives(d: &Derivatives) -> Result<LocalGeometry, Degenerate> {
        let cross = d.du.cross(&d.dv);
        let len = cross.norm();
        let scale = d.du.norm() * d.dv.norm();
        if !(len > 1e-12 * scale) || !len.is_finite() {
            return Err(Degenerate);
        }
        let normal = cross / len;
        let (e, f, g) = (d.du.dot(&d.du), d.du.dot(&d.dv), d.dv.dot(&d.dv));
        let (l, m, n) = (d.duu.dot(&normal), d.duv.dot(&normal), d.dvv.dot(&normal));
        let det1 = e * g - f * f;
        let gaussian = (l * n - m * m) / det1;
        let mean = (e * n - 2.0 * f * m + g * l) / (2.0 * det1);
        let disc = (mean * mean - gaussian).max(0.0).sqrt();
        let (k1, k2) = (mean + disc, mean - disc);
        let (dir1, dir2) = principal_directions(d, e, f, g, l, m, n, k1, k2, &normal);
        Ok(LocalGeometry {
            point: d.point,
            normal,
            e,
            f,
            g,
            l,
            m,
            n,
            gaussian,
            mean,
            k1,
            k2,
            dir1,
            dir2,
        })
    }

    /// Normal curvature in the tangent direction `t` (any length, tangent):
    /// II(t) / I(t) in terms of the space vector, with this point's normal.
    pub fn normal_curvature(&self, d: &Derivatives, t: &Vector3<f64>) -> f64 {
        // Components of t in the (r_u, r_v) basis: solve the 2×2 Gram system.
        let (a, b) = (t.dot(&d.du), t.dot(&d.dv));
        let det = self.e * self.g - self.f * self.f;
        let du = (self.g * a - self.f * b) / det;
        let dv = (self.e * b - self.f * a) / det;
        let two = self.l * du * du + 2.0 * self.m * du * dv + self.n * dv * dv;
        let one = self.e * du * du + 2.0 * self.f * du * dv + self.g * dv * dv;
        two / one
    }
}

/// Eigenvectors of the shape operator I⁻¹·II in the (r_u, r_v) basis,
/// mapped to space and normalised.
#[allow(clippy::too_many_arguments)]
fn principal_directions(
    d: &Derivatives,
    e: f64,
    f: f64,
    g: f64,
    l: f64,
    m: f64,
    n: f64,
    k1: f64,
    k2: f64,
    normal: &Vector3<f64>,
) -> (Vector3<f64>, Vector3<f64>) {
    let scale = k1.abs().max(k2.abs());
    let t1 = d.du.normalize();
    if !(k1 - k2 > 1e-9 * scale) {
        // Umbilic (or flat): every direction is principal.
        return (t1, normal.cross(&t1));
    }
    // (II − k I) (du, dv)ᵀ = 0: take the row with the larger entries.
    let dir = |k: f64| {
        let (a, b) = (l - k * e, m - k * f);
        let (c, dd) = (m - k * f, n - k * g);
        let (du, dv) = if a.abs() + b.abs() >= c.abs() + dd.abs() {
            (-b, a)
        } else {
            (-dd, c)
        };
        (d.du * du + d.dv * dv).normalize()
    };
    let v1 = dir(k1);
    // The second is orthogonal to the first in the tangent plane.
    let v2 = normal.cross(&v1);
    (v1, v2)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The graph z = (a x² + b y²) / 2 at the origin: K = ab, H = (a+b)/2,
    /// principal directions x (a) and y (b); normal +z.
    #[test]
    fn paraboloid_at_its_vertex() {
        let (a, b) = (0.3, -0.1);
        let d = Derivatives {
            point: Vector3::zeros(),
            du: Vector3::x(),
            dv: Vector3::y(),
            duu: Vector3::new(0.0, 0.0, a),
            duv: Vector3::zeros(),
            dvv: Vector3::new(0.0, 0.0, b),
        };
        let g = LocalGeometry::from_derivatives(&d).unwrap();
        assert!((g.gaussian - a * b).abs() < 1e-15);
        assert!((g.mean - (a + b) / 2.0).abs() < 1e-15);
        assert!((g.k1 - a).abs() < 1e-15 && (g.k2 - b).abs() < 1e-15);
        assert!(g.dir1.cross(&Vector3::x()).norm() < 1e-12);
        assert!(g.dir2.cross(&Vector3::y()).norm() < 1e-12);
        assert!(
            (g.normal_curvature(&d, &Vector3::new(1.0, 1.0, 0.0)) - (a + b) / 2.0).abs() < 1e-15
        );
    }

    #[test]
    fn degenerate_parametrisation_is_an_error() {
        let d = Derivatives {
            point: Vector3::zeros(),
            du: Vector3::x(),
            dv: Vector3::x() * 2.0,
            duu: Vector3::zeros(),
            duv: Vector3::zeros(),
            dvv: Vector3::zeros(),
        };
        assert_eq!(LocalGeometry::from_derivatives(&d), Err(Degenerate));
    }
}
