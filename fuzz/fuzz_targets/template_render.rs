//! Fuzz target: any template text, as a machine file's header or footer or
//! a dialect's template, is checked and rendered within the template
//! limits (fuel, output, nesting) — it ends, in bounded memory, with text
//! or an error, never a panic — and program variables from outside
//! (program name, file name, tool) never put a control character or a
//! line break into the header of a built-in dialect. Run with
//! `cargo +nightly fuzz run template_render fuzz/corpus/template_render`.
//!
//! Input: the template, a NUL byte, then the program name, a NUL, the CL
//! file name, a NUL, the tool name.

#![no_main]

use kinpost_nc::{AxisSpec, Dialect, NcWriter, ProgramInfo, TemplateKind, check_template};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let mut parts = text.split('\0');
    let template = parts.next().unwrap_or("");
    let info = ProgramInfo {
        program_name: parts.next().unwrap_or("P").to_string(),
        cl_file: parts.next().unwrap_or("p.cls").to_string(),
        tool: parts.next().unwrap_or("T").to_string(),
        tool_number: 1,
        ..ProgramInfo::default()
    };
    for kind in [TemplateKind::Header, TemplateKind::SpindleOn] {
        if let Err(e) = check_template(kind, template) {
            let _ = e.to_string();
            if let Some(r) = e.range {
                assert!(r.start <= template.len());
            }
        }
    }
    let axes = ["X", "Y", "Z", "A", "C"].map(AxisSpec::linear);
    // The template as a machine file's header, in one dialect (a template
    // that uses up its fuel takes a while under the sanitizer): text or an
    // error.
    let names = Dialect::builtin_names();
    let dialect = Dialect::builtin(names[data.len() % names.len()]).expect("listed");
    let mut w = NcWriter::new(&dialect, &axes, Vec::new());
    let _ = w.header(&info, Some(template));
    for name in names {
        let dialect = Dialect::builtin(name).expect("listed");
        // The dialect's own header with the fuzzed names: one safe line each.
        let mut w = NcWriter::new(&dialect, &axes, Vec::new());
        w.header(&info, None).expect("built-in header");
        let out = w.finish().expect("in memory");
        assert!(
            !out.iter().any(|&b| b < 0x20 && b != b'\n'),
            "{name}: {:?}",
            String::from_utf8_lossy(&out)
        );
        let lines = String::from_utf8_lossy(&out).lines().count();
        let mut w = NcWriter::new(&dialect, &axes, Vec::new());
        w.header(&ProgramInfo { tool_number: 1, ..ProgramInfo::default() }, None)
            .expect("built-in header");
        let plain = String::from_utf8_lossy(&w.finish().expect("in memory")).lines().count();
        // No name adds a line of its own (an empty one may remove an
        // `{% if %}` line: at most as many).
        assert!(lines <= plain + 3, "{name}: {lines} lines, {plain} without names");
    }
});
