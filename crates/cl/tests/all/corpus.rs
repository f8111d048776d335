//! Every real CL file in the repository's `data/cl/` reads to its end with
//! no error and no warning, and gives the events listed in
//! `tests/corpus/<system>/<file>.events` (a golden listing: a change of the
//! reader that changes what a real file means shows up there).
//!
//! A listing has one line per event (its CL line and the event, `GOTO`,
//! `CIRCLE` and `FEDRAT` shortened); runs of three or more `GOTO`s are
//! shortened to their count, first and last point; a long file is listed up
//! to its 300th line of listing. The second line carries a hash of the full
//! listing of every event, so that a change anywhere shows too.
//!
//! To write the listings anew after a deliberate change, run
//! `KINPOST_BLESS=1 cargo test -p kinpost-cl --test all corpus::` and review the
//! diff.

use std::collections::BTreeSet;
use std::fmt::Write as _;
use std::fs::File;
use std::io::BufReader;
use std::path::{Path, PathBuf};

use kinpost_cl::{ClEvent, ClReader, Statement, Units};
use kinpost_testkit::Goldens;

/// How a file is read: the tool axis of files that write none (SOLIDWORKS
/// CAM, Creo 3-axis: their documentation and files take it as +Z) and the
/// units of files that do not declare them.
struct Case {
    path: &'static str,
    default_axis: bool,
    units: Option<Units>,
    /// The post-processor words of the file's own machine, which the
    /// reader rightly warns about as unknown statements (and nothing else).
    machine_words: &'static [&'static str],
    /// The file is ISO 8859-1 text (`--encoding latin1`).
    latin1: bool,
}

const fn case(path: &'static str, default_axis: bool, units: Option<Units>) -> Case {
    Case {
        path,
        default_axis,
        units,
        machine_words: &[],
        latin1: false,
    }
}

const INCH: Option<Units> = Some(Units::Inch);

const CASES: &[Case] = &[
    // CATIA V5 for a shot-peening machine: its own words (glass beads,
    // air, recipes, feed overrides) are not a mill's.
    Case {
        path: "catia/peening.aptsource",
        default_axis: false,
        units: None,
        machine_words: &[
            "AIR", "FEEDOVER", "GLASS", "INITIAL", "RECIPE", "SATUTEST", "SAVERE", "SPINDLE",
            "STANDOFF", "SUBPROG", "SURFACE",
        ],
        latin1: false,
    },
    // CATIA V5 spot drilling: French comments in ISO 8859-1, positional
    // CYCLE/DRILL.
    Case {
        path: "catia/PrepaFlans_Pointage.aptsource",
        default_axis: false,
        units: None,
        machine_words: &[],
        latin1: true,
    },
    case("nx/APT_Project2.txt", false, INCH),
    case("nx/APT_SimpleMillPlane.txt", false, None),
    case("nx/APT_SimpleMillPlane_ZIG.txt", false, None),
    case("nx/APT_Variable_Axis.txt", false, INCH),
    case("nx/APT_Zig_Zag_Smoothed.txt", false, None),
    case("creo/bohren_1.ncl.8", true, None),
    case("creo/profilfraesen_2.ncl.1", true, None),
    case("solidworks/Dem-target1.apt", true, None),
    case("solidworks/Guincho_LLbar-left.apt", true, None),
    case("solidworks/Leg-holder-thin.apt", true, None),
    case("solidworks/Paralelipipedo.apt", true, None),
    case("solidworks/RotateThin.apt", true, None),
    case("solidworks/Sacrifice-Board.apt", true, None),
    case("solidworks/SlewMachine.apt", true, None),
    case("solidworks/SupPetriLED.apt", true, None),
    case("solidworks/Suporte-parede-side-drill.apt", true, None),
    case("solidworks/Teflon-gasket.apt", true, None),
    case("solidworks/Telemecanique-Tilt-Support1.apt", true, None),
    case("solidworks/Teste-Metrologia.apt", true, None),
    case("solidworks/boss.apt", true, None),
    case("solidworks/lateral-leg-holder.apt", true, None),
    case("solidworks/manufacture3-top.apt", true, None),
    case("solidworks/shimemcunha.apt", true, None),
];

fn data() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/cl")
}

fn golden() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/corpus")
}

/// FNV-1a, 64 bits: a stable hash of the full listing (not for security).
fn fnv1a(text: &str) -> u64 {
    text.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// All statements of a case; panics at an error or a warning.
fn statements(case: &Case) -> Vec<Statement> {
    let path = data().join(case.path);
    let file = File::open(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let text: Box<dyn std::io::Read> = if case.latin1 {
        Box::new(kinpost_cl::encoding::Latin1::new(file))
    } else {
        Box::new(file)
    };
    let mut reader = ClReader::new(BufReader::new(text), case.path).with_units(case.units);
    if case.default_axis {
        reader = reader.with_default_axis([0.0, 0.0, 1.0]);
    }
    let mut out = Vec::new();
    loop {
        let result = reader.next_statement();
        let warnings = reader.take_warnings();
        assert!(
            warnings.iter().all(|w| case
                .machine_words
                .iter()
                .any(|m| w.message.starts_with(&format!("unknown statement `{m}`")))),
            "{}: {warnings:#?}",
            case.path
        );
        match result {
            Ok(Some(s)) => out.push(s),
            Ok(None) => return out,
            Err(e) => panic!("{}: {e}", case.path),
        }
    }
}

/// The lines of a listing past which a file is only in the hash.
const MAX_LINES: usize = 300;

/// An event, shortened where it is frequent.
fn short(event: &ClEvent) -> String {
    match event {
        ClEvent::Goto {
            point,
            axis,
            reference,
            motion,
        } => {
            let mut s = format!("GOTO {point:?} {axis:?}");
            if let Some(r) = reference {
                write!(s, " {r:?}").unwrap();
            }
            if *motion == kinpost_cl::Motion::Rapid {
                s.push_str(" RAPID");
            }
            s
        }
        ClEvent::Circle(c) => {
            let mut s = format!(
                "CIRCLE centre {:?} axis {:?} r {}",
                c.centre, c.axis, c.radius_mm
            );
            if c.turns != 1 {
                write!(s, " turns {}", c.turns).unwrap();
            }
            if let (Some(t), Some(d), Some(e)) =
                (c.tolerance_mm, c.tool_diameter_mm, c.tool_corner_radius_mm)
            {
                write!(s, " tol {t} tool {d}/{e}").unwrap();
            }
            s
        }
        ClEvent::Feedrate { value, unit } => format!("FEDRAT {value} {unit:?}"),
        other => format!("{other:?}"),
    }
}

/// The golden listing of a case.
fn listing(case: &Case, statements: &[Statement]) -> String {
    let full: String = statements
        .iter()
        .map(|s| format!("{} {:?}\n", s.line, s.event))
        .collect();
    let mut out = format!(
        "# data/cl/{}{}{}\n# {} events, hash {:016x}\n",
        case.path,
        if case.default_axis {
            ", default axis 0,0,1"
        } else {
            ""
        },
        if case.units.is_some() {
            ", --units inch"
        } else {
            ""
        },
        statements.len(),
        fnv1a(&full)
    );
    let mut k = 0;
    let mut lines = 0;
    while k < statements.len() {
        if lines == MAX_LINES {
            writeln!(out, "… {} more events (in the hash)", statements.len() - k).unwrap();
            break;
        }
        lines += 1;
        let run = statements[k..]
            .iter()
            .take_while(|s| matches!(s.event, ClEvent::Goto { .. }))
            .count();
        if run >= 3 {
            let point = |s: &Statement| match s.event {
                ClEvent::Goto { point, .. } => point,
                _ => unreachable!(),
            };
            let (first, last) = (&statements[k], &statements[k + run - 1]);
            writeln!(
                out,
                "{}-{} {run} GOTOs, from {:?} to {:?}",
                first.line,
                last.line,
                point(first),
                point(last)
            )
            .unwrap();
            k += run;
        } else {
            let s = &statements[k];
            writeln!(out, "{} {}", s.line, short(&s.event)).unwrap();
            k += 1;
        }
    }
    out
}

#[test]
fn every_real_cl_file_reads_to_its_listing() {
    // Every file of data/cl/ has its case, and every case its file.
    let mut present = BTreeSet::new();
    for dir in std::fs::read_dir(data()).unwrap() {
        let dir = dir.unwrap().path();
        for f in std::fs::read_dir(&dir).unwrap() {
            let f = f.unwrap().path();
            let rel = f.strip_prefix(data()).unwrap();
            present.insert(rel.to_string_lossy().replace('\\', "/"));
        }
    }
    let listed: BTreeSet<String> = CASES.iter().map(|c| c.path.to_string()).collect();
    assert_eq!(present, listed, "data/cl/ and the cases differ");
    assert!(CASES.len() >= 20);

    let mut goldens = Goldens::from_env();
    for case in CASES {
        let statements = statements(case);
        let text = listing(case, &statements);
        goldens.check(&golden().join(format!("{}.events", case.path)), &text);
    }
    goldens.finish();
}
