//! Fuzz target: any bytes (as lossy UTF-8) fed to the machine-file loader
//! must give a machine or located diagnostics, never a panic; a machine that
//! loads must survive forward kinematics at home and inverse kinematics of
//! that pose, and the check of its `[post]` templates. Run with `cargo +nightly fuzz run machine_file` from the
//! repository root (seed the corpus with `crates/machine/machines/*.toml` and
//! `crates/machine/tests/malformed/*.toml`).

#![no_main]

use kinpost_machine::{Kinematics, machine_from_toml};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    match machine_from_toml(&text, "fuzz.toml") {
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
        }
    }
});
