//! The CL a program was posted from, as the polyline of its `GOTO`s, and
//! the distance of replayed tool points and axes from it.

use std::io::BufRead;

use kinpost_cl::{Circle, ClEvent, ClReader, Move, Next};
use kinpost_post::cycle::{HoleCycle, HoleStep};
use nalgebra::Vector3;

use crate::SimError;

/// How many CL segments ahead of the last match a tool point is looked for:
/// the post writes one or more blocks per CL segment, so the match moves
/// forward by about one segment per block; a window keeps a path that comes
/// back near itself (a zigzag) from matching an earlier or later pass.
const WINDOW: usize = 64;

/// Chord tolerance of the CL's arcs in the polyline, mm: far below any
/// output rounding.
pub const ARC_CHORD_MM: f64 = 1e-5;

/// The most points of a CL's path (48 bytes each: 800 MB): a CL whose arcs
/// or holes make more (a million holes of ten thousand pecks) is refused,
/// not held in memory.
pub const MAX_CL_PATH_POINTS: usize = 1 << 24;

/// [`MAX_CL_PATH_POINTS`] holds for `points`, made up to CL line `line`.
fn within_bound(points: &[ClPoint], line: usize) -> Result<(), SimError> {
    if points.len() > MAX_CL_PATH_POINTS {
        return Err(SimError::ClTooLong {
            line,
            max: MAX_CL_PATH_POINTS,
        });
    }
    Ok(())
}

/// A CL motion the polyline cannot hold.
fn not_compared(line: usize, what: &'static str) -> SimError {
    SimError::ClNotCompared { line, what }
}

/// One `GOTO`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClPoint {
    /// Tool point, part frame, mm.
    pub point: Vector3<f64>,
    /// Tool axis, unit.
    pub axis: Vector3<f64>,
    /// Its CL line.
    pub line: usize,
}

/// The CL polyline and the place along it the replay has reached.
#[derive(Debug, Clone)]
pub struct ClPath {
    points: Vec<ClPoint>,
    cursor: usize,
}

/// A tool pose measured against the CL.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measured {
    /// Distance of the point from the polyline, mm.
    pub position_mm: f64,
    /// Angle between the axis and the CL's axis at the nearest point, rad.
    pub axis_rad: f64,
    /// CL line of the segment's first `GOTO`.
    pub cl_line: usize,
}

impl ClPath {
    /// The path of a CL file: its `GOTO`s, the arcs of its `CIRCLE`s as
    /// chords within [`ARC_CHORD_MM`] (the tool axis interpolated linearly
    /// along them), and the holes of its canned cycles as the post expands
    /// them (see [`kinpost_post::cycle`]: the moves along the hole axis a
    /// control's cycle makes). Other statements do not move the tool; a CL
    /// without any `GOTO` is an error, and so is a `NURBS` curve, which the
    /// polyline does not hold: it is not compared.
    pub fn read<R: BufRead>(input: R, file: &str) -> Result<ClPath, SimError> {
        let mut reader = ClReader::new(input, file);
        let mut points: Vec<ClPoint> = Vec::new();
        let mut circle: Option<(Box<Circle>, usize)> = None;
        let mut cycle: Option<HoleCycle> = None;
        let mut m = Move::default();
        loop {
            let (point, axis, line) = match reader.next_move(&mut m).map_err(SimError::Cl)? {
                Next::Move => (m.point, m.axis, m.line),
                Next::Statement(s) => match s.event {
                    ClEvent::Goto { point, axis, .. } => (point, axis, s.line),
                    ClEvent::Circle(c) => {
                        circle = Some((c, s.line));
                        continue;
                    }
                    ClEvent::Nurbs(_) => return Err(not_compared(s.line, "a NURBS curve")),
                    ClEvent::Cycle(c) => {
                        // Only the geometry counts here: any feed and speed.
                        let hole =
                            HoleCycle::resolve(&c, Some(1.0), Some(1.0)).map_err(|source| {
                                SimError::ClCycle {
                                    line: s.line,
                                    source,
                                }
                            })?;
                        cycle = Some(hole);
                        continue;
                    }
                    ClEvent::CycleOff => {
                        cycle = None;
                        continue;
                    }
                    _ => continue,
                },
                Next::End => break,
            };
            let goto = ClPoint {
                point: Vector3::from(point),
                axis: Vector3::from(axis),
                line,
            };
            if let Some(hole) = &cycle {
                let steps = match points.last() {
                    Some(at) => hole.expand(point, axis, at.point.into()),
                    None => hole.expand_from_unknown(point, axis),
                };
                for step in steps {
                    if let HoleStep::Rapid(p) | HoleStep::Feed(p) = step {
                        points.push(ClPoint {
                            point: Vector3::from(p),
                            ..goto
                        });
                    }
                }
                within_bound(&points, line)?;
                continue;
            }
            if let (Some((c, circle_line)), Some(prev)) = (circle.take(), points.last().copied()) {
                let arc = c
                    .arc(prev.point.into(), point)
                    .map_err(|source| SimError::ClArc {
                        line: circle_line,
                        source,
                    })?;
                let samples =
                    arc.sample(ARC_CHORD_MM)
                        .map_err(|source| SimError::ClArcSampling {
                            line: circle_line,
                            source,
                        })?;
                let n = samples.len();
                for (k, p) in samples.iter().enumerate().take(n.saturating_sub(1)) {
                    let t = (k + 1) as f64 / n as f64;
                    points.push(ClPoint {
                        point: Vector3::from(*p),
                        axis: prev.axis + t * (goto.axis - prev.axis),
                        line: circle_line,
                    });
                }
            }
            points.push(goto);
            within_bound(&points, line)?;
        }
        ClPath::new(points).ok_or_else(|| SimError::EmptyCl(file.to_string()))
    }

    /// A path through `points` (`None` when there are none).
    pub fn new(points: Vec<ClPoint>) -> Option<ClPath> {
        (!points.is_empty()).then_some(ClPath { points, cursor: 0 })
    }

    /// Number of `GOTO`s.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether there are none (never: [`ClPath::new`] refuses that).
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// The distance of `point` and `axis` from the polyline, searched from
    /// the segment last matched up to [`WINDOW`] segments ahead; the match
    /// moves on to the segment found.
    pub fn measure(&mut self, point: &Vector3<f64>, axis: &Vector3<f64>) -> Measured {
        let pts = &self.points;
        if pts.len() == 1 {
            let p = &pts[0];
            return Measured {
                position_mm: (point - p.point).norm(),
                axis_rad: angle(axis, &p.axis),
                cl_line: p.line,
            };
        }
        let last = pts.len() - 2;
        let (mut best, mut best_d2, mut best_s) = (self.cursor, f64::INFINITY, 0.0);
        for j in self.cursor..=(self.cursor + WINDOW).min(last) {
            let (a, b) = (&pts[j].point, &pts[j + 1].point);
            let ab = b - a;
            let len2 = ab.norm_squared();
            let s = if len2 > 0.0 {
                ((point - a).dot(&ab) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let d2 = (point - (a + s * ab)).norm_squared();
            if d2 < best_d2 {
                (best, best_d2, best_s) = (j, d2, s);
            }
        }
        self.cursor = best;
        let (a, b) = (&pts[best], &pts[best + 1]);
        let cl_axis = a.axis + best_s * (b.axis - a.axis);
        Measured {
            position_mm: best_d2.sqrt(),
            axis_rad: angle(axis, &cl_axis),
            cl_line: if best_s >= 1.0 { b.line } else { a.line },
        }
    }
}

/// The angle between two directions (not necessarily unit), radians, by
/// the half-angle formula (accurate near 0).
fn angle(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    let (na, nb) = (a.norm(), b.norm());
    if na == 0.0 || nb == 0.0 {
        return 0.0;
    }
    let (a, b) = (a / na, b / nb);
    2.0 * (a - b).norm().atan2((a + b).norm())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(x: f64, y: f64, line: usize) -> ClPoint {
        ClPoint {
            point: Vector3::new(x, y, 0.0),
            axis: Vector3::z(),
            line,
        }
    }

    /// The holes of a canned cycle are on the path as the post expands
    /// them: down to R, feed to the bottom, back out.
    #[test]
    fn a_hole_is_its_moves() {
        let cl = "GOTO/0,0,10,0,0,1\nCYCLE/DRILL,FEDTO,5,RAPTO,2,MMPM,100\nGOTO/5,0,0\nCYCLE/OFF\n";
        let path = ClPath::read(cl.as_bytes(), "h.cls").unwrap();
        let z: Vec<[f64; 3]> = path.points.iter().map(|p| p.point.into()).collect();
        assert_eq!(
            z,
            [
                [0.0, 0.0, 10.0],
                [5.0, 0.0, 10.0],
                [5.0, 0.0, 2.0],
                [5.0, 0.0, -5.0],
                [5.0, 0.0, 2.0]
            ]
        );
    }

    /// Holes of ten thousand pecks each make a path too long to hold: an
    /// error at the hole that passes the bound, not memory without end.
    #[test]
    fn a_path_too_long_is_refused() {
        let mut cl =
            String::from("GOTO/0,0,10,0,0,1\nCYCLE/DEEP,FEDTO,999,RAPTO,1,STEP,0.1,MMPM,100\n");
        for k in 0..900 {
            cl.push_str(&format!("GOTO/{k},0,0\n"));
        }
        match ClPath::read(cl.as_bytes(), "h.cls") {
            Err(SimError::ClTooLong { line, max }) => {
                assert_eq!(max, MAX_CL_PATH_POINTS);
                assert!((100..903).contains(&line), "{line}");
            }
            other => panic!("{:?}", other.map(|p| p.len())),
        }
    }

    #[test]
    fn distance_to_the_polyline() {
        let mut cl = ClPath::new(vec![p(0.0, 0.0, 1), p(10.0, 0.0, 2), p(10.0, 10.0, 3)]).unwrap();
        let m = cl.measure(&Vector3::new(5.0, 0.5, 0.0), &Vector3::z());
        assert!((m.position_mm - 0.5).abs() < 1e-12 && m.cl_line == 1);
        let m = cl.measure(&Vector3::new(11.0, 5.0, 0.0), &Vector3::x());
        assert!((m.position_mm - 1.0).abs() < 1e-12 && m.cl_line == 2);
        assert!((m.axis_rad - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    }
}
