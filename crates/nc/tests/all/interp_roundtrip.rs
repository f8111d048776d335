//! write → read is the identity: random programs written with `NcWriter` in
//! every built-in dialect (rapid and feed blocks, with and without
//! tool-centre-point control, with and without inverse-time feed, comments,
//! spindle and coolant commands, the pressure word where the dialect has
//! one, circular and helical blocks in every plane where the dialect writes
//! arcs) read back by the interpreter give every block as written, in the
//! block model the writer takes ([`kinpost_nc::interp::Step::block`]): the
//! written, rounded value of every axis (endless axes in [0, 360)), the
//! motion, the feed in force and its mode, the arc's plane, sense and
//! centre, the CL line of a CSV row, the TCP state.

use kinpost_nc::interp::{Event, Family, FeedMode, Options, read_all};
use kinpost_nc::{
    ArcMotion, ArcPlane, AxisSpec, Block, Dialect, Motion, NcWriter, ProgramInfo, Spindle,
};
use proptest::prelude::*;

fn axes(pressure: bool) -> Vec<AxisSpec> {
    let mut a = vec![
        AxisSpec::linear("X"),
        AxisSpec::endless("A"),
        AxisSpec::linear("Y"),
        AxisSpec::linear("Z"),
        AxisSpec::rotary("B"),
        AxisSpec::rotary("C").fixed(),
    ];
    if pressure {
        a.push(AxisSpec::pressure_word("H1"));
    }
    a
}

/// A value in [0, 360), as the interpreter reports an endless axis.
fn wrap(v: f64) -> f64 {
    let r = v.rem_euclid(360.0);
    if r >= 360.0 { 0.0 } else { r + 0.0 }
}

#[derive(Debug, Clone)]
struct Input {
    rapid: bool,
    values: [f64; 6],
    feed: f64,
    pressure: f64,
    comment: Option<String>,
    command: u8,
    /// A circle instead of a line (where the dialect writes arcs, on a
    /// feed block): plane, clockwise, radius, the centre's direction from
    /// the start, the angle swept (rad) and the helix's travel.
    arc: Option<(u8, bool, f64, f64, f64, f64)>,
}

fn inputs() -> impl Strategy<Value = Vec<Input>> {
    proptest::collection::vec(
        (
            any::<bool>(),
            [
                -2000.0..2000.0f64,
                -720.0..720.0f64,
                -500.0..500.0f64,
                -100.0..900.0f64,
                -60.0..60.0f64,
                -1.0..1.0f64,
            ],
            prop_oneof![Just(250.0), 1.0..20000.0f64, 0.01..5.0f64],
            prop_oneof![Just(3000.0), 2800.0..3700.0f64],
            proptest::option::of("[ -~]{0,30}"),
            0u8..8,
            proptest::option::weighted(
                0.3,
                (
                    0u8..3,
                    any::<bool>(),
                    1.0..200.0f64,
                    0.0..std::f64::consts::TAU,
                    0.1..6.2f64,
                    prop_oneof![Just(0.0), -20.0..20.0f64],
                ),
            ),
        )
            .prop_map(
                |(rapid, values, feed, pressure, comment, command, arc)| Input {
                    rapid,
                    values,
                    feed,
                    pressure,
                    comment,
                    command,
                    arc,
                },
            ),
        1..40,
    )
}

/// The program X, Y, Z of the machine of [`axes`].
const XYZ: [usize; 3] = [0, 2, 3];

/// The end of a circle from `start` (program X, Y, Z): its plane, sense,
/// centre offset and end point.
fn circle(start: [f64; 3], arc: (u8, bool, f64, f64, f64, f64)) -> (ArcMotion, [f64; 3]) {
    let (plane, clockwise, r, phase, sweep, helix) = arc;
    let plane = [ArcPlane::Xy, ArcPlane::Zx, ArcPlane::Yz][usize::from(plane)];
    let [a, b, n] = plane.axes();
    let mut centre_offset = [0.0; 3];
    centre_offset[a] = r * phase.cos();
    centre_offset[b] = r * phase.sin();
    // The start is at angle phase + π seen from the centre.
    let end_angle = phase + std::f64::consts::PI + if clockwise { -sweep } else { sweep };
    let mut end = start;
    end[a] = start[a] + centre_offset[a] + r * end_angle.cos();
    end[b] = start[b] + centre_offset[b] + r * end_angle.sin();
    end[n] = start[n] + helix;
    let arc = ArcMotion {
        plane,
        clockwise,
        centre_offset,
    };
    (arc, end)
}

fn round_trip(name: &str, input: &[Input], tcp: bool, inverse: bool) -> Result<(), TestCaseError> {
    let dialect = Dialect::builtin(name).unwrap();
    let family = Family::of_dialect(&dialect).unwrap();
    let pressure = dialect.writes_pressure() || name == "csv";
    let axes = axes(pressure);
    let n = axes.len();
    let mut w = NcWriter::new(&dialect, &axes, Vec::new());
    let inverse = inverse
        && (name == "csv"
            || dialect
                .template(kinpost_nc::TemplateKind::InverseTimeOn)
                .is_some());
    let tcp = tcp && name != "csv";
    if inverse && name == "csv" {
        w.add_feed_mode_column();
    }
    let info = ProgramInfo {
        program_name: "RT (1)".into(),
        machine: "test".into(),
        tool: "T1".into(),
        tool_number: 1,
        ..ProgramInfo::default()
    };
    w.header(&info, None).unwrap();
    if tcp {
        w.tcp(true).unwrap();
    }
    if inverse {
        w.inverse_time(true).unwrap();
    }
    let mut expected: Vec<Block<Vec<f64>>> = Vec::new();
    let mut state: Vec<f64> = vec![0.0; n];
    let mut last = vec![0.0; n];
    let mut feed = None;
    let feed_format = dialect.feed_format().word.number;
    for (k, b) in input.iter().enumerate() {
        if let Some(text) = &b.comment {
            w.comment(text).unwrap();
        }
        match b.command {
            1 => w.spindle(Spindle::Cw(3000.0)).unwrap(),
            2 => w.coolant(Some("flood")).unwrap(),
            _ => {}
        }
        let mut v: Vec<f64> = b.values.to_vec();
        v[0] += k as f64;
        if pressure {
            v.push(b.pressure);
        }
        let motion = if b.rapid { Motion::Rapid } else { Motion::Feed };
        let mut arc = None;
        let plane_of = |a: &(u8, bool, f64, f64, f64, f64)| {
            [ArcPlane::Xy, ArcPlane::Zx, ArcPlane::Yz][usize::from(a.0)]
        };
        if let Some(a) = b
            .arc
            // (No arc before a first block: an absolute centre, Heidenhain's
            // CC, needs a start.)
            .filter(|a| !b.rapid && w.blocks_written() > 0 && w.writes_arc(plane_of(a), a.5 != 0.0))
        {
            // From the point written last, rotary axes standing.
            let (circle, end) = circle(XYZ.map(|i| state[i]), a);
            for (k, &i) in XYZ.iter().enumerate() {
                v[i] = end[k];
            }
            for i in [1, 4] {
                v[i] = last[i];
            }
            arc = Some(circle);
        }
        let before = w.blocks_written();
        w.block(&Block {
            arc,
            motion,
            ..Block::feed(v.as_slice(), b.feed).with_cl_line(k + 1)
        })
        .unwrap();
        last.clone_from(&v);
        if w.blocks_written() == before {
            continue;
        }
        for (i, a) in axes.iter().enumerate() {
            if a.fixed && !dialect.block_format().write_fixed && name != "csv" {
                continue;
            }
            let q = w.quantized(i, v[i]);
            state[i] = if a.endless { wrap(q) } else { q };
        }
        if !b.rapid {
            feed = Some(feed_format.quantize(b.feed));
        }
        expected.push(Block {
            cl_line: (name == "csv").then_some(k + 1),
            motion,
            feed: if b.rapid { None } else { feed },
            arc: arc.map(|mut a| {
                a.centre_offset = [0, 1, 2].map(|k| w.quantized_centre(k, a.centre_offset[k]));
                // (The centre along the plane's normal is not written: the
                // start's.)
                a.centre_offset[a.plane.axes()[2]] = 0.0;
                a
            }),
            ..Block::rapid(state.clone())
        });
    }
    if inverse {
        w.inverse_time(false).unwrap();
    }
    if tcp {
        w.tcp(false).unwrap();
    }
    w.footer(&info, None).unwrap();
    let text = String::from_utf8(w.finish().unwrap()).unwrap();
    let options = Options {
        tcp_mcodes: (name == "linuxcnc").then_some((428, 429)),
        ..Options::default()
    };
    let (steps, _) = read_all(&text, family, &axes, &options, "rt")
        .map_err(|e| TestCaseError::fail(format!("{name}: {e}\n{text}")))?;
    let moves: Vec<_> = steps
        .iter()
        .filter_map(|s| match &s.event {
            Event::Move(m) => Some((s, m)),
            _ => None,
        })
        .collect();
    prop_assert_eq!(moves.len(), expected.len(), "{}: {}", name, text);
    for ((step, m), e) in moves.iter().zip(&expected) {
        let read = step.block().unwrap();
        prop_assert_eq!(read.cl_line, e.cl_line, "{}", text);
        prop_assert_eq!(read.motion, e.motion, "{}", text);
        prop_assert_eq!(read.axes, e.axes.as_slice(), "{}: {}", name, text);
        if e.feed.is_some() {
            prop_assert_eq!(read.feed, e.feed, "{}", text);
            let mode = if inverse {
                FeedMode::InverseTime
            } else {
                FeedMode::PerMinute
            };
            prop_assert_eq!(m.feed_mode, mode);
        }
        match (read.arc, e.arc) {
            (None, None) => {}
            (Some(r), Some(e)) => {
                prop_assert_eq!((r.plane, r.clockwise), (e.plane, e.clockwise), "{}", text);
                // (The interpreter resolves the absolute centre; its
                // offset from the start is the written one to a few ulps.)
                for k in 0..3 {
                    prop_assert!(
                        (r.centre_offset[k] - e.centre_offset[k]).abs() <= 1e-9,
                        "{:?} read as {:?}\n{}",
                        e,
                        r,
                        text
                    );
                }
            }
            (r, e) => prop_assert!(false, "arc {:?} read as {:?}\n{}", e, r, text),
        }
        prop_assert_eq!(m.state.tcp, tcp, "{}", text);
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn sinumerik(input in inputs(), tcp: bool, inverse: bool) {
        round_trip("sinumerik", &input, tcp, inverse)?;
    }

    #[test]
    fn fanuc(input in inputs(), tcp: bool, inverse: bool) {
        round_trip("fanuc", &input, tcp, inverse)?;
    }

    #[test]
    fn heidenhain(input in inputs(), tcp: bool, inverse: bool) {
        round_trip("heidenhain", &input, tcp, inverse)?;
    }

    #[test]
    fn linuxcnc(input in inputs(), tcp: bool, inverse: bool) {
        round_trip("linuxcnc", &input, tcp, inverse)?;
    }

    #[test]
    fn csv(input in inputs(), inverse: bool) {
        round_trip("csv", &input, false, inverse)?;
    }
}
