//! What programming a pressure means for a machine, a dialect and a run
//! (Qi, thesis, ch. 3): the pressure word's column, and the checks of a
//! pressure the CL or the command line programs.

use kinpost_machine::{Clamp, Machine, OutputMode};
use kinpost_nc::{AxisSpec, Dialect};

use crate::error::{PressureError, PressureWarning};

/// The pressure column of a machine's blocks, after its axes.
pub(crate) fn pressure_spec(machine: &Machine) -> Option<AxisSpec> {
    machine
        .pressure
        .as_ref()
        .map(|p| AxisSpec::pressure_word(&p.name))
}

/// What programming a pressure means for this machine, dialect and run.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct PressureCheck {
    /// The warnings to give.
    pub warnings: Vec<PressureWarning>,
    /// The wheel moves and the post does not compensate it.
    pub uncompensated: bool,
}

/// Checks a pressure the CL or the command line programs: the warnings to
/// give, or why it cannot be written.
pub(crate) fn check_pressure(
    machine: &Machine,
    dialect: &Dialect,
    output: OutputMode,
    compensate: bool,
    value: f64,
) -> Result<PressureCheck, PressureError> {
    let Some(p) = &machine.pressure else {
        return Err(PressureError::NoPressureAxis(machine.name.clone()));
    };
    if !dialect.writes_pressure() {
        return Err(PressureError::NoPressureWord {
            dialect: dialect.name().to_string(),
            word: p.name.clone(),
        });
    }
    let written = dialect.quantize(&AxisSpec::pressure_word(&p.name), value);
    let mut warnings = Vec::new();
    let [lo, hi] = p.range();
    let stop = match p.clamp(written) {
        Clamp::Inside => None,
        Clamp::Below => Some((false, lo)),
        Clamp::Above => Some((true, hi)),
    };
    if let Some((above, end)) = stop {
        warnings.push(PressureWarning::OnStop {
            word: p.name.clone(),
            value: number(written),
            above,
            range: [number(lo), number(hi)],
            stop: number(end),
        });
    }
    let offset = p.offset(written);
    let moved = offset.norm() > 0.0;
    if moved && compensate && output == OutputMode::Tcp {
        return Err(PressureError::TcpCannotCompensate {
            word: p.name.clone(),
            value: number(written),
            offset_mm: offset.norm(),
        });
    }
    let uncompensated = moved && !compensate;
    if uncompensated {
        let [d1, d2] = p.plane_offset(written);
        warnings.push(PressureWarning::NotCompensated {
            word: p.name.clone(),
            value: number(written),
            offset_mm: offset.norm(),
            reference: number(p.reference),
            along: [
                (d1, machine.axes[p.plane[0]].name.clone()),
                (d2, machine.axes[p.plane[1]].name.clone()),
            ],
        });
    }
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
    fn checks_name_the_problem() {
        let m = builtin::load("mts1600").unwrap().unwrap();
        let sinumerik = Dialect::builtin("sinumerik").unwrap();
        let fanuc = Dialect::builtin("fanuc").unwrap();
        let joint = OutputMode::Joint;
        let ok = check_pressure(&m, &sinumerik, joint, true, 3300.0).unwrap();
        assert!(ok.warnings.is_empty() && !ok.uncompensated);
        let low = check_pressure(&m, &sinumerik, joint, true, 2500.0).unwrap();
        assert!(
            low.warnings[0]
                .to_string()
                .contains("H1 = 2500 is below the machine's calibration (3000 .. 3600)")
        );
        let off = check_pressure(&m, &sinumerik, joint, false, 3000.0).unwrap();
        assert!(off.uncompensated);
        assert!(
            off.warnings[0].to_string().contains("not compensated"),
            "{:?}",
            off.warnings
        );
        let e = check_pressure(&m, &fanuc, joint, true, 3000.0)
            .err()
            .unwrap()
            .to_string();
        assert!(
            e.contains("dialect `fanuc` cannot write the pressure word `H1`"),
            "{e}"
        );
        let e = check_pressure(&m, &sinumerik, OutputMode::Tcp, true, 3000.0)
            .err()
            .unwrap();
        assert!(
            matches!(e, PressureError::TcpCannotCompensate { .. }),
            "{e}"
        );
        // At the reference nothing moves: TCP output is fine there.
        assert!(check_pressure(&m, &sinumerik, OutputMode::Tcp, true, 3475.0).is_ok());
        let plain = builtin::load("trunnion-ac").unwrap().unwrap();
        let e = check_pressure(&plain, &sinumerik, joint, true, 3000.0)
            .err()
            .unwrap();
        assert!(e.to_string().contains("has no pressure axis"), "{e}");
    }
}
