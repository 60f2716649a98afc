//! Each field of a trial's state is written in one file, the stage that owns it: an assignment (`=`, `+=`, …) or an in-place change (`push`, `insert`, `clear`, …) of a field of the world, the localisation, the perception, the verdict or the trial itself appears only in its owner's file under `src/trial/`, so a reader who wants to know what changes a value reads one file.

use std::fs;
use std::path::Path;

/// Owners by field path, longest prefix first wins; every written path needs one.
const OWNERS: &[(&str, &str)] = &[
    ("world.", "engine.rs"),
    ("loc.first_fix", "sense.rs"),
    ("loc.", "localize.rs"),
    ("sense.", "sense.rs"),
    ("verdict.out.legs", "mission.rs"),
    ("verdict.out.phases", "phases.rs"),
    ("verdict.out.cycle", "phases.rs"),
    ("verdict.out.path_length_m", "plan.rs"),
    ("verdict.out.estimate", "sense.rs"),
    ("verdict.out.replans", "drive.rs"),
    ("verdict.out.lateral_error_m", "drive.rs"),
    ("verdict.out.heading_error_rad", "drive.rs"),
    ("verdict.out.max_contact_force_n", "drive.rs"),
    ("verdict.out.", "judge.rs"),
    ("verdict.timed_out", "drive.rs"),
    ("verdict.pick_started", "mod.rs"),
    ("verdict.pick_waited_s", "sense.rs"),
    ("verdict.phase_measures", "phase_host.rs"),
    ("trial.path", "plan.rs"),
    ("trial.path_version", "plan.rs"),
    ("trial.stage", "engine.rs"),
    ("trial.link", "mod.rs"),
    ("trial.safety", "safety/mod.rs"),
];

/// The trial's own fields, written as `self.F`, `t.F` or `trial.F`.
const TRIAL_FIELDS: &[&str] = &[
    "path",
    "path_version",
    "stage",
    "link",
    "safety",
    "insertion_m",
    "planner",
    "tracker",
    "world",
    "loc",
    "sense",
    "verdict",
];

const CHANGES: &[&str] = &[
    "push", "insert", "remove", "clear", "take", "replace", "extend", "retain", "append",
    "truncate", "drain", "pop",
];

fn ident(c: char) -> bool {
    c.is_alphanumeric() || c == '_'
}

/// The dotted path that starts at byte `at` of `line`, and what follows it.
fn path_at(line: &str, at: usize) -> (String, &str) {
    let rest = &line[at..];
    let end = rest
        .char_indices()
        .find(|&(i, c)| {
            !(ident(c) || (c == '.' && rest[i + 1..].starts_with(|d: char| d.is_alphabetic())))
        })
        .map_or(rest.len(), |(i, _)| i);
    (rest[..end].to_owned(), &rest[end..])
}

/// Whether what follows a path writes it: `= x` (not `==`), `op= x`, or an in-place change.
fn writes(path: &str, after: &str) -> Option<String> {
    let a = after.trim_start();
    let assign = (a.starts_with('=') && !a.starts_with("=="))
        || ["+=", "-=", "*=", "/=", "|=", "&="]
            .iter()
            .any(|op| a.starts_with(op));
    if assign {
        return Some(path.to_owned());
    }
    let (head, last) = path.rsplit_once('.')?;
    (CHANGES.contains(&last) && a.starts_with('(')).then(|| head.to_owned())
}

/// Every field path of trial state that `text` writes, with its line number.
fn written(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    // `self` is a trial inside an `impl` for `Trial` only (a session's own fields are not
    // the trial's state).
    let mut self_is_trial = true;
    for (n, line) in text.lines().enumerate() {
        let line = line.split("//").next().unwrap_or_default();
        if line.starts_with("impl") {
            self_is_trial = line.contains("Trial<") || line.contains("Trial ");
        }
        for (at, _) in line.char_indices() {
            if at > 0 && line[..at].ends_with(|c: char| ident(c) || c == '.') {
                continue;
            }
            let (path, after) = path_at(line, at);
            let parts: Vec<&str> = path.split('.').collect();
            let key = match parts.as_slice() {
                [base, field, ..]
                    if ["t", "trial"].contains(base) || (*base == "self" && self_is_trial) =>
                {
                    if !TRIAL_FIELDS.contains(field) {
                        continue;
                    }
                    if ["world", "loc", "sense", "verdict"].contains(field) {
                        parts[1..].join(".")
                    } else {
                        format!("trial.{}", parts[1..].join("."))
                    }
                }
                [base, _, ..] if ["world", "loc", "sense", "verdict"].contains(base) => {
                    path.clone()
                }
                _ => continue,
            };
            if let Some(w) = writes(&key, after)
                && w.contains('.')
            {
                out.push((n + 1, w));
            }
        }
    }
    out
}

fn owner(path: &str) -> Option<&'static str> {
    OWNERS
        .iter()
        .filter(|(prefix, _)| path.starts_with(prefix.trim_end_matches('.')))
        .max_by_key(|(prefix, _)| prefix.len())
        .map(|(_, file)| *file)
}

/// Every `.rs` file under `dir`, named by its path below `root` (`safety/mod.rs`).
fn sources(root: &Path, dir: &Path, out: &mut Vec<(String, String)>) {
    for entry in fs::read_dir(dir).expect("a source folder") {
        let path = entry.expect("entry").path();
        if path.is_dir() {
            sources(root, &path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            let name = path
                .strip_prefix(root)
                .expect("below root")
                .to_string_lossy();
            let text = fs::read_to_string(&path).expect("source");
            out.push((name.replace('\\', "/"), text));
        }
    }
}

#[test]
fn every_field_of_trial_state_is_written_by_its_owner_only() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/trial");
    let mut files = Vec::new();
    sources(&dir, &dir, &mut files);
    let mut wrong = Vec::new();
    let mut seen = 0;
    for (file, text) in &files {
        if file == "state.rs" || file == "setup.rs" {
            continue; // the state's definition and its one construction
        }
        let text = text.split("#[cfg(test)]").next().unwrap_or_default();
        for (line, field) in written(text) {
            seen += 1;
            match owner(&field) {
                Some(o) if o == file => {}
                Some(o) => wrong.push(format!("{file}:{line}: writes {field}, which {o} owns")),
                None => wrong.push(format!("{file}:{line}: writes {field}, which has no owner")),
            }
        }
    }
    assert!(seen > 20, "only {seen} writes found: the scan is broken");
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

#[test]
fn the_scan_sees_assignments_and_in_place_changes() {
    let text = "self.verdict.out.replans += 1;\n t.sense.in_flight = None;\n if self.loc.fix_lost == x {}\n\
                self.verdict.out.legs.push(leg);\n world.travelled_m += d;\n self.stage = s;\n let a = self.path.len();";
    let got: Vec<String> = written(text).into_iter().map(|(_, f)| f).collect();
    assert_eq!(
        got,
        [
            "verdict.out.replans",
            "sense.in_flight",
            "verdict.out.legs",
            "world.travelled_m",
            "trial.stage"
        ]
    );
    assert_eq!(owner("verdict.out.replans_failed"), Some("drive.rs"));
    assert_eq!(owner("verdict.out.estimates_missed"), Some("sense.rs"));
    assert_eq!(owner("verdict.out.success"), Some("judge.rs"));
    assert_eq!(owner("loc.first_fix"), Some("sense.rs"));
    assert_eq!(owner("trial.stage"), Some("engine.rs"));
    assert_eq!(owner("trial.insertion_m"), None);
}
