//! `docs/scenario-format.md` cannot drift from the code: every key and default of each table with defaults is documented with the same default (and nothing else is), and the document's full examples load.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use forkbench_trial::scenario::mission::GlobalFile;
use forkbench_trial::scenario::{NoiseFile, PickFile, ReplanFile, Tolerances};
use forkbench_trial::{Scenario, World};

fn repo(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(rel)
}

fn value<T: serde::Serialize>(v: &T) -> toml::Value {
    toml::Value::try_from(v).expect("serialises to TOML")
}

/// The truck's defaults, with the keys its serialisation leaves out at their default (so
/// settings hashes made before they existed still match) put back.
fn truck_defaults() -> toml::Value {
    let spec = forkbench_core::ForkliftSpec::default();
    let mut v = value(&spec);
    if let toml::Value::Table(t) = &mut v {
        t.insert(
            "rated_capacity_kg".to_owned(),
            toml::Value::Float(spec.rated_capacity_kg),
        );
        // Tables of their own in the document.
        for table in ["steering", "drive", "control"] {
            t.remove(table);
        }
    }
    v
}

/// Each table with defaults, by the heading it has in the document.
fn defaulted() -> Vec<(String, toml::Value)> {
    let phases = forkbench_trial::phase::phase_defaults()
        .into_iter()
        .map(|(name, v)| (format!("[phase.{name}]"), v));
    defaulted_tables()
        .into_iter()
        .map(|(s, v)| (s.to_owned(), v))
        .chain(phases)
        .collect()
}

fn defaulted_tables() -> Vec<(&'static str, toml::Value)> {
    let noise = NoiseFile::default();
    let scanner =
        |m: &str| value(&forkbench_sensors::scan::ScannerConfig::preset(m).expect("preset"));
    vec![
        ("[truck]", truck_defaults()),
        (
            "[truck.steering]",
            value(&forkbench_core::actuators::SteeringActuator::default()),
        ),
        (
            "[truck.drive]",
            value(&forkbench_core::actuators::DriveActuator::default()),
        ),
        (
            "[truck.control]",
            value(&forkbench_core::actuators::ControlTiming::default()),
        ),
        ("[sim]", value(&forkbench_sim::SimConfig::default())),
        ("[noise.nav350]", value(&noise.nav350)),
        ("[noise.pallet_estimate]", value(&noise.pallet_estimate)),
        ("[noise.odometry]", value(&noise.odometry)),
        ("[replan]", value(&ReplanFile::default())),
        ("[pick]", value(&PickFile::default())),
        ("[tolerances]", value(&Tolerances::default())),
        (
            "[safety]",
            value(&forkbench_safety::SafetyConfig::default()),
        ),
        (
            "[planner] bspline",
            value(&forkbench_plan::BsplineConfig::default()),
        ),
        (
            "[planner] spiral",
            value(&forkbench_plan::SpiralConfig::default()),
        ),
        (
            "[tracker] pure_pursuit",
            value(&forkbench_track::TrackerConfig::default()),
        ),
        (
            "[tracker] regulated_pure_pursuit",
            value(&forkbench_track::RegulatedConfig::default()),
        ),
        (
            "[sensors.localizer] nav350",
            value(&forkbench_sensors::ReflectorNavSettings::default()),
        ),
        ("[sensors.pallet.scanners.tim561]", scanner("tim561")),
        ("[sensors.pallet.scanners.kinect2]", scanner("kinect2")),
        (
            "[sensors.pallet.detector] pockets",
            value(&forkbench_sensors::detect::DetectorConfig::default()),
        ),
        ("[mission.global]", value(&GlobalFile::default())),
        (
            "[mission.tracker]",
            value(&forkbench_trial::scenario::mission::mission_tracker()),
        ),
    ]
}

/// Leaves of a table as dotted keys (`mount.x_m`).
fn leaves(prefix: &str, v: &toml::Value, out: &mut BTreeMap<String, toml::Value>) {
    match v {
        toml::Value::Table(t) => {
            for (k, v) in t {
                let key = if prefix.is_empty() {
                    k.clone()
                } else {
                    format!("{prefix}.{k}")
                };
                leaves(&key, v, out);
            }
        }
        _ => {
            out.insert(prefix.to_owned(), v.clone());
        }
    }
}

/// The document's tables: heading → key → default as written (`—` for none).
fn documented(doc: &str) -> BTreeMap<String, BTreeMap<String, String>> {
    let mut out: BTreeMap<String, BTreeMap<String, String>> = BTreeMap::new();
    let mut section = String::new();
    for line in doc.lines() {
        if line.starts_with("## ") {
            section.clear();
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

fn same(doc: &str, code: &toml::Value) -> bool {
    let Ok(t) = toml::from_str::<toml::Table>(&format!("v = {doc}")) else {
        return false;
    };
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-6 * a.abs().max(b.abs()).max(1e-12);
    match (&t["v"], code) {
        (toml::Value::Float(a), toml::Value::Float(b)) => close(*a, *b),
        (toml::Value::Integer(a), toml::Value::Float(b)) => close(*a as f64, *b),
        (toml::Value::Array(a), toml::Value::Array(b)) => {
            a.len() == b.len() && a.iter().zip(b).all(|(x, y)| same(&x.to_string(), y))
        }
        (a, b) => a == b,
    }
}

#[test]
fn every_defaulted_key_is_documented_with_its_default() {
    let doc = std::fs::read_to_string(repo("docs/scenario-format.md")).expect("the format doc");
    let tables = documented(&doc);
    let dump = std::env::var_os("FORKBENCH_DUMP_FORMAT").is_some();
    let mut problems = Vec::new();
    for (section, v) in defaulted() {
        let mut code = BTreeMap::new();
        leaves("", &v, &mut code);
        if dump {
            println!("### `{section}`\n\n| key | default | meaning |\n|---|---|---|");
            for (k, v) in &code {
                println!("| `{k}` | `{v}` | |");
            }
            println!();
        }
        let Some(doc_keys) = tables.get(&section) else {
            problems.push(format!("{section}: no table"));
            continue;
        };
        for (k, v) in &code {
            match doc_keys.get(k) {
                None => problems.push(format!("{section}: `{k}` undocumented")),
                Some(d) if !same(d, v) => {
                    problems.push(format!("{section}: `{k}` documented {d}, the code has {v}"))
                }
                Some(_) => {}
            }
        }
        for (k, d) in doc_keys {
            // `—`: an optional key without a default (absent from the serialised default).
            if !code.contains_key(k) && d != "—" {
                problems.push(format!("{section}: `{k}` documented but not in the code"));
            }
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// The fenced blocks after "Full example: scenario" and "Full example: world".
fn example(doc: &str, title: &str) -> String {
    let at = doc.find(title).unwrap_or_else(|| panic!("{title}"));
    let rest = &doc[at..];
    let start = rest.find("```toml\n").expect("a toml block") + 8;
    let end = rest[start..].find("```").expect("closed") + start;
    rest[start..end].to_owned()
}

#[test]
fn the_documents_full_examples_load() {
    let doc = std::fs::read_to_string(repo("docs/scenario-format.md")).expect("the format doc");
    let world_text = example(&doc, "Full example: world");
    let world = World::parse(&world_text, "example-world.toml").expect("the example world loads");
    let scenario_text = example(&doc, "Full example: scenario");
    let scn = Scenario::parse(&scenario_text, "example.toml", |_| Ok(world.clone()))
        .expect("the example scenario loads");
    assert_eq!(scn.localizer.kind, "nav350");
    assert!(scn.mission.is_some() && !scn.cases.is_empty());
}
