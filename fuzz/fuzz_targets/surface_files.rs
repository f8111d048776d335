//! Fuzz target: any bytes (as lossy UTF-8) fed to the grid readers (CSV,
//! whitespace tables, NASA blade tables) and the surface-file loader must
//! give a grid / surface or located diagnostics, never a panic; what loads
//! is fitted or evaluated, and a surface file is placed, tessellated and
//! grown into a stock's shell as `kinpost sim --design` does. Run with `cargo +nightly fuzz run surface_files`
//! from the repository root (seed the corpus with
//! `data/li-bspline/points.csv` and a `kinpost surface fit` output).

#![no_main]

use kinpost_stock::Design;
use kinpost_surface::grid::{BladeSide, read_blade_table, read_grid};
use kinpost_surface::json::{from_json, to_json};
use kinpost_surface::{FitOptions, Surface};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let lines = text.split('\n').count();
    let located = |d: &kinpost_surface::grid::Diagnostic| {
        assert!(d.line <= lines);
        let _ = d.to_string();
    };
    match read_grid(&text, "fuzz.csv") {
        Ok(g) => {
            if let Ok(s) = Surface::fit(&g, &FitOptions::default()) {
                let _ = s.geometry(0.5, 0.5);
            }
        }
        Err(d) => d.0.iter().for_each(located),
    }
    if let Err(d) = read_blade_table(&text, "fuzz.dat", BladeSide::Theta2) {
        d.0.iter().for_each(located);
    }
    match from_json(&text, "fuzz.json") {
        Ok(s) => {
            let _ = s.geometry(0.25, 0.75);
            assert_eq!(from_json(&to_json(&s), "again.json").unwrap(), s);
            // As a design of `kinpost sim`: placed, tessellated, and grown
            // into the shell of a stock `design+0.1,1`.
            let placed = s.transformed(&nalgebra::Isometry3::new(
                nalgebra::Vector3::new(-100.0, -10.0, 20.0),
                nalgebra::Vector3::new(0.0, 0.0, std::f64::consts::PI),
            ));
            let (u0, u1) = placed.u_range();
            let (v0, v1) = placed.v_range();
            let region = [u0, 0.5 * (u0 + u1), v0, v1];
            let _ = Design::from_surface_region(&placed, region, 1.0, true);
            let _ = Design::shell_of_surface(&placed, region, 1.0, false, 0.1, 1.0);
        }
        Err(d) => located(&d),
    }
});
