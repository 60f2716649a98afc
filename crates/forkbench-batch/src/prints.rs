//! Fingerprints of the components a batch runs with settings of their own: the settings, and the content of each file an external one's command names, so a resume after an edited script or setting is refused, naming it.

use std::collections::BTreeMap;
use std::path::Path;

use forkbench_trial::Scenario;
use forkbench_trial::components::{ComponentSpec, Role};
use serde::{Deserialize, Serialize};
use serde_json::Value;

/// Largest file a fingerprint reads; a larger one is fingerprinted by its size and time.
const MAX_HASHED_BYTES: u64 = 64 << 20;

/// One external component as a batch ran it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ComponentPrint {
    pub role: String,
    pub name: String,
    pub kind: String,
    /// Its settings table (the command, timeout, environment and its own keys).
    pub settings: Value,
    /// Each file its command names that lies under its directory, as the command writes
    /// it, with the FNV-1a of its content.
    pub files: BTreeMap<String, String>,
}

/// The prints of every external component `scn` runs with `planners` and `trackers`
/// (names; empty: the scenario's own), its detector and its localiser.
pub fn prints_of(scn: &Scenario, planners: &[String], trackers: &[String]) -> Vec<ComponentPrint> {
    let chosen = |role: Role, names: &[String]| -> Vec<ComponentSpec> {
        if names.is_empty() {
            return scn.component(role, None).into_iter().collect();
        }
        names
            .iter()
            .filter_map(|n| scn.component(role, Some(n)).ok())
            .collect()
    };
    let mut specs = chosen(Role::Planner, planners);
    specs.extend(chosen(Role::Tracker, trackers));
    if let forkbench_trial::scenario::sensors::PalletSensing::Scanner { detector, .. } =
        &scn.pallet_sensing
    {
        specs.push(detector.clone());
    }
    specs.push(scn.localizer.clone());
    specs.iter().filter_map(print_of).collect()
}

/// The print of `spec` when it runs a command or has settings of its own (a built-in kind
/// defined by name with its keys: editing them changes every trial it runs); a built-in
/// at its defaults has none.
fn print_of(spec: &ComponentSpec) -> Option<ComponentPrint> {
    let command: Vec<String> = match spec.settings.get("command") {
        Some(c) => c
            .as_array()?
            .iter()
            .filter_map(|v| v.as_str().map(str::to_owned))
            .collect(),
        None if spec.settings.is_empty() => return None,
        None => Vec::new(),
    };
    let dir = spec.dir.canonicalize().ok();
    let files = command
        .iter()
        .filter_map(|arg| {
            let path = spec.dir.join(arg).canonicalize().ok()?;
            let inside = dir.as_ref().is_some_and(|d| path.starts_with(d));
            (inside && path.is_file()).then(|| (arg.clone(), content_hash(&path)))
        })
        .collect();
    Some(ComponentPrint {
        role: spec.role.to_string(),
        name: spec.name.clone(),
        kind: spec.kind.clone(),
        settings: serde_json::to_value(&spec.settings).unwrap_or(Value::Null),
        files,
    })
}

/// FNV-1a of the file's bytes as hex, or its size and modification time when it is too
/// large (or unreadable) to hash.
fn content_hash(path: &Path) -> String {
    match forkbench_core::files::read_bytes(path, MAX_HASHED_BYTES) {
        Ok(bytes) => format!(
            "{:016x}",
            forkbench_core::hash::fnv1a(bytes.iter().copied())
        ),
        Err(_) => {
            let meta = std::fs::metadata(path).ok();
            let modified = meta
                .as_ref()
                .and_then(|m| m.modified().ok())
                .and_then(|t| t.duration_since(std::time::UNIX_EPOCH).ok())
                .map_or(0, |d| d.as_nanos());
            format!("{} bytes, modified {modified}", meta.map_or(0, |m| m.len()))
        }
    }
}
