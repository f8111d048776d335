//! Fuzz target: any bytes (as lossy UTF-8) fed to the machine-file loader
//! must give a machine or located diagnostics, never a panic; a machine that
//! loads must survive forward kinematics at home and inverse kinematics of
//! that pose, the check of its `[post]` templates, and the collision world
//! of its solids (built, checked at home and along a move). The bytes after
//! the first NUL, if any, are the embedded mesh file `part.stl` a `[[solid]]`
//! may name (`mesh = "part.stl"`). Run with `cargo +nightly fuzz run
//! machine_file` from the repository root (seed the corpus with
//! `crates/machine/machines/*.toml` and `crates/machine/tests/malformed/*.toml`).

#![no_main]

use kinpost_collide::{Motion, World};
use kinpost_machine::{Kinematics, MeshFiles, machine_from_toml_with};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let (toml, stl) = match data.iter().position(|&b| b == 0) {
        Some(i) => (&data[..i], &data[i + 1..]),
        None => (data, &[][..]),
    };
    let text = String::from_utf8_lossy(toml);
    let files = [("part.stl", stl)];
    match machine_from_toml_with(&text, "fuzz.toml", MeshFiles::Embedded(&files)) {
        Err(diags) => {
            assert!(!diags.0.is_empty());
            let lines = text.split('\n').count();
            for d in &diags.0 {
                assert!(d.line >= 1 && d.line <= lines && d.column >= 1 && d.width >= 1);
                let _ = d.to_string();
            }
        }
        Ok(machine) => {
            if let Err(diags) = kinpost_post::check_machine_templates(&text, "fuzz.toml") {
                let lines = text.split('\n').count();
                for d in &diags.0 {
                    assert!(d.line >= 1 && d.line <= lines && d.column >= 1);
                    let _ = d.to_string();
                }
            }
            let kin = Kinematics::new(&machine);
            let home = machine.home_joints();
            let pose = kin.fk(&home);
            let mut solutions = Vec::new();
            let _ = kin.ik(&pose, None, &mut solutions);
            let _ = kin.ik(&pose, Some(&home), &mut solutions);
            let _ = kin.ik_all_branches(&pose, None, &mut solutions);
            if let Ok(world) = World::new(&machine) {
                let _ = world.check_pose(&home, Motion::Rapid);
                let moved: Vec<f64> = home.iter().map(|v| v + 7.5).collect();
                let _ = world.check_move(&home, &moved, Motion::Rapid);
            }
        }
    }
});
