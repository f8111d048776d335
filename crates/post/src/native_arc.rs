//! Native arcs: where a CL arc lies in a plane of the machine at constant
//! rotary axes, the program writes it as one circular block (`G2`/`G3`
//! with the plane and the centre) instead of its lines.
//!
//! At fixed rotary values the linear axes move the tool point by a rigid
//! map of the part frame: p(l) = p(s) + M (l − s), M orthonormal, measured
//! here through the forward kinematics (the tool point's motion per mm of
//! X, Y and Z). The arc's normal n maps to Mᵀ n in the program's X, Y, Z:
//! along Z the arc is a G17 arc, along Y G18, along X G19; its centre is
//! s + Mᵀ (c − p(s)). The sense follows the sign of the mapped normal and
//! whether M mirrors (det M < 0). The closed-loop check then runs the
//! block as a controller interpolates it (the angle, the radius between
//! its start and end radii and the rise on the third axis in proportion)
//! back through the forward kinematics and compares it with the CL arc.

use kinpost_cl::Arc;
use kinpost_machine::tolerance::{
    NATIVE_ARC_PLANE_COS, NATIVE_ARC_RADIUS_MISMATCH_MM, NATIVE_ARC_RIGID,
};
use kinpost_machine::{Kinematics, MAX_AXES, Machine};
use kinpost_nc::{ArcMotion, ArcPlane};
use nalgebra::{Matrix3, Vector3};

/// The machine axes that carry the program's X, Y, Z words, and the other
/// free axes (which must stand still along a native arc).
#[derive(Debug, Clone, PartialEq)]
pub struct ProgramAxes {
    /// Machine indices of the free linear axes named X, Y and Z.
    pub xyz: [usize; 3],
    /// The other free axes, rotary ones included.
    pub others: Vec<usize>,
}

impl ProgramAxes {
    /// The program axes of `machine`; `None` when it lacks a free linear
    /// X, Y or Z (its arcs are written as lines).
    pub fn of(machine: &Machine) -> Option<ProgramAxes> {
        let mut xyz = [usize::MAX; 3];
        for (k, name) in ["X", "Y", "Z"].into_iter().enumerate() {
            xyz[k] = machine
                .axes
                .iter()
                .position(|a| !a.is_rotary() && a.is_free() && a.name.eq_ignore_ascii_case(name))?;
        }
        let others = (0..machine.axes.len())
            .filter(|i| machine.axes[*i].is_free() && !xyz.contains(i))
            .collect();
        Some(ProgramAxes { xyz, others })
    }

    /// The program's X, Y, Z of machine values `q`.
    pub fn point(&self, q: &[f64]) -> Vector3<f64> {
        Vector3::new(q[self.xyz[0]], q[self.xyz[1]], q[self.xyz[2]])
    }
}

/// The circular block of `arc` (part frame) from machine values `start`
/// (as written), if the arc lies in a program plane at these rotary
/// values; `None` when the linear axes are not a rigid map there or the
/// arc's normal is not along X, Y or Z of the program.
pub fn fit(kin: &Kinematics, axes: &ProgramAxes, arc: &Arc, start: &[f64]) -> Option<ArcMotion> {
    let p0 = kin.fk(start).point;
    let mut q = [0.0; MAX_AXES];
    q[..start.len()].copy_from_slice(start);
    let mut m = Matrix3::zeros();
    for (k, &i) in axes.xyz.iter().enumerate() {
        q[i] += 1.0;
        m.set_column(k, &(kin.fk(&q[..start.len()]).point - p0));
        q[i] = start[i];
    }
    if (m.transpose() * m - Matrix3::identity()).amax() > NATIVE_ARC_RIGID {
        return None;
    }
    let normal = m.transpose() * Vector3::from(arc.axis());
    let k = normal.iamax();
    if 1.0 - normal[k].abs() > NATIVE_ARC_PLANE_COS {
        return None;
    }
    let plane = match k {
        2 => ArcPlane::Xy,
        1 => ArcPlane::Zx,
        _ => ArcPlane::Yz,
    };
    // The CL arc turns counter-clockwise about its axis; a mirroring map
    // turns the sense over.
    let counter_clockwise = (normal[k] > 0.0) != (m.determinant() < 0.0);
    let centre = m.transpose() * (Vector3::from(arc.centre()) - p0);
    Some(ArcMotion {
        plane,
        clockwise: !counter_clockwise,
        centre_offset: [centre.x, centre.y, centre.z],
    })
}

/// The largest distance, mm, between the CL `arc` and the circular block
/// `native` from `start` to `end` (machine values as written, the centre
/// offset as written) as a controller interpolates it, at `samples + 1`
/// equally spaced parameters, each through the forward kinematics;
/// infinite when the block is no arc a controller takes (start on the
/// centre, radii differing by more than
/// [`NATIVE_ARC_RADIUS_MISMATCH_MM`]).
pub fn deviation_mm(
    kin: &Kinematics,
    axes: &ProgramAxes,
    arc: &Arc,
    start: &[f64],
    end: &[f64],
    native: &ArcMotion,
    samples: usize,
) -> f64 {
    let [a, b, h] = native.plane.axes();
    let s = axes.point(start);
    let e = axes.point(end);
    let c = s + Vector3::from(native.centre_offset);
    let (sa, sb) = (s[a] - c[a], s[b] - c[b]);
    let (ea, eb) = (e[a] - c[a], e[b] - c[b]);
    let (rs, re) = (sa.hypot(sb), ea.hypot(eb));
    if rs <= NATIVE_ARC_RADIUS_MISMATCH_MM || (rs - re).abs() > NATIVE_ARC_RADIUS_MISMATCH_MM {
        return f64::INFINITY;
    }
    // The angle from start to end in the block's sense (a half circle
    // whose end rounds past the opposite point still turns its way).
    let tau = std::f64::consts::TAU;
    let mut sweep = (sa * eb - sb * ea).atan2(sa * ea + sb * eb);
    if native.clockwise {
        if sweep >= 0.0 {
            sweep -= tau;
        }
    } else if sweep <= 0.0 {
        sweep += tau;
    }
    let phi = sb.atan2(sa);
    let mut q = [0.0; MAX_AXES];
    q[..start.len()].copy_from_slice(start);
    let samples = samples.max(1);
    let mut worst: f64 = 0.0;
    for i in 0..=samples {
        let t = i as f64 / samples as f64;
        let r = rs + (re - rs) * t;
        let (sin, cos) = (phi + sweep * t).sin_cos();
        let mut p = Vector3::zeros();
        p[a] = c[a] + r * cos;
        p[b] = c[b] + r * sin;
        p[h] = s[h] + (e[h] - s[h]) * t;
        for k in 0..3 {
            q[axes.xyz[k]] = p[k];
        }
        let got = kin.fk(&q[..start.len()]).point;
        worst = worst.max((got - Vector3::from(arc.point_at(t))).norm());
    }
    worst
}
