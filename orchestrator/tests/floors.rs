//! The orchestrator's floors: no import circle between its top-level
//! modules (`src/*.rs`, `src/*/`). A module may use those below it, never
//! one that (directly or through others) uses it back.
//!
//! An edge is any `crate::NAME` (or `crate::{NAME, …}`) in a line of code
//! of a module's files, tests included; comment lines are not code.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

/// Top-level module name → the files that make it.
fn modules(src: &Path) -> BTreeMap<String, Vec<PathBuf>> {
    let mut out = BTreeMap::new();
    for entry in fs::read_dir(src).expect("src/ is readable") {
        let path = entry.expect("an entry").path();
        let name = path
            .file_stem()
            .expect("a name")
            .to_string_lossy()
            .into_owned();
        if path.is_dir() && name != "bin" {
            out.insert(name, rust_files(&path));
        } else if path.extension().is_some_and(|e| e == "rs") && name != "lib" {
            out.insert(name, vec![path]);
        }
    }
    out
}

/// Every `.rs` file under `dir`.
fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for entry in fs::read_dir(dir).expect("a readable directory") {
        let path = entry.expect("an entry").path();
        if path.is_dir() {
            out.extend(rust_files(&path));
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
    out
}

/// The names `code` reaches through `crate::` (a name, or each of a group).
fn crate_paths(code: &str) -> Vec<String> {
    let ident = |s: &str| -> String {
        s.chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect()
    };
    let mut out = Vec::new();
    for (at, _) in code.match_indices("crate::") {
        let rest = &code[at + "crate::".len()..];
        match rest.strip_prefix('{') {
            Some(group) => {
                let group = &group[..group.find('}').unwrap_or(group.len())];
                out.extend(group.split(',').map(|s| ident(s.trim())));
            }
            None => out.push(ident(rest)),
        }
    }
    out
}

/// Module → the other top-level modules its code uses.
fn edges(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let modules = modules(src);
    let mut out: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for (name, files) in &modules {
        let used = out.entry(name.clone()).or_default();
        for file in files {
            let text = fs::read_to_string(file).expect("a readable file");
            // A `use` group may span lines: join the code into one string.
            let code: String = (text.lines())
                .filter(|l| !l.trim_start().starts_with("//"))
                .collect::<Vec<_>>()
                .join(" ");
            for target in crate_paths(&code) {
                if &target != name && modules.contains_key(&target) {
                    used.insert(target);
                }
            }
        }
    }
    out
}

/// A circle through `from`, if its edges close one (depth-first).
fn circle(
    graph: &BTreeMap<String, BTreeSet<String>>,
    from: &str,
    path: &mut Vec<String>,
) -> Option<Vec<String>> {
    for next in graph.get(from).into_iter().flatten() {
        if next == &path[0] {
            return Some(path.clone());
        }
        if !path.contains(next) {
            path.push(next.clone());
            if let Some(c) = circle(graph, next, path) {
                return Some(c);
            }
            path.pop();
        }
    }
    None
}

#[test]
fn the_top_level_modules_form_no_circle() {
    let graph = edges(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src"));
    assert!(graph.len() > 10, "too few modules found: {graph:?}");
    for start in graph.keys() {
        if let Some(c) = circle(&graph, start, &mut vec![start.clone()]) {
            panic!("import circle: {} -> {start}", c.join(" -> "));
        }
    }
}

#[test]
fn the_edge_reader_finds_names_and_groups_and_a_circle() {
    let paths = crate_paths("use crate::{a, b::c}; let x = crate::d::f();");
    assert_eq!(paths, ["a", "b", "d"]);
    let graph: BTreeMap<String, BTreeSet<String>> = [("a", "b"), ("b", "c"), ("c", "a")]
        .into_iter()
        .map(|(x, y)| (x.to_string(), BTreeSet::from([y.to_string()])))
        .collect();
    let c = circle(&graph, "a", &mut vec!["a".to_string()]);
    assert_eq!(c, Some(vec!["a".into(), "b".into(), "c".into()]));
}

/// The workspace's crates (each directory with a `Cargo.toml` beside
/// `orchestrator/`), but not `examples/` (a user's programs) nor `fuzz/`.
fn workspace_sources() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut out = Vec::new();
    for entry in fs::read_dir(&root).expect("the workspace is readable") {
        let dir = entry.expect("an entry").path();
        let name = dir
            .file_name()
            .expect("a name")
            .to_string_lossy()
            .into_owned();
        if dir.join("Cargo.toml").is_file()
            && !["examples", "fuzz", "target"].contains(&name.as_str())
        {
            for sub in ["src", "tests", "benches"] {
                if dir.join(sub).is_dir() {
                    out.extend(rust_files(&dir.join(sub)));
                }
            }
        }
    }
    out
}

/// Each `Result<…>` in `code` whose error type (its last top-level
/// argument) is `String`.
fn string_results(code: &str) -> Vec<String> {
    let mut out = Vec::new();
    for (at, _) in code.match_indices("Result<") {
        let args = &code[at + "Result<".len()..];
        let (mut depth, mut last, mut end) = (1, 0, None);
        for (k, c) in args.char_indices() {
            match c {
                '<' | '(' | '[' => depth += 1,
                '>' | ')' | ']' => depth -= 1,
                ',' if depth == 1 => last = k + 1,
                _ => {}
            }
            if depth == 0 {
                end = Some(k);
                break;
            }
        }
        if let Some(end) = end
            && last > 0
            && args[last..end].trim() == "String"
        {
            out.push(format!("Result<{}>", &args[..end]));
        }
    }
    out
}

#[test]
fn no_failure_is_a_string() {
    let mut found = Vec::new();
    for file in workspace_sources() {
        let text = fs::read_to_string(&file).expect("a readable file");
        let code: String = (text.lines())
            .filter(|l| !l.trim_start().starts_with("//"))
            .collect::<Vec<_>>()
            .join(" ");
        for r in string_results(&code) {
            found.push(format!("{}: {r}", file.display()));
        }
    }
    assert!(
        found.is_empty(),
        "errors as strings (use a thiserror enum):\n{}",
        found.join("\n")
    );
    assert_eq!(
        string_results(
            "fn f() -> Result<Vec<(u8, String)>,\n String> {} fn g() -> Result<(), E> {}"
        ),
        ["Result<Vec<(u8, String)>,\n String>"]
    );
}

#[test]
fn the_engine_phases_do_not_know_where_a_node_runs() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/processes");
    for file in rust_files(&dir) {
        let text = fs::read_to_string(&file).expect("a readable file");
        let code = text.lines().filter(|l| !l.trim_start().starts_with("//"));
        for line in code {
            assert!(
                !line.contains("remote") && !line.contains("hosts::"),
                "{}: the engine names the remote: {line}",
                file.display()
            );
        }
    }
}
