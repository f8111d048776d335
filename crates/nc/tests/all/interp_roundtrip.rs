//! write → read is the identity: random programs written with `NcWriter` in
//! every built-in dialect (rapid and feed blocks, with and without
//! tool-centre-point control, with and without inverse-time feed, comments,
//! spindle and coolant commands, the pressure word where the dialect has
//! one) read back by the interpreter give every block's values exactly as
//! written: the written, rounded value of every axis (endless axes in
//! [0, 360)), the motion, the feed in force and its mode, the TCP state.

use kinpost_nc::interp::{Event, Family, FeedMode, MotionKind, Options, read_all};
use kinpost_nc::{AxisSpec, Block, Dialect, Motion, NcWriter, ProgramInfo, Spindle};
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
        )
            .prop_map(|(rapid, values, feed, pressure, comment, command)| Input {
                rapid,
                values,
                feed,
                pressure,
                comment,
                command,
            }),
        1..40,
    )
}

/// What a block must read back as.
#[derive(Debug, Clone, PartialEq)]
struct Expected {
    rapid: bool,
    axes: Vec<f64>,
    feed: Option<f64>,
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
    let mut expected = Vec::new();
    let mut state: Vec<f64> = vec![0.0; n];
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
        let before = w.blocks_written();
        w.block(&Block {
            cl_line: Some(k + 1),
            motion,
            axes: &v,
            feed: Some(b.feed),
        })
        .unwrap();
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
        expected.push(Expected {
            rapid: b.rapid,
            axes: state.clone(),
            feed: if b.rapid { None } else { feed },
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
            Event::Move(m) => Some(m.clone()),
            _ => None,
        })
        .collect();
    prop_assert_eq!(moves.len(), expected.len(), "{}: {}", name, text);
    for (m, e) in moves.iter().zip(&expected) {
        prop_assert_eq!(m.kind == MotionKind::Rapid, e.rapid, "{}", text);
        prop_assert_eq!(m.axes(), e.axes.as_slice(), "{}: {}", name, text);
        if let Some(f) = e.feed {
            prop_assert_eq!(m.feed, f, "{}", text);
            let mode = if inverse {
                FeedMode::InverseTime
            } else {
                FeedMode::PerMinute
            };
            prop_assert_eq!(m.feed_mode, mode);
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
