//! The hole expansions written out by hand from the G-code definitions of
//! each cycle (LinuxCNC G-code reference: G73, G83, G84, G85).

use super::*;

const Z: [f64; 3] = [0.0, 0.0, 1.0];

fn cycle(motion: HoleMotion, dwell_s: f64) -> HoleCycle {
    HoleCycle {
        motion,
        depth_mm: 4.0,
        feed_start_mm: 1.0,
        retract_mm: 5.0,
        feed_mm_min: 100.0,
        dwell_s,
    }
}

fn z(h: f64) -> [f64; 3] {
    [0.0, 0.0, h]
}

/// G73: feed a peck, back off, feed on (from where it backed off to);
/// out of the hole after every second peck, then rapid down to the
/// clearance above the bottom.
#[test]
fn chip_breaking() {
    let c = cycle(
        HoleMotion::ChipBreak {
            first_mm: 1.5,
            next_mm: 1.5,
            back_off_mm: 0.5,
            full_retract_every: Some(2),
        },
        0.0,
    );
    use HoleStep::{Feed, Rapid};
    assert_eq!(
        c.expand([0.0; 3], Z, z(10.0)),
        [
            Rapid(z(1.0)),
            Feed(z(-0.5)),
            Rapid(z(0.0)),
            Feed(z(-2.0)),
            Rapid(z(1.0)),
            Rapid(z(-2.0 + PECK_CLEARANCE_MM)),
            Feed(z(-3.5)),
            Rapid(z(-3.0)),
            Feed(z(-4.0)),
            Rapid(z(5.0)),
        ]
    );
}

/// G85/G89: feed in, dwell, feed out to R, then up to the retract height.
#[test]
fn boring_feeds_out() {
    let c = cycle(HoleMotion::Bore, 0.5);
    use HoleStep::{Dwell, Feed, Rapid};
    assert_eq!(
        c.expand([0.0; 3], Z, z(10.0)),
        [
            Rapid(z(1.0)),
            Feed(z(-4.0)),
            Dwell(0.5),
            Feed(z(1.0)),
            Rapid(z(5.0)),
        ]
    );
}

/// A tool below the feed start goes up along its own axis first, then
/// across.
#[test]
fn a_tool_below_the_feed_start_goes_up_first() {
    let c = cycle(HoleMotion::Drill, 0.0);
    use HoleStep::{Feed, Rapid};
    assert_eq!(
        c.expand([0.0; 3], Z, [7.0, 0.0, -2.0]),
        [
            Rapid([7.0, 0.0, 1.0]),
            Rapid(z(1.0)),
            Feed(z(-4.0)),
            Rapid(z(5.0)),
        ]
    );
}

fn raw(kind: CycleKind) -> Cycle {
    Cycle {
        kind,
        depth_mm: Some(4.0),
        feed_start_mm: Some(1.0),
        retract_mm: None,
        peck_mm: None,
        next_peck_mm: None,
        dwell: None,
        feed: None,
        pitch_mm: None,
        back_off_mm: None,
        full_retract_every: None,
    }
}

/// What cannot be expanded is an error naming what is missing.
#[test]
fn resolve_errors() {
    // No peck: one, the whole feed from the feed start to the bottom.
    let single = HoleCycle::resolve(&raw(CycleKind::Deep), Some(100.0), None).unwrap();
    assert!(HoleCycle::single_peck(&raw(CycleKind::Deep)));
    assert_eq!(
        single.expand([0.0; 3], Z, z(10.0)),
        [
            HoleStep::Rapid(z(single.feed_start_mm)),
            HoleStep::Feed(z(-single.depth_mm)),
            HoleStep::Rapid(z(single.retract_mm)),
        ]
    );
    assert_eq!(
        HoleCycle::resolve(&raw(CycleKind::Drill), None, None),
        Err(CycleError::NoFeed)
    );
    let mut c = raw(CycleKind::Deep);
    c.peck_mm = Some(1e-6);
    assert!(matches!(
        HoleCycle::resolve(&c, Some(100.0), None),
        Err(CycleError::TooManyPecks { .. })
    ));
    assert_eq!(
        HoleCycle::resolve(&raw(CycleKind::Other("FOO".into())), Some(1.0), None),
        Err(CycleError::Kind("FOO".into()))
    );
    let mut c = raw(CycleKind::Drill);
    c.depth_mm = None;
    assert_eq!(
        HoleCycle::resolve(&c, Some(100.0), None),
        Err(CycleError::NoDepth)
    );
    // A dwell in revolutions at 600 rpm: 60 / 600 s each.
    let mut c = raw(CycleKind::Drill);
    c.dwell = Some(Dwell::Revolutions(5.0));
    assert_eq!(
        HoleCycle::resolve(&c, Some(100.0), Some(600.0))
            .unwrap()
            .dwell_s,
        0.5
    );
}

/// NX's `FEDTO,0`: the hole point is the bottom, fed to from R.
#[test]
fn a_depth_of_zero_feeds_to_the_hole_point() {
    let mut c = raw(CycleKind::Drill);
    c.depth_mm = Some(0.0);
    let hole = HoleCycle::resolve(&c, Some(100.0), None).unwrap();
    assert_eq!(
        hole.expand([0.0; 3], Z, z(10.0)),
        [
            HoleStep::Rapid(z(1.0)),
            HoleStep::Feed(z(0.0)),
            HoleStep::Rapid(z(1.0))
        ]
    );
    c.depth_mm = Some(-1.0);
    assert!(matches!(
        HoleCycle::resolve(&c, Some(100.0), None),
        Err(CycleError::Distance { what: "depth", .. })
    ));
}

/// A cycle that opens the program (no point before it): the first hole is
/// reached at the retract height, not from an assumed origin.
#[test]
fn the_first_hole_of_a_program_is_reached_at_the_retract_height() {
    let c = cycle(HoleMotion::Drill, 0.0);
    assert_eq!(
        c.expand_from_unknown([3.0, 4.0, 0.0], Z),
        [
            HoleStep::Rapid([3.0, 4.0, 5.0]),
            HoleStep::Rapid([3.0, 4.0, 1.0]),
            HoleStep::Feed([3.0, 4.0, -4.0]),
            HoleStep::Rapid([3.0, 4.0, 5.0]),
        ]
    );
}
