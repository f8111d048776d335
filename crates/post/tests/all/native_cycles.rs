//! Native canned cycles (`--cycles native`) against their moves
//! (`--cycles expand`), through LinuxCNC's own interpreter: `rs274 -g`
//! runs the G81…G89 of the native program into the moves it makes, and
//! they must be the moves of the expanded program, one for one, rapid for
//! rapid, within 1e-4 mm. On the real CL files of `data/cl` with cycles,
//! on the machines of tests/all/corpus.rs, and on a CL written here for
//! every kind of cycle (peck, chip break, tap, bore, dwell, G98 and G99).
//! Every program is also read back through the read-back stage.

use kinpost_post::machine::{Machine, builtin};
use kinpost_post::nc::Dialect;
use kinpost_post::{ArcMode, CycleMode, InsertMode, PostOptions, post_read_back};

use crate::native_arcs::{Move, dist, rs274, test_machine, trace};

/// How close the two programs' moves must be, mm.
const SAME_PATH_MM: f64 = 1e-4;

fn post(cl: &[u8], file: &str, machine: &Machine, cycles: CycleMode) -> (String, u64) {
    let options = PostOptions {
        cl_file: file.into(),
        lintol_mm: Some(0.01),
        default_axis: Some([0.0, 0.0, 1.0]),
        insert: InsertMode::Comment,
        arcs: ArcMode::Linear,
        cycles,
        ..Default::default()
    };
    let dialect = Dialect::builtin("linuxcnc").unwrap();
    let (out, summary) = post_read_back(cl, machine, &dialect, Vec::new(), &options)
        .unwrap_or_else(|e| panic!("{file}: {e}"));
    assert!(
        summary.max_position_error_mm <= summary.tolerance_mm,
        "{file}"
    );
    let out = out.unwrap_or_else(|e| panic!("{file}: {e}"));
    (
        String::from_utf8(out).unwrap(),
        summary.planning.native_cycles,
    )
}

/// The end point and kind of every straight move that moves (LinuxCNC's
/// G85 ends with a rapid to the R plane it is at).
fn lines(moves: &[Move]) -> Vec<([f64; 3], bool)> {
    moves
        .iter()
        .filter_map(|m| match m {
            Move::Line { from, to, feed } => (from != to).then_some((*to, *feed)),
            Move::Arc { .. } => panic!("an arc with --arcs linear"),
        })
        .collect()
}

/// Both programs of `cl` make the same moves in LinuxCNC; the number of
/// holes written as cycles.
fn same_moves(rs274: &std::path::Path, cl: &[u8], file: &str, machine: &Machine) -> u64 {
    let (native, holes) = post(cl, file, machine, CycleMode::Native);
    let (expanded, none) = post(cl, file, machine, CycleMode::Expand);
    assert_eq!(none, 0, "{file}");
    let a = lines(&trace(rs274, &native));
    let b = lines(&trace(rs274, &expanded));
    assert_eq!(a.len(), b.len(), "{file}: moves\n{native}");
    for (k, ((p, pf), (q, qf))) in a.iter().zip(&b).enumerate() {
        assert!(
            pf == qf && dist(*p, *q) <= SAME_PATH_MM,
            "{file}: move {k}: {p:?} {pf} against {q:?} {qf}"
        );
    }
    holes
}

#[test]
fn the_corpus_cycles_move_as_their_expansion_in_linuxcnc() {
    let Some(rs274) = rs274() else {
        return;
    };
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/cl");
    // The holes left as moves: SOLIDWORKS CAM's pecks of 5 then 2 mm
    // (`DEEP2,…,1STPECK,5.,SUBPECK,2.`), which no G83 makes, and the
    // tilted holes of the 3+2 files on the head-head machine.
    let files = [
        ("catia/PrepaFlans_Pointage.aptsource", "free3", 12),
        ("creo/bohren_1.ncl.8", "free3", 2),
        ("solidworks/Dem-target1.apt", "free3", 0),
        ("solidworks/Guincho_LLbar-left.apt", "free3", 2),
        ("solidworks/Leg-holder-thin.apt", "free3", 0),
        ("solidworks/RotateThin.apt", "free3", 5),
        ("solidworks/Sacrifice-Board.apt", "free5", 6),
        ("solidworks/SlewMachine.apt", "free3", 6),
        ("solidworks/SupPetriLED.apt", "free3", 12),
        ("solidworks/Suporte-parede-side-drill.apt", "free3", 0),
        ("solidworks/Teflon-gasket.apt", "free3", 1),
        ("solidworks/Telemecanique-Tilt-Support1.apt", "free5", 0),
        ("solidworks/manufacture3-top.apt", "free3", 0),
        ("solidworks/shimemcunha.apt", "free5", 0),
    ];
    for (file, machine_name, want) in files {
        let mut cl = std::fs::read(root.join(file)).unwrap();
        if file.starts_with("catia/") {
            // ISO 8859-1: each byte is its char.
            cl = cl
                .iter()
                .map(|&b| char::from(b))
                .collect::<String>()
                .into_bytes();
        }
        let holes = same_moves(&rs274, &cl, file, &test_machine(machine_name));
        eprintln!("{file}: {holes} holes as cycles");
        assert_eq!(holes, want, "{file}");
    }
}

/// `tests/cl/every-cycle.cls`: every kind of cycle on a three-axis mill,
/// holes at two heights, G99 and G98 (RTRCTO above RAPTO), pecks, chip
/// breaking, tapping, boring with and without a dwell, a dwell on a drill.
fn every_kind() -> Vec<u8> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/cl/every-cycle.cls");
    std::fs::read(path).unwrap()
}

#[test]
fn every_kind_of_cycle_moves_as_its_expansion_in_linuxcnc() {
    let Some(rs274) = rs274() else {
        return;
    };
    let holes = same_moves(
        &rs274,
        &every_kind(),
        "every-cycle.cls",
        &test_machine("free3"),
    );
    assert_eq!(holes, 10);
}

/// 3+2 holes on a table/table machine in joint output: the table tilts
/// the part, the tool stays along the Z axis, and the holes are cycles in
/// machine coordinates at the tilted A.
#[test]
fn tilted_holes_on_a_trunnion_are_cycles_in_machine_z() {
    let Some(rs274) = rs274() else {
        return;
    };
    let cl = "FEDRAT/MMPM,500\nRAPID\nGOTO/0,-20,60,0,-0.5,0.8660254\n\
              CYCLE/DRILL,FEDTO,5,RAPTO,2,MMPM,100\nGOTO/10,0,0\nGOTO/20,0,0\nCYCLE/OFF\n\
              GOTO/0,-20,60\n";
    let machine = builtin::load("trunnion-ac").unwrap().unwrap();
    let holes = same_moves(&rs274, cl.as_bytes(), "tilted.cls", &machine);
    assert_eq!(holes, 2);
}

/// A peck the program's Q word would round (0.55555 mm at LinuxCNC's four
/// decimals) is not the peck checked, and one shorter than G83's 0.254 mm
/// re-approach makes rs274 rapid above R: those holes stay moves; a peck
/// the word holds is a cycle.
#[test]
fn a_peck_the_word_rounds_stays_moves() {
    let Some(rs274) = rs274() else {
        return;
    };
    let cl = |peck: &str| {
        format!(
            "FEDRAT/MMPM,500\nRAPID\nGOTO/0,0,20,0,0,1\n\
             CYCLE/DEEP,FEDTO,1,RAPTO,1,STEP,{peck},MMPM,100\nGOTO/5,0,0\nCYCLE/OFF\n"
        )
    };
    let free3 = test_machine("free3");
    for (peck, holes) in [("0.55555", 0), ("0.2", 0), ("0.5555", 1)] {
        let got = same_moves(&rs274, cl(peck).as_bytes(), "peck.cls", &free3);
        assert_eq!(got, holes, "peck {peck}");
    }
}
