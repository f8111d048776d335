//! Property tests: random bytes, random TOML-ish text and random mutations of
//! the built-in machine file never make the loader panic; every diagnostic
//! points into the input; and a machine that loads can be used: forward
//! kinematics at home and inverse kinematics of that pose do not panic.

use kinpost_machine::{Kinematics, builtin, machine_from_toml};
use proptest::prelude::*;

fn valid() -> &'static str {
    builtin::source("mts1600").expect("built-in mts1600")
}

const PIECES: &[&str] = &[
    "name = \"m\"\n",
    "[[axis]]\n",
    "[tool]\n",
    "[workpiece]\n",
    "[post]\n",
    "kind = \"linear\"\n",
    "kind = \"rotary\"\n",
    "side = \"tool\"\n",
    "side = \"workpiece\"\n",
    "direction = ",
    "point = ",
    "axis = ",
    "reference = ",
    "limits = ",
    "fixed = ",
    "machine_offset = ",
    "origin = ",
    "x = ",
    "z = ",
    "[1, 0, 0]\n",
    "[0, 1, 0]\n",
    "[0, 0, 1]\n",
    "[0, 0, 0]\n",
    "[-90, 90]\n",
    "[",
    "]",
    ",",
    "=",
    "\"",
    "\"\"\"",
    "'",
    "#",
    "\n",
    "\r\n",
    " ",
    "\t",
    "0",
    "1",
    "-1",
    "0.5",
    "nan",
    "inf",
    "-inf",
    "1e308",
    "-0",
    "1e-320",
    "{",
    "}",
    "é",
    "平",
    "\u{feff}",
    "[[solid]]\n",
    "[collision]\n",
    "[[collision.pair]]\n",
    "name = \"s\"\n",
    "on = \"tool\"\n",
    "on = \"A\"\n",
    "on = \"base\"\n",
    "box = { size = ",
    "cylinder = { radius = 5, height = ",
    "cone = { radius_bottom = 0, radius_top = 3, height = ",
    "sphere = { radius = ",
    " }\n",
    "mesh = \"no-such.stl\"\n",
    "mesh = \"/dev/null\"\n",
    "role = \"cutter\"\n",
    "role = \"stock\"\n",
    "group = \"head\"\n",
    "groups = [\"head\", \"wheel\"]\n",
    "ignore = [[\"wheel\", \"bed\"]]\n",
    "check = [[\"ram\", \"belt-head\"]]\n",
    "warning_clearance = ",
    "error_clearance = ",
];

const NUMBERS: &[&str] = &[
    "0",
    "-0",
    "1",
    "-1",
    "nan",
    "+nan",
    "-nan",
    "inf",
    "-inf",
    "1e308",
    "-1e308",
    "1e-308",
    "5e-324",
    "0.7071067811865476",
    "360",
    "3600",
    "1e9",
    "1e15",
    "\"1\"",
    "true",
];

/// Loads `bytes`; checks the diagnostics, or runs the kinematics.
fn check(bytes: &[u8]) {
    let text = String::from_utf8_lossy(bytes);
    match machine_from_toml(&text, "fuzz.toml") {
        Err(diags) => {
            assert!(!diags.0.is_empty());
            let lines = text.split('\n').count();
            for d in &diags.0 {
                assert!(d.line >= 1 && d.line <= lines, "{d:?}");
                assert!(d.column >= 1 && d.width >= 1, "{d:?}");
                assert_eq!(d.file, "fuzz.toml");
                let _ = d.to_string();
            }
        }
        Ok(m) => {
            let kin = Kinematics::new(&m);
            let home = m.home_joints();
            let pose = kin.fk(&home);
            let mut solutions = Vec::new();
            let _ = kin.ik(&pose, None, &mut solutions);
            let _ = kin.ik(&pose, Some(&home), &mut solutions);
            let _ = kin.ik_all_branches(&pose, None, &mut solutions);
        }
    }
}

#[derive(Debug, Clone)]
enum Edit {
    FlipByte(usize, u8),
    DeleteLine(usize),
    DuplicateLine(usize),
    SwapLines(usize, usize),
    /// Replace the n-th number of the text.
    Number(usize, usize),
    Insert(usize, usize),
}

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        (any::<usize>(), any::<u8>()).prop_map(|(at, b)| Edit::FlipByte(at, b)),
        any::<usize>().prop_map(Edit::DeleteLine),
        any::<usize>().prop_map(Edit::DuplicateLine),
        (any::<usize>(), any::<usize>()).prop_map(|(a, b)| Edit::SwapLines(a, b)),
        (any::<usize>(), 0..NUMBERS.len()).prop_map(|(at, n)| Edit::Number(at, n)),
        (any::<usize>(), 0..PIECES.len()).prop_map(|(at, p)| Edit::Insert(at, p)),
    ]
}

/// Byte ranges of the numbers of `text` (digits with signs, dots and
/// exponents).
fn numbers(text: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < text.len() {
        if text[i].is_ascii_digit() && (i == 0 || !text[i - 1].is_ascii_alphanumeric()) {
            let start = if i > 0 && text[i - 1] == b'-' {
                i - 1
            } else {
                i
            };
            let mut end = i;
            while end < text.len() && matches!(text[end], b'0'..=b'9' | b'.' | b'e' | b'E') {
                end += 1;
            }
            out.push((start, end));
            i = end;
        } else {
            i += 1;
        }
    }
    out
}

fn apply(mut text: Vec<u8>, edits: &[Edit]) -> Vec<u8> {
    for e in edits {
        match *e {
            Edit::FlipByte(at, b) if !text.is_empty() => {
                let at = at % text.len();
                text[at] ^= b;
            }
            Edit::DeleteLine(at) | Edit::DuplicateLine(at) | Edit::SwapLines(at, _) => {
                let mut lines: Vec<Vec<u8>> =
                    text.split(|&b| b == b'\n').map(<[u8]>::to_vec).collect();
                let n = lines.len();
                let at = at % n;
                match *e {
                    Edit::DeleteLine(_) => {
                        lines.remove(at);
                    }
                    Edit::DuplicateLine(_) => {
                        let line = lines[at].clone();
                        lines.insert(at, line);
                    }
                    Edit::SwapLines(_, other) => lines.swap(at, other % n),
                    _ => unreachable!(),
                }
                text = lines.join(&b'\n');
            }
            Edit::Number(at, n) => {
                let found = numbers(&text);
                if !found.is_empty() {
                    let (start, end) = found[at % found.len()];
                    text.splice(start..end, NUMBERS[n].bytes());
                }
            }
            Edit::Insert(at, p) => {
                let at = at % (text.len() + 1);
                text.splice(at..at, PIECES[p].bytes());
            }
            _ => {}
        }
    }
    text
}

#[test]
fn the_valid_file_is_valid() {
    let m = machine_from_toml(valid(), "mts1600.toml").unwrap();
    assert_eq!(m.axes.len(), 6);
    assert!(numbers(valid().as_bytes()).len() > 40);
}

/// Values the brief asks about, on every number of the file in turn.
#[test]
fn every_number_replaced_by_every_special_value() {
    let text = valid().as_bytes().to_vec();
    let count = numbers(&text).len();
    for at in 0..count {
        for n in 0..NUMBERS.len() {
            check(&apply(text.clone(), &[Edit::Number(at, n)]));
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1000))]

    #[test]
    fn random_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..600)) {
        check(&bytes);
    }

    #[test]
    fn random_pieces_never_panic(pieces in proptest::collection::vec(0..PIECES.len(), 0..120)) {
        let text: String = pieces.iter().map(|&p| PIECES[p]).collect();
        check(text.as_bytes());
    }

    #[test]
    fn mutated_machine_file_never_panics(edits in proptest::collection::vec(edit(), 1..10)) {
        check(&apply(valid().as_bytes().to_vec(), &edits));
    }
}
