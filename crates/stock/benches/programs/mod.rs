//! The benchmark programs, shared by `benches/stock.rs` and
//! `examples/profile_stock.rs`.

#![allow(dead_code)]

use kinpost_stock::{Stock, Tool, ToolPose};
use nalgebra::{Point3, Vector3};

/// The 250 × 80 × 40 mm block at resolution `h`.
pub fn stock(h: f64) -> Stock {
    Stock::from_box(
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(250.0, 80.0, 40.0),
        h,
    )
    .unwrap()
}

/// 100,000 poses: 40 passes of 2,500 steps of 0.1 mm along X, 1.5 mm apart,
/// the tool point at height `z`; the tool axis leans about Y by
/// `lean_deg`·sin(2πx/50) and tilts about X by `tilt_deg`·cos(2πx/37).
pub fn program(z: f64, lean_deg: f64, tilt_deg: f64) -> Vec<ToolPose> {
    let mut poses = Vec::with_capacity(100_000);
    for pass in 0..40 {
        let y = 10.0 + 1.5 * pass as f64;
        let forward = pass % 2 == 0;
        for i in 0..2500 {
            let s = i as f64 * 0.1;
            let x = if forward { s } else { 250.0 - s };
            let lean = lean_deg.to_radians() * (2.0 * std::f64::consts::PI * x / 50.0).sin();
            let tilt = tilt_deg.to_radians() * (2.0 * std::f64::consts::PI * x / 37.0).cos();
            let axis = Vector3::new(
                lean.sin(),
                -tilt.sin() * lean.cos(),
                tilt.cos() * lean.cos(),
            );
            poses.push(ToolPose::new(Point3::new(x, y, z), axis).with_reference(Vector3::x()));
        }
    }
    poses
}

/// The contact wheel of the five-axis benchmark (R 50 mm, 25 mm wide,
/// Qiao et al. 2022 §4.1) and its program: 0.05 mm deep, tilting ±0.2°.
pub fn wheel_5axis() -> (Tool, Vec<ToolPose>) {
    (
        Tool::ContactWheel {
            radius: 50.0,
            width: 25.0,
            edge_radius: 0.0,
        },
        program(39.95, 0.0, 0.2),
    )
}

/// The 6 mm ball end mill of the three-axis benchmark, 0.5 mm deep.
pub fn ball_3axis() -> (Tool, Vec<ToolPose>) {
    (
        Tool::BallEnd {
            diameter: 6.0,
            flute_length: 20.0,
            shank: None,
        },
        program(39.5, 0.0, 0.0),
    )
}
