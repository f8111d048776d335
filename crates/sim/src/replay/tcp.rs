//! Blocks under tool-centre-point control (Sinumerik `TRAORI`, Fanuc
//! `G43.4`, Heidenhain `M128` / `FUNCTION TCPM`, LinuxCNC's `M428`): the
//! X Y Z words are the tool point in the part frame; the controller moves
//! the tool point (along a line or an arc) and the rotary axes linearly and
//! solves the linear axes. The replay does the same at sampled points. For
//! fixed rotary values the tool point is an affine function of the linear
//! axes (each translates what it carries), so four forward kinematics and a
//! 3×3 solve give them exactly; between samples the joints move
//! joint-linearly (the steps of [`Replay::pieces`]).

use kinpost_nc::interp::{MAX_AXES, MotionKind, Move, Step};
use nalgebra::{Matrix3, Vector3};

use super::Replay;
use crate::path::{BlockPath, Joints, Shape};
use crate::removal::BlockConditions;
use crate::report::At;
use crate::{SimError, tolerance};

impl Replay {
    /// A block under tool-centre-point control.
    pub(super) fn tcp_motion(&mut self, step: &Step, m: &Move, at: &At) -> Result<(), SimError> {
        let line = step.line;
        let lin = self.tcp_axes(line)?;
        // The programmed path: the tool point in place of X Y Z.
        let mut from = self.q;
        let p0 = self.kin.fk(&self.q[..self.n]).point;
        for k in 0..3 {
            from[lin[k]] = p0[k];
        }
        let mut programmed = self.block_path(m, line, &from)?;
        if let Shape::Rapid { .. } = programmed.shape {
            // (A rapid under TCP is interpolated too.)
            programmed.shape = Shape::Joint;
        }
        let p1 = Vector3::new(
            programmed.to[lin[0]],
            programmed.to[lin[1]],
            programmed.to[lin[2]],
        );
        let pieces = self.pieces(&programmed, &(p1 - p0).norm());
        let mut joints: Vec<Joints> = Vec::with_capacity(pieces + 1);
        joints.push(self.q);
        let mut v = [0.0; MAX_AXES];
        for k in 1..=pieces {
            programmed.at(k as f64 / pieces as f64, &mut v);
            let q = self
                .solve_linear(&v, lin)
                .ok_or(SimError::TcpUnsolvable { line })?;
            joints.push(q);
        }
        let known_before = self.known;
        self.known |= m.programmed & self.all;
        let last = joints[pieces];
        for i in 0..self.n {
            let range = if known_before & (1 << i) != 0 {
                joints
                    .iter()
                    .fold([f64::INFINITY, f64::NEG_INFINITY], |[lo, hi], q| {
                        [lo.min(q[i]), hi.max(q[i])]
                    })
            } else {
                [last[i], last[i]]
            };
            self.charge_travel(i, range, [joints[0][i], last[i]], at, known_before);
        }
        let joint_path = BlockPath {
            n: self.n,
            from: joints[0],
            to: last,
            shape: Shape::Joint,
        };
        let seconds = self.block_time_s(m, &programmed, &joint_path);
        self.report.duration_s += seconds;
        if self.known == self.all {
            self.complete_at.get_or_insert(line);
            let conditions = self.conditions(m, seconds);
            self.tcp_checks(
                &joints,
                at,
                m.kind == MotionKind::Rapid,
                known_before == self.all,
                conditions,
            )?;
        }
        self.q = last;
        self.offset[..self.n].copy_from_slice(&m.state.offset.as_slice()[..self.n]);
        Ok(())
    }

    /// The CL comparison and the collision check of a TCP block sampled at
    /// `joints` (its start first); `started`: its start is known.
    fn tcp_checks(
        &mut self,
        joints: &[Joints],
        at: &At,
        rapid: bool,
        started: bool,
        conditions: BlockConditions,
    ) -> Result<(), SimError> {
        let pieces = joints.len() - 1;
        if started
            && let Some((pole, cone)) = self.singular
            && self.may_pass_pole(&joints[0], &joints[pieces], cone)
        {
            // The TCP path's samples: the tool axis at each.
            let least = joints
                .iter()
                .map(|q| pole.distance(&self.kin.fk(&q[..self.n]).axis))
                .fold(f64::INFINITY, f64::min);
            let turn_deg = (joints[pieces][pole.axis] - joints[0][pole.axis]).abs();
            self.note_passage(at, least, turn_deg);
        }
        if self.cl.is_some() && !rapid {
            let first = if started { 1 } else { pieces };
            for (k, q) in joints.iter().enumerate().skip(first) {
                let pose = self.kin.fk(&q[..self.n]);
                self.measure(&pose, at, k == pieces);
            }
        }
        let rotary = self.axes_rotary();
        if let Some(w) = &mut self.worlds {
            let sub = |a: usize, b: usize| BlockPath {
                n: self.n,
                from: joints[a],
                to: joints[b],
                shape: Shape::Joint,
            };
            if started {
                // Chords of the TCP path, each within the collision step.
                let chords = collision_chords(joints, &rotary);
                let mut a = 0;
                for j in 1..=chords {
                    let b = (j * pieces).div_ceil(chords);
                    if b > a {
                        w.check(&sub(a, b), at, rapid, true, self.pressure)?;
                        a = b;
                    }
                }
            } else {
                w.check(&sub(0, pieces), at, rapid, false, self.pressure)?;
            }
        }
        if self.cutting.is_some() {
            // The tool point moves straight under TCP: its samples are the
            // poses (the start's only once known).
            let first = if started { 0 } else { pieces };
            let poses: Vec<_> = joints[first..]
                .iter()
                .map(|q| self.kin.fk(&q[..self.n]))
                .collect();
            if let Some(c) = &mut self.cutting {
                c.cut(&poses, at, rapid, Some(conditions))?;
            }
        }
        Ok(())
    }

    /// Which axes are rotary.
    fn axes_rotary(&self) -> Vec<bool> {
        self.axes.iter().map(|a| a.rotary).collect()
    }

    /// The machine's X, Y and Z axes (linear, not locked): what the TCP
    /// words X Y Z move.
    fn tcp_axes(&self, line: usize) -> Result<[usize; 3], SimError> {
        let [x, y, z] = self.xyz;
        match (x, y, z) {
            (Some(x), Some(y), Some(z))
                if [x, y, z]
                    .iter()
                    .all(|&i| self.axes[i].travel.is_none_or(|[lo, hi]| lo < hi)) =>
            {
                Ok([x, y, z])
            }
            _ => Err(SimError::TcpAxes { line }),
        }
    }

    /// The joints that put the tool point at `v[lin]` with the other axes
    /// at their values in `v`; `None` where the linear axes cannot reach
    /// every direction (a singular machine).
    fn solve_linear(&self, v: &Joints, lin: [usize; 3]) -> Option<Joints> {
        let mut q = *v;
        for &i in &lin {
            q[i] = 0.0;
        }
        let b = self.kin.fk(&q[..self.n]).point;
        let mut columns = [Vector3::zeros(); 3];
        for (k, &i) in lin.iter().enumerate() {
            let mut e = q;
            e[i] = 1.0;
            columns[k] = self.kin.fk(&e[..self.n]).point - b;
        }
        let a = Matrix3::from_columns(&columns);
        let target = Vector3::new(v[lin[0]], v[lin[1]], v[lin[2]]) - b;
        let x = a.lu().solve(&target)?;
        for (k, &i) in lin.iter().enumerate() {
            q[i] = x[k];
        }
        Some(q)
    }
}

/// How many joint-linear chords a TCP block sampled at `joints` is checked
/// for collisions in: each spans at most [`tolerance::TCP_CHORD_DEG`] of any
/// rotary axis and [`tolerance::TCP_CHORD_MM`] of any linear one.
fn collision_chords(joints: &[Joints], rotary: &[bool]) -> usize {
    let (first, last) = (&joints[0], &joints[joints.len() - 1]);
    let mut k: f64 = 1.0;
    for (i, &r) in rotary.iter().enumerate() {
        // (The linear axes curve under TCP: their largest excursion from
        // the start bounds their travel.)
        let span = if r {
            (last[i] - first[i]).abs()
        } else {
            joints
                .iter()
                .map(|q| (q[i] - first[i]).abs())
                .fold(0.0, f64::max)
                * 2.0
        };
        let step = if r {
            tolerance::TCP_CHORD_DEG
        } else {
            tolerance::TCP_CHORD_MM
        };
        k = k.max((span / step).ceil());
    }
    (k as usize).clamp(1, joints.len() - 1)
}
