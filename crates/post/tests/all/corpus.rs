//! Every real CL file of `data/cl` (NX, Creo, SOLIDWORKS CAM, CATIA V5; origins and
//! licenses in `data/MANIFEST.md`) posts, with the closed-loop check
//! passing, on a test machine without travel limits (`tests/machines/`:
//! `free3`, a three-axis mill, for files whose tool axis is always +Z;
//! `free5`, a head-head B/C five-axis, for the 3+2 and five-axis ones), in
//! the linuxcnc dialect, its `INSERT` notes as comments (`--insert
//! comment`), arcs within 0.01 mm. Each program is fixed in an insta snapshot
//! (`tests/snapshots/corpus__*.snap`) with the warnings of the post;
//! programs over 120 KB are fixed by their FNV-1a digest, length and line
//! count, with their first 80 and last 20 lines to read. LinuxCNC's own
//! interpreter reads every program without an error.

use std::path::{Path, PathBuf};

use kinpost_post::cl::Units;
use kinpost_post::machine::{Machine, machine_from_toml};
use kinpost_post::nc::Dialect;
use kinpost_post::{InsertMode, PostOptions, post};

/// The files, the machine each needs and whether it is in inches without
/// saying so (NX information listings with `FEDRAT/IPM`).
const CORPUS: [(&str, &str, bool); 25] = [
    ("catia/PrepaFlans_Pointage.aptsource", "free3", false),
    ("catia/peening.aptsource", "free5", false),
    ("creo/bohren_1.ncl.8", "free3", false),
    ("creo/profilfraesen_2.ncl.1", "free3", false),
    ("nx/APT_Project2.txt", "free5", true),
    ("nx/APT_SimpleMillPlane.txt", "free3", false),
    ("nx/APT_SimpleMillPlane_ZIG.txt", "free3", false),
    ("nx/APT_Variable_Axis.txt", "free5", true),
    ("nx/APT_Zig_Zag_Smoothed.txt", "free3", false),
    ("solidworks/Dem-target1.apt", "free3", false),
    ("solidworks/Guincho_LLbar-left.apt", "free3", false),
    ("solidworks/Leg-holder-thin.apt", "free3", false),
    ("solidworks/Paralelipipedo.apt", "free3", false),
    ("solidworks/RotateThin.apt", "free3", false),
    ("solidworks/Sacrifice-Board.apt", "free5", false),
    ("solidworks/SlewMachine.apt", "free3", false),
    ("solidworks/SupPetriLED.apt", "free3", false),
    ("solidworks/Suporte-parede-side-drill.apt", "free3", false),
    ("solidworks/Teflon-gasket.apt", "free3", false),
    ("solidworks/Telemecanique-Tilt-Support1.apt", "free5", false),
    ("solidworks/Teste-Metrologia.apt", "free5", false),
    ("solidworks/boss.apt", "free5", false),
    ("solidworks/lateral-leg-holder.apt", "free3", false),
    ("solidworks/manufacture3-top.apt", "free3", false),
    ("solidworks/shimemcunha.apt", "free5", false),
];

/// The files in ISO 8859-1 (`--encoding latin1`).
const LATIN1: [&str; 1] = ["catia/PrepaFlans_Pointage.aptsource"];

/// Programs larger than this are fixed by digest, head and tail.
const FULL_SNAPSHOT_BYTES: usize = 120_000;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn machine(name: &str) -> Machine {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("tests/machines/{name}.toml"));
    let text = std::fs::read_to_string(&path).unwrap();
    machine_from_toml(&text, &path.display().to_string()).unwrap_or_else(|e| panic!("{e}"))
}

/// FNV-1a, 64 bits: a fingerprint of a program (not a security hash).
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(*b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// The program of `file` on its machine, and the post's warnings.
fn post_file(file: &str, machine_name: &str, inch: bool) -> (String, Vec<String>) {
    let mut cl = std::fs::read(root().join("data/cl").join(file)).unwrap();
    if LATIN1.contains(&file) {
        // ISO 8859-1 is the first 256 code points: each byte its char.
        cl = cl
            .iter()
            .map(|&b| char::from(b))
            .collect::<String>()
            .into_bytes();
    }
    let options = PostOptions {
        cl_file: file.into(),
        lintol_mm: Some(0.01),
        default_axis: Some([0.0, 0.0, 1.0]),
        units: inch.then_some(Units::Inch),
        // SOLIDWORKS CAM's INSERTs are tool and stock notes.
        insert: InsertMode::Comment,
        ..Default::default()
    };
    let dialect = Dialect::builtin("linuxcnc").unwrap();
    let mut out = Vec::new();
    let summary = post(
        cl.as_slice(),
        &machine(machine_name),
        &dialect,
        &mut out,
        &options,
    )
    .unwrap_or_else(|e| panic!("{file}: {e}"));
    assert!(
        summary.max_position_error_mm <= summary.tolerance_mm,
        "{file}"
    );
    let warnings = summary
        .warnings
        .iter()
        .map(|w| format!("line {}: {}", w.line, w.message))
        .collect();
    (String::from_utf8(out).unwrap(), warnings)
}

fn snapshot_name(file: &str) -> String {
    file.replace(['/', '.'], "_")
}

#[test]
fn every_real_cl_file_posts_to_its_fixed_program() {
    for (file, machine_name, inch) in CORPUS {
        let (program, warnings) = post_file(file, machine_name, inch);
        let mut text = format!("machine: {machine_name}\nwarnings:\n");
        for w in &warnings {
            text.push_str(&format!("  {w}\n"));
        }
        if program.len() <= FULL_SNAPSHOT_BYTES {
            text.push_str(&program);
        } else {
            let lines: Vec<&str> = program.lines().collect();
            text.push_str(&format!(
                "program: {} bytes, {} lines, FNV-1a {:016x}\n",
                program.len(),
                lines.len(),
                fnv1a(program.as_bytes())
            ));
            text.push_str(&lines[..80].join("\n"));
            text.push_str("\n...\n");
            text.push_str(&lines[lines.len() - 20..].join("\n"));
            text.push('\n');
        }
        insta::assert_snapshot!(snapshot_name(file), text);
    }
}

/// Every file of `data/cl` is in the list above.
#[test]
fn the_corpus_list_is_complete() {
    let mut found = Vec::new();
    for system in ["catia", "creo", "nx", "solidworks"] {
        for entry in std::fs::read_dir(root().join("data/cl").join(system)).unwrap() {
            let name = entry.unwrap().file_name().to_string_lossy().into_owned();
            found.push(format!("{system}/{name}"));
        }
    }
    found.sort();
    let mut listed: Vec<String> = CORPUS.iter().map(|c| c.0.to_string()).collect();
    listed.sort();
    assert_eq!(found, listed);
}

/// LinuxCNC's interpreter reads every program of the corpus to its end
/// without an error (`rs274 -g`; skipped where it is not installed, unless
/// `CI` is set).
#[test]
fn linuxcnc_reads_every_corpus_program() {
    let Some(rs274) = ["/usr/bin/rs274"]
        .into_iter()
        .map(PathBuf::from)
        .chain(std::env::var_os("RS274").map(Into::into))
        .find(|p| p.is_file())
    else {
        assert!(std::env::var_os("CI").is_none(), "rs274 missing under CI");
        eprintln!("SKIPPED: rs274 not found");
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    // Tools 1 to 200 in pockets 1 to 200, of diameter 0: the programs call
    // the CL's tools, and cutter compensation (G41/G42) of a zero radius
    // leaves the path as written.
    let table: String = (1..=200).map(|t| format!("T{t} P{t} D0 Z0 ;\n")).collect();
    let table_path = dir.path().join("tools.tbl");
    std::fs::write(&table_path, table).unwrap();
    for (file, machine_name, inch) in CORPUS {
        let (program, _) = post_file(file, machine_name, inch);
        let path = dir.path().join(format!("{}.ngc", snapshot_name(file)));
        std::fs::write(&path, &program).unwrap();
        let out = std::process::Command::new(&rs274)
            .arg("-t")
            .arg(&table_path)
            .arg("-g")
            .arg(&path)
            .current_dir(dir.path())
            // rs274 keeps its tool table in `$HOME/.tool.mmap`: one of its
            // own, as the other tests that run it in parallel.
            .env("HOME", dir.path())
            .stdin(std::process::Stdio::null())
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&out.stdout);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            text.contains("PROGRAM_END()") && !err.contains("rror"),
            "{file}: rs274 did not read the program to its end:\n{err}\n{}",
            text.lines().rev().take(5).collect::<Vec<_>>().join("\n")
        );
    }
}
