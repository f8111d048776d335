//! `--frame absolute`: the CL's geometry mapped out of the machine
//! coordinate system of the `MSYS` in force into the absolute frame
//! (`Frame::to_outer` for points, `direction_to_outer` for axes).

use kinpost_cl::{ClEvent, Frame, Move};

/// A `GOTO` (or the fast path's move) in the absolute frame.
pub(super) fn move_out(frame: &Frame, m: &mut Move) {
    m.point = frame.to_outer(m.point);
    m.axis = frame.direction_to_outer(m.axis);
    m.reference = m.reference.map(|r| frame.direction_to_outer(r));
}

/// A statement's geometry in the absolute frame: points, axes, circles
/// and NURBS curves; every other statement as it is.
pub(super) fn event_out(frame: &Frame, event: ClEvent) -> ClEvent {
    let point = |p| frame.to_outer(p);
    let axis = |v| frame.direction_to_outer(v);
    match event {
        ClEvent::Goto {
            point: p,
            axis: a,
            reference,
            motion,
        } => ClEvent::Goto {
            point: point(p),
            axis: axis(a),
            reference: reference.map(axis),
            motion,
        },
        ClEvent::Circle(mut c) => {
            c.centre = point(c.centre);
            c.axis = axis(c.axis);
            ClEvent::Circle(c)
        }
        ClEvent::Nurbs(n) => ClEvent::Nurbs(n.map_points(point)),
        ClEvent::From { point: p, axis: a } => ClEvent::From {
            point: point(p),
            axis: a.map(axis),
        },
        ClEvent::GoHome { point: p, axis: a } => ClEvent::GoHome {
            point: p.map(point),
            axis: a.map(axis),
        },
        other => other,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An MCS turned 90° about Z and moved by (100, 0, 50): its X is the
    /// absolute Y, its origin the absolute (100, 0, 50).
    #[test]
    fn points_and_axes_leave_a_turned_mcs() {
        let f = Frame::from_axes([100.0, 0.0, 50.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]).unwrap();
        let mut m = Move {
            point: [10.0, 0.0, 0.0],
            axis: [1.0, 0.0, 0.0],
            ..Move::default()
        };
        move_out(&f, &mut m);
        assert_eq!(m.point, [100.0, 10.0, 50.0]);
        assert_eq!(m.axis, [0.0, 1.0, 0.0]);
        let ClEvent::GoHome { point, axis } = event_out(
            &f,
            ClEvent::GoHome {
                point: Some([0.0, 2.0, 1.0]),
                axis: None,
            },
        ) else {
            panic!()
        };
        assert_eq!((point, axis), (Some([98.0, 0.0, 51.0]), None));
    }
}
