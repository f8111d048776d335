//! Test jobs shared by the golden and tool-centre-point tests.

use kinpost_post::machine::{Kinematics, Machine};

/// Joint values a fraction `t` of the way between two corners well inside
/// the travel (23 % and 64 % of each range, rotary ranges cut to ±150° so
/// that no axis needs to unwind; ±100 mm / ±60° where none).
pub fn joints(m: &Machine, t: f64) -> Vec<f64> {
    m.axes
        .iter()
        .map(|a| match (a.fixed, a.limits) {
            (Some(v), _) => v,
            (None, Some([lo, hi])) => {
                let (lo, hi) = if a.is_rotary() {
                    (lo.max(-150.0), hi.min(150.0))
                } else {
                    (lo.max(-400.0), hi.min(400.0))
                };
                lo + (hi - lo) * (0.23 + 0.41 * t)
            }
            (None, None) if a.is_rotary() => -60.0 + 120.0 * (0.23 + 0.41 * t),
            (None, None) => -100.0 + 200.0 * (0.23 + 0.41 * t),
        })
        .collect()
}

/// A small 5-axis job every machine can reach: ten points along a line in
/// joint space, through the machine's forward kinematics, as CL text.
pub fn job(m: &Machine) -> String {
    let kin = Kinematics::new(m);
    let mut cl = format!(
        "PARTNO/GOLDEN {}\nLOAD/TOOL,3\nSPINDL/3000,RPM,CLW\nCOOLNT/FLOOD\nRAPID\n",
        m.name
    );
    for k in 0..10 {
        let p = kin.fk(&joints(m, k as f64 / 9.0));
        if k == 1 {
            cl.push_str("FEDRAT/MMPM,400\n");
        }
        cl.push_str(&format!(
            "GOTO/{:.4},{:.4},{:.4},{:.7},{:.7},{:.7}\n",
            p.point.x, p.point.y, p.point.z, p.axis.x, p.axis.y, p.axis.z
        ));
    }
    cl.push_str("$$ end of the golden job\nCOOLNT/OFF\nSPINDL/OFF\nEND-OF-PATH\n");
    cl
}
