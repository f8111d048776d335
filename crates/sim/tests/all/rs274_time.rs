//! The run time of LinuxCNC's own 5-axis sample programs (kept in
//! `data/linuxcnc/`), from the replay, against the same rules applied to the
//! canonical machining calls LinuxCNC's interpreter prints for them (`rs274
//! -g`: STRAIGHT_TRAVERSE, STRAIGHT_FEED, ARC_FEED, SET_FEED_RATE, DWELL),
//! an independent reading of the program: feeds apply to the X Y Z path (or
//! to the rotary degrees where X Y Z stand still), rapids move each axis at
//! its own rate. rs274 turns the impeller's inverse-time feeds (G93) into
//! mm/min per block. The remapped `M428`/`M429` (the sample configuration's
//! TCP switch, which rs274 cannot read) are stripped first.

use std::f64::consts::TAU;
use std::path::Path;
use std::process::Command;

use kinpost_machine::builtin;
use kinpost_nc::interp::Family;
use kinpost_sim::tolerance::{ASSUMED_RAPID_DEG_PER_MIN, ASSUMED_RAPID_MM_PER_MIN};
use kinpost_sim::{SimOptions, simulate};

fn args(line: &str, call: &str) -> Option<Vec<f64>> {
    let rest = &line[line.find(call)? + call.len()..];
    let inner = rest.strip_prefix('(')?.split(')').next()?;
    inner.split(',').map(|v| v.trim().parse().ok()).collect()
}

/// Seconds, from rs274's canonical calls (X Y Z A B C).
fn rs274_seconds(text: &str) -> f64 {
    let (mut pos, mut feed, mut minutes, mut seconds) = ([0.0f64; 6], 0.0, 0.0, 0.0);
    let xyz_len = |a: &[f64; 6], b: &[f64]| {
        ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2) + (b[2] - a[2]).powi(2)).sqrt()
    };
    for line in text.lines() {
        if let Some(v) = args(line, "STRAIGHT_TRAVERSE") {
            let mut t: f64 = 0.0;
            for i in 0..6 {
                let rate = if i < 3 {
                    ASSUMED_RAPID_MM_PER_MIN
                } else {
                    ASSUMED_RAPID_DEG_PER_MIN
                };
                t = t.max((v[i] - pos[i]).abs() / rate);
            }
            minutes += t;
            pos.copy_from_slice(&v[..6]);
        } else if let Some(v) = args(line, "SET_FEED_RATE") {
            feed = v[0];
        } else if let Some(v) = args(line, "STRAIGHT_FEED") {
            let mut len = xyz_len(&pos, &v);
            if len <= 1e-9 {
                len = (3..6).map(|i| (v[i] - pos[i]).powi(2)).sum::<f64>().sqrt();
            }
            minutes += len / feed;
            pos.copy_from_slice(&v[..6]);
        } else if let Some(v) = args(line, "ARC_FEED") {
            // (first_end, second_end, first_centre, second_centre, rotation,
            // end along the normal, a, b, c), plane XY in these programs.
            let (c0, c1) = (v[2], v[3]);
            let th0 = (pos[1] - c1).atan2(pos[0] - c0);
            let th1 = (v[1] - c1).atan2(v[0] - c0);
            let r = 0.5 * ((pos[0] - c0).hypot(pos[1] - c1) + (v[0] - c0).hypot(v[1] - c1));
            let turn = |d: f64| {
                let d = d.rem_euclid(TAU);
                if d <= 1e-12 { TAU } else { d }
            };
            let rot = v[4];
            let sweep = if rot > 0.0 {
                turn(th1 - th0)
            } else {
                turn(th0 - th1)
            } + (rot.abs() - 1.0) * TAU;
            minutes += (r * sweep).hypot(v[5] - pos[2]) / feed;
            pos = [v[0], v[1], v[5], v[6], v[7], v[8]];
        } else if let Some(v) = args(line, "DWELL") {
            seconds += v[0];
        }
    }
    minutes * 60.0 + seconds
}

#[test]
fn run_time_agrees_with_rs274() {
    let m = builtin::load("trunnion-ac").unwrap().unwrap();
    for name in ["boat-xyzac.ngc", "impeller-7bl-xyzac.ngc"] {
        let p = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../data/linuxcnc")
            .join(name);
        let text = std::fs::read_to_string(p)
            .unwrap()
            .replace("M428", "")
            .replace("M429", "");
        let dir = std::env::temp_dir().join(format!("kinpost-sim-time-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join(name);
        std::fs::write(&file, &text).unwrap();
        let Ok(out) = Command::new("rs274").arg("-g").arg(&file).output() else {
            eprintln!("rs274 is not installed: skipped");
            return;
        };
        let want = rs274_seconds(&String::from_utf8_lossy(&out.stdout));
        let options = SimOptions {
            collisions: false,
            ..SimOptions::default()
        };
        let r = simulate(
            &text,
            Family::LinuxCnc,
            name,
            &m,
            &options,
            None,
            &mut |_| {},
        )
        .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(want > 60.0, "{name}: {want}");
        assert!(
            (r.duration_s - want).abs() <= 1e-6 * want,
            "{name}: replay {} s, rs274 {want} s",
            r.duration_s
        );
        std::fs::remove_dir_all(&dir).ok();
    }
}
