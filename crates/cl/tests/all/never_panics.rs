//! Property tests: random bytes and random mutations of valid CL text never
//! make the reader panic or loop, and every diagnostic points into the input.

use kinpost_cl::{ClEvent, ClReader, Diagnostic};
use proptest::prelude::*;

const VALID: &str = "TOOL PATH/平板件测试,TOOL,代砂轮
TLDATA/MILL,25.0000,0.0000,75.0000,0.0000,0.0000
MSYS/226.8083,392.8435,0.0000,1.0000000,0.0000000,0.0000000,0,1,0
$$ centerline data
PAINT/COLOR,186
RAPID
GOTO/-416.0000,70.5000,16.5300,0.0000000,0.0000000,1.0000000
FEDRAT/MMPM,250.0000
GOTO/-416.0000,70.3931,11.3684
GOTO / 1, 2, 3, 0, 0.6, 0.8, 1, 0, 0 $$ with a reference
GOTO/1,2,$
  3,0,0,1
FEDRAT/ 250, MMPM
LOAD/TOOL,1
SELECT/TOOL,5
SPINDL/12000,RPM,CLW
COOLNT/FLOOD
INSERT/G05.1 Q1
PRESSURE/H1,3000
UNITS/INCHES
MULTAX/ON
CUTCOM/LEFT
CSYS/1.,0,0,0,0,1.,0,0,0,0,1.,0
SPINDL/OFF
GOTO/10,0,0,0,0,1
CIRCLE/0,0,0,0,0,-1,10,0.06,0.5,10,0
GOTO/0,10,0
CIRCLE / 0, 0, 0,  $
0, 0, 1, 10
GOTO / -10, 0, 0
       0, -10, 0
NURBS/
KNOT/0.5,1.0
CNTRL/1,1,1
CNTRL/2,2,2
CNTRL/3,3,3
CYCLE/DRILL,DEEP,RAPTO,3,FEDTO,-10,STEP,2,MMPM,100
GOTO/5,5,0
CYCLE / BRKCHP, DEPTH, 5, STEP, 1, MMPM, 40, CLEAR, 2, BACK, 0.2, TIMES, 3
GOTO/6,5,0
CYCLE/OFF
FROM/0,0,100,0,0,1
GOHOME
$$-> CSYS / 1, 0, 0, 0,  $
            0, 1, 0, 0
MACHIN/UNCX01,1
LOAD/TOOL,2,ADJUST,2
SPINDL/RPM,200,SMM,CCLW,MAXRPM,3000
STOP
OPSTOP
DELAY/2
Tool Path Listing has 53 lines.
END-OF-PATH
FINI
";

const PIECES: &[&str] = &[
    ",",
    "/",
    "$",
    "$$",
    "\n",
    "\r\n",
    "\r",
    " ",
    "\t",
    "GOTO/",
    "RAPID\n",
    "-",
    ".",
    "e",
    "E",
    "1",
    "0",
    "9",
    "é",
    "平",
    "\u{feff}",
    "CIRCLE/",
    "MSYS/",
    "FEDRAT/",
    "TOOL PATH/",
    "1e999",
    "NaN",
    "inf",
    "CIRCLE/0,0,0,0,0,1,",
    "NURBS/\n",
    "KNOT/",
    "CNTRL/",
    "CYCLE/DRILL,",
    "FEDTO,",
    "TIMES,",
    "BACK,",
    "1001",
    "CUTCOM/LEFT,XYPLAN,",
    "CSYS/",
    "MSYS/",
    "SPINDL/SFM,",
    "FROM/",
    "GOHOME",
    "$$-> ",
    "  1, 2, 3\n",
    "UNITS/INCHES\n",
    "IPM",
    "Information listing created by x\nDate\t1\n",
];

/// Reads everything, going on after errors; checks every diagnostic.
fn check(bytes: &[u8], default_axis: bool) {
    let lines: Vec<String> = bytes
        .split(|&b| b == b'\n')
        .enumerate()
        .map(|(i, l)| {
            let l = l.strip_suffix(b"\r").unwrap_or(l);
            let l = if i == 0 {
                l.strip_prefix(b"\xef\xbb\xbf").unwrap_or(l)
            } else {
                l
            };
            String::from_utf8_lossy(l).into_owned()
        })
        .collect();
    let check_diag = |d: &Diagnostic| {
        assert!(d.line >= 1 && d.line <= lines.len(), "{d:?}");
        assert_eq!(d.source_line, lines[d.line - 1], "{d:?}");
        let chars = d.source_line.chars().count();
        assert!(d.column >= 1 && d.column + d.width <= chars + 2, "{d:?}");
        let _ = d.to_string();
    };
    let mut reader = ClReader::new(bytes, "fuzz.cls");
    if default_axis {
        reader = reader.with_default_axis([0.0, 0.0, 1.0]);
    }
    // Each call consumes at least one line, except that a further point of
    // a Creo GOTO after an arc gives two statements (the circle again).
    for _ in 0..=2 * lines.len() + 1 {
        let result = reader.next_statement();
        for w in reader.take_warnings() {
            check_diag(&w);
        }
        match result {
            Ok(None) => return,
            Ok(Some(s)) => {
                assert!(s.line >= 1 && s.line <= lines.len());
                if let ClEvent::Goto {
                    point,
                    axis,
                    reference,
                    ..
                } = s.event
                {
                    assert!(point.iter().all(|v| v.is_finite()));
                    let n = axis.iter().map(|v| v * v).sum::<f64>();
                    assert!((n - 1.0).abs() < 1e-12, "{axis:?}");
                    if let Some(r) = reference {
                        let n = r.iter().map(|v| v * v).sum::<f64>();
                        assert!((n - 1.0).abs() < 1e-12, "{r:?}");
                    }
                }
            }
            Err(e) => check_diag(&e),
        }
    }
    panic!("the reader did not finish");
}

#[derive(Debug, Clone)]
enum Edit {
    Delete(usize, usize),
    Insert(usize, usize),
    InsertByte(usize, u8),
    Duplicate(usize, usize),
}

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        (any::<usize>(), 0..20usize).prop_map(|(at, n)| Edit::Delete(at, n)),
        (any::<usize>(), 0..PIECES.len()).prop_map(|(at, p)| Edit::Insert(at, p)),
        (any::<usize>(), any::<u8>()).prop_map(|(at, b)| Edit::InsertByte(at, b)),
        (any::<usize>(), 0..60usize).prop_map(|(at, n)| Edit::Duplicate(at, n)),
    ]
}

fn apply(mut text: Vec<u8>, edits: &[Edit]) -> Vec<u8> {
    for e in edits {
        let len = text.len();
        match *e {
            Edit::Delete(at, n) if len > 0 => {
                let at = at % len;
                text.drain(at..(at + n).min(len));
            }
            Edit::Insert(at, p) => {
                let at = at % (len + 1);
                text.splice(at..at, PIECES[p].bytes());
            }
            Edit::InsertByte(at, b) => text.insert(at % (len + 1), b),
            Edit::Duplicate(at, n) if len > 0 => {
                let at = at % len;
                let piece: Vec<u8> = text[at..(at + n).min(len)].to_vec();
                text.splice(at..at, piece);
            }
            _ => {}
        }
    }
    text
}

#[test]
fn the_valid_text_is_valid() {
    let mut reader = ClReader::new(VALID.as_bytes(), "valid.cls");
    let mut n = 0;
    while reader
        .next_statement()
        .unwrap_or_else(|e| panic!("{e}"))
        .is_some()
    {
        n += 1;
    }
    assert_eq!(n, 45);
    assert_eq!(reader.take_warnings(), vec![]);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn random_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..400), axis: bool) {
        check(&bytes, axis);
    }

    #[test]
    fn random_pieces_never_panic(pieces in proptest::collection::vec(0..PIECES.len(), 0..80), axis: bool) {
        let text: String = pieces.iter().map(|&p| PIECES[p]).collect();
        check(text.as_bytes(), axis);
    }

    #[test]
    fn mutated_cl_never_panics(edits in proptest::collection::vec(edit(), 1..12), axis: bool) {
        let text = apply(VALID.as_bytes().to_vec(), &edits);
        check(&text, axis);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(5000))]

    /// The fast number parser agrees with std on every APT-style number.
    #[test]
    fn numbers_agree_with_std(text in "[+-]?[0-9]{0,24}(\\.[0-9]{0,24})?([eE][+-]?[0-9]{1,3})?") {
        let std = text.parse::<f64>().ok().filter(|v| v.is_finite());
        prop_assert_eq!(kinpost_cl::parse_number(&text).map(f64::to_bits), std.map(f64::to_bits));
    }

    #[test]
    fn formatted_floats_round_trip(v in any::<f64>().prop_filter("finite", |v| v.is_finite()), decimals in 0usize..9) {
        for text in [format!("{v}"), format!("{v:e}"), format!("{v:.decimals$}"), format!("{:.decimals$}", v / 1e12)] {
            let std = text.parse::<f64>().ok();
            prop_assert_eq!(kinpost_cl::parse_number(&text).map(f64::to_bits), std.map(f64::to_bits), "{}", text);
        }
    }

    /// GOTO values come out exactly as std parses them, whatever the spacing.
    #[test]
    fn goto_values_match_std(
        values in proptest::collection::vec(-1000.0f64..1000.0, 6),
        decimals in proptest::collection::vec(0usize..8, 6),
        spaces in proptest::collection::vec(0usize..3, 12),
    ) {
        let fields: Vec<String> = values
            .iter()
            .zip(&decimals)
            .zip(spaces.chunks(2))
            .map(|((v, &d), s)| format!("{}{v:.d$}{}", " ".repeat(s[0]), "\t".repeat(s[1])))
            .collect();
        // Keep the axis non-zero.
        let line = format!("GOTO/{},1\n", fields[..5].join(","));
        let mut reader = ClReader::new(line.as_bytes(), "p.cls");
        let s = reader.next_statement().unwrap().unwrap();
        let expected: Vec<f64> = fields[..5].iter().map(|f| f.trim().parse().unwrap()).collect();
        match s.event {
            ClEvent::Goto { point, .. } => prop_assert_eq!(point.to_vec(), expected[..3].to_vec()),
            other => prop_assert!(false, "{:?}", other),
        }
    }
}
