//! The grinding pressure in the post (DESIGN.md §2.2, seed 001 ch. 3): every
//! block carries the pressure in force, and its axis values are solved, and
//! checked, through the machine with the wheel at that pressure.
//!
//! The wheel offset Δ(p) is constant after the last tool-side axis, so the
//! machine at pressure p is the same machine with its home tool point moved
//! by Δ(p) ([`Machine::at_pressure`]; seed 001 eq. 3.4–3.7 insert the
//! translation T_ws'^ws into the tool chain). Pressures change rarely: one
//! [`Kinematics`] is compiled per wheel offset and kept in a small cache.

use kinpost_machine::{Clamp, Kinematics, Machine, OutputMode, PressureAxis};
use kinpost_nc::{AxisSpec, Dialect};
use nalgebra::Vector3;

/// Kinematics compiled for this many wheel offsets at most (the oldest is
/// dropped beyond), so that a CL changing the pressure at every point keeps
/// its memory bounded.
const CACHE: usize = 16;

/// The wheel of a program: which kinematics is in force for a pressure.
pub(crate) struct Wheel {
    /// The program's machine, wheel at the reference pressure.
    machine: Machine,
    axis: PressureAxis,
    /// `--no-pressure-compensation`: the kinematics stays at the reference.
    compensate: bool,
    /// The written pressure whose kinematics is in force (NaN: none).
    current: f64,
    /// The wheel offset of the kinematics in force.
    offset: Vector3<f64>,
    /// Kinematics of other offsets, by the bits of the offset.
    cache: Vec<([u64; 3], Kinematics)>,
}

fn key(v: &Vector3<f64>) -> [u64; 3] {
    [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()]
}

impl Wheel {
    /// The wheel of `machine` (the machine of the program, at the reference
    /// pressure), if it has a pressure axis.
    pub(crate) fn new(machine: &Machine, compensate: bool) -> Option<Wheel> {
        Some(Wheel {
            axis: machine.pressure.clone()?,
            machine: machine.clone(),
            compensate,
            current: f64::NAN,
            offset: Vector3::zeros(),
            cache: Vec::new(),
        })
    }

    /// Puts the kinematics of the pressure `written` (as the program writes
    /// it; NaN: none programmed, the reference applies) in `kin`, which
    /// holds that of the previous pressure. Returns the wheel offset the
    /// post compensates.
    #[inline]
    pub(crate) fn select(&mut self, kin: &mut Kinematics, written: f64) -> Vector3<f64> {
        // The hot path: the pressure of the previous block.
        if written.to_bits() == self.current.to_bits() {
            return self.offset;
        }
        self.change(kin, written)
    }

    #[cold]
    fn change(&mut self, kin: &mut Kinematics, written: f64) -> Vector3<f64> {
        self.current = written;
        let offset = if self.compensate && !written.is_nan() {
            self.axis.offset(written)
        } else {
            Vector3::zeros()
        };
        if key(&offset) == key(&self.offset) {
            return offset;
        }
        let new = match self.cache.iter().position(|(k, _)| *k == key(&offset)) {
            Some(i) => self.cache.remove(i).1,
            None => {
                let mut new = Kinematics::new(&self.machine.at_pressure(written));
                new.set_axis_rounding(kin.axis_rounding());
                new
            }
        };
        let old = std::mem::replace(kin, new);
        self.cache.push((key(&self.offset), old));
        if self.cache.len() > CACHE {
            self.cache.remove(0);
        }
        self.offset = offset;
        offset
    }
}

/// The pressure column of a machine's blocks, after its axes.
pub(crate) fn pressure_spec(machine: &Machine) -> Option<AxisSpec> {
    machine
        .pressure
        .as_ref()
        .map(|p| AxisSpec::pressure_word(&p.name))
}

/// What programming `value` means for this machine, dialect and run: the
/// warnings to give, or why it cannot be written. `quantize` gives the
/// value as the program writes it.
pub(crate) struct PressureCheck {
    pub warnings: Vec<String>,
    /// The offset the post does not compensate (`--no-pressure-compensation`).
    pub uncompensated: Option<Vector3<f64>>,
}

/// Checks a pressure the CL or the command line programs.
pub(crate) fn check_pressure(
    machine: &Machine,
    dialect: &Dialect,
    output: OutputMode,
    compensate: bool,
    value: f64,
) -> Result<PressureCheck, String> {
    let Some(p) = &machine.pressure else {
        return Err(format!(
            "machine `{}` has no pressure axis (no [pressure] section)",
            machine.name
        ));
    };
    if !dialect.writes_pressure() {
        return Err(format!(
            "dialect `{}` cannot write the pressure word `{}`: it has no [pressure] table \
             (copy it and add one, see DIALECTS.md)",
            dialect.name(),
            p.name
        ));
    }
    let written = dialect.quantize(&AxisSpec::pressure_word(&p.name), value);
    let mut warnings = Vec::new();
    let [lo, hi] = p.range();
    let stop = match p.clamp(written) {
        Clamp::Inside => None,
        Clamp::Below => Some(("below", lo)),
        Clamp::Above => Some(("above", hi)),
    };
    if let Some((side, end)) = stop {
        warnings.push(format!(
            "{} = {} is {side} the machine's calibration ({} .. {}): the wheel sits on its stop, \
             where it is at {} = {}",
            p.name,
            number(written),
            number(lo),
            number(hi),
            p.name,
            number(end)
        ));
    }
    let offset = p.offset(written);
    let moved = offset.norm() > 0.0;
    if moved && compensate && output == OutputMode::Tcp {
        return Err(format!(
            "tool-centre-point output cannot compensate the wheel offset at {} = {} ({:.3} mm): \
             the controller puts the tool point where its own tool data says; use joint output \
             (--output joint), or --no-pressure-compensation",
            p.name,
            number(written),
            offset.norm()
        ));
    }
    let uncompensated = (moved && !compensate).then(|| {
        let [d1, d2] = p.plane_offset(written);
        warnings.push(format!(
            "not compensated (--no-pressure-compensation): at {} = {} the wheel is {:.3} mm from \
             where it is at the reference {} = {} ({:.3} mm along {}, {:.3} mm along {}), and so \
             is every contact point",
            p.name,
            number(written),
            offset.norm(),
            p.name,
            number(p.reference),
            d1,
            machine.axes[p.plane[0]].name,
            d2,
            machine.axes[p.plane[1]].name,
        ));
        offset
    });
    Ok(PressureCheck {
        warnings,
        uncompensated,
    })
}

/// A pressure as a user writes it: no trailing zeros.
fn number(v: f64) -> String {
    let s = format!("{v:.6}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.into() }
}

#[cfg(test)]
mod tests {
    use super::*;
    use kinpost_machine::builtin;

    #[test]
    fn cache_swaps_kinematics_per_offset() {
        let m = builtin::load("mts1600").unwrap().unwrap();
        let mut kin = Kinematics::new(&m);
        let mut wheel = Wheel::new(&m, true).unwrap();
        let q = m.home_joints();
        let at_ref = kin.fk(&q).point;
        // No pressure and the reference: the reference kinematics, untouched.
        assert_eq!(wheel.select(&mut kin, f64::NAN), Vector3::zeros());
        assert_eq!(wheel.select(&mut kin, 3475.0), Vector3::zeros());
        assert_eq!(kin.fk(&q).point, at_ref);
        let d = wheel.select(&mut kin, 3000.0);
        assert!((kin.fk(&q).point - (at_ref + d)).norm() < 1e-12);
        // Clamped pressures share the offset of the stop.
        assert_eq!(wheel.select(&mut kin, 2000.0), d);
        assert_eq!(wheel.select(&mut kin, 3475.0), Vector3::zeros());
        assert_eq!(kin.fk(&q).point, at_ref);
        // Without compensation the kinematics never changes.
        let mut off = Wheel::new(&m, false).unwrap();
        assert_eq!(off.select(&mut kin, 3000.0), Vector3::zeros());
        assert_eq!(kin.fk(&q).point, at_ref);
        // The cache stays bounded.
        for k in 0..100 {
            wheel.select(&mut kin, 3000.0 + f64::from(k));
        }
        assert!(wheel.cache.len() <= CACHE);
    }

    #[test]
    fn checks_name_the_problem() {
        let m = builtin::load("mts1600").unwrap().unwrap();
        let sinumerik = Dialect::builtin("sinumerik").unwrap();
        let fanuc = Dialect::builtin("fanuc").unwrap();
        let joint = OutputMode::Joint;
        let ok = check_pressure(&m, &sinumerik, joint, true, 3300.0).unwrap();
        assert!(ok.warnings.is_empty() && ok.uncompensated.is_none());
        let low = check_pressure(&m, &sinumerik, joint, true, 2500.0).unwrap();
        assert!(
            low.warnings[0].contains("H1 = 2500 is below the machine's calibration (3000 .. 3600)")
        );
        let off = check_pressure(&m, &sinumerik, joint, false, 3000.0).unwrap();
        assert!(off.uncompensated.is_some());
        assert!(
            off.warnings[0].contains("not compensated"),
            "{:?}",
            off.warnings
        );
        let e = check_pressure(&m, &fanuc, joint, true, 3000.0)
            .err()
            .unwrap();
        assert!(
            e.contains("dialect `fanuc` cannot write the pressure word `H1`"),
            "{e}"
        );
        let e = check_pressure(&m, &sinumerik, OutputMode::Tcp, true, 3000.0)
            .err()
            .unwrap();
        assert!(
            e.contains("tool-centre-point output cannot compensate"),
            "{e}"
        );
        // At the reference nothing moves: TCP output is fine there.
        assert!(check_pressure(&m, &sinumerik, OutputMode::Tcp, true, 3475.0).is_ok());
        let plain = builtin::load("trunnion-ac").unwrap().unwrap();
        let e = check_pressure(&plain, &sinumerik, joint, true, 3000.0)
            .err()
            .unwrap();
        assert!(e.contains("has no pressure axis"), "{e}");
    }
}
