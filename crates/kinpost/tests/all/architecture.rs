//! The shape of the code, checked on its text: no import cycle among the
//! modules of any crate, the post's stages importing only the stages before
//! them, no function over 150 lines outside tests, and no `String` error in
//! a library's public functions.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn crates_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The `.rs` files under `dir`.
fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The text of a source file without its `#[cfg(test)]` items (test
/// modules may import anything).
fn without_tests(text: &str) -> String {
    let lines: Vec<&str> = text.lines().collect();
    let mut kept = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        if lines[i].trim() == "#[cfg(test)]" && i + 1 < lines.len() {
            let item = lines[i + 1];
            let indent = item.len() - item.trim_start().len();
            let mut k = i + 1;
            if !item.trim_end().ends_with(';') {
                k += 1;
                while k < lines.len() && !is_closing(lines[k], indent) {
                    k += 1;
                }
            }
            i = k + 1;
            continue;
        }
        kept.push(lines[i]);
        i += 1;
    }
    kept.join("\n")
}

/// Whether `line` closes an item opened at `indent`.
fn is_closing(line: &str, indent: usize) -> bool {
    line.len() > indent && line[..indent].trim().is_empty() && line[indent..].starts_with('}')
}

/// A library crate's top-level modules and the files of each.
fn modules(crate_dir: &Path) -> BTreeMap<String, Vec<PathBuf>> {
    let src = crate_dir.join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let mut modules: BTreeMap<String, Vec<PathBuf>> = BTreeMap::new();
    for f in files {
        let rel = f.strip_prefix(&src).unwrap();
        let first = rel.iter().next().unwrap().to_string_lossy().to_string();
        let top = first.trim_end_matches(".rs").to_string();
        modules.entry(top).or_default().push(f);
    }
    modules
}

/// For each top-level module, the crate's other top-level modules it uses
/// (`crate::name`), outside tests.
fn imports(modules: &BTreeMap<String, Vec<PathBuf>>) -> BTreeMap<String, BTreeSet<String>> {
    let mut edges: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for (top, files) in modules {
        let used = edges.entry(top.clone()).or_default();
        if top == "lib" || top == "main" {
            continue;
        }
        for f in files {
            let text = without_tests(&std::fs::read_to_string(f).unwrap());
            for piece in text.split("crate::").skip(1) {
                let name: String = piece
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                if name != *top && modules.contains_key(&name) {
                    used.insert(name);
                }
            }
        }
    }
    edges
}

/// A cycle in `edges`, if there is one.
fn cycle(edges: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        u: &str,
        edges: &BTreeMap<String, BTreeSet<String>>,
        state: &mut BTreeMap<String, u8>,
        stack: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        state.insert(u.to_string(), 1);
        stack.push(u.to_string());
        for v in edges.get(u).into_iter().flatten() {
            match state.get(v) {
                Some(1) => {
                    let at = stack.iter().position(|s| s == v).unwrap();
                    let mut c = stack[at..].to_vec();
                    c.push(v.clone());
                    return Some(c);
                }
                None => {
                    if let Some(c) = visit(v, edges, state, stack) {
                        return Some(c);
                    }
                }
                _ => {}
            }
        }
        stack.pop();
        state.insert(u.to_string(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for u in edges.keys() {
        if !state.contains_key(u)
            && let Some(c) = visit(u, edges, &mut state, &mut Vec::new())
        {
            return Some(c);
        }
    }
    None
}

fn crate_dirs() -> Vec<PathBuf> {
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(crates_dir())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.join("src").is_dir())
        .collect();
    dirs.sort();
    dirs
}

#[test]
fn no_crate_has_an_import_cycle_among_its_modules() {
    for dir in crate_dirs() {
        let edges = imports(&modules(&dir));
        assert_eq!(cycle(&edges), None, "{}", dir.display());
    }
}

/// The post's modules in the order of the data: a module imports only
/// those before it (the stages' shared leaves come first).
#[test]
fn the_post_stages_import_only_upstream() {
    let order = [
        "cycle",
        "error",
        "native_arc",
        "native_cycle",
        "command",
        "config",
        "pressure",
        "program",
        "motion",
        "check",
        "sink",
        "readback",
        "setup",
        "summary",
        "machine_templates",
    ];
    let modules = modules(&crates_dir().join("post"));
    let listed: BTreeSet<&str> = order.iter().copied().chain(["lib"]).collect();
    let present: BTreeSet<&str> = modules.keys().map(String::as_str).collect();
    assert_eq!(present, listed, "every module of the post has its place");
    let edges = imports(&modules);
    for (k, module) in order.iter().enumerate() {
        for used in &edges[*module] {
            let at = order.iter().position(|m| m == used).unwrap();
            assert!(
                at < k,
                "`{module}` imports `{used}`, which comes after it in the data flow"
            );
        }
    }
}

/// Each function of the sources outside tests, with its first line and its
/// length in lines.
fn functions(text: &str) -> Vec<(usize, String, usize)> {
    let lines: Vec<&str> = text.lines().collect();
    let mut found = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        let t = line.trim_start();
        let words: Vec<&str> = t.split_whitespace().collect();
        let Some(at) = words.iter().position(|w| *w == "fn") else {
            continue;
        };
        let qualifiers = [
            "pub",
            "pub(crate)",
            "pub(super)",
            "const",
            "unsafe",
            "async",
        ];
        if !words[..at].iter().all(|w| qualifiers.contains(w)) || t.trim_end().ends_with(';') {
            continue;
        }
        let indent = line.len() - t.len();
        let end = (i + 1..lines.len())
            .find(|&k| is_closing(lines[k], indent))
            .unwrap_or(lines.len() - 1);
        found.push((
            i + 1,
            words.get(at + 1).unwrap_or(&"").to_string(),
            end - i + 1,
        ));
    }
    found
}

#[test]
fn no_function_is_over_150_lines_outside_tests() {
    let mut long = Vec::new();
    for dir in crate_dirs() {
        let mut files = Vec::new();
        rust_files(&dir.join("src"), &mut files);
        for f in files {
            let text = without_tests(&std::fs::read_to_string(&f).unwrap());
            for (line, name, length) in functions(&text) {
                if length > 150 {
                    // (The line is of the text without its tests.)
                    long.push(format!("{}:{line}: {name} ({length} lines)", f.display()));
                }
            }
        }
    }
    assert!(long.is_empty(), "functions over 150 lines: {long:#?}");
}

#[test]
fn no_library_returns_a_string_error() {
    let mut found = Vec::new();
    for dir in crate_dirs() {
        if dir.ends_with("kinpost") {
            continue;
        }
        let mut files = Vec::new();
        rust_files(&dir.join("src"), &mut files);
        for f in files {
            let text = without_tests(&std::fs::read_to_string(&f).unwrap());
            for piece in text.split("pub fn ").skip(1) {
                let signature = piece.split('{').next().unwrap_or("");
                let compact: String = signature.split_whitespace().collect();
                if compact.contains(",String>") && compact.contains("Result<") {
                    found.push(format!(
                        "{}: {}",
                        f.display(),
                        signature.split('(').next().unwrap_or("")
                    ));
                }
            }
        }
    }
    assert!(
        found.is_empty(),
        "public functions with a String error: {found:#?}"
    );
}
