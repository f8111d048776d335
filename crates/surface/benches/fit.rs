//! Fitting speed: interpolation of a 200 × 200 grid (the aim: "well under a
//! second") and a least-squares fit of the same grid, and evaluating the
//! local geometry.

use criterion::{Criterion, criterion_group, criterion_main};
use kinpost_surface::grid::Grid;
use kinpost_surface::{FitOptions, Method, Parameterisation, Surface};

fn wavy(m: usize, n: usize) -> Grid {
    let mut points = Vec::with_capacity(m * n);
    for i in 0..m {
        for j in 0..n {
            let (u, v) = (i as f64 / (m - 1) as f64, j as f64 / (n - 1) as f64);
            points.push([
                100.0 * u,
                80.0 * v,
                5.0 * (3.0 * u).sin() * (2.0 * v).cos() + 0.3 * (17.0 * u * v).sin(),
            ]);
        }
    }
    Grid {
        rows: m,
        cols: n,
        points,
    }
}

fn bench(c: &mut Criterion) {
    let g = wavy(200, 200);
    c.bench_function("interpolate 200x200 natural uniform", |b| {
        b.iter(|| Surface::fit(&g, &FitOptions::default()).unwrap())
    });
    c.bench_function("interpolate 200x200 natural chord-length", |b| {
        let o = FitOptions {
            parameterisation: Parameterisation::ChordLength,
            ..FitOptions::default()
        };
        b.iter(|| Surface::fit(&g, &o).unwrap())
    });
    c.bench_function("approximate 200x200 by 40x40", |b| {
        let o = FitOptions {
            method: Method::Approximation { rows: 40, cols: 40 },
            parameterisation: Parameterisation::Uniform,
        };
        b.iter(|| Surface::fit(&g, &o).unwrap())
    });
    let s = Surface::fit(&g, &FitOptions::default()).unwrap();
    c.bench_function("geometry at one (u, v)", |b| {
        let mut k = 0u32;
        b.iter(|| {
            k = k.wrapping_add(1);
            let t = f64::from(k % 1000) / 1000.0;
            s.geometry(t, 1.0 - t).unwrap()
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
