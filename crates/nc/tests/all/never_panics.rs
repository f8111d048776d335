//! The dialect loader and the NC readers never panic, on random bytes and
//! on random edits of the built-in dialect files and of programs they write
//! (the stable-Rust side of the `dialect_file` and `nc_program` fuzz
//! targets).

use kinpost_nc::{AxisSpec, Block, Dialect, Motion, NcWriter, ProgramInfo, read_program};
use proptest::prelude::*;

fn axes() -> [AxisSpec; 5] {
    [
        AxisSpec::linear("X"),
        AxisSpec::endless("A"),
        AxisSpec::rotary("B"),
        AxisSpec::rotary("C").fixed(),
        AxisSpec::pressure_word("H1"),
    ]
}

/// A short program of a built-in dialect.
fn program(name: &str) -> String {
    let d = Dialect::builtin(name).unwrap();
    let mut w = NcWriter::new(&d, &axes(), Vec::new());
    w.header(&ProgramInfo::default(), None).unwrap();
    for k in 0..4 {
        // The pressure: none, then changing, where the dialect writes one.
        let h1 = if k == 0 || !d.writes_pressure() {
            f64::NAN
        } else {
            3000.0 + 125.0 * (k / 2) as f64
        };
        let v = [k as f64 * 1.25, 350.0 + k as f64 * 7.0, -12.5, 0.0, h1];
        let motion = if k == 0 { Motion::Rapid } else { Motion::Feed };
        w.block(&Block {
            line: None,
            number: None,
            arc: None,
            cl_line: Some(k + 1),
            motion,
            axes: &v,
            feed: Some(250.0),
        })
        .unwrap();
    }
    w.comment("a (note)").unwrap();
    w.footer(&ProgramInfo::default(), None).unwrap();
    String::from_utf8(w.finish().unwrap()).unwrap()
}

/// `text` with a few random edits: byte flips, deleted or repeated lines.
fn mutated(text: &str, edits: &[(usize, u8, u8)]) -> String {
    let mut bytes = text.as_bytes().to_vec();
    for &(at, kind, byte) in edits {
        if bytes.is_empty() {
            break;
        }
        let at = at % bytes.len();
        match kind % 4 {
            0 => bytes[at] = byte,
            1 => {
                bytes.remove(at);
            }
            2 => bytes.insert(at, byte),
            _ => {
                let line: Vec<u8> = bytes[at..]
                    .iter()
                    .take_while(|&&b| b != b'\n')
                    .copied()
                    .collect();
                bytes.splice(at..at, line.into_iter().chain([b'\n']));
            }
        }
    }
    String::from_utf8_lossy(&bytes).into_owned()
}

fn exercise(dialect: &Dialect) {
    let mut w = NcWriter::new(dialect, &axes(), Vec::new());
    let _ = w.header(&ProgramInfo::default(), None);
    let v = [1.0, -400.0, 12.25, 0.0, 3000.0];
    let _ = w.block(&Block {
        line: None,
        number: None,
        arc: None,
        cl_line: None,
        motion: Motion::Feed,
        axes: &v,
        feed: Some(100.0),
    });
    let _ = w.footer(&ProgramInfo::default(), None);
    if let Ok(out) = w.finish() {
        let _ = read_program(dialect, &axes(), "p.nc", &String::from_utf8_lossy(&out));
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(600))]

    #[test]
    fn dialect_loader_never_panics_on_bytes(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
        if let Ok(d) = Dialect::from_toml(&String::from_utf8_lossy(&bytes), "f.toml") {
            exercise(&d);
        }
    }

    #[test]
    fn dialect_loader_never_panics_on_edited_builtins(
        which in 0usize..5,
        edits in proptest::collection::vec((any::<usize>(), any::<u8>(), any::<u8>()), 1..6),
    ) {
        let name = Dialect::builtin_names()[which % Dialect::builtin_names().len()];
        let text = mutated(Dialect::builtin_source(name).unwrap(), &edits);
        match Dialect::from_toml(&text, "f.toml") {
            Ok(d) => exercise(&d),
            Err(diags) => {
                for d in &diags.0 {
                    prop_assert!(d.line >= 1 && d.column >= 1, "{d}");
                }
            }
        }
    }

    #[test]
    fn readers_never_panic_on_edited_programs(
        which in 0usize..5,
        edits in proptest::collection::vec((any::<usize>(), any::<u8>(), any::<u8>()), 1..8),
    ) {
        let names = Dialect::builtin_names();
        let name = names[which % names.len()];
        let text = mutated(&program(name), &edits);
        for reader in names {
            let d = Dialect::builtin(reader).unwrap();
            if let Err(e) = read_program(&d, &axes(), "p.nc", &text) {
                prop_assert!(e.line >= 1, "{e}");
            }
        }
    }
}
