//! `kinpost calibrate` end to end: traces made from the closed forms of
//! the process model (a pass's depth K_p·v·F/(v_f·W), a dwell's peak depth
//! K_p·v·T·(3F/(4W√(2R)))^{2/3}·k^{1/3}; the module doc of
//! `kinpost_stock::process`) give back K_p and k; the calibrated process
//! file keeps the force table and is read by `sim --process`; bad trace
//! files are located errors.

use std::path::PathBuf;

use crate::common::{self, root, run_in};

fn temp_dir(name: &str) -> PathBuf {
    common::temp_dir(&format!("calibrate-{name}"))
}

/// The number after `label` in `text`.
fn number_after(text: &str, label: &str) -> f64 {
    let rest = &text[text
        .find(label)
        .unwrap_or_else(|| panic!("{label} in {text}"))
        + label.len()..];
    rest.split_whitespace().next().unwrap().parse().unwrap()
}

#[test]
fn traces_from_the_closed_forms_give_back_the_coefficients() {
    let dir = temp_dir("fit");
    let (kp, k) = (2.0e-6, 3.0);
    let (width, radius) = (25.0, 25.0);
    let mut traces = String::new();
    for (force, rpm, feed) in [
        (100.0, 3000.0, 8.0),
        (250.0, 2000.0, 5.0),
        (300.0, 3500.0, 12.0),
    ] {
        let belt = 2.0 * std::f64::consts::PI * rpm / 60.0 * radius;
        let depth = kp * belt * force / (feed * width);
        traces += &format!(
            "[[trace]]\nkind = \"pass\"\nforce_n = {force}\nbelt_mm_s = {belt}\nfeed_mm_s = {feed}\nwidth_mm = {width}\ndepth_mm = {depth}\n\n"
        );
    }
    for (force, dwell) in [(150.0, 2.0), (300.0, 1.0)] {
        let belt = 2.0 * std::f64::consts::PI * 3000.0 / 60.0 * radius;
        let c = (3.0 * force / (4.0 * width * (2.0f64 * radius).sqrt())).powf(2.0 / 3.0);
        let depth = kp * belt * dwell * c * f64::cbrt(k);
        traces += &format!(
            "[[trace]]\nkind = \"dwell\"\nforce_n = {force}\nbelt_mm_s = {belt}\ndwell_s = {dwell}\nwidth_mm = {width}\nradius_mm = {radius}\ndepth_mm = {depth}\n\n"
        );
    }
    std::fs::write(dir.join("traces.toml"), traces).unwrap();
    let process = root().join("crates/stock/process/mts1600.toml");
    let o = run_in(
        &dir,
        &[
            "calibrate",
            "traces.toml",
            "--process",
            process.to_str().unwrap(),
            "-o",
            "calibrated.toml",
        ],
    );
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let out = String::from_utf8(o.stdout).unwrap();
    let got_kp = number_after(&out, "K_p = ");
    let got_k = number_after(&out, "stiffness k = ");
    assert!((got_kp - kp).abs() < 1e-6 * kp, "{out}");
    assert!((got_k - k).abs() < 1e-5 * k, "{out}");
    // The written file: the force table kept, the fitted coefficients in.
    let written = std::fs::read_to_string(dir.join("calibrated.toml")).unwrap();
    let model = kinpost_stock::ProcessModel::from_toml(&written, "calibrated.toml").unwrap();
    assert!((model.wheel.preston_mm2_per_n - kp).abs() < 1e-9 * kp);
    assert!((model.wheel.stiffness_n_per_mm3 - k).abs() < 1e-6 * k);
    assert_eq!(model.force.newtons, vec![[3000.0, 300.0], [3600.0, 0.0]]);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_trace_files_are_located_errors() {
    let dir = temp_dir("errors");
    std::fs::write(
        dir.join("typo.toml"),
        "[[trace]]\nkind = \"pass\"\nforce_n = 100\nbelt_mm_s = 7000\nfeed_mms = 8\nwidth_mm = 25\ndepth_mm = 0.01\n",
    )
    .unwrap();
    let o = run_in(&dir, &["calibrate", "typo.toml"]);
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("typo.toml:"), "{err}");
    // Dwells alone cannot give K_p.
    std::fs::write(
        dir.join("dwells.toml"),
        "[[trace]]\nkind = \"dwell\"\nforce_n = 100\nbelt_mm_s = 7000\ndwell_s = 1\nwidth_mm = 25\nradius_mm = 25\ndepth_mm = 0.01\n",
    )
    .unwrap();
    let o = run_in(&dir, &["calibrate", "dwells.toml"]);
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("cannot calibrate from dwells.toml"), "{err}");
    // -o needs the process file whose force table it keeps.
    let o = run_in(&dir, &["calibrate", "dwells.toml", "-o", "x.toml"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(!dir.join("x.toml").exists());
    std::fs::remove_dir_all(&dir).ok();
}
