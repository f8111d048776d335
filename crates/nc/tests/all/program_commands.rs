//! The commands of CL program flow in every built-in dialect: program and
//! optional stop, dwell (in each control's unit: Fanuc `G04 P` in whole
//! milliseconds, LinuxCNC `G4 P` and Sinumerik `G4 F` in seconds,
//! Heidenhain cycle 9 in seconds), cutter radius compensation; a dialect
//! without a template for what the program asks is an error, never a
//! silent drop. LinuxCNC's own interpreter reads the LinuxCNC lines as the
//! same stops and dwell.

use kinpost_nc::{AxisSpec, Dialect, NcError, NcWriter};

fn lines(dialect: &str, write: impl Fn(&mut NcWriter<Vec<u8>>) -> Result<(), NcError>) -> String {
    let d = Dialect::builtin(dialect).unwrap();
    let axes = [
        AxisSpec::linear("X"),
        AxisSpec::linear("Y"),
        AxisSpec::linear("Z"),
    ];
    let mut w = NcWriter::new(&d, &axes, Vec::new());
    write(&mut w).unwrap();
    String::from_utf8(w.finish().unwrap()).unwrap()
}

fn flow(w: &mut NcWriter<Vec<u8>>) -> Result<(), NcError> {
    w.stop(false)?;
    w.stop(true)?;
    w.dwell(1.5)?;
    w.dwell(0.25)
}

fn cutcom(w: &mut NcWriter<Vec<u8>>) -> Result<(), NcError> {
    w.cutter_compensation(Some((true, 3)))?;
    w.cutter_compensation(Some((false, 12)))?;
    w.cutter_compensation(None)
}

#[test]
fn stops_and_dwells_in_every_dialect() {
    assert_eq!(lines("fanuc", flow), "M00\nM01\nG04 P1500\nG04 P250\n");
    assert_eq!(lines("linuxcnc", flow), "M0\nM1\nG4 P1.5\nG4 P0.25\n");
    assert_eq!(lines("sinumerik", flow), "M0\nM1\nG4 F1.5\nG4 F0.25\n");
    assert_eq!(
        lines("heidenhain", flow),
        "0 STOP\n1 M1\n2 CYCL DEF 9.0 DWELL TIME\n3 CYCL DEF 9.1 DWELL 1.5\n\
         4 CYCL DEF 9.0 DWELL TIME\n5 CYCL DEF 9.1 DWELL 0.25\n"
    );
    // CSV is a list of points: commands have no rows there (as spindle
    // and coolant).
    assert_eq!(lines("csv", flow), "line,motion,X,Y,Z,feed\n");
}

#[test]
fn cutter_compensation_where_the_dialect_has_it() {
    assert_eq!(lines("fanuc", cutcom), "G41 D3\nG42 D12\nG40\n");
    assert_eq!(lines("linuxcnc", cutcom), "G41 D3\nG42 D12\nG40\n");
    assert_eq!(lines("sinumerik", cutcom), "G41\nG42\nG40\n");
    // Heidenhain's is RL/RR on the motion blocks: no line of its own.
    assert_eq!(lines("heidenhain", cutcom), "");
    let d = Dialect::from_toml("name = \"bare\"\nextension = \"nc\"\n", "bare.toml").unwrap();
    let mut w = NcWriter::new(&d, &[AxisSpec::linear("X")], Vec::new());
    let e = w.cutter_compensation(Some((true, 1))).unwrap_err();
    assert!(matches!(
        e,
        NcError::MissingTemplate {
            template: "cutcom_on",
            ..
        }
    ));
    assert!(e.to_string().contains("bare"), "{e}");
}

#[test]
fn dwells_that_cannot_be_written_are_errors() {
    let d = Dialect::builtin("fanuc").unwrap();
    let mut w = NcWriter::new(&d, &[AxisSpec::linear("X")], Vec::new());
    for s in [0.0, -1.0, f64::NAN, f64::INFINITY, 1e6] {
        assert!(matches!(w.dwell(s), Err(NcError::Value { .. })), "{s}");
    }
}

/// `rs274 -g` prints PROGRAM_STOP, OPTIONAL_PROGRAM_STOP and DWELL(1.5000)
/// for the LinuxCNC lines.
#[test]
fn linuxcnc_reads_the_stops_and_dwells() {
    let Some(rs274) = ["/usr/bin/rs274"]
        .into_iter()
        .map(std::path::PathBuf::from)
        .chain(std::env::var_os("RS274").map(Into::into))
        .find(|p| p.is_file())
    else {
        assert!(std::env::var_os("CI").is_none(), "rs274 missing under CI");
        eprintln!("SKIPPED: rs274 not found");
        return;
    };
    let body = lines("linuxcnc", flow);
    let dir = std::env::temp_dir().join(format!("kinpost-nc-flow-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("flow.ngc");
    std::fs::write(&file, format!("%\nG21 G90\n{body}M2\n%\n")).unwrap();
    let out = std::process::Command::new(rs274)
        .arg("-g")
        .arg(&file)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    let calls: Vec<&str> = text
        .lines()
        .filter_map(|l| l.split("N..... ").nth(1))
        .filter(|c| c.contains("STOP(") || c.starts_with("DWELL"))
        .collect();
    assert_eq!(
        calls,
        [
            "PROGRAM_STOP()",
            "OPTIONAL_PROGRAM_STOP()",
            "DWELL(1.5000)",
            "DWELL(0.2500)"
        ],
        "{text}"
    );
    std::fs::remove_dir_all(&dir).ok();
}
