//! The kinematics in force for the pressure a program writes (Qi, thesis,
//! eq. 3.4–3.7): every block of a belt-grinding program is solved, and
//! checked, through the machine with the wheel where its pressure puts it.
//!
//! The wheel offset Δ(p) is constant after the last tool-side axis, so the
//! machine at pressure p is the same machine with its home tool point moved
//! by Δ(p) ([`Machine::at_pressure`]). Pressures change rarely: one
//! [`Kinematics`] is compiled per wheel offset and kept in a small cache.

use std::ops::Deref;

use nalgebra::Vector3;

use crate::kinematics::Kinematics;
use crate::model::Machine;
use crate::pressure::PressureAxis;

/// Kinematics compiled for this many wheel offsets at most (the oldest is
/// dropped beyond), so that a CL changing the pressure at every point keeps
/// its memory bounded.
const CACHE: usize = 16;

/// A machine's kinematics, with the wheel at the pressure last selected
/// ([`KinematicsAtPressure::select`]). A machine without a pressure axis
/// has one kinematics whatever the pressure. Dereferences to the
/// [`Kinematics`] in force.
#[derive(Debug, Clone)]
pub struct KinematicsAtPressure {
    kin: Kinematics,
    wheel: Option<Wheel>,
}

/// The pressure axis of the machine and the kinematics of other offsets.
#[derive(Debug, Clone)]
struct Wheel {
    /// The program's machine, wheel at the reference pressure.
    machine: Machine,
    axis: PressureAxis,
    /// Compensation off: the kinematics stays at the reference.
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

impl KinematicsAtPressure {
    /// `kin`, the kinematics of `machine` at its reference pressure (with
    /// the settings the program wants, e.g. its axis rounding), and what a
    /// pressure does to it: nothing for a machine without a pressure axis,
    /// or when `compensate` is false (the machine maker's post: every block
    /// solved at the reference pressure).
    pub fn new(machine: &Machine, kin: Kinematics, compensate: bool) -> KinematicsAtPressure {
        let wheel = machine.pressure.clone().map(|axis| Wheel {
            axis,
            machine: machine.clone(),
            compensate,
            current: f64::NAN,
            offset: Vector3::zeros(),
            cache: Vec::new(),
        });
        KinematicsAtPressure { kin, wheel }
    }

    /// Puts the kinematics of the pressure `written` (as the program writes
    /// it; NaN: none programmed, the reference applies) in force. Returns
    /// the wheel offset the post compensates (zero without a pressure axis).
    #[inline]
    pub fn select(&mut self, written: f64) -> Vector3<f64> {
        let Some(w) = &mut self.wheel else {
            return Vector3::zeros();
        };
        // The hot path: the pressure of the previous block.
        if written.to_bits() == w.current.to_bits() {
            return w.offset;
        }
        w.change(&mut self.kin, written)
    }
}

impl Wheel {
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

impl Deref for KinematicsAtPressure {
    type Target = Kinematics;

    #[inline]
    fn deref(&self) -> &Kinematics {
        &self.kin
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::builtin;

    /// Changing the pressure swaps the kinematics; the reference, no
    /// pressure and clamped pressures keep what they share; the cache
    /// stays bounded.
    #[test]
    fn cache_swaps_kinematics_per_offset() {
        let m = builtin::load("mts1600").unwrap().unwrap();
        let mut kin = KinematicsAtPressure::new(&m, Kinematics::new(&m), true);
        let q = m.home_joints();
        let at_ref = kin.fk(&q).point;
        // No pressure and the reference: the reference kinematics, untouched.
        assert_eq!(kin.select(f64::NAN), Vector3::zeros());
        assert_eq!(kin.select(3475.0), Vector3::zeros());
        assert_eq!(kin.fk(&q).point, at_ref);
        let d = kin.select(3000.0);
        assert!((kin.fk(&q).point - (at_ref + d)).norm() < 1e-12);
        // Clamped pressures share the offset of the stop.
        assert_eq!(kin.select(2000.0), d);
        assert_eq!(kin.select(3475.0), Vector3::zeros());
        assert_eq!(kin.fk(&q).point, at_ref);
        // Without compensation the kinematics never changes.
        let mut off = KinematicsAtPressure::new(&m, Kinematics::new(&m), false);
        assert_eq!(off.select(3000.0), Vector3::zeros());
        assert_eq!(off.fk(&q).point, at_ref);
        // The cache stays bounded.
        for k in 0..100 {
            kin.select(3000.0 + f64::from(k));
        }
        assert!(kin.wheel.as_ref().unwrap().cache.len() <= CACHE);
    }
}
