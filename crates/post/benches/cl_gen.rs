//! The generated CL path of the posting benchmark.

use std::fmt::Write as _;

/// A 5-axis zig-zag over a gently curved surface: every point moves X, Y, Z,
/// A and B.
pub fn generate_cl(points: usize) -> String {
    let mut cl = String::with_capacity(points * 64);
    cl.push_str("TOOL PATH/BENCH,TOOL,WHEEL\nLOAD/TOOL,1\nFEDRAT/MMPM,2000\n");
    for k in 0..points {
        let t = k as f64 / points as f64;
        let s = (k % 1000) as f64 / 1000.0;
        let b = (-20.0 + 40.0 * s).to_radians();
        let a = (10.0 * (std::f64::consts::TAU * t).sin()).to_radians();
        let n = [b.sin(), -a.sin() * b.cos(), a.cos() * b.cos()];
        writeln!(
            cl,
            "GOTO/{:.4},{:.4},{:.4},{:.7},{:.7},{:.7}",
            -400.0 + 50.0 * s,
            60.0 - 40.0 * t,
            5.0 + 3.0 * (7.0 * s).sin(),
            n[0],
            n[1],
            n[2]
        )
        .unwrap();
    }
    cl
}
