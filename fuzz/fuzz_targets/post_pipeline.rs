//! Fuzz target: the whole post (`kinpost_post::post`) of any CL text on any
//! machine file (a built-in one when the text does not load) in every
//! built-in dialect gives a program and a summary, or an error — never a
//! panic — and a program never holds a control character other than the
//! line end, whatever PARTNO, PPRINT or TOOL PATH say (INSERT aside, which
//! the input here leaves out). Run with `cargo +nightly fuzz run
//! post_pipeline fuzz/corpus/post_pipeline`.
//!
//! Input: the CL text, then, after a line `%%MACHINE`, a machine file.

#![no_main]

use kinpost_post::machine::{builtin, machine_from_toml};
use kinpost_post::nc::Dialect;
use kinpost_post::{PostOptions, post};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let (cl, machine_text) = match text.split_once("\n%%MACHINE\n") {
        Some((cl, m)) => (cl, Some(m)),
        None => (&*text, None),
    };
    // INSERT is the one deliberate pass-through of code.
    if cl.to_ascii_uppercase().contains("INSERT") {
        return;
    }
    let machine = match machine_text.map(|m| machine_from_toml(m, "fuzz.toml")) {
        Some(Ok(m)) => m,
        _ => builtin::load("trunnion-ac").expect("built in").expect("valid"),
    };
    // A bounded post: a long CL is the cl_reader target's business.
    if cl.len() > 4096 || machine.axes.len() > 9 {
        return;
    }
    let options = PostOptions {
        cl_file: "fuzz\n.cls".into(),
        ..PostOptions::default()
    };
    for name in Dialect::builtin_names() {
        let dialect = Dialect::builtin(name).expect("listed");
        let mut out = Vec::new();
        match post(cl.as_bytes(), &machine, &dialect, &mut out, &options) {
            Ok(summary) => {
                let _ = summary.to_json();
                assert!(
                    !out.iter().any(|&b| b < 0x20 && b != b'\n'),
                    "{name}: {:?}",
                    String::from_utf8_lossy(&out)
                );
            }
            Err(e) => {
                let _ = e.to_string();
            }
        }
    }
});
