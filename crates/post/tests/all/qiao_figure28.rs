//! Golden test from Qiao et al. 2022: the verbatim Figure 28(a) CL file posts on the
//! built-in `mts1600` to the feed moves printed in Figure 28(b), to the last
//! printed decimal, with its two defects reported as warnings.

use kinpost_post::{PostOptions, post};

fn data(path: &str) -> String {
    let p = format!("{}/../../data/{path}", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{p}: {e} (data/ of the repository)"))
}

#[test]
fn figure28_posts_to_the_printed_program() {
    let cl = data("qiao2022/figure28a-verbatim.cls");
    let printed = data("qiao2022/figure28b-verbatim.mpf");
    // The example shipped in the repository is the same file.
    let example = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/flat-part.cls"
    ))
    .unwrap();
    assert_eq!(example, cl);

    let machine = kinpost_post::machine::builtin::load("mts1600")
        .unwrap()
        .unwrap();
    let dialect =
        kinpost_post::nc::Dialect::builtin(machine.post.dialect.as_deref().unwrap()).unwrap();
    let mut out = Vec::new();
    let options = PostOptions {
        cl_file: "figure28a-verbatim.cls".into(),
        ..Default::default()
    };
    let summary = post(cl.as_bytes(), &machine, &dialect, &mut out, &options).unwrap();
    let nc = String::from_utf8(out).unwrap();

    let want: Vec<&str> = printed.lines().filter(|l| l.starts_with("X=")).collect();
    assert_eq!(want.len(), 11);
    // Motion blocks carry the axis words first; the feed word (and the
    // motion word of a dialect that writes one) may follow or precede them.
    let axis_words = |l: &str| -> String {
        l.split_whitespace()
            .filter(|w| ["X", "Y", "Z", "A", "B"].iter().any(|a| w.starts_with(a)))
            .collect::<Vec<_>>()
            .join(" ")
    };
    let got: Vec<String> = nc
        .lines()
        .filter(|l| l.contains("X=") && l.contains("A=DC("))
        .map(axis_words)
        .collect();
    // Two rapids, then the 12 feed moves of which the figure prints 11.
    assert_eq!(got.len(), 14, "{nc}");
    for (g, w) in got[2..13].iter().zip(&want) {
        assert_eq!(g, w, "\n{nc}");
    }
    assert_eq!(summary.cl_points, 14);
    assert_eq!(summary.blocks, 14);
    let lines: Vec<usize> = summary.warnings.iter().map(|w| w.line).collect();
    assert_eq!(lines, vec![2, 3], "{:?}", summary.warnings);
    assert!(summary.warnings[0].message.contains("TLDDATA"));
    assert!(summary.warnings[1].message.contains("MSYS"));
    assert!(summary.max_position_error_mm <= summary.tolerance_mm);
    // The last CL point GOTO/-416,58,0.5 is 459, 79.2-58, 350.5.
    assert_eq!(got[13], "X=459.000 Y=21.200 Z350.500 B0.000 A=DC(0.000)");
}

#[test]
fn same_input_same_bytes() {
    let cl = data("qiao2022/figure28a-verbatim.cls");
    let machine = kinpost_post::machine::builtin::load("mts1600")
        .unwrap()
        .unwrap();
    let dialect = kinpost_post::nc::Dialect::builtin("sinumerik").unwrap();
    let run = || {
        let mut out = Vec::new();
        post(
            cl.as_bytes(),
            &machine,
            &dialect,
            &mut out,
            &PostOptions::default(),
        )
        .unwrap();
        out
    };
    assert_eq!(run(), run());
}
