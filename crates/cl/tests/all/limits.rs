//! The line reader's limits: a statement of many `$` lines or one line
//! without end is an error at its place (memory stays bounded), and a
//! carriage return inside a line is an error, never a file read as one
//! line.

use kinpost_cl::{ClReader, MAX_STATEMENT_BYTES, MAX_STATEMENT_LINES};

/// The first error of `cl` (every statement before it read).
fn first_error(cl: &[u8]) -> kinpost_cl::Diagnostic {
    let mut r = ClReader::new(cl, "t.cls").with_default_axis([0.0, 0.0, 1.0]);
    loop {
        match r.next_statement() {
            Ok(Some(_)) => {}
            Ok(None) => panic!("no error"),
            Err(e) => {
                // After it, the reader ends.
                assert!(matches!(r.next_statement(), Ok(None)));
                return e;
            }
        }
    }
}

#[test]
fn many_continuation_lines_are_an_error_at_the_limit() {
    let mut cl = b"GOTO/1,2,3\nPPRINT a $\n".to_vec();
    for _ in 0..MAX_STATEMENT_LINES + 50 {
        cl.extend_from_slice(b"$\n");
    }
    cl.extend_from_slice(b"b\n");
    let e = first_error(&cl);
    assert_eq!(e.line, 2 + MAX_STATEMENT_LINES, "{e}");
    assert!(e.message.contains("starts on line 2"), "{e}");
}

#[test]
fn a_line_without_end_is_an_error_not_a_gigabyte() {
    let mut cl = b"GOTO/1,2,3\nPPRINT ".to_vec();
    cl.extend(std::iter::repeat_n(b'x', MAX_STATEMENT_BYTES + 10));
    let e = first_error(&cl);
    assert_eq!(e.line, 2, "{e}");
    assert!(e.message.contains("longer than"), "{e}");
    assert!(e.source_line.len() <= 200, "{}", e.source_line.len());
    // A long statement within the limit is read.
    let mut ok = b"PPRINT ".to_vec();
    ok.extend(std::iter::repeat_n(b'y', MAX_STATEMENT_BYTES / 2));
    ok.push(b'\n');
    let mut r = ClReader::new(&ok[..], "t.cls");
    assert!(r.next_statement().unwrap().is_some());
}

#[test]
fn a_file_with_cr_line_ends_is_an_error_at_the_first_cr() {
    for cl in [
        &b"PARTNO FLAT\rFEDRAT/MMPM,500\rGOTO/0,0,0,0,0,1\r"[..],
        b"$$ made by X\rGOTO/0,0,0,0,0,1\r",
        b"PARTNO NAME\rG00 Z-100\n",
        "PPRINT Gehäuse\rG0\n".as_bytes(),
    ] {
        let e = first_error(cl);
        assert_eq!(e.line, 1, "{e}");
        assert!(e.message.contains("carriage return"), "{e}");
        let text = String::from_utf8_lossy(cl);
        let col = text[..text.find('\r').unwrap()].chars().count() + 1;
        assert_eq!(e.column, col, "{e}");
    }
    // CR LF line ends are line ends.
    let mut r = ClReader::new(&b"PARTNO X\r\nGOTO/0,0,0,0,0,1\r\n"[..], "t.cls");
    assert!(r.next_statement().unwrap().is_some());
    assert!(r.next_statement().unwrap().is_some());
    assert!(r.next_statement().unwrap().is_none());
}

/// Every statement and diagnostic of `input`, through `reader`.
fn transcript(reader: impl std::io::BufRead) -> Vec<String> {
    let mut r = ClReader::new(reader, "t.cls");
    let mut out = Vec::new();
    for _ in 0..100 {
        let item = r.next_statement();
        let end = matches!(item, Ok(None));
        out.push(format!("{item:?}"));
        out.extend(r.take_warnings().iter().map(|w| format!("{w:?}")));
        if end {
            break;
        }
    }
    out
}

/// Found by the `cl_reader` fuzz target: a CR in a long line gave the same
/// error on both paths but another source line.
#[test]
fn a_carriage_return_in_a_long_line_reads_alike_on_both_paths() {
    let text = format!(
        "PARTNO/FIVE AXIS DEMO\nTPARTNO NAME\rG00 {} Z-100\nSPINDL/1200,CLW\n",
        "\0".repeat(300)
    );
    let general = transcript(std::io::BufReader::with_capacity(1, text.as_bytes()));
    assert_eq!(transcript(text.as_bytes()), general);
    assert!(
        general.iter().any(|t| t.contains("carriage return")),
        "{general:?}"
    );
}
