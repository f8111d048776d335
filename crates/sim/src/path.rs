//! The path of one motion block in joint space, as a controller without
//! tool-centre-point control moves it: joint-linear for a feed move, each
//! axis at its own rate for a rapid (the dog-leg), a circle (or helix) in the
//! working plane for an arc, the other axes linear with it.

use std::f64::consts::FRAC_PI_2;

use kinpost_nc::ArcPlane;
use kinpost_nc::interp::MAX_AXES;

/// Joint values of every machine axis (NC values with the work offset
/// applied), machine order; the first `n` entries are meaningful.
pub type Joints = [f64; MAX_AXES];

/// An arc in joint coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArcPath {
    /// Machine axis indices of the plane's first and second coordinate and
    /// of its normal (G17: X Y Z; G18: Z X Y; G19: Y Z X).
    pub axes: [usize; 3],
    /// Centre in the plane (joint coordinates).
    pub centre: [f64; 2],
    /// Radius at the start and at the end.
    pub radius: [f64; 2],
    /// Angle of the start, radians.
    pub start_rad: f64,
    /// Signed angle swept (counter-clockwise positive), radians.
    pub sweep_rad: f64,
}

/// How a block moves between its ends.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shape {
    /// Every axis linear in one parameter (a feed move).
    Joint,
    /// Each axis at its own rate: axis `i` is at its end at `reach[i]` of
    /// the block's time (a rapid).
    Rapid {
        /// The fraction of the block's time at which each axis arrives.
        reach: Joints,
    },
    /// An arc in the plane of `ArcPath::axes`, the other axes linear.
    Arc(ArcPath),
}

/// One block's path: where it starts and ends and how it moves.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BlockPath {
    /// Number of machine axes.
    pub n: usize,
    /// The joints at the start.
    pub from: Joints,
    /// The joints at the end.
    pub to: Joints,
    /// How it moves.
    pub shape: Shape,
}

/// The machine axes of a plane: its two coordinates and its normal, from
/// the machine's X, Y, Z axes (`xyz`); `None` when the machine lacks one.
pub fn plane_axes(plane: ArcPlane, xyz: [Option<usize>; 3]) -> Option<[usize; 3]> {
    let [x, y, z] = xyz;
    Some(match plane {
        ArcPlane::Xy => [x?, y?, z?],
        ArcPlane::Zx => [z?, x?, y?],
        ArcPlane::Yz => [y?, z?, x?],
    })
}

impl ArcPath {
    /// The arc from `from` to `to` about `centre` (in the plane of `axes`),
    /// sweeping `sweep_deg` (positive) clockwise or not.
    pub fn new(
        axes: [usize; 3],
        centre: [f64; 2],
        from: &Joints,
        to: &Joints,
        sweep_deg: f64,
        clockwise: bool,
    ) -> ArcPath {
        let [u, v, _] = axes;
        let (du0, dv0) = (from[u] - centre[0], from[v] - centre[1]);
        let (du1, dv1) = (to[u] - centre[0], to[v] - centre[1]);
        let sweep = sweep_deg.to_radians();
        ArcPath {
            axes,
            centre,
            radius: [du0.hypot(dv0), du1.hypot(dv1)],
            start_rad: dv0.atan2(du0),
            sweep_rad: if clockwise { -sweep } else { sweep },
        }
    }

    /// The plane coordinates at `t` (0 start, 1 end).
    #[inline]
    pub fn at(&self, t: f64) -> [f64; 2] {
        let r = self.radius[0] + t * (self.radius[1] - self.radius[0]);
        let (s, c) = (self.start_rad + t * self.sweep_rad).sin_cos();
        [self.centre[0] + r * c, self.centre[1] + r * s]
    }

    /// The parameters `t` strictly inside (0, 1) at which the angle passes
    /// a multiple of 90°: where a plane coordinate turns back (its extremes),
    /// in increasing order.
    pub fn quadrant_crossings(&self, out: &mut Vec<f64>) {
        out.clear();
        if self.sweep_rad == 0.0 {
            return;
        }
        let a0 = self.start_rad;
        let a1 = self.start_rad + self.sweep_rad;
        let (lo, hi) = (a0.min(a1), a0.max(a1));
        let mut k = (lo / FRAC_PI_2).floor() + 1.0;
        while k * FRAC_PI_2 < hi {
            let t = (k * FRAC_PI_2 - a0) / self.sweep_rad;
            if t > 0.0 && t < 1.0 {
                out.push(t);
            }
            k += 1.0;
            // (A sweep is at most a few thousand turns: bounded.)
            if out.len() > 4 * 100_000 {
                break;
            }
        }
        out.sort_by(f64::total_cmp);
    }

    /// Parameter steps for a chord error of at most `tol_mm`: the number
    /// of pieces to sample the arc in.
    pub fn pieces(&self, tol_mm: f64) -> usize {
        let r = self.radius[0].max(self.radius[1]);
        if r <= tol_mm {
            return 1;
        }
        // Chord error of a step δ: r (1 − cos(δ/2)) ≤ tol.
        let step = 2.0 * (1.0 - tol_mm / r).acos();
        ((self.sweep_rad.abs() / step).ceil() as usize).max(1)
    }
}

impl BlockPath {
    /// The joints at `t` (0 start, 1 end) into `q` (its first `n` entries).
    #[inline]
    pub fn at(&self, t: f64, q: &mut [f64]) {
        if t >= 1.0 {
            q[..self.n].copy_from_slice(&self.to[..self.n]);
            return;
        }
        match &self.shape {
            Shape::Joint => self.lerp(t, q),
            Shape::Rapid { reach } => {
                let ends = self.from.iter().zip(&self.to).zip(reach);
                for (q, ((a, b), r)) in q[..self.n].iter_mut().zip(ends) {
                    let f = if *r <= 0.0 { 1.0 } else { (t / r).min(1.0) };
                    *q = a + f * (b - a);
                }
            }
            Shape::Arc(arc) => {
                self.lerp(t, q);
                let [u, v] = arc.at(t);
                q[arc.axes[0]] = u;
                q[arc.axes[1]] = v;
            }
        }
    }

    /// Every axis linear from `from` to `to`, at `t`.
    #[inline]
    fn lerp(&self, t: f64, q: &mut [f64]) {
        let ends = self.from.iter().zip(&self.to);
        for (q, (a, b)) in q[..self.n].iter_mut().zip(ends) {
            *q = a + t * (b - a);
        }
    }

    /// The smallest and largest value axis `i` takes along the block:
    /// exact (a linear axis and a rapid's axes move monotonically; an arc's
    /// plane coordinates are taken at its ends and where it crosses a
    /// quadrant), with `crossings` as scratch space.
    pub fn range(&self, i: usize, crossings: &mut Vec<f64>) -> [f64; 2] {
        let (a, b) = (self.from[i], self.to[i]);
        let mut r = [a.min(b), a.max(b)];
        if let Shape::Arc(arc) = &self.shape
            && (i == arc.axes[0] || i == arc.axes[1])
        {
            let k = usize::from(i == arc.axes[1]);
            arc.quadrant_crossings(crossings);
            for &t in crossings.iter() {
                let c = arc.at(t)[k];
                r = [r[0].min(c), r[1].max(c)];
            }
        }
        r
    }

    /// The parameters that split the block into pieces along which every
    /// axis moves monotonically (never turns back), 0 and 1 included: the
    /// swept collision test needs it.
    pub fn monotonic_breaks(&self, out: &mut Vec<f64>) {
        match &self.shape {
            Shape::Arc(arc) => {
                let mut inner = Vec::new();
                arc.quadrant_crossings(&mut inner);
                out.clear();
                out.push(0.0);
                out.extend(inner);
                out.push(1.0);
            }
            _ => {
                out.clear();
                out.extend([0.0, 1.0]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn joints(v: &[f64]) -> Joints {
        let mut q = [0.0; MAX_AXES];
        q[..v.len()].copy_from_slice(v);
        q
    }

    /// A half circle of radius 10 about the origin from (10, 0) to (-10, 0)
    /// counter-clockwise passes (0, 10): Y reaches 10 inside the block,
    /// though it is 0 at both ends.
    #[test]
    fn half_circle_range_reaches_its_top() {
        let (from, to) = (joints(&[10.0, 0.0, 0.0]), joints(&[-10.0, 0.0, 0.0]));
        let arc = ArcPath::new([0, 1, 2], [0.0, 0.0], &from, &to, 180.0, false);
        let p = BlockPath {
            n: 3,
            from,
            to,
            shape: Shape::Arc(arc),
        };
        let mut s = Vec::new();
        let [lo, hi] = p.range(1, &mut s);
        assert_eq!(lo, 0.0);
        assert!((hi - 10.0).abs() < 1e-12, "{hi}");
        // Clockwise the other way round: down to -10.
        let arc = ArcPath::new([0, 1, 2], [0.0, 0.0], &from, &to, 180.0, true);
        let p = BlockPath {
            shape: Shape::Arc(arc),
            ..p
        };
        let [lo, hi] = p.range(1, &mut s);
        assert!((lo + 10.0).abs() < 1e-12 && hi == 0.0, "{lo} {hi}");
    }

    #[test]
    fn rapid_axes_arrive_at_their_own_time() {
        let p = BlockPath {
            n: 2,
            from: joints(&[0.0, 0.0]),
            to: joints(&[100.0, 10.0]),
            shape: Shape::Rapid {
                reach: joints(&[1.0, 0.1]),
            },
        };
        let mut q = [0.0; 2];
        p.at(0.1, &mut q);
        assert_eq!(q, [10.0, 10.0]);
        p.at(0.5, &mut q);
        assert_eq!(q, [50.0, 10.0]);
    }
}
