//! The reader on the real CL files in the repository's `data/` folder.

use std::fs::File;
use std::io::BufReader;
use std::path::PathBuf;

use kinpost_cl::{ClEvent, ClReader, Diagnostic, FeedUnit, Motion, Severity, Statement};

fn data(path: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../data")
        .join(path)
}

fn open(path: &str) -> ClReader<BufReader<File>> {
    let file = data(path);
    let f = File::open(&file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    ClReader::new(BufReader::new(f), path)
}

/// Reads until the end or the first error.
fn read_all<R: std::io::BufRead>(
    mut r: ClReader<R>,
) -> (Vec<Statement>, Vec<Diagnostic>, Option<Diagnostic>) {
    let mut statements = Vec::new();
    loop {
        match r.next_statement() {
            Ok(Some(s)) => statements.push(s),
            Ok(None) => return (statements, r.take_warnings(), None),
            Err(e) => return (statements, r.take_warnings(), Some(e)),
        }
    }
}

#[test]
fn seed_figure_28a() {
    let (statements, warnings, error) = read_all(open("qiao2022/figure28a-verbatim.cls"));
    assert_eq!(error, None);

    let gotos: Vec<_> = statements
        .iter()
        .filter_map(|s| match &s.event {
            ClEvent::Goto {
                point,
                axis,
                motion,
                ..
            } => Some((s.line, *point, *axis, *motion)),
            _ => None,
        })
        .collect();
    assert_eq!(gotos.len(), 14);
    assert!(gotos[..2].iter().all(|g| g.3 == Motion::Rapid));
    assert!(gotos[2..].iter().all(|g| g.3 == Motion::Feed));
    assert!(gotos.iter().all(|g| g.2 == [0.0, 0.0, 1.0]));
    assert_eq!(gotos[0].0, 9);
    assert_eq!(gotos[0].1, [-416.0, 70.5, 16.53]);
    assert_eq!(gotos[2].1, [-416.0, 70.3931, 11.3684]);
    assert_eq!(
        gotos[13],
        (26, [-416.0, 58.0, 0.5], [0.0, 0.0, 1.0], Motion::Feed)
    );

    // The feed rate is set once, before the first feed move.
    let feeds: Vec<_> = statements
        .iter()
        .filter(|s| matches!(s.event, ClEvent::Feedrate { .. }))
        .collect();
    assert_eq!(feeds.len(), 1);
    assert_eq!(
        feeds[0].event,
        ClEvent::Feedrate {
            value: 250.0,
            unit: FeedUnit::Mmpm
        }
    );
    assert!(feeds[0].line < gotos[2].0);

    assert_eq!(
        statements[0].event,
        ClEvent::ToolPath {
            name: "平板件测试".into(),
            words: vec!["TOOL".into(), "代砂轮".into()],
        }
    );
    assert!(statements.iter().any(|s| s.event
        == ClEvent::MachineSystem {
            origin: [226.8083, 392.8435, 0.0],
            x: Some([1.0, 0.0, 0.0]),
            y: None,
        }));
    assert!(
        statements
            .iter()
            .any(|s| s.event == ClEvent::Comment("centerline data".into()))
    );

    assert_eq!(warnings.len(), 2, "{warnings:#?}");
    assert!(warnings.iter().all(|w| w.severity == Severity::Warning));
    assert_eq!((warnings[0].line, warnings[0].column), (2, 1));
    assert!(warnings[0].message.contains("`TLDDATA`"));
    assert!(warnings[0].message.contains("did you mean `TLDATA`"));
    assert_eq!(warnings[1].line, 3);
    assert!(
        warnings[1]
            .message
            .starts_with("MSYS has 6 values, expected 3 or 9; ")
    );
    assert!(warnings[1].source_line.starts_with("MSYS/226.8083"));
}

/// SolidWorks-CAM APT files: 3-axis (no tool axis anywhere), arcs as CIRCLE.
#[test]
fn apt_files_read_up_to_the_first_circle() {
    for (path, circle_line, gotos_before) in [
        ("cl/solidworks/boss.apt", 37, 19),
        ("cl/solidworks/RotateThin.apt", 23, 4),
    ] {
        // Without a default axis the first GOTO is already an error.
        let (_, _, error) = read_all(open(path));
        let e = error.expect("GOTO without a tool axis");
        assert!(e.message.contains("before any tool axis"), "{e}");

        let (statements, warnings, error) = read_all(open(path).with_default_axis([0.0, 0.0, 1.0]));
        let e = error.unwrap_or_else(|| panic!("{path}: no error at the first CIRCLE"));
        assert_eq!(e.severity, Severity::Error);
        assert_eq!((e.file.as_str(), e.line, e.column), (path, circle_line, 1));
        assert!(e.message.starts_with("CIRCLE is not supported yet"), "{e}");
        assert!(e.source_line.starts_with("CIRCLE/"));
        let rendered = e.to_string();
        assert!(
            rendered.contains(&format!("{path}:{circle_line}:1")),
            "{rendered}"
        );

        let gotos = statements
            .iter()
            .filter(|s| matches!(s.event, ClEvent::Goto { .. }))
            .count();
        assert_eq!(gotos, gotos_before, "{path}");
        assert_eq!(statements[0].event, ClEvent::PartNo("1".into()));
        assert!(statements.iter().any(|s| s.event
            == ClEvent::ToolData {
                kind: "CUTTER".into(),
                values: match path {
                    "cl/solidworks/boss.apt" => vec![6.0, 0.0, 3.0, 0.0, 0.0, 0.0, 51.0],
                    _ => vec![20.0, 0.0, 10.0, 0.0, 0.0, 0.0, 100.0],
                },
            }));
        // Only RotateThin has cutter compensation before its first arc.
        let cutcom = warnings
            .iter()
            .filter(|w| w.message.starts_with("cutter compensation ignored"))
            .count();
        assert_eq!(
            cutcom,
            usize::from(path == "cl/solidworks/RotateThin.apt"),
            "{warnings:#?}"
        );
        assert_eq!(warnings.len(), cutcom, "{warnings:#?}");
    }
}

#[test]
fn apt_first_moves_are_rapid_then_feed() {
    let (statements, _, _) =
        read_all(open("cl/solidworks/boss.apt").with_default_axis([0.0, 0.0, 1.0]));
    let moves: Vec<_> = statements
        .iter()
        .filter_map(|s| match s.event {
            ClEvent::Goto { point, motion, .. } => Some((point, motion)),
            _ => None,
        })
        .take(4)
        .collect();
    assert_eq!(
        moves,
        vec![
            ([89.2375, 5.7625, 25.0], Motion::Rapid),
            ([89.2375, 5.7625, 2.5], Motion::Rapid),
            ([89.2375, 5.7625, -3.0], Motion::Feed),
            ([89.2375, 33.799705, -3.0], Motion::Feed),
        ]
    );
}
