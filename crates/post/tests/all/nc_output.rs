//! What the NC writer cannot write is an error naming the CL statement it
//! comes from.

use kinpost_post::machine::builtin;
use kinpost_post::nc::Dialect;
use kinpost_post::{PostError, PostOptions, post};

/// A built-in dialect with one line of its file replaced.
fn dialect_with(name: &str, key: &str, line: &str) -> Dialect {
    let source = Dialect::builtin_source(name).unwrap();
    assert!(source.lines().any(|l| l.starts_with(key)), "{name}: {key}");
    let edited: Vec<&str> = source
        .lines()
        .map(|l| if l.starts_with(key) { line } else { l })
        .collect();
    Dialect::from_toml(&edited.join("\n"), "edited.toml").unwrap_or_else(|e| panic!("{e}"))
}

/// `cl` posted on `trunnion-ac` in `dialect`: the program.
fn post_on_trunnion(dialect: &Dialect, cl: &str) -> Result<String, PostError> {
    let machine = builtin::load("trunnion-ac").unwrap().unwrap();
    let options = PostOptions {
        cl_file: "job.cls".into(),
        ..PostOptions::default()
    };
    let mut out = Vec::new();
    post(cl.as_bytes(), &machine, dialect, &mut out, &options)?;
    Ok(String::from_utf8(out).unwrap())
}

fn post_error(dialect: &Dialect, cl: &str) -> kinpost_post::nc::Diagnostic {
    match post_on_trunnion(dialect, cl) {
        Err(e) => match e.diagnostic() {
            Some(d) => d.clone(),
            None => panic!("not an input error: {e}"),
        },
        Ok(_) => panic!("posted"),
    }
}

/// A template that fails while the post writes it (here on a value the
/// caller did not pass in `extra`) names the CL statement it was written
/// for, though the planner writes it after the reader has moved on.
#[test]
fn template_error_names_the_cl_line() {
    let dialect = dialect_with(
        "linuxcnc",
        "spindle_on =",
        "spindle_on = \"S{{ speed | num(0) }} M3 P{{ extra.slot }}\"",
    );
    let cl =
        "RAPID\nGOTO/0,0,50,0,0,1\nFEDRAT/MMPM,100\nGOTO/0,0,40\nSPINDL/1000,RPM\nGOTO/0,0,60\n";
    let d = post_error(&dialect, cl);
    assert_eq!(
        (d.file.as_str(), d.line, d.column),
        ("job.cls", 5, 1),
        "{d}"
    );
    assert_eq!(d.source_line, "SPINDL/1000,RPM");
    assert!(d.message.contains("template `spindle_on`"), "{d}");
}

/// An INSERT longer than the dialect's `max_line_length` (LinuxCNC's 253
/// bytes with the newline) is code kinpost cannot shorten: an error at its
/// CL line. A CL comment as long is shortened (see `rs274.rs`).
#[test]
fn insert_longer_than_the_controller_reads_names_the_cl_line() {
    let dialect = Dialect::builtin("linuxcnc").unwrap();
    let cl = format!(
        "RAPID\nGOTO/0,0,50,0,0,1\n$$ {}\nINSERT/(MSG, {})\nRAPID\nGOTO/0,0,60\n",
        "c".repeat(400),
        "i".repeat(300)
    );
    let d = post_error(&dialect, &cl);
    assert_eq!(
        (d.file.as_str(), d.line, d.column),
        ("job.cls", 4, 1),
        "{d}"
    );
    assert!(d.message.contains("INSERT"), "{d}");
    assert!(d.message.contains("max_line_length of 253"), "{d}");
}

/// A coolant mode the dialect has no code for (through-spindle, air) is an
/// error at its CL line in every built-in word dialect, not flood coolant;
/// `COOLNT/ON,MIST` is mist.
#[test]
fn a_coolant_mode_without_a_code_stops_the_post_at_its_line() {
    let cl = "RAPID\nGOTO/0,0,50,0,0,1\nCOOLNT/AIR\nFEDRAT/300\nGOTO/0,0,10\n";
    for name in ["sinumerik", "fanuc", "heidenhain", "linuxcnc"] {
        let dialect = Dialect::builtin(name).unwrap();
        let d = post_error(&dialect, cl);
        assert_eq!((d.line, d.column), (3, 1), "{name}: {d:?}");
        assert!(
            d.message
                .contains("coolant mode `air` has no code in this dialect"),
            "{name}: {}",
            d.message
        );
        let mist = cl.replace("COOLNT/AIR", "COOLNT/ON,MIST");
        let nc = post_on_trunnion(&dialect, &mist).unwrap();
        assert!(
            nc.lines().any(|l| l.ends_with("M07") || l.ends_with("M7")),
            "{name}\n{nc}"
        );
    }
}
