//! Fuzz target: any bytes fed to the STL loader must give a mesh or an
//! error, never a panic; what loads becomes a stock (a lattice of 16 rays
//! across its longest extent, at least 1 µm apart), is cut, compared with itself as the design,
//! meshed, and grown by an allowance. A few moves cut as one batch must
//! give the stock they give one by one. The same bytes, as text, go to the
//! process-file and trace-file readers, and the traces read to the
//! calibration (a fit or an error). Run with `cargo +nightly fuzz run stock_stl` from
//! the repository root.

#![no_main]

use std::io::Cursor;

use kinpost_stock::{
    Design, Mesh, Move, ProcessModel, Stock, Tool, ToolPose, TraceFile, calibrate, compare,
    contour,
};
use libfuzzer_sys::fuzz_target;
use nalgebra::Vector3;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    if let Err(d) = ProcessModel::from_toml(&text, "fuzz.toml") {
        assert!(d.line <= text.split('\n').count());
    }
    match TraceFile::from_toml(&text, "traces.toml") {
        Ok(t) => {
            if let Ok(fit) = calibrate(&t.trace) {
                assert!(fit.preston_mm2_per_n.is_finite());
            }
        }
        Err(d) => assert!(d.line <= text.split('\n').count()),
    }
    let Ok(mesh) = Mesh::read_stl(Cursor::new(data), "fuzz.stl") else {
        return;
    };
    let Some((lo, hi)) = mesh.bounds() else {
        return;
    };
    // 16 rays across the longest extent, and no finer than a micrometre.
    let extent = (hi - lo).amax();
    let h = if extent.is_finite() {
        (extent / 16.0).max(1e-3)
    } else {
        1.0
    };
    if let Ok(mut s) = Stock::from_mesh(&mesh, h) {
        let tool = Tool::BullNose {
            diameter: 4.0 * h,
            corner_radius: h,
            flute_length: 8.0 * h,
            shank: None,
        };
        let mid = lo + (hi - lo) / 2.0;
        let a = ToolPose::new(mid, Vector3::z());
        let b = ToolPose::new(mid + Vector3::new(h, h, -h), Vector3::new(0.1, 0.0, 1.0));
        let _ = s.cut_move(&tool, &a, &b, 1);
        // A ball: translations and a turn, back over its own path.
        let ball = Tool::BallEnd {
            diameter: 3.0 * h,
            flute_length: 8.0 * h,
            shank: None,
        };
        let c = ToolPose::new(mid + Vector3::new(2.0 * h, -h, 0.0), Vector3::z());
        let d = ToolPose::new(mid + Vector3::new(-h, 0.0, -2.0 * h), Vector3::new(0.0, 0.2, 1.0));
        let poses = [a, c, d, a, b];
        let moves: Vec<Move> = poses
            .windows(2)
            .enumerate()
            .map(|(i, w)| Move {
                from: w[0],
                to: w[1],
                id: 2 + (i as u32 % 2),
            })
            .collect();
        let mut one = s.clone();
        for m in &moves {
            if one.cut_move(&ball, &m.from, &m.to, m.id).is_err() {
                break;
            }
        }
        let _ = s.cut_moves(&ball, &moves);
        for k in 0..3 {
            assert!(one.family(k).rays == s.family(k).rays, "a batch differs");
        }
        let _ = contour(&s);
        if let Ok(d) = Design::from_mesh(mesh.clone()) {
            let _ = compare(&s, &d, 0.01);
        }
    }
    let _ = Stock::from_mesh_offset(&mesh, h, h);
});
