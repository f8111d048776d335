//! Collisions along the replayed path, through `kinpost-collide`: every
//! block swept (conservative advancement between its ends, in pieces along
//! which every axis moves one way), the wheel where the program's pressure
//! puts it.

use std::collections::HashMap;

use kinpost_collide::{ContactKind, Motion, World};
use kinpost_machine::Machine;

use crate::path::BlockPath;
use crate::report::{At, Contact};
use crate::{SimError, tolerance};

/// Worlds at most kept for other pressures (the oldest is dropped beyond).
const PRESSURE_WORLDS: usize = 8;

/// The machine's worlds: at the reference pressure and at the pressures
/// the program wrote; the contacts found so far.
pub(crate) struct Worlds {
    machine: Machine,
    reference: World,
    at_pressure: Vec<(u64, World)>,
    compensate: bool,
    collisions: Vec<Contact>,
    near: Vec<Contact>,
    /// The last contact of each pair (solid indices, error or not): index
    /// into `collisions` or `near`.
    last: HashMap<([usize; 2], bool), usize>,
    breaks: Vec<f64>,
}

impl Worlds {
    /// The worlds of `machine`; `compensate`: the pressure moves the wheel.
    pub fn new(machine: &Machine, compensate: bool) -> Result<Worlds, SimError> {
        Ok(Worlds {
            machine: machine.clone(),
            reference: World::new(machine)?,
            at_pressure: Vec::new(),
            compensate,
            collisions: Vec::new(),
            near: Vec::new(),
            last: HashMap::new(),
            breaks: Vec::new(),
        })
    }

    fn world(&mut self, pressure: f64) -> Result<&World, SimError> {
        if !self.compensate || pressure.is_nan() || self.machine.pressure.is_none() {
            return Ok(&self.reference);
        }
        let key = pressure.to_bits();
        let i = match self.at_pressure.iter().position(|(k, _)| *k == key) {
            Some(i) => i,
            None => {
                if self.at_pressure.len() >= PRESSURE_WORLDS {
                    self.at_pressure.remove(0);
                }
                let w = World::new(&self.machine.at_pressure(pressure))?;
                self.at_pressure.push((key, w));
                self.at_pressure.len() - 1
            }
        };
        Ok(&self.at_pressure[i].1)
    }

    /// Checks one block (`started`: it has a known start; else only its
    /// end pose is checked).
    pub fn check(
        &mut self,
        path: &BlockPath,
        at: &At,
        rapid: bool,
        started: bool,
        pressure: f64,
    ) -> Result<(), SimError> {
        let motion = if rapid { Motion::Rapid } else { Motion::Feed };
        let n = path.n;
        let mut found = Vec::new();
        let mut breaks = std::mem::take(&mut self.breaks);
        {
            let world = self.world(pressure)?;
            if started {
                path.monotonic_breaks(&mut breaks);
                for w in breaks.windows(2) {
                    let (ta, tb) = (w[0], w[1]);
                    let piece = |t: f64, q: &mut Vec<f64>| {
                        q.resize(n, 0.0);
                        path.at(ta + t * (tb - ta), q);
                    };
                    for mut c in world.check_path(&piece, motion) {
                        // The sweep stops at the first pose within the
                        // clearance: the pair may come nearer after it.
                        nearest_after(world, &piece, c.fraction, motion, &mut c.contact);
                        found.push((c.contact, ta + c.fraction * (tb - ta)));
                    }
                }
            } else {
                for c in world.check_pose(&path.to[..n], motion) {
                    found.push((c, 1.0));
                }
            }
        }
        self.breaks = breaks;
        for (c, fraction) in found {
            self.record(c, fraction, at);
        }
        Ok(())
    }

    /// A contact: extends the pair's contact of the previous block, or a
    /// new one.
    fn record(&mut self, c: kinpost_collide::Contact, fraction: f64, at: &At) {
        let error = c.kind.is_error();
        let list = if error {
            &mut self.collisions
        } else {
            &mut self.near
        };
        let key = (c.indices, error);
        if let Some(&i) = self.last.get(&key) {
            let e = &mut list[i];
            if e.last_block + 1 >= at.block {
                e.last_block = at.block;
                e.distance_mm = e.distance_mm.min(c.distance_mm);
                e.penetration_mm = deeper(e.penetration_mm, c.penetration_mm);
                return;
            }
        }
        self.last.insert(key, list.len());
        list.push(Contact {
            at: at.clone(),
            last_block: at.block,
            solids: [c.solids[0].to_string(), c.solids[1].to_string()],
            kind: match c.kind {
                ContactKind::Collision => "collision",
                ContactKind::RapidIntoStock => "rapid_into_stock",
                ContactKind::NearMiss => "near_miss",
            },
            distance_mm: c.distance_mm,
            penetration_mm: c.penetration_mm,
            fraction,
            clearances_mm: [c.clearances_mm.0, c.clearances_mm.1],
        });
    }

    /// The collisions (errors) and near misses (warnings) found.
    pub fn into_contacts(self) -> (Vec<Contact>, Vec<Contact>) {
        (self.collisions, self.near)
    }
}

/// The deeper of two overlaps, where computed.
/// Lowers `contact`'s distance (and deepens its penetration) to the
/// nearest the pair comes on `piece` from `from` (a fraction of it) to its
/// end: [`tolerance::NEAREST_SAMPLES`] poses, then a golden-section search
/// around the nearest of them. (The pair's distance along a piece is not
/// convex in general: the search finds the nearest sampled valley to
/// within [`tolerance::NEAREST_FRACTION`] of the piece.)
fn nearest_after(
    world: &World,
    piece: &(dyn Fn(f64, &mut Vec<f64>) + Sync),
    from: f64,
    motion: Motion,
    contact: &mut kinpost_collide::Contact,
) {
    let mut q = Vec::new();
    let mut at = |t: f64, contact: &mut kinpost_collide::Contact| -> f64 {
        piece(t, &mut q);
        let pair = world
            .check_pose(&q, motion)
            .into_iter()
            .find(|c| c.indices == contact.indices);
        match pair {
            Some(c) => {
                contact.penetration_mm = deeper(contact.penetration_mm, c.penetration_mm);
                contact.distance_mm = contact.distance_mm.min(c.distance_mm);
                c.distance_mm
            }
            None => f64::INFINITY,
        }
    };
    let k = tolerance::NEAREST_SAMPLES;
    let ts: Vec<f64> = (0..=k)
        .map(|i| from + (1.0 - from) * i as f64 / k as f64)
        .collect();
    let ds: Vec<f64> = ts.iter().map(|&t| at(t, contact)).collect();
    let Some(best) = (0..ds.len()).min_by(|&a, &b| ds[a].total_cmp(&ds[b])) else {
        return;
    };
    if ds[best] <= 0.0 {
        return;
    }
    let (mut lo, mut hi) = (ts[best.saturating_sub(1)], ts[(best + 1).min(k)]);
    let phi = 0.5 * (5f64.sqrt() - 1.0);
    while hi - lo > tolerance::NEAREST_FRACTION {
        let (a, b) = (hi - phi * (hi - lo), lo + phi * (hi - lo));
        if at(a, contact) <= at(b, contact) {
            hi = b;
        } else {
            lo = a;
        }
    }
}

fn deeper(a: Option<f64>, b: Option<f64>) -> Option<f64> {
    match (a, b) {
        (Some(a), Some(b)) => Some(a.max(b)),
        (a, b) => a.or(b),
    }
}
