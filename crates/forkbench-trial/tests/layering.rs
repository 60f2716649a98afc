//! The crate's modules in layers: each top-level module names (through `crate::` paths or the root's re-exports) only modules below it, and the files of one folder import one another without a cycle.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

/// The top-level modules, lowest first: each may name only those before it.
const LAYERS: &[&str] = &[
    "outcome",
    "stage_error",
    "step_criteria",
    "mission_summary",
    "recorder",
    "phase",
    "components",
    "scenario",
    "defaults",
    "trial",
];

fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

/// Every `.rs` file under `dir`.
fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for entry in fs::read_dir(dir).expect("reads the source folder") {
        let path = entry.expect("entry").path();
        if path.is_dir() {
            out.extend(rust_files(&path));
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
    out
}

/// A file's code: comments and its `#[cfg(test)]` tail left out (a doc link or a test's
/// import is not a dependency of the module).
fn code(path: &Path) -> String {
    let text = fs::read_to_string(path).expect("reads a source file");
    let text = text.split("#[cfg(test)]").next().unwrap_or_default();
    text.lines()
        .map(|l| l.split("//").next().unwrap_or_default())
        .collect::<Vec<_>>()
        .join("\n")
}

/// The identifiers that follow `prefix` in `text`, and the names a `prefix{a, b::c}`
/// group imports.
fn after(text: &str, prefix: &str) -> Vec<String> {
    let ident = |s: &str| -> String {
        s.chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect()
    };
    let mut out = Vec::new();
    for (i, _) in text.match_indices(prefix) {
        let rest = &text[i + prefix.len()..];
        if let Some(group) = rest.strip_prefix('{') {
            let inner = &group[..group.find('}').unwrap_or(group.len())];
            out.extend(inner.split(',').map(|p| ident(p.trim())));
        } else {
            out.push(ident(rest));
        }
    }
    out.retain(|s| !s.is_empty());
    out
}

/// What each name the crate root re-exports (`pub use module::{A, B}`) comes from.
fn root_reexports() -> BTreeMap<String, String> {
    let lib = code(&src().join("lib.rs"));
    let mut out = BTreeMap::new();
    for line in lib.split(';') {
        let Some(rest) = line.trim().strip_prefix("pub use ") else {
            continue;
        };
        let Some((module, names)) = rest.split_once("::") else {
            continue;
        };
        for name in after(&format!("::{names}"), "::") {
            out.insert(name, module.to_owned());
        }
    }
    out
}

#[test]
fn each_module_names_only_those_below_it() {
    let reexports = root_reexports();
    let rank = |m: &str| LAYERS.iter().position(|l| *l == m);
    let mut wrong = Vec::new();
    for file in rust_files(&src()) {
        let rel = file.strip_prefix(src()).expect("under src");
        let top = rel.iter().next().expect("a part").to_string_lossy();
        let top = top.trim_end_matches(".rs");
        if top == "lib" {
            continue;
        }
        let me = rank(top).unwrap_or_else(|| panic!("module {top} is missing from LAYERS"));
        for name in after(&code(&file), "crate::") {
            let module = reexports.get(&name).cloned().unwrap_or(name);
            if let Some(r) = rank(&module)
                && r > me
            {
                wrong.push(format!("{} names {module}", rel.display()));
            }
        }
    }
    assert!(wrong.is_empty(), "edges against the layers: {wrong:#?}");
}

/// The files (or subfolders) of `dir` that each one imports through `super::` or
/// `crate::<folder>::` (a crate's own `src/`, `folder` empty: through `super::` or
/// `crate::`; its `lib.rs` is the folder's `mod.rs`).
fn sibling_edges(dir: &Path, folder: &str) -> BTreeMap<String, BTreeSet<String>> {
    let unit = |p: &Path| -> String {
        let rel = p.strip_prefix(dir).expect("under the folder");
        let first = rel.iter().next().expect("a part").to_string_lossy();
        first.trim_end_matches(".rs").to_owned()
    };
    let files = rust_files(dir);
    let units: BTreeSet<String> = files.iter().map(|f| unit(f)).collect();
    let through = match folder {
        "" => "crate::".to_owned(),
        f => format!("crate::{f}::"),
    };
    let mut edges: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for file in &files {
        let me = unit(file);
        if me == "mod" || me == "lib" {
            continue;
        }
        let text = code(file);
        let mut named = after(&text, "super::");
        named.extend(after(&text, &through));
        for n in named {
            if n != me && n != "mod" && units.contains(&n) {
                edges.entry(me.clone()).or_default().insert(n);
            }
        }
    }
    edges
}

/// A cycle in `edges`, if there is one.
fn a_cycle(edges: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        v: &str,
        edges: &BTreeMap<String, BTreeSet<String>>,
        path: &mut Vec<String>,
        done: &mut BTreeSet<String>,
    ) -> Option<Vec<String>> {
        if let Some(i) = path.iter().position(|p| p == v) {
            return Some(path[i..].to_vec());
        }
        if done.contains(v) {
            return None;
        }
        path.push(v.to_owned());
        for w in edges.get(v).into_iter().flatten() {
            if let Some(c) = visit(w, edges, path, done) {
                return Some(c);
            }
        }
        path.pop();
        done.insert(v.to_owned());
        None
    }
    let mut done = BTreeSet::new();
    edges
        .keys()
        .find_map(|v| visit(v, edges, &mut Vec::new(), &mut done))
}

#[test]
fn the_files_of_a_folder_import_one_another_without_a_cycle() {
    for folder in [
        "phase",
        "components",
        "step_criteria",
        "trial",
        "trial/safety",
    ] {
        let edges = sibling_edges(&src().join(folder), &folder.replace('/', "::"));
        assert_eq!(a_cycle(&edges), None, "in {folder}/");
    }
    // The scenario format's crate: its modules are the root's files.
    let format = src().join("../../forkbench-scenario/src");
    assert_eq!(
        a_cycle(&sibling_edges(&format, "")),
        None,
        "in forkbench-scenario"
    );
}

#[test]
fn the_checks_see_a_cycle_and_an_edge_against_the_layers() {
    let mut edges: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    edges.entry("a".into()).or_default().insert("b".into());
    assert_eq!(a_cycle(&edges), None);
    edges.entry("b".into()).or_default().insert("a".into());
    assert_eq!(a_cycle(&edges), Some(vec!["a".to_owned(), "b".to_owned()]));
    assert_eq!(
        after("use crate::{outcome::X, scenario};", "crate::"),
        ["outcome", "scenario"]
    );
    assert_eq!(after("crate::World::load", "crate::"), ["World"]);
    let format = sibling_edges(&src().join("../../forkbench-scenario/src"), "");
    assert!(
        format.get("phases").is_some_and(|e| e.contains("checks")),
        "the format crate's imports are seen: {format:?}"
    );
    assert_eq!(
        root_reexports().get("World").map(String::as_str),
        Some("scenario")
    );
}
