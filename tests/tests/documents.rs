//! The documents stay readable and inside the repository (issue 34, part 5):
//! README.md is a front door of at most 250 lines, ARCHITECTURE.md one page
//! of at most 150; no tracked file points at the paper's notes in a
//! `shared` directory beside the repository ([`FORBIDDEN`]) or into a
//! machine's work tree ([`WORK_TREE`]); every relative Markdown link
//! `[text](path)` of a tracked `*.md` file resolves to a file or directory
//! of the repository.
//!
//! The files are those `git ls-files` lists; outside a git checkout, every
//! file under the repository except `.git`, `target` and `results`.

use std::fs;
use std::path::{Component, Path, PathBuf};
use std::process::Command;

/// The most lines README.md may have.
const README_LINES: usize = 250;
/// The most lines ARCHITECTURE.md may have.
const ARCHITECTURE_LINES: usize = 150;

/// What no tracked file may contain, split so that this file does not.
const FORBIDDEN: [&str; 2] = [concat!("..", "/shared"), concat!("shared", "/paper")];
/// A path into a machine's work tree, split likewise.
const WORK_TREE: &str = concat!("/wo", "rk/");

/// The repository's root: the parent of this crate.
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("the tests crate sits in the repository")
        .to_path_buf()
}

/// The repository's files, relative to `root`.
fn tracked(root: &Path) -> Vec<PathBuf> {
    let git = Command::new("git")
        .arg("-C")
        .arg(root)
        .args(["ls-files", "-z"])
        .output();
    match git {
        Ok(out) if out.status.success() => out
            .stdout
            .split(|&b| b == 0)
            .filter(|name| !name.is_empty())
            .map(|name| PathBuf::from(String::from_utf8_lossy(name).into_owned()))
            .filter(|p| root.join(p).is_file())
            .collect(),
        _ => {
            let mut files = Vec::new();
            walk(root, Path::new(""), &mut files);
            files
        }
    }
}

/// Every file under `root/dir`, skipping build output and git's own files.
fn walk(root: &Path, dir: &Path, files: &mut Vec<PathBuf>) {
    let Ok(entries) = fs::read_dir(root.join(dir)) else {
        return;
    };
    for entry in entries.flatten() {
        let name = entry.file_name();
        let rel = dir.join(&name);
        let Ok(kind) = entry.file_type() else {
            continue;
        };
        if kind.is_dir() {
            if !matches!(name.to_str(), Some(".git" | "target" | "results")) {
                walk(root, &rel, files);
            }
        } else if kind.is_file() {
            files.push(rel);
        }
    }
}

/// `path`'s number of lines.
fn lines(path: &Path) -> usize {
    fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .lines()
        .count()
}

/// Where `bytes` contains a path outside the repository: a forbidden string
/// or a work-tree path ([`WORK_TREE`] not preceded by a name's character).
fn outside_paths(bytes: &[u8]) -> Vec<&'static str> {
    let mut found: Vec<&'static str> = FORBIDDEN
        .iter()
        .copied()
        .filter(|needle| contains(bytes, needle.as_bytes()))
        .collect();
    let w = WORK_TREE.as_bytes();
    let work_tree = (0..bytes.len().saturating_sub(w.len() - 1)).any(|i| {
        bytes[i..].starts_with(w)
            && (i == 0 || !(bytes[i - 1].is_ascii_alphanumeric() || b"_-.".contains(&bytes[i - 1])))
    });
    if work_tree {
        found.push(WORK_TREE);
    }
    found
}

fn contains(haystack: &[u8], needle: &[u8]) -> bool {
    haystack.windows(needle.len()).any(|w| w == needle)
}

/// The targets of the inline links `[text](target)` of a Markdown text,
/// outside fenced code blocks and inline code, with their line numbers.
fn link_targets(text: &str) -> Vec<(usize, String)> {
    let mut targets = Vec::new();
    let mut fenced = false;
    for (n, line) in text.lines().enumerate() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced {
            continue;
        }
        // Drop inline code spans: `[a](b)` in backticks is not a link.
        let mut prose = String::new();
        for (k, part) in line.split('`').enumerate() {
            if k % 2 == 0 {
                prose.push_str(part);
            }
        }
        let mut rest = prose.as_str();
        while let Some(at) = rest.find("](") {
            let after = &rest[at + 2..];
            let Some(end) = after.find(')') else {
                break;
            };
            let inner = after[..end].trim();
            let target = inner
                .strip_prefix('<')
                .and_then(|t| t.split('>').next())
                .unwrap_or_else(|| inner.split_whitespace().next().unwrap_or(""));
            targets.push((n + 1, target.to_string()));
            rest = &after[end..];
        }
    }
    targets
}

/// Why `target`, linked from `file` (relative to `root`), does not resolve
/// inside the repository; `None` if it does or is not a relative link.
fn broken_link(root: &Path, file: &Path, target: &str) -> Option<String> {
    let lower = target.to_ascii_lowercase();
    if lower.starts_with("http://") || lower.starts_with("https://") || lower.starts_with("mailto:")
    {
        return None;
    }
    let path = target.split('#').next().unwrap_or("");
    if path.is_empty() {
        return None; // an anchor in the same file
    }
    if path.starts_with('/') || path.contains("://") {
        return Some("not a relative path".to_string());
    }
    // Resolve lexically against the file's directory, never above the root.
    let mut resolved = PathBuf::new();
    for part in file
        .parent()
        .unwrap_or(Path::new(""))
        .join(path)
        .components()
    {
        match part {
            Component::Normal(p) => resolved.push(p),
            Component::CurDir => {}
            Component::ParentDir => {
                if !resolved.pop() {
                    return Some("leaves the repository".to_string());
                }
            }
            _ => return Some("not a relative path".to_string()),
        }
    }
    if root.join(&resolved).exists() {
        None
    } else {
        Some(format!("{} does not exist", resolved.display()))
    }
}

#[test]
fn readme_is_a_front_door() {
    let n = lines(&root().join("README.md"));
    assert!(
        n <= README_LINES,
        "README.md has {n} lines, more than {README_LINES}: move the detail into docs/"
    );
}

#[test]
fn architecture_is_one_page() {
    let n = lines(&root().join("ARCHITECTURE.md"));
    assert!(
        n <= ARCHITECTURE_LINES,
        "ARCHITECTURE.md has {n} lines, more than {ARCHITECTURE_LINES}: the detail belongs in module docs"
    );
}

#[test]
fn no_file_points_outside_the_repository() {
    let root = root();
    let files = tracked(&root);
    assert!(
        files.iter().any(|f| f == Path::new("README.md")),
        "no files found under {}",
        root.display()
    );
    let mut problems = Vec::new();
    for file in &files {
        let Ok(bytes) = fs::read(root.join(file)) else {
            continue;
        };
        for needle in outside_paths(&bytes) {
            problems.push(format!("{}: contains {needle:?}", file.display()));
        }
    }
    assert!(
        problems.is_empty(),
        "paths outside the repository (cite docs/paper.md or the paper's reference instead):\n{}",
        problems.join("\n")
    );
}

#[test]
fn every_relative_markdown_link_resolves() {
    let root = root();
    let mut checked = 0;
    let mut problems = Vec::new();
    for file in tracked(&root) {
        if file.extension().and_then(|e| e.to_str()) != Some("md") {
            continue;
        }
        let text = fs::read_to_string(root.join(&file))
            .unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        for (line, target) in link_targets(&text) {
            checked += 1;
            if let Some(why) = broken_link(&root, &file, &target) {
                problems.push(format!("{}:{line}: ({target}): {why}", file.display()));
            }
        }
    }
    assert!(checked > 0, "no Markdown links found");
    assert!(
        problems.is_empty(),
        "broken Markdown links:\n{}",
        problems.join("\n")
    );
}

/// The checks themselves find what they are for.
#[test]
fn the_checks_can_fail() {
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path();
    fs::create_dir(root.join("docs")).unwrap();
    fs::write(root.join("docs/a.md"), "# A\n").unwrap();
    let readme = "line\n".repeat(README_LINES + 1);
    fs::write(root.join("README.md"), &readme).unwrap();
    assert!(lines(&root.join("README.md")) > README_LINES);

    // The paper's notes beside the repository, as the scenarios cited them.
    let notes = format!("see {}{}/NOTES.md", FORBIDDEN[0], &FORBIDDEN[1][6..]);
    assert_eq!(outside_paths(notes.as_bytes()), FORBIDDEN.to_vec());
    let built = format!("built in {WORK_TREE}wt-fuzz/target");
    assert_eq!(outside_paths(built.as_bytes()), vec![WORK_TREE]);
    let quoted = format!("`{}/`", FORBIDDEN[1]);
    assert_eq!(outside_paths(quoted.as_bytes()), vec![FORBIDDEN[1]]);
    assert!(outside_paths(b"network/work/ homework/x docs/paper.md").is_empty());

    let text = "[ok](docs/a.md#top) [gone](docs/b.md) [up](../x.md) [abs](/etc/passwd)\n\
                [web](https://example.org) [here](#anchor) `[code](nowhere.md)`\n\
                ```\n[fenced](nowhere.md)\n```\n";
    let targets: Vec<String> = link_targets(text).into_iter().map(|(_, t)| t).collect();
    assert_eq!(
        targets,
        [
            "docs/a.md#top",
            "docs/b.md",
            "../x.md",
            "/etc/passwd",
            "https://example.org",
            "#anchor"
        ]
    );
    let file = Path::new("README.md");
    let broken: Vec<bool> = targets
        .iter()
        .map(|t| broken_link(root, file, t).is_some())
        .collect();
    assert_eq!(broken, [false, true, true, true, false, false]);
    // From docs/, `../README.md` is inside the repository.
    assert!(broken_link(root, Path::new("docs/a.md"), "../README.md").is_none());
}
