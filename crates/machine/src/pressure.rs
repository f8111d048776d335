//! The grinding-pressure axis (Qi (thesis), chapters 2–3): a
//! process axis that moves the tool point.
//!
//! On the MTS1600 belt grinder the contact wheel hangs on the coupler BC of a
//! parallelogram four-bar linkage (fixed link AD, input link AB, output link
//! DC, |AB| = |DC|) that a pneumatic cylinder lowers as the pressure setting
//! H1 drops. The coupler translates without turning (Qi (thesis) §2.9), so every
//! point of the wheel moves exactly as the joint B does, whose path is the
//! circle of Qi (thesis) eq. (2.35):
//!
//! ```text
//! y_B = L_AB·cos α,   z_B = L_AB·sin α          α from the first plane axis
//! Δ(p) = L_AB·((cos α(p) − cos α_ref)·e₁ + (sin α(p) − sin α_ref)·e₂)
//! ```
//!
//! with e₁, e₂ the home directions of the two linear axes spanning the
//! linkage plane and α_ref = α(reference). The wheel offset Δ is a pure
//! translation in the tool chain after its last axis (Qi (thesis) eq. 3.7:
//! T_ws'^ws = translation (0, d_y, d_z)), expressed at home, so the machine
//! at pressure p is the same machine with its home tool point moved by Δ(p)
//! ([`Machine::at_pressure`]); Δ(reference) = 0.
//!
//! H1 → α is a measured calibration curve (Qi (thesis) §2.12, Table 2.5),
//! interpolated piecewise linearly and clamped at its ends, where the piston
//! sits on its stops (Qi (thesis) §2.4: H1 ≥ 3600 upper stop, H1 ≤ 3000 lower
//! stop). A machine may instead give the measured offsets per pressure.

use nalgebra::Vector3;

use crate::model::Machine;

/// How the wheel offset depends on the pressure.
#[derive(Debug, Clone, PartialEq)]
pub enum WheelModel {
    /// The four-bar linkage: input link length and the calibration curve
    /// pressure → angle α of the input link (degrees, from the first plane
    /// direction towards the second).
    Linkage {
        /// |AB| in mm.
        link_length: f64,
        /// Rows `[pressure, α in degrees]`, pressures strictly increasing.
        alpha_deg: Vec<[f64; 2]>,
    },
    /// Measured wheel offsets: rows `[pressure, d₁, d₂]` (mm along the first
    /// and second plane direction, relative to any fixed position; only
    /// differences to the reference row count), pressures strictly increasing.
    Offsets(Vec<[f64; 3]>),
}

/// A process axis that moves the tool point: the grinding pressure H1.
#[derive(Debug, Clone, PartialEq)]
pub struct PressureAxis {
    /// The NC word, e.g. `H1`.
    pub name: String,
    /// The pressure at which `[tool] point` was measured: no offset there.
    pub reference: f64,
    /// Indices of the two linear axes whose home directions span the
    /// linkage plane.
    pub plane: [usize; 2],
    /// Their home directions e₁, e₂ (unit, perpendicular).
    pub directions: [Vector3<f64>; 2],
    /// How the wheel offset depends on the pressure.
    pub model: WheelModel,
}

/// Where a pressure lies against the calibration table.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Clamp {
    /// Inside the table.
    Inside,
    /// Below its first row: the offset is that of the first row.
    Below,
    /// Above its last row: the offset is that of the last row.
    Above,
}

impl PressureAxis {
    /// The first and last pressure of the calibration table.
    pub fn range(&self) -> [f64; 2] {
        fn ends<const N: usize>(rows: &[[f64; N]]) -> [f64; 2] {
            [
                rows.first().map_or(0.0, |r| r[0]),
                rows.last().map_or(0.0, |r| r[0]),
            ]
        }
        match &self.model {
            WheelModel::Linkage { alpha_deg, .. } => ends(alpha_deg),
            WheelModel::Offsets(rows) => ends(rows),
        }
    }

    /// Whether `pressure` is inside the calibration table or clamped to one
    /// of its ends.
    pub fn clamp(&self, pressure: f64) -> Clamp {
        let [lo, hi] = self.range();
        if pressure < lo {
            Clamp::Below
        } else if pressure > hi {
            Clamp::Above
        } else {
            Clamp::Inside
        }
    }

    /// The angle α of the input link at `pressure`, degrees (linkage model
    /// only).
    pub fn alpha_deg(&self, pressure: f64) -> Option<f64> {
        match &self.model {
            WheelModel::Linkage { alpha_deg, .. } => Some(interpolate(alpha_deg, pressure)[1]),
            WheelModel::Offsets(_) => None,
        }
    }

    /// The wheel offset Δ(p) as components along the two plane directions
    /// (e₁, e₂), mm; exactly zero at the reference pressure.
    pub fn plane_offset(&self, pressure: f64) -> [f64; 2] {
        match &self.model {
            WheelModel::Linkage {
                link_length,
                alpha_deg,
            } => {
                let a = interpolate(alpha_deg, pressure)[1].to_radians();
                let r = interpolate(alpha_deg, self.reference)[1].to_radians();
                // cos a − cos r = −2 sin((a+r)/2) sin((a−r)/2) and
                // sin a − sin r = 2 cos((a+r)/2) sin((a−r)/2): no
                // cancellation near the reference, exactly 0 at it.
                let (mean, half) = ((a + r) / 2.0, (a - r) / 2.0);
                let s = 2.0 * link_length * half.sin();
                // `0.0 -` and `+ 0.0`: +0, never −0, at the reference.
                [0.0 - s * mean.sin(), s * mean.cos() + 0.0]
            }
            WheelModel::Offsets(rows) => {
                let at = interpolate(rows, pressure);
                let reference = interpolate(rows, self.reference);
                [at[1] - reference[1] + 0.0, at[2] - reference[2] + 0.0]
            }
        }
    }

    /// The wheel offset Δ(p) in the machine frame at home, mm.
    pub fn offset(&self, pressure: f64) -> Vector3<f64> {
        let [d1, d2] = self.plane_offset(pressure);
        self.directions[0] * d1 + self.directions[1] * d2
    }
}

/// The row of a table sorted by its first column at `x`: piecewise linear
/// between rows, the end rows outside them (the piston on its stops).
pub fn interpolate<const N: usize>(rows: &[[f64; N]], x: f64) -> [f64; N] {
    let (Some(first), Some(last)) = (rows.first(), rows.last()) else {
        return [0.0; N];
    };
    if x.is_nan() || x <= first[0] {
        return *first;
    }
    if x >= last[0] {
        return *last;
    }
    // The first row whose pressure is above x (x lies strictly inside).
    let k = rows.partition_point(|r| r[0] <= x);
    let (a, b) = (&rows[k - 1], &rows[k]);
    let t = (x - a[0]) / (b[0] - a[0]);
    let mut out = [x; N];
    for i in 1..N {
        out[i] = a[i] + t * (b[i] - a[i]);
    }
    out
}

impl Machine {
    /// The machine with its wheel held at `pressure`: the home tool point
    /// moved by the wheel offset Δ(pressure) (Qi (thesis) eq. 3.4–3.7; the
    /// offset is constant after the last tool-side axis, so it turns with the
    /// head), and no pressure axis. Forward and inverse kinematics at that
    /// pressure are those of `Kinematics::new(&machine.at_pressure(p))`. A
    /// machine without a pressure axis is returned as it is.
    pub fn at_pressure(&self, pressure: f64) -> Machine {
        let mut m = self.clone();
        if let Some(p) = m.pressure.take() {
            m.tool.point += p.offset(pressure);
        }
        m
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn linkage(rows: Vec<[f64; 2]>, reference: f64) -> PressureAxis {
        PressureAxis {
            name: "H1".into(),
            reference,
            plane: [0, 1],
            directions: [Vector3::new(0.0, -1.0, 0.0), Vector3::z()],
            model: WheelModel::Linkage {
                link_length: 250.0,
                alpha_deg: rows,
            },
        }
    }

    #[test]
    fn interpolation_is_piecewise_linear_and_clamped() {
        let rows = [[0.0, 10.0, 1.0], [10.0, 20.0, 3.0], [30.0, 0.0, 3.0]];
        assert_eq!(interpolate(&rows, -5.0), rows[0]);
        assert_eq!(interpolate(&rows, 0.0), rows[0]);
        assert_eq!(interpolate(&rows, 5.0), [5.0, 15.0, 2.0]);
        assert_eq!(interpolate(&rows, 10.0), rows[1]);
        assert_eq!(interpolate(&rows, 20.0), [20.0, 10.0, 3.0]);
        assert_eq!(interpolate(&rows, 30.0), rows[2]);
        assert_eq!(interpolate(&rows, 99.0), rows[2]);
    }

    #[test]
    fn linkage_offset_is_the_arc_of_eq_2_35() {
        let p = linkage(vec![[3000.0, -6.73], [3600.0, 5.0]], 3600.0);
        // At the reference: exactly zero.
        assert_eq!(p.plane_offset(3600.0), [0.0, 0.0]);
        // Upper to lower stop, straight from L·(cos α, sin α).
        let (lo, hi) = (-6.73f64.to_radians(), 5f64.to_radians());
        let want = [250.0 * (lo.cos() - hi.cos()), 250.0 * (lo.sin() - hi.sin())];
        let got = p.plane_offset(3000.0);
        assert!((got[0] - want[0]).abs() < 1e-12, "{got:?} {want:?}");
        assert!((got[1] - want[1]).abs() < 1e-12, "{got:?} {want:?}");
        // The stroke of Qi (thesis) §2.7: 51.075 mm measured.
        assert!((got[1].abs() - 51.075).abs() < 0.1);
        // Clamped: the piston sits on its stop.
        assert_eq!(p.plane_offset(1000.0), got);
        assert_eq!(p.clamp(1000.0), Clamp::Below);
        assert_eq!(p.clamp(4000.0), Clamp::Above);
        assert_eq!(p.clamp(3300.0), Clamp::Inside);
        // In the machine frame: e₁ = −y, e₂ = +z.
        let v = p.offset(3000.0);
        assert!((v - Vector3::new(0.0, -want[0], want[1])).norm() < 1e-12);
    }

    #[test]
    fn measured_offsets_are_relative_to_the_reference() {
        let p = PressureAxis {
            model: WheelModel::Offsets(vec![[3000.0, -1.12, -51.075], [3600.0, 0.0, 0.0]]),
            ..linkage(Vec::new(), 3300.0)
        };
        assert_eq!(p.plane_offset(3300.0), [0.0, 0.0]);
        let d = p.plane_offset(3000.0);
        assert!((d[0] + 0.56).abs() < 1e-12 && (d[1] + 25.5375).abs() < 1e-12);
        assert_eq!(p.alpha_deg(3000.0), None);
    }
}
