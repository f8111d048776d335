//! Statement words and "did you mean" suggestions for unknown ones.

/// Words the reader understands, for suggestions.
const KNOWN: &[&str] = &[
    "GOTO",
    "RAPID",
    "FEDRAT",
    "TLDATA",
    "CUTTER",
    "MSYS",
    "LOAD",
    "SELECT",
    "SPINDL",
    "COOLNT",
    "INSERT",
    "END-OF-PATH",
    "PARTNO",
    "UNITS",
    "MULTAX",
    "PRESSURE",
    "FINI",
    "PPRINT",
    "PAINT",
    "TRNTYP",
    "CSYS",
    "CUTCOM",
    "CIRCLE",
    "CYCLE",
    "NURBS",
    "TLAXIS",
    "GODLTA",
    "LOADTL",
    "FROM",
    "GOHOME",
    "STOP",
    "OPSTOP",
    "END",
    "MACHIN",
    "OPNAME",
    "CLAMP",
    "TMARK",
    "ORIGIN",
    "DELAY",
    "DWELL",
    "KNOT",
    "CNTRL",
    "SETUP",
    "TPRINT",
    "TOOLNO",
    "REWIND",
];

/// The known word closest to `word` (case-insensitive), if it is close enough
/// to be a likely misspelling: one edit for short words, two for longer ones.
pub(crate) fn suggest(word: &str) -> Option<&'static str> {
    if word.is_empty() || word.len() > 40 {
        return None;
    }
    let upper = word.to_ascii_uppercase();
    let limit = if upper.len() <= 4 { 1 } else { 2 };
    KNOWN
        .iter()
        .map(|k| (distance(upper.as_bytes(), k.as_bytes()), *k))
        .filter(|&(d, _)| d > 0 && d <= limit)
        .min_by_key(|&(d, _)| d)
        .map(|(_, k)| k)
}

/// Optimal string alignment distance (Levenshtein plus adjacent swaps).
fn distance(a: &[u8], b: &[u8]) -> usize {
    let n = b.len();
    let mut two_ago: Vec<usize> = vec![0; n + 1];
    let mut prev: Vec<usize> = (0..=n).collect();
    let mut cur: Vec<usize> = vec![0; n + 1];
    for i in 1..=a.len() {
        cur[0] = i;
        for j in 1..=n {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            let mut d = (prev[j] + 1).min(cur[j - 1] + 1).min(prev[j - 1] + cost);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                d = d.min(two_ago[j - 2] + 1);
            }
            cur[j] = d;
        }
        std::mem::swap(&mut two_ago, &mut prev);
        std::mem::swap(&mut prev, &mut cur);
    }
    prev[n]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn suggests_close_words_only() {
        assert_eq!(suggest("TLDDATA"), Some("TLDATA"));
        assert_eq!(suggest("fedrate"), Some("FEDRAT"));
        assert_eq!(suggest("GOOT"), Some("GOTO"));
        assert_eq!(suggest("SPINDLE"), Some("SPINDL"));
        assert_eq!(suggest("FOO"), None);
        assert_eq!(suggest("GOTO"), None);
        assert_eq!(distance(b"abc", b""), 3);
        assert_eq!(distance(b"ab", b"ba"), 1);
    }
}
