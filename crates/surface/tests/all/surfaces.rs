//! Surface fitting and geometry: Li (B-spline grinding)'s points, analytic cylinder and
//! sphere, exact reproduction of polynomials, least squares on noisy data,
//! and surface files that load back bit-identically.

use crate::common;

use std::f64::consts::PI;

use kinpost_surface::grid::Grid;
use kinpost_surface::json::{from_json, to_json};
use kinpost_surface::{Ends, FitOptions, Method, Parameterisation, Surface};
use nalgebra::Vector3;

fn grid(m: usize, n: usize, mut f: impl FnMut(f64, f64) -> [f64; 3]) -> Grid {
    let mut points = Vec::with_capacity(m * n);
    for i in 0..m {
        for j in 0..n {
            points.push(f(i as f64 / (m - 1) as f64, j as f64 / (n - 1) as f64));
        }
    }
    Grid {
        rows: m,
        cols: n,
        points,
    }
}

fn natural() -> FitOptions {
    FitOptions::default()
}

#[test]
fn li_surface_passes_through_all_35_points() {
    let g = common::li_points();
    assert_eq!((g.rows, g.cols), (5, 7));
    let s = Surface::fit(&g, &natural()).unwrap();
    // (m + 2) × (n + 2) control points (Li (B-spline grinding), §2).
    assert_eq!(s.net_size(), (7, 9));
    for i in 0..5 {
        for j in 0..7 {
            let p = s.point(i as f64 / 4.0, j as f64 / 6.0);
            let d = (p - Vector3::from(g.at(i, j))).norm();
            assert!(d < 1e-9, "point ({i}, {j}) off by {d:e} mm");
        }
    }
    assert!(s.residual().unwrap().max < 1e-9);
    // Natural ends: no second derivative across the boundary, all along it.
    for k in 0..=20 {
        let t = k as f64 / 20.0;
        for (u, v, along_u) in [
            (0.0, t, true),
            (1.0, t, true),
            (t, 0.0, false),
            (t, 1.0, false),
        ] {
            let d = s.derivatives(u, v);
            let second = if along_u { d.duu } else { d.dvv };
            assert!(
                second.norm() < 1e-8,
                "second derivative {second} at ({u}, {v})"
            );
        }
    }
    // The clamped knots of Li (B-spline grinding): open, uniform.
    assert_eq!(
        s.knots_u(),
        &[0.0, 0.0, 0.0, 0.0, 0.25, 0.5, 0.75, 1.0, 1.0, 1.0, 1.0]
    );
}

/// Cylinder of radius R about z: u the angle (30°), v the height; outward
/// normal, so k1 = 0 (along the axis), k2 = −1/R, K = 0, H = −1/(2R).
#[test]
fn cylinder_curvatures_match_the_analytic_ones() {
    let r = 50.0;
    let arc = PI / 6.0;
    let g = grid(301, 41, |u, v| {
        let t = arc * u;
        [r * t.cos(), r * t.sin(), 80.0 * v]
    });
    for ends in [Ends::Natural, Ends::NotAKnot, Ends::ClampedTangent] {
        let s = Surface::fit(
            &g,
            &FitOptions {
                method: Method::Interpolation(ends),
                parameterisation: Parameterisation::Uniform,
            },
        )
        .unwrap();
        for i in 0..=12 {
            for j in 0..=6 {
                let (u, v) = (0.2 + 0.6 * i as f64 / 12.0, 0.2 + 0.6 * j as f64 / 6.0);
                let geo = s.geometry(u, v).unwrap();
                let t = arc * u;
                let outward = Vector3::new(t.cos(), t.sin(), 0.0);
                assert!((geo.normal - outward).norm() < 1e-6);
                let rel = |got: f64, want: f64| (got - want).abs() / want.abs();
                assert!(rel(geo.mean, -0.5 / r) < 1e-6, "{ends:?} H {}", geo.mean);
                assert!(rel(geo.k2, -1.0 / r) < 1e-6, "{ends:?} k2 {}", geo.k2);
                assert!(geo.k1.abs() < 1e-6 / r, "k1 {}", geo.k1);
                assert!(geo.gaussian.abs() < 1e-6 / (r * r), "K {}", geo.gaussian);
                // Principal directions: the axis for k1, the circle for k2.
                assert!(geo.dir1.cross(&Vector3::z()).norm() < 1e-6, "{}", geo.dir1);
                let around = Vector3::new(-t.sin(), t.cos(), 0.0);
                assert!(geo.dir2.cross(&around).norm() < 1e-6, "{}", geo.dir2);
            }
        }
    }
}

/// Sphere of radius R, u the polar angle, v the azimuth: outward normal,
/// K = 1/R², H = k1 = k2 = −1/R.
#[test]
fn sphere_curvatures_match_the_analytic_ones() {
    let r = 30.0;
    let (t0, t1, p1) = (0.5, 1.0, 0.5);
    let g = grid(301, 301, |u, v| {
        let (t, p) = (t0 + (t1 - t0) * u, p1 * v);
        [r * t.sin() * p.cos(), r * t.sin() * p.sin(), r * t.cos()]
    });
    let s = Surface::fit(&g, &natural()).unwrap();
    let rel = |got: f64, want: f64| (got - want).abs() / want.abs();
    for i in 0..=10 {
        for j in 0..=10 {
            let (u, v) = (0.2 + 0.06 * i as f64, 0.2 + 0.06 * j as f64);
            let geo = s.geometry(u, v).unwrap();
            let outward = geo.point / geo.point.norm();
            assert!((geo.normal - outward).norm() < 1e-6);
            assert!((geo.point.norm() - r).abs() < 1e-6);
            assert!(
                rel(geo.gaussian, 1.0 / (r * r)) < 1e-6,
                "K {}",
                geo.gaussian
            );
            assert!(rel(geo.mean, -1.0 / r) < 1e-6, "H {}", geo.mean);
            assert!(rel(geo.k1, -1.0 / r) < 1e-6 && rel(geo.k2, -1.0 / r) < 1e-6);
        }
    }
}

/// A bicubic polynomial graph lies in the spline space: not-a-knot
/// interpolation and least squares both reproduce it exactly, at any
/// parameters (here chord length).
#[test]
fn bicubic_polynomials_are_reproduced() {
    let f = |u: f64, v: f64| {
        [
            10.0 * u,
            7.0 * v,
            u * u * u - 2.0 * u * v * v + 0.5 * v * v * v * u + v - 1.0,
        ]
    };
    let g = grid(9, 12, f);
    for method in [
        Method::Interpolation(Ends::NotAKnot),
        Method::Approximation { rows: 6, cols: 5 },
    ] {
        let s = Surface::fit(
            &g,
            &FitOptions {
                method,
                parameterisation: Parameterisation::Uniform,
            },
        )
        .unwrap();
        for k in 0..=30 {
            let (u, v) = (k as f64 / 30.0, (k * 7 % 31) as f64 / 30.0);
            let p = s.point(u, v);
            let want = Vector3::from(f(u, v));
            assert!((p - want).norm() < 1e-11, "{method:?} at ({u}, {v})");
        }
    }
}

/// Least squares on a noisy scan: the fitted net has the asked size, stays
/// near the true surface, and its residual is about the noise.
#[test]
fn least_squares_smooths_a_noisy_scan() {
    let r = 40.0;
    let mut seed = 12345u64;
    let mut noise = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 0.02 // ±0.01 mm
    };
    let g = grid(120, 90, |u, v| {
        let t = u * 0.8;
        [
            r * t.cos() + noise(),
            r * t.sin() + noise(),
            30.0 * v + noise(),
        ]
    });
    let s = Surface::fit(
        &g,
        &FitOptions {
            method: Method::Approximation { rows: 12, cols: 8 },
            parameterisation: Parameterisation::Uniform,
        },
    )
    .unwrap();
    assert_eq!(s.net_size(), (12, 8));
    let res = s.residual().unwrap();
    assert!(res.rms < 0.012 && res.rms > 0.004, "rms {}", res.rms);
    for k in 0..=20 {
        let (u, v) = (0.1 + 0.04 * k as f64, 0.5);
        let p = s.point(u, v);
        let radial = (p.x * p.x + p.y * p.y).sqrt();
        assert!((radial - r).abs() < 0.01, "radius {radial} at u {u}");
    }
}

#[test]
fn surface_files_load_back_bit_identically() {
    let g = common::li_points();
    for options in [
        natural(),
        FitOptions {
            method: Method::Interpolation(Ends::NotAKnot),
            parameterisation: Parameterisation::ChordLength,
        },
        FitOptions {
            method: Method::Approximation { rows: 4, cols: 5 },
            parameterisation: Parameterisation::Centripetal,
        },
    ] {
        let s = Surface::fit(&g, &options).unwrap();
        let text = to_json(&s);
        let back = from_json(&text, "s.json").unwrap();
        // Every f64 (knots, control points, data) identical, and the file.
        assert_eq!(back, s);
        let bits = |s: &Surface| -> Vec<u64> {
            s.control_points()
                .iter()
                .flatten()
                .chain(s.knots_u())
                .chain(s.knots_v())
                .map(|v| v.to_bits())
                .collect()
        };
        assert_eq!(bits(&back), bits(&s));
        assert_eq!(to_json(&back), text);
        assert_eq!(back.method(), Some(options.method));
        assert_eq!(back.parameterisation(), Some(options.parameterisation));
    }
}

#[test]
fn bad_surface_files_are_located() {
    let s = Surface::fit(&common::li_points(), &natural()).unwrap();
    let text = to_json(&s);
    // A syntax error: the missing comma's line.
    let broken = text.replacen("\"version\": 1,", "\"version\": 1", 1);
    let d = from_json(&broken, "s.json").unwrap_err();
    assert_eq!(d.line, 4, "{d}");
    assert!(d.message.contains("expected `,`"), "{d}");
    // A semantic error: one knot too many, at the `knots_u` key.
    let broken = text.replacen("\"knots_u\": [0.0,", "\"knots_u\": [0.0, 0.0,", 1);
    let d = from_json(&broken, "s.json").unwrap_err();
    assert!(d.message.contains("knots_u has 12 knots"), "{d}");
    assert_eq!(
        d.source_line.trim_start().split(':').next(),
        Some("\"knots_u\"")
    );
    assert_eq!((d.line, d.column), (8, 3));
    let d = from_json(&text.replacen("\"format\"", "\"fromat\"", 1), "s.json").unwrap_err();
    assert!(d.message.contains("unknown field `fromat`"), "{d}");
    assert_eq!(d.line, 2);
    let d = from_json("", "s.json").unwrap_err();
    assert!(d.message.contains("EOF"), "{d}");
}

#[test]
fn a_placed_surface_is_the_surface_moved() {
    // Li's surface turned 180° about z and moved, as `kinpost surface place`
    // and `kinpost path --rotate z:180 --translate …` place a part: every
    // point moves with the placement, the normal turns with it, and the fit
    // data move too (the residual stays).
    let s = Surface::fit(&common::li_points(), &natural()).unwrap();
    let placement = nalgebra::Isometry3::new(
        Vector3::new(-400.0, -10.0, 20.0),
        Vector3::new(0.3, -0.2, PI),
    );
    let moved = s.transformed(&placement);
    let (u0, u1) = s.u_range();
    let (v0, v1) = s.v_range();
    for i in 0..=6 {
        for j in 0..=6 {
            let (u, v) = (
                u0 + (u1 - u0) * i as f64 / 6.0,
                v0 + (v1 - v0) * j as f64 / 6.0,
            );
            let expected = placement * nalgebra::Point3::from(s.point(u, v));
            assert!((moved.point(u, v) - expected.coords).norm() < 1e-9);
            let n = s.geometry(u, v).unwrap().normal;
            let m = moved.geometry(u, v).unwrap().normal;
            assert!((m - placement.rotation * n).norm() < 1e-9);
        }
    }
    let (r0, r1) = (s.residual().unwrap(), moved.residual().unwrap());
    assert!((r0.max - r1.max).abs() < 1e-9);
    let back = from_json(&to_json(&moved), "moved.json").unwrap();
    assert_eq!(back, moved);
}
