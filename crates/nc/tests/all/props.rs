use kinpost_nc::{
    AxisSpec, Block, Dialect, Motion, NcWriter, NumberFormat, TrailingZeros, read_program,
};
use proptest::prelude::*;

/// The reference: std formatting, with `-0.000` made `0.000`.
fn reference(v: f64, d: usize) -> String {
    let s = format!("{v:.d$}");
    match s.strip_prefix('-') {
        Some(rest) if rest.bytes().all(|b| b == b'0' || b == b'.') => rest.to_string(),
        _ => s,
    }
}

fn styled(reference: &str, f: &NumberFormat) -> String {
    let mut s = reference.to_string();
    if f.trailing_zeros != TrailingZeros::Keep && s.contains('.') {
        while s.ends_with('0') {
            s.pop();
        }
        if f.trailing_zeros == TrailingZeros::Trim && s.ends_with('.') {
            s.pop();
        }
    }
    if f.trailing_zeros == TrailingZeros::Point && !s.contains('.') {
        s.push('.');
    }
    let (sign, body) = match s.strip_prefix('-') {
        Some(b) => ("-", b.to_string()),
        None => (if f.plus_sign { "+" } else { "" }, s.clone()),
    };
    let body = match body.strip_prefix("0.") {
        Some(frac) if !f.leading_zero && !frac.is_empty() => format!(".{frac}"),
        _ => body,
    };
    format!("{sign}{body}")
}

fn value() -> impl Strategy<Value = f64> {
    prop_oneof![
        -1000.0..1000.0f64,
        -1.0..1.0f64,
        -1e-3..1e-3f64,
        (-1e6..1e6f64),
        // Exact and near ties at 1..6 decimals.
        (-100000i64..100000, 1u32..7).prop_map(|(k, d)| (k as f64 + 0.5) / 10f64.powi(d as i32)),
        (-100000i64..100000).prop_map(|k| k as f64 / 16.0),
        Just(0.0),
        Just(-0.0),
    ]
}

fn format_strategy() -> impl Strategy<Value = NumberFormat> {
    (
        0u8..=9,
        prop_oneof![
            Just(TrailingZeros::Keep),
            Just(TrailingZeros::Point),
            Just(TrailingZeros::Trim)
        ],
        any::<bool>(),
        any::<bool>(),
    )
        .prop_map(
            |(decimals, trailing_zeros, leading_zero, plus_sign)| NumberFormat {
                decimals,
                trailing_zeros,
                leading_zero,
                plus_sign,
                modulo: None,
            },
        )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4000))]

    #[test]
    fn formatting_matches_std(v in value(), f in format_strategy()) {
        let d = usize::from(f.decimals);
        let got = f.format(v).unwrap();
        let want = styled(&reference(v, d), &f);
        prop_assert_eq!(&got, &want, "value {:e} decimals {}", v, d);
        prop_assert!(!got.starts_with("-0") || got.bytes().any(|b| (b'1'..=b'9').contains(&b)));
        // What is printed is what `quantize` says, bit for bit.
        let printed: f64 = got.parse().unwrap();
        prop_assert_eq!(printed.to_bits(), (f.quantize(v) + 0.0).to_bits());
    }

    #[test]
    fn modulo_stays_in_range(v in -5000.0..5000.0f64, d in 0u8..=6) {
        let f = NumberFormat { decimals: d, modulo: Some(360.0), ..NumberFormat::default() };
        let q = f.quantize(v);
        prop_assert!((0.0..360.0).contains(&q), "{} -> {}", v, q);
        let printed: f64 = f.format(v).unwrap().parse().unwrap();
        prop_assert_eq!(printed, q);
        // Same angle, up to the rounding.
        let diff = (q - v).rem_euclid(360.0);
        prop_assert!(diff.min(360.0 - diff) <= 0.5 / 10f64.powi(d as i32) + 1e-9);
    }
}

fn mts_axes() -> Vec<AxisSpec> {
    vec![
        AxisSpec::linear("X"),
        AxisSpec::endless("A"),
        AxisSpec::linear("Y"),
        AxisSpec::linear("Z"),
        AxisSpec::rotary("B"),
        AxisSpec::rotary("C").fixed(),
    ]
}

fn blocks() -> impl Strategy<Value = Vec<(bool, [f64; 6], f64)>> {
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
            prop_oneof![Just(250.0), 1.0..20000.0f64],
        ),
        1..60,
    )
}

const MODAL: &str = r#"
name = "modal"
extension = "nc"
[linear]
modal = true
decimals = 4
trailing_zeros = "trim"
leading_zero = false
[rotary]
modal = true
plus_sign = true
[axis.A]
prefix = "A=DC("
suffix = ")"
modulo = 360.0
[numbering]
enabled = true
[comment]
prefix = "("
suffix = ")"
"#;

fn round_trip(dialect: &Dialect, input: &[(bool, [f64; 6], f64)]) -> Result<(), TestCaseError> {
    let axes = mts_axes();
    let mut w = NcWriter::new(dialect, &axes, Vec::new());
    // What the program must say after each block, per axis (None = not yet).
    let mut expected = Vec::new();
    let mut state: Vec<Option<f64>> = vec![None; 6];
    let mut feed = None;
    for (k, (rapid, v, f)) in input.iter().enumerate() {
        // Make every block differ (X steps), so none is suppressed.
        let mut v = *v;
        v[0] += k as f64;
        let motion = if *rapid { Motion::Rapid } else { Motion::Feed };
        w.comment("block (k)").unwrap();
        w.block(&Block {
            line: None,
            number: None,
            arc: None,
            cl_line: Some(k + 1),
            motion,
            axes: &v,
            feed: Some(*f),
        })
        .unwrap();
        for (i, a) in axes.iter().enumerate() {
            if !a.fixed || dialect.block_format().write_fixed {
                state[i] = Some(w.quantized(i, v[i]));
                prop_assert_eq!(state[i], Some(dialect.quantize(a, v[i])));
            }
        }
        if motion == Motion::Feed {
            feed = Some(dialect.feed_format().word.number.quantize(*f));
        }
        expected.push((motion, state.clone(), feed));
    }
    let blocks_written = w.blocks_written();
    let text = String::from_utf8(w.finish().unwrap()).unwrap();
    let read = read_program(dialect, &axes, "rt.nc", &text).unwrap();
    prop_assert_eq!(read.len() as u64, blocks_written);
    prop_assert_eq!(read.len(), expected.len(), "{}", text);
    for (r, (motion, axes, feed)) in read.iter().zip(&expected) {
        prop_assert_eq!(r.motion, *motion);
        prop_assert_eq!(&r.axes, axes);
        prop_assert_eq!(r.feed, *feed);
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn sinumerik_round_trip(input in blocks()) {
        round_trip(&Dialect::builtin("sinumerik").unwrap(), &input)?;
    }

    #[test]
    fn modal_dialect_round_trip(input in blocks()) {
        round_trip(&Dialect::from_toml(MODAL, "modal.toml").unwrap(), &input)?;
    }

    #[test]
    fn csv_round_trip(input in blocks()) {
        let d = Dialect::builtin("csv").unwrap();
        let axes = mts_axes();
        let mut w = NcWriter::new(&d, &axes, Vec::new());
        for (k, (rapid, v, f)) in input.iter().enumerate() {
            let motion = if *rapid { Motion::Rapid } else { Motion::Feed };
            let cl = (k % 3 != 0).then_some(k);
            w.block(&Block { cl_line: cl, motion, ..Block::feed(v, *f) }).unwrap();
        }
        let text = String::from_utf8(w.finish().unwrap()).unwrap();
        let read = read_program(&d, &axes, "rt.csv", &text).unwrap();
        prop_assert_eq!(read.len(), input.len());
        for (k, (r, (rapid, v, f))) in read.iter().zip(&input).enumerate() {
            prop_assert_eq!(r.cl_line, (k % 3 != 0).then_some(k));
            for i in 0..6 {
                prop_assert_eq!(r.axes[i], Some(d.quantize(&axes[i], v[i])));
            }
            let want_feed = (!rapid).then(|| d.feed_format().word.number.quantize(*f));
            prop_assert_eq!(r.feed, want_feed);
        }
    }
}
