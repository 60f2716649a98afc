//! Every numeric setting the format document lists has a checked range: each one, set far outside any sensible value in an otherwise valid scenario, is refused at load with the field named (the document's tables are the list, so a new key without a check fails here).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use forkbench_trial::{Scenario, World};

fn repo(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(rel)
}

/// The document's tables: heading → key → default as written.
fn documented(doc: &str) -> BTreeMap<String, BTreeMap<String, String>> {
    let mut out: BTreeMap<String, BTreeMap<String, String>> = BTreeMap::new();
    let mut section = String::new();
    for line in doc.lines() {
        if line.starts_with("## ") {
            section = if line.starts_with("## The scenario file") {
                "Top level".into()
            } else {
                String::new()
            };
            continue;
        }
        if let Some(h) = line.strip_prefix("### ") {
            section = h.replace('`', "");
            continue;
        }
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        if cells.len() >= 4 && cells[1].starts_with('`') && !section.is_empty() {
            let key = cells[1].trim_matches('`').to_owned();
            let default = cells[2].trim_matches('`').to_owned();
            out.entry(section.clone()).or_default().insert(key, default);
        }
    }
    out
}

/// A table's path in the scenario, and the entries that select its kind.
type Place<'a> = (Vec<&'a str>, Vec<(&'a str, &'a str)>);

/// Where a document section's keys live in a scenario, and the table entries that select
/// the kind the section describes.
fn place(section: &str) -> Option<Place<'_>> {
    let (path, kind): (&str, Option<&str>) = match section.split_once(' ') {
        Some((p, k)) => (p, Some(k)),
        None => (section, None),
    };
    if section == "Top level" {
        return Some((vec![], vec![]));
    }
    let path = path.strip_prefix('[')?.strip_suffix(']')?;
    let keys: Vec<&str> = path.split('.').collect();
    let kind = match kind {
        Some(k) if path != "sensors.pallet.detector" => vec![("kind", k)],
        _ => vec![],
    };
    Some((keys, kind))
}

/// The base scenario (the warehouse cycle: a mission, every phase, a NAV350 and two
/// pallet scanners) with each `(key, value)` at `table.key`.
fn with_settings(
    table: &[&str],
    select: &[(&str, &str)],
    settings: &[(String, toml::Value)],
) -> String {
    let base = std::fs::read_to_string(repo("scenarios/warehouse-cycle.toml")).expect("base");
    let mut doc: toml::Table = toml::from_str(&base).expect("base parses");
    let mut t = &mut doc;
    for k in table {
        let slot = t
            .entry((*k).to_owned())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        if !slot.is_table() {
            // `planner = "bspline"` becomes a table of that kind.
            *slot = toml::Value::Table(toml::Table::new());
        }
        t = slot.as_table_mut().expect("a table");
    }
    for (k, v) in select {
        t.insert((*k).to_owned(), toml::Value::String((*v).to_owned()));
    }
    for (key, value) in settings {
        let mut parts: Vec<&str> = key.split('.').collect();
        let last = parts.pop().expect("a key");
        let mut inner = &mut *t;
        for k in parts {
            inner = inner
                .entry(k.to_owned())
                .or_insert_with(|| toml::Value::Table(toml::Table::new()))
                .as_table_mut()
                .expect("a table");
        }
        inner.insert(last.to_owned(), value.clone());
    }
    toml::to_string(&doc).expect("serialises")
}

/// A documented default as a TOML value.
fn default_value(text: &str) -> Option<toml::Value> {
    let t: toml::Table = toml::from_str(&format!("v = {text}")).ok()?;
    t.get("v").cloned()
}

/// The documented defaults of `key`'s sibling keys (`mount.y_m` beside `mount.x_m`): a
/// table whose keys are all required.
fn siblings(keys: &BTreeMap<String, String>, key: &str) -> Vec<(String, toml::Value)> {
    let Some((prefix, _)) = key.rsplit_once('.') else {
        return vec![];
    };
    keys.iter()
        .filter(|(k, _)| k.rsplit_once('.').is_some_and(|(p, _)| p == prefix) && *k != key)
        .filter_map(|(k, d)| Some((k.clone(), default_value(d)?)))
        .collect()
}

fn load(text: &str) -> Result<Scenario, String> {
    let file = repo("scenarios/walk.toml");
    Scenario::parse(text, &file.display().to_string(), |w| {
        World::load(&repo("scenarios").join(w))
    })
    .map_err(|e| e.to_string())
}

#[test]
fn every_documented_numeric_setting_is_range_checked() {
    let doc = std::fs::read_to_string(repo("docs/scenario-format.md")).expect("the format doc");
    load(&with_settings(&[], &[], &[])).expect("the base loads");
    let mut problems = Vec::new();
    let mut walked = 0;
    for (section, keys) in documented(&doc) {
        let Some((table, select)) = place(&section) else {
            continue;
        };
        for (key, default) in &keys {
            // A seed's range is all of u64: it names a random stream, it sizes nothing.
            if key == "seed" {
                continue;
            }
            let bad: Vec<toml::Value> = if default.parse::<i64>().is_ok() && key != "payload_kg" {
                vec![toml::Value::Integer(i64::MAX)]
            } else if default.parse::<f64>().is_ok() {
                vec![toml::Value::Float(1e300), toml::Value::Float(-1e300)]
            } else {
                continue;
            };
            walked += 1;
            let field = key.rsplit('.').next().expect("a key");
            for v in bad {
                let shown = match &v {
                    toml::Value::Float(f) => format!("{f:e}"),
                    other => other.to_string(),
                };
                let mut settings = siblings(&keys, key);
                settings.push((key.clone(), v));
                match load(&with_settings(&table, &select, &settings)) {
                    Ok(_) => problems.push(format!("{section} `{key}` = {shown}: accepted")),
                    Err(e) if !e.contains(field) => problems.push(format!(
                        "{section} `{key}` = {shown}: refused without naming it: {e}"
                    )),
                    Err(_) => {}
                }
            }
        }
    }
    assert!(
        walked > 100,
        "only {walked} numeric keys found in the document"
    );
    assert!(
        problems.is_empty(),
        "{} problems:\n{}",
        problems.len(),
        problems.join("\n")
    );
}
