//! Property tests: random bytes and random edits of valid files never make
//! the grid readers or the surface-file loader panic; every diagnostic
//! points into the input; whatever loads can be fitted or evaluated.

use crate::common;

use kinpost_surface::grid::{BladeSide, read_blade_table, read_grid};
use kinpost_surface::json::{from_json, to_json};
use kinpost_surface::{FitOptions, Surface};
use proptest::prelude::*;

fn check_diagnostics(text: &str, diags: &[kinpost_surface_diag::Diagnostic]) {
    let lines = text.split('\n').count();
    assert!(!diags.is_empty());
    for d in diags {
        assert!(d.line <= lines, "line {} of {lines}", d.line);
        let _ = d.to_string();
    }
}

mod kinpost_surface_diag {
    pub use kinpost_diag::Diagnostic;
}

fn exercise_grid(text: &str) {
    match read_grid(text, "g.csv") {
        Ok(g) => {
            assert_eq!(g.points.len(), g.rows * g.cols);
            if let Ok(s) = Surface::fit(&g, &FitOptions::default()) {
                let _ = s.geometry(0.5, 0.5);
                let _ = s.residual();
            }
        }
        Err(d) => check_diagnostics(text, &d.0),
    }
    match read_blade_table(text, "b.dat", BladeSide::Theta1) {
        Ok(g) => assert_eq!(g.points.len(), g.rows * g.cols),
        Err(d) => check_diagnostics(text, &d.0),
    }
}

fn exercise_json(text: &str) {
    match from_json(text, "s.json") {
        Ok(s) => {
            let _ = s.geometry(0.3, 0.7);
            let _ = s.residual();
            let again = to_json(&s);
            assert_eq!(from_json(&again, "s.json").unwrap(), s);
        }
        Err(d) => check_diagnostics(text, std::slice::from_ref(&d)),
    }
}

fn valid_csv() -> String {
    std::fs::read_to_string(common::li_points_path()).unwrap()
}

fn valid_json() -> String {
    to_json(&Surface::fit(&common::li_points(), &FitOptions::default()).unwrap())
}

/// `text` with a few bytes replaced, inserted or removed at random places.
fn mutate(text: &str, edits: &[(usize, u8, u8)]) -> String {
    let mut b = text.as_bytes().to_vec();
    for &(pos, kind, byte) in edits {
        if b.is_empty() {
            break;
        }
        let p = pos % b.len();
        match kind % 3 {
            0 => b[p] = byte,
            1 => b.insert(p, byte),
            _ => {
                b.remove(p);
            }
        }
    }
    String::from_utf8_lossy(&b).into_owned()
}

const PIECES: &[u8] = b"0123456789.,-+eE \n\r\t#[]{}\":xyzrowcolnaif";

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    #[test]
    fn random_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
        let text = String::from_utf8_lossy(&bytes);
        exercise_grid(&text);
        exercise_json(&text);
    }

    #[test]
    fn number_soup_never_panics(idx in proptest::collection::vec(0usize..PIECES.len(), 0..300)) {
        let text: String = idx.iter().map(|&i| PIECES[i] as char).collect();
        exercise_grid(&text);
        exercise_json(&text);
    }

    #[test]
    fn edited_grids_never_panic(edits in proptest::collection::vec((any::<usize>(), any::<u8>(), prop::sample::select(PIECES.to_vec())), 1..6)) {
        exercise_grid(&mutate(&valid_csv(), &edits));
    }

    #[test]
    fn edited_surface_files_never_panic(edits in proptest::collection::vec((any::<usize>(), any::<u8>(), prop::sample::select(PIECES.to_vec())), 1..6)) {
        exercise_json(&mutate(&valid_json(), &edits));
    }
}
