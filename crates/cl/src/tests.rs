//! Unit tests, one or more per statement kind.

use super::*;

fn read(cl: &str) -> (Vec<Statement>, Vec<Diagnostic>) {
    let mut r = ClReader::new(cl.as_bytes(), "t.cls");
    let mut out = Vec::new();
    while let Some(s) = r.next_statement().unwrap_or_else(|e| panic!("{e}")) {
        out.push(s);
    }
    (out, r.take_warnings())
}

fn events(cl: &str) -> Vec<ClEvent> {
    let (s, w) = read(cl);
    assert!(w.is_empty(), "unexpected warnings: {w:?}");
    s.into_iter().map(|s| s.event).collect()
}

fn one(cl: &str) -> ClEvent {
    let mut e = events(cl);
    assert_eq!(e.len(), 1, "{e:?}");
    e.pop().unwrap()
}

fn error(cl: &str) -> Diagnostic {
    let mut r = ClReader::new(cl.as_bytes(), "t.cls").with_default_axis([0.0, 0.0, 1.0]);
    loop {
        match r.next_statement() {
            Ok(Some(_)) => {}
            Ok(None) => panic!("no error in {cl:?}"),
            Err(e) => {
                assert_eq!(e.severity, Severity::Error);
                return e;
            }
        }
    }
}

fn rpm(rpm: f64, dir: SpindleDir) -> ClEvent {
    ClEvent::Spindle {
        speed: SpindleSpeed::Rpm(rpm),
        dir,
        range: None,
        max_rpm: None,
    }
}

fn goto(point: Vec3, axis: Vec3, motion: Motion) -> ClEvent {
    ClEvent::Goto {
        point,
        axis,
        reference: None,
        motion,
    }
}

#[test]
fn goto_rapid_is_one_shot_and_axis_is_modal() {
    let (s, w) =
        read("RAPID\nGOTO/1,2,3,0,0,2\nGOTO/4,5,6\nRAPID/\nGOTO/7,8,9\nGOTO/1,1,1,0,3,4\n");
    let e: Vec<ClEvent> = s.into_iter().map(|s| s.event).collect();
    // Axes far from unit length are scaled to it, with one warning.
    assert_eq!(
        w.iter()
            .map(|w| (w.line, w.column, w.width))
            .collect::<Vec<_>>(),
        [(2, 12, 5)]
    );
    assert_eq!(
        w[0].message,
        "the tool axis (i,j,k) has length 2.000000, not 1: it is scaled to unit length (further ones are not reported)"
    );
    assert_eq!(
        e,
        vec![
            goto([1., 2., 3.], [0., 0., 1.], Motion::Rapid),
            goto([4., 5., 6.], [0., 0., 1.], Motion::Feed),
            goto([7., 8., 9.], [0., 0., 1.], Motion::Rapid),
            goto([1., 1., 1.], [0., 0.6, 0.8], Motion::Feed),
        ]
    );
}

#[test]
fn goto_nine_values_sets_reference() {
    let e = events("GOTO/1,2,3,0,0,1,2,0,0\nGOTO/1,2,4\nGOTO/1,2,5,0,1,0\n");
    let refs: Vec<_> = e
        .iter()
        .map(|e| match e {
            ClEvent::Goto { reference, .. } => *reference,
            _ => panic!(),
        })
        .collect();
    assert_eq!(refs, vec![Some([1., 0., 0.]); 3]);
}

#[test]
fn goto_errors() {
    let e = error("GOTO/1,2,3,0,0,0\n");
    assert_eq!((e.line, e.column, e.width), (1, 12, 5));
    assert!(e.message.contains("tool axis"), "{}", e.message);
    let e = error("GOTO/1,2,3,0,0,1,1,0,0\nGOTO/1,2,3,0,0,1,0,0,2\n");
    assert_eq!((e.line, e.column, e.width), (2, 18, 5));
    assert!(e.message.contains("parallel"), "{}", e.message);
    let e = error("GOTO/1,2,3,0,0,1,0,0,0\n");
    assert!(e.message.contains("reference"), "{}", e.message);
    let e = error("GOTO/1,2,3,4\n");
    assert_eq!((e.column, e.width), (12, 1));
    assert!(e.message.starts_with("GOTO has 4 values"), "{}", e.message);
    let e = error("GOTO/1,2\n");
    assert!(e.message.starts_with("GOTO has 2 values"), "{}", e.message);
    let e = error("GOTO\n");
    assert!(e.message.starts_with("GOTO has 0 values"), "{}", e.message);
    let e = error("GOTO 1,2,3\n");
    assert_eq!(e.message, "expected `/` after `GOTO`");
    let e = error("GOTO/1,2,3,0,0,1,0,0,1,5\n");
    assert_eq!(e.column, 24);
    let e = error("GOTO/1,2,3,0,0,1e999\n");
    assert_eq!(e.message, "number `1e999` is out of range");
}

#[test]
fn goto_without_axis_needs_a_default() {
    let mut r = ClReader::new("GOTO/1,2,3\n".as_bytes(), "t.cls");
    let e = r.next_statement().unwrap_err();
    assert_eq!((e.line, e.column, e.width), (1, 6, 5));
    let mut r = ClReader::new("GOTO/1,2,3\n".as_bytes(), "t.cls").with_default_axis([0., 0., 5.]);
    assert_eq!(r.tool_axis(), Some([0., 0., 1.]));
    assert_eq!(
        r.next_statement().unwrap().unwrap().event,
        goto([1., 2., 3.], [0., 0., 1.], Motion::Feed)
    );
}

#[test]
fn malformed_numbers_point_at_the_field() {
    let e = error("GOTO/1.2.3,4,5\n");
    assert_eq!(
        e.to_string(),
        "error: malformed number `1.2.3`\n --> t.cls:1:6\n  |\n1 | GOTO/1.2.3,4,5\n  |      ^^^^^"
    );
    let e = error("GOTO / 1, abc , 3\n");
    assert_eq!((e.column, e.width), (11, 3));
    let e = error("GOTO/1,,3\n");
    assert_eq!((e.column, e.width), (8, 1));
    assert_eq!(e.message, "empty field: expected a number");
    let e = error("GOTO/1,2,\n");
    assert_eq!((e.column, e.width), (10, 1));
}

#[test]
fn apt_numbers() {
    assert_eq!(
        one("GOTO/94.0375,.9625,-3.,0,0,1E0\n"),
        goto([94.0375, 0.9625, -3.0], [0., 0., 1.], Motion::Feed)
    );
}

#[test]
fn catia_spacing_and_case() {
    let e = events("multax\n  goto / 1 , 2 ,3, 0 , 0 , 1\nFedRat /  250 ,  mmpm\nFINI\n");
    assert_eq!(
        e,
        vec![
            ClEvent::Multax(true),
            goto([1., 2., 3.], [0., 0., 1.], Motion::Feed),
            ClEvent::Feedrate {
                value: 250.0,
                unit: FeedUnit::Mmpm
            },
            ClEvent::Fini,
        ]
    );
}

#[test]
fn fedrat_both_orders_and_units() {
    let f = |value, unit| ClEvent::Feedrate { value, unit };
    assert_eq!(
        events(
            "UNITS/MM\nFEDRAT/MMPM,250.0000\nFEDRAT/ 250, MMPM\nFEDRAT/ipm,10\nFEDRAT/0.1,MMPR\nFEDRAT/IPR,.01\nFEDRAT/300\nUNITS/INCHES\nFEDRAT/20\n"
        ),
        vec![
            ClEvent::Units(Units::Mm),
            f(250.0, FeedUnit::Mmpm),
            f(250.0, FeedUnit::Mmpm),
            // Inch feeds in mm: 10 × 25.4 and 0.01 × 25.4.
            f(254.0, FeedUnit::Mmpm),
            f(0.1, FeedUnit::Mmpr),
            f(0.254, FeedUnit::Mmpr),
            f(300.0, FeedUnit::Mmpm),
            ClEvent::Units(Units::Inch),
            // A feed without its unit is in the file's units: 20 in/min.
            f(508.0, FeedUnit::Mmpm),
        ]
    );
    assert!(error("FEDRAT/MMPM,0\n").message.contains("positive"));
    let e = error("FEDRAT/-5,MMPM\n");
    assert_eq!((e.column, e.width), (8, 2));
    assert!(
        error("FEDRAT/INVERS,5\n")
            .message
            .contains("unknown feed unit `INVERS`")
    );
    assert!(
        error("FEDRAT/MMPM\n")
            .message
            .contains("without a feed value")
    );
    assert!(
        error("FEDRAT/MMPM,1,2\n")
            .message
            .contains("two feed values")
    );
}

#[test]
fn tool_path_any_utf8() {
    assert_eq!(
        one("TOOL PATH/平板件测试,TOOL,代砂轮\n"),
        ClEvent::ToolPath {
            name: "平板件测试".into(),
            words: vec!["TOOL".into(), "代砂轮".into()]
        }
    );
    assert_eq!(
        one("tool  path / OP 1 , TOOL , T1\n"),
        ClEvent::ToolPath {
            name: "OP 1".into(),
            words: vec!["TOOL".into(), "T1".into()]
        }
    );
}

#[test]
fn tool_data_and_cutter() {
    assert_eq!(
        one("TLDATA/MILL,25.0000,0.0000,75.0000,0.0000,0.0000\n"),
        ClEvent::ToolData(Box::new(ToolData {
            kind: "MILL".into(),
            words: vec![],
            values: vec![25.0, 0.0, 75.0, 0.0, 0.0],
            diameter_mm: Some(25.0),
            corner_radius_mm: Some(0.0),
            length_mm: Some(75.0),
        }))
    );
    assert_eq!(
        one("CUTTER/6.,0,3.,0,0,0,51.\n"),
        ClEvent::ToolData(Box::new(ToolData {
            kind: "CUTTER".into(),
            words: vec![],
            values: vec![6.0, 0.0, 3.0, 0.0, 0.0, 0.0, 51.0],
            diameter_mm: Some(6.0),
            corner_radius_mm: Some(0.0),
            length_mm: Some(51.0),
        }))
    );
    assert!(
        error("TLDATA/MILL,2x\n")
            .message
            .contains("malformed number `2x`")
    );
}

#[test]
fn msys_full_short_and_cut() {
    assert_eq!(
        one("MSYS/1,2,3,1,0,0,0,1,0\n"),
        ClEvent::MachineSystem {
            origin: [1., 2., 3.],
            x: Some([1., 0., 0.]),
            y: Some([0., 1., 0.]),
            frame: Some(Box::new(Frame {
                origin: [1., 2., 3.],
                ..Frame::IDENTITY
            })),
        }
    );
    assert_eq!(
        one("MSYS/1,2,3\n"),
        ClEvent::MachineSystem {
            origin: [1., 2., 3.],
            x: None,
            y: None,
            frame: None,
        }
    );
    let (s, w) = read("MSYS/1,2,3,1,0,0,\n");
    assert_eq!(
        s[0].event,
        ClEvent::MachineSystem {
            origin: [1., 2., 3.],
            x: Some([1., 0., 0.]),
            y: None,
            frame: None,
        }
    );
    assert_eq!(w.len(), 1);
    assert!(
        w[0].message
            .starts_with("MSYS has 6 values, expected 3 or 9; ")
    );
    assert!(error("MSYS/1,2\n").message.contains("origin"));
}

#[test]
fn comments() {
    assert_eq!(
        events("$$ centerline data\n  $$\nGOTO/1,2,3,0,0,1 $$ trailing\nPPRINT/ hello \n"),
        vec![
            ClEvent::Comment("centerline data".into()),
            ClEvent::Comment(String::new()),
            goto([1., 2., 3.], [0., 0., 1.], Motion::Feed),
            ClEvent::Comment("hello".into()),
        ]
    );
}

#[test]
fn tools_spindle_coolant() {
    assert_eq!(
        events(
            "LOAD/TOOL,1\nSELECT/ tool , 5.\nSPINDL/12000,RPM,CLW\nSPINDL/RPM,500,CCLW\nSPINDL/OFF\nSPINDL/ON\nCOOLNT/FLOOD\nCOOLNT/mist\nCOOLNT/OFF\nCOOLNT\nCOOLNT/ON,THRU\nCOOLNT/ON\n"
        ),
        vec![
            ClEvent::LoadTool {
                number: 1,
                adjust: None
            },
            ClEvent::SelectTool { number: 5 },
            rpm(12000.0, SpindleDir::Clockwise),
            rpm(500.0, SpindleDir::CounterClockwise),
            ClEvent::SpindleOff,
            rpm(500.0, SpindleDir::CounterClockwise),
            ClEvent::Coolant {
                on: true,
                mode: "FLOOD".into()
            },
            ClEvent::Coolant {
                on: true,
                mode: "MIST".into()
            },
            ClEvent::Coolant {
                on: false,
                mode: "OFF".into()
            },
            ClEvent::Coolant {
                on: true,
                mode: "ON".into()
            },
            ClEvent::Coolant {
                on: true,
                mode: "THRU".into()
            },
            ClEvent::Coolant {
                on: true,
                mode: "ON".into()
            },
        ]
    );
    assert!(error("LOAD/TOOL,1.5\n").message.contains("whole number"));
    assert!(error("LOAD/TOOL,-1\n").message.contains("whole number"));
    assert!(error("LOAD/1\n").message.contains("LOAD/TOOL,n"));
    assert!(error("SPINDL/0,RPM\n").message.contains("positive"));
    assert!(error("SPINDL/ON\n").message.contains("no earlier speed"));
    let (s, w) = read("LOAD/TOOL,3,ADJUST,3,HIGH\n");
    assert_eq!(
        s[0].event,
        ClEvent::LoadTool {
            number: 3,
            adjust: Some(3)
        }
    );
    assert_eq!(w[0].message, "`HIGH` after the tool number ignored");
}

#[test]
fn insert_partno_units_multax_pressure_end() {
    assert_eq!(
        events(
            "INSERT/[HOLDER=C40-M06EM2] 6MM CRB 2FL, 19 LOC\nINSERT/ G05.1 Q1  \nPARTNO/1\nPARTNO  my part \nUNIT/MM\nUNITS/INCHES\nMULTAX/OFF\nMULTAX/ON\nPRESSURE/H1,3000\nPRESSURE/ 2.5\nEND-OF-PATH\nFINI\n"
        ),
        vec![
            ClEvent::Insert("[HOLDER=C40-M06EM2] 6MM CRB 2FL, 19 LOC".into()),
            ClEvent::Insert(" G05.1 Q1".into()),
            ClEvent::PartNo("1".into()),
            ClEvent::PartNo("my part".into()),
            ClEvent::Units(Units::Mm),
            ClEvent::Units(Units::Inch),
            ClEvent::Multax(false),
            ClEvent::Multax(true),
            ClEvent::Pressure {
                word: Some("H1".into()),
                value: 3000.0
            },
            ClEvent::Pressure {
                word: None,
                value: 2.5
            },
            ClEvent::EndOfPath,
            ClEvent::Fini,
        ]
    );
    assert!(error("UNITS/FEET\n").message.contains("unknown units"));
    assert!(error("PRESSURE/H1,-3\n").message.contains("negative"));
    assert!(error("MULTAX/MAYBE\n").message.contains("MULTAX"));
}

#[test]
fn silent_statements() {
    assert!(events("PAINT/PATH\nPAINT/COLOR,186\nTRNTYP/WORLD,0,0,0\nCSI_SET_FLUTE_LENGTH/19.\nCYCLE/INIT\nCYCLE/CLEAR\nRAPID\n\n   \n").is_empty());
    assert!(error("CSYS/1,0,0\n").message.contains("expected 12"));
}

#[test]
fn unknown_statements_are_warnings() {
    let (s, w) = read("FOO/1,2\nTLDDATA/MILL,1\nGOTO/1,2,3,0,0,1\n平板/1\n/x\nP1=POINT/1,2,3\n");
    assert_eq!(s.len(), 1);
    let got: Vec<_> = w
        .iter()
        .map(|d| (d.line, d.column, d.width, d.message.as_str()))
        .collect();
    assert_eq!(
        got,
        vec![
            (1, 1, 3, "unknown statement `FOO` ignored"),
            (
                2,
                1,
                7,
                "unknown statement `TLDDATA` (did you mean `TLDATA`?) ignored"
            ),
            (4, 1, 2, "unknown statement `平板` ignored"),
            (5, 1, 1, "unknown statement `/` ignored"),
            (6, 1, 2, "unknown statement `P1` ignored"),
        ]
    );
    assert!(w.iter().all(|d| d.severity == Severity::Warning));
}

#[test]
fn continuation_lines() {
    let (s, w) = read(
        "GOTO/1,2,$\n  3,0,0,1\nTOOL PATH/A$\nB,TOOL,T$  $$ comment\n$$ skipped comment\n,X\n",
    );
    assert!(w.is_empty());
    assert_eq!(s[0].line, 1);
    assert_eq!(s[0].event, goto([1., 2., 3.], [0., 0., 1.], Motion::Feed));
    assert_eq!(s[1].line, 3);
    assert_eq!(
        s[1].event,
        ClEvent::ToolPath {
            name: "AB".into(),
            words: vec!["TOOL".into(), "T".into(), "X".into()]
        }
    );
    // Diagnostics point at the physical line holding the bad text.
    let e = error("GOTO/1,2,$\n  3,0,x,1\n");
    assert_eq!(
        (e.line, e.column, e.source_line.as_str()),
        (2, 7, "  3,0,x,1")
    );
    let e = error("GOTO/1,2,3,$\n");
    assert_eq!((e.line, e.column), (1, 12));
    assert!(e.message.contains("past the end of the file"));
}

#[test]
fn crlf_bom_blank_lines() {
    let (s, w) = read("\u{feff}RAPID\r\nGOTO/1,2,3,0,0,1\r\n\r\n\r\nGOTO/1,2,4 \r\nFOO\r\n");
    assert_eq!(s.len(), 2);
    assert_eq!(s[1].line, 5);
    assert_eq!(s[0].event, goto([1., 2., 3.], [0., 0., 1.], Motion::Rapid));
    assert_eq!((w[0].line, w[0].source_line.as_str()), (6, "FOO"));
    // A BOM on line 1 is not part of the columns.
    let e = error("\u{feff}GOTO/x,2,3\n");
    assert_eq!((e.column, e.source_line.as_str()), (6, "GOTO/x,2,3"));
}

#[test]
fn invalid_utf8_is_an_error_with_a_line() {
    let mut r = ClReader::new(&b"GOTO/1,2,3,0,0,1\nTOOL PATH/ab\xff\xfe\n"[..], "t.cls");
    assert!(r.next_statement().unwrap().is_some());
    let e = r.next_statement().unwrap_err();
    assert_eq!((e.line, e.column), (2, 13));
    assert!(e.message.starts_with("invalid UTF-8 (byte 0xFF)"));
    assert_eq!(r.next_statement().unwrap(), None);
}

#[test]
fn reader_continues_after_an_error() {
    let mut r = ClReader::new(
        "RAPID\nGOTO/1,2,x,0,0,1\nGOTO/1,2,3,0,0,1\n".as_bytes(),
        "t.cls",
    );
    assert!(r.next_statement().is_err());
    // The failed GOTO had no effect: the RAPID still applies.
    assert_eq!(
        r.next_statement().unwrap().unwrap().event,
        goto([1., 2., 3.], [0., 0., 1.], Motion::Rapid)
    );
    assert_eq!(r.next_statement().unwrap(), None);
    assert_eq!(r.lines_read(), 3);
}

#[test]
fn iterator_and_io_errors() {
    struct Failing;
    impl std::io::Read for Failing {
        fn read(&mut self, _: &mut [u8]) -> std::io::Result<usize> {
            Err(std::io::Error::other("disk on fire"))
        }
    }
    let r = ClReader::new(std::io::BufReader::new(Failing), "t.cls");
    let all: Vec<_> = r.collect();
    assert_eq!(all.len(), 1);
    let e = all[0].as_ref().unwrap_err();
    assert_eq!(e.line, 1);
    assert!(e.message.contains("disk on fire"));
    let n = ClReader::new("GOTO/1,2,3,0,0,1\nGOTO/1,2,3\n".as_bytes(), "t.cls").count();
    assert_eq!(n, 2);
}

#[test]
fn statement_diagnostic_names_the_last_statement() {
    // Plain lines (fast path), CRLF, blanks and comments (general path), a
    // continued statement, and lines split across the input buffer.
    let cl = "GOTO/-391.2345,57.1234,7.1234,0.1234567,-0.0123456,0.9922222\n\
              GOTO/1,2,3\r\n  GOTO / 4,5,6 $$ note\nGOTO/7,8,$\n9\nGOTO/1.5,2.5,3.5";
    let expected = [
        (
            1,
            "GOTO/-391.2345,57.1234,7.1234,0.1234567,-0.0123456,0.9922222",
            1,
            60,
        ),
        (2, "GOTO/1,2,3", 1, 10),
        (3, "  GOTO / 4,5,6 $$ note", 3, 12),
        (4, "GOTO/7,8,$", 1, 9),
        (6, "GOTO/1.5,2.5,3.5", 1, 16),
    ];
    for capacity in [8192, 7, 1] {
        let input = std::io::BufReader::with_capacity(capacity, cl.as_bytes());
        let mut r = ClReader::new(input, "t.cls").with_default_axis([0.0, 0.0, 1.0]);
        for &(line, source, column, width) in &expected {
            let s = r.next_statement().unwrap().unwrap();
            assert!(matches!(s.event, ClEvent::Goto { .. }));
            assert_eq!(s.line, line);
            let d = r.statement_diagnostic(Severity::Error, "x");
            assert_eq!(d.severity, Severity::Error);
            assert_eq!(
                (
                    d.line,
                    d.column,
                    d.width,
                    d.source_line.as_str(),
                    d.message.as_str()
                ),
                (line, column, width, source, "x"),
                "capacity {capacity}"
            );
        }
        assert_eq!(r.next_statement().unwrap(), None);
    }
}

/// Everything the reader returns, as text.
fn transcript(input: impl std::io::BufRead) -> Vec<String> {
    let mut r = ClReader::new(input, "t.cls");
    let mut out = Vec::new();
    for _ in 0..100 {
        let item = r.next_statement();
        let end = matches!(item, Ok(None));
        match item {
            Ok(Some(s)) => {
                out.push(format!("{s:?}"));
                let d = r.statement_diagnostic(Severity::Warning, "here");
                out.push(format!("{d:?}"));
            }
            other => out.push(format!("{other:?}")),
        }
        out.extend(r.take_warnings().iter().map(|w| format!("{w:?}")));
        if end {
            break;
        }
    }
    out
}

#[test]
fn fast_paths_agree_with_the_general_path() {
    // A one-byte buffer never holds a whole line: everything then takes the
    // general path.
    let texts = [
        "GOTO/-391.2345,57.1234,7.1234,0.1234567,-0.0123456,0.9922222\nGOTO/1,2,3\n",
        "GOTO/1,2,3,0,0,1\r\nGOTO/1,2,3\r\nGOTO/4,5,6 \nGOTO/4,5,6\t\x0b\nGOTO/1,2,3,0,0,0\n",
        "GOTO/1,2,3,0,0,1,1,0,0\nGOTO/1,2,3,0,0,1,0,0,1\nGOTO/1,2,3,0,0,1,0,0,1,5\n",
        "GOTO/1,2\nGOTO/\nGOTO\nGOTO/1,,2\nGOTO/1,2,3,\nGOTO/,1,2,3\nGOTO/1e3,2,3,0,0,1\n",
        "GOTO/12345678.5,2,3,0,0,1\nGOTO/1.123456789,2,3\nGOTO/.5,-.5,+.5\nGOTO/5.,-0,+0.0\n",
        "GOTO/1.2.3,4,5\nGOTO/1-2,3,4\nGOTO/1 ,2,3\nGOTO/1,2,3$\n,0,0,1\nGOTO/1,2,3 $$ c\n",
        "goto/1,2,3,0,0,1\nGOTO/1,2,3,0,0,1\rGOTO/1,2,3\n\u{feff}GOTO/1,2,3\nGOTO/1,2,x\n",
        "\u{feff}GOTO/1,2,3,0,0,1\nRAPID\nGOTO/1,2,3\nFEDRAT/MMPM,250\nFOO/1\nGOTO/é,1,2\n",
        "GOTO/1,2,3,0,0,1\nGOTO/4,5,6",
        "GOTO/1,2,3,0,0,1\nGOTO/4,5,6\r",
        "GOTO/1,2,3,0,0,1,0,1,0,7\nGOTO/1e999,2,3,0,0,1\nGOTO/0.00000001,2,3,0,0,1\n",
        // The fast path looks for the line end in the 64 bytes after `GOTO/`:
        // lines of 63 and 64 bytes, a `\r\n` at 62 and at 63, nine values.
        "GOTO/-1234.5678,-1234.5678,-1234.567,-0.123456,-0.123456,-0.98765432\n\
         GOTO/-1234.5678,-1234.5678,-1234.5678,-0.123456,-0.123456,-0.98765432\n\
         GOTO/-1234.5678,-1234.567,-1234.567,-0.123456,-0.123456,-0.98765432\r\n\
         GOTO/-1234.5678,-1234.5678,-1234.567,-0.123456,-0.123456,-0.98765432\r\n\
         GOTO/-1234.5678,-1234.5678,-1234.5678,-0.1234567,-0.1234567,-0.9876543,-0.1234567,-0.1234567,-0.9876543\n",
    ];
    for text in texts {
        let general = transcript(std::io::BufReader::with_capacity(1, text.as_bytes()));
        assert_eq!(transcript(text.as_bytes()), general, "{text:?}");
        let small = std::io::BufReader::with_capacity(13, text.as_bytes());
        assert_eq!(transcript(small), general, "{text:?}");
    }
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(1000))]

    /// Random CL-ish text reads the same through the fast paths as through
    /// the general path.
    #[test]
    fn fast_paths_agree_on_random_text(
        pieces in proptest::collection::vec(0usize..25, 0..60),
    ) {
        const PIECES: &[&str] = &[
            "GOTO/", "GOTO/-391.2345,57.1234,7.1234,0.1234567,-0.0123456,0.9922222\n",
            ",", "\n", "\r\n", "\r", " ", "$", "$$", "-", "+", ".", "1", "0", "9", "12345678",
            "e", "é", "\u{feff}", "RAPID\n", "x", "\t", "0.1234567", "-416.0000", "\0",
        ];
        let text: String = pieces.iter().map(|&k| PIECES[k]).collect();
        let general = transcript(std::io::BufReader::with_capacity(1, text.as_bytes()));
        proptest::prop_assert_eq!(transcript(text.as_bytes()), general);
    }
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(2000))]

    /// `GOTO` values as CAM systems write them read as the very bits of
    /// `str::parse::<f64>`, through the fast paths (whole input in memory)
    /// and through the general path (a one-byte buffer).
    #[test]
    fn goto_values_are_bit_identical_to_std(
        values in proptest::collection::vec(
            "[-+]?(0{0,2}[0-9]{1,7}(\\.[0-9]{0,8})?|\\.[0-9]{1,8})([eE][-+]?[0-9]{1,2})?",
            3,
        ),
        crlf in proptest::bool::ANY,
    ) {
        let line_end = if crlf { "\r\n" } else { "\n" };
        let text = format!("GOTO/{}{line_end}GOTO/1,2,3{line_end}", values.join(","));
        let expected: Vec<u64> = values.iter().map(|v| v.parse::<f64>().unwrap().to_bits()).collect();
        let fast = ClReader::new(text.as_bytes(), "t.cls").with_default_axis([0.0, 0.0, 1.0]);
        let general = ClReader::new(std::io::BufReader::with_capacity(1, text.as_bytes()), "t.cls")
            .with_default_axis([0.0, 0.0, 1.0]);
        for mut reader in [fast.map(|s| s.map(|s| s.event)).collect::<Vec<_>>(), general.map(|s| s.map(|s| s.event)).collect()] {
            proptest::prop_assert_eq!(reader.len(), 2);
            match reader.remove(0) {
                Ok(ClEvent::Goto { point, .. }) => {
                    let bits: Vec<u64> = point.iter().map(|v| v.to_bits()).collect();
                    proptest::prop_assert_eq!(&bits, &expected, "{}", text);
                }
                other => proptest::prop_assert!(false, "{other:?}"),
            }
        }
    }
}

#[test]
fn tlaxis_sets_the_axis_of_three_value_gotos() {
    let e = events("TLAXIS/0,3,4\nGOTO/1,2,3\nGOTO/4,5,6,0,0,1\nGOTO/7,8,9\n");
    assert_eq!(
        e,
        vec![
            goto([1., 2., 3.], [0., 0.6, 0.8], Motion::Feed),
            goto([4., 5., 6.], [0., 0., 1.], Motion::Feed),
            goto([7., 8., 9.], [0., 0., 1.], Motion::Feed),
        ]
    );
    let e = error("TLAXIS/NORMPS\n");
    assert_eq!(
        (e.line, e.message.as_str()),
        (
            1,
            "expected `TLAXIS/i,j,k`; other TLAXIS forms (NORMPS, ATANGL, …) belong to the APT part-program language, not to CL data: have the CAM system output the tool axis"
        )
    );
    assert_eq!(
        error("TLAXIS/0,0,0\n").message,
        "the tool axis (i,j,k) is zero or not finite"
    );
}

#[test]
fn godlta_after_a_change_of_units_moves_in_the_new_ones() {
    // 1 inch, then 25.4 mm along X: 50.8 mm, i.e. 2 inches, from the
    // origin, then 1 inch more; the events carry mm.
    let e = events(
        "UNITS/INCHES\nGOTO/1,0,1,0,0,1\nUNITS/MM\nGODLTA/25.4,0,0\nUNITS/INCHES\nGODLTA/1,0,0\n",
    );
    assert_eq!(
        e,
        vec![
            ClEvent::Units(Units::Inch),
            goto([25.4, 0., 25.4], [0., 0., 1.], Motion::Feed),
            ClEvent::Units(Units::Mm),
            goto([50.8, 0., 25.4], [0., 0., 1.], Motion::Feed),
            ClEvent::Units(Units::Inch),
            goto([50.8 + 25.4, 0., 25.4], [0., 0., 1.], Motion::Feed),
        ]
    );
}

#[test]
fn godlta_moves_from_the_last_point() {
    let e = events("GOTO/1,2,3,0,0,1\nGODLTA/0,0,-5\nRAPID\nGODLTA/10\nGODLTA/1,1,1\n");
    assert_eq!(
        e,
        vec![
            goto([1., 2., 3.], [0., 0., 1.], Motion::Feed),
            goto([1., 2., -2.], [0., 0., 1.], Motion::Feed),
            goto([1., 2., 8.], [0., 0., 1.], Motion::Rapid),
            goto([2., 3., 9.], [0., 0., 1.], Motion::Feed),
        ]
    );
    assert_eq!(
        error("GODLTA/0,0,5\n").message,
        "GODLTA before any GOTO: a relative move needs a point to start from"
    );
    assert_eq!(
        error("GOTO/1,2,3\nGODLTA/1,2\n").message,
        "GODLTA has 2 values, expected 1 (along the tool axis) or 3 (dx,dy,dz)"
    );
}

#[test]
fn loadtl_loads_a_tool_and_partno_loses_its_quotes() {
    assert_eq!(
        events("LOADTL/2\nPARTNO/'1001'\nPARTNO \"A B\"\nPARTNO/it's\n"),
        vec![
            ClEvent::LoadTool {
                number: 2,
                adjust: None
            },
            ClEvent::PartNo("1001".into()),
            ClEvent::PartNo("A B".into()),
            ClEvent::PartNo("it's".into()),
        ]
    );
    let (s, w) = read("LOADTL/3,ADJUST,4\nLOADTL/5,IN\n");
    assert_eq!(
        s[0].event,
        ClEvent::LoadTool {
            number: 3,
            adjust: Some(4)
        }
    );
    assert_eq!(w.len(), 1);
    assert_eq!(
        (w[0].line, w[0].message.as_str()),
        (2, "`IN` after the tool number ignored")
    );
    assert_eq!(
        error("LOADTL/2.5\n").message,
        "the tool number must be a whole number from 0 to 4294967295, got `2.5`"
    );
}

#[test]
fn every_msys_is_an_event_and_the_post_decides() {
    // Repeated as it was (and cut short): fine.
    events("MSYS/1,2,3,1,0,0,0,1,0\nMSYS/1,2,3,1,0,0,0,1,0\nMSYS/1,2,3\n");
    // More than nine values, twice (found by the fuzzer: out of bounds).
    let (_, w) = read("MSYS/1,2,3,1,0,0,0,1,0,7\nMSYS/1,2,3,1,0,0,0,1,0,8\n");
    assert_eq!(w.len(), 2);
    // A second setup in another frame (NX writes one MSYS per operation):
    // a frame of its own, rotated a quarter turn about Z, Z kept.
    let e = events("MSYS/1,2,3,1,0,0,0,1,0\nGOTO/0,0,0,0,0,1\nMSYS/1,2,4,0,1,0,-1,0,0\n");
    let ClEvent::MachineSystem { frame: Some(f), .. } = &e[2] else {
        panic!("{e:?}")
    };
    assert_eq!((f.origin, f.z), ([1., 2., 4.], [0., 0., 1.]));
    // A skewed frame is refused.
    let e = error("MSYS/0,0,0,1,0,0,0.01,1,0\n");
    assert!(
        e.message
            .starts_with("MSYS: the frame's X and Y axes are not perpendicular"),
        "{e}"
    );
    assert_eq!((e.line, e.column), (1, 12));
}

#[test]
fn a_feed_rate_cancels_an_unused_rapid() {
    let (s, w) = read("GOTO/0,0,9,0,0,1\nRAPID\nFEDRAT/100\nGOTO/0,0,1\nFEDRAT/200\n");
    let motions: Vec<_> = s
        .iter()
        .filter_map(|s| match s.event {
            ClEvent::Goto { motion, .. } => Some(motion),
            _ => None,
        })
        .collect();
    assert_eq!(motions, [Motion::Feed, Motion::Feed]);
    assert_eq!(w.len(), 1);
    assert_eq!(
        (w[0].line, w[0].message.as_str()),
        (
            3,
            "FEDRAT after RAPID: the next move is at this feed, not rapid"
        )
    );
}
