//! The default scenario set, embedded in the binary so the main job runs from anywhere.

use std::path::Path;

use crate::ScenarioError;
use crate::scenario::{Scenario, World};

const SCENARIOS: [(&str, &str); 8] = [
    (
        "scenarios/field-test.toml",
        include_str!("../data/scenarios/field-test.toml"),
    ),
    (
        "scenarios/rack-pick.toml",
        include_str!("../data/scenarios/rack-pick.toml"),
    ),
    (
        "scenarios/bspline-table2.toml",
        include_str!("../data/scenarios/bspline-table2.toml"),
    ),
    (
        "scenarios/spiral-table2.toml",
        include_str!("../data/scenarios/spiral-table2.toml"),
    ),
    (
        "scenarios/warehouse-mission.toml",
        include_str!("../data/scenarios/warehouse-mission.toml"),
    ),
    (
        "scenarios/warehouse-cycle.toml",
        include_str!("../data/scenarios/warehouse-cycle.toml"),
    ),
    (
        "scenarios/warehouse-people.toml",
        include_str!("../data/scenarios/warehouse-people.toml"),
    ),
    (
        "scenarios/warehouse-people-short.toml",
        include_str!("../data/scenarios/warehouse-people-short.toml"),
    ),
];

const WORLDS: [(&str, &str); 4] = [
    (
        "open-floor.toml",
        include_str!("../data/worlds/open-floor.toml"),
    ),
    (
        "rack-bay.toml",
        include_str!("../data/worlds/rack-bay.toml"),
    ),
    (
        "warehouse.toml",
        include_str!("../data/worlds/warehouse.toml"),
    ),
    (
        "warehouse-narrow.toml",
        include_str!("../data/worlds/warehouse-narrow.toml"),
    ),
];

/// An embedded world by file name (`warehouse.toml`), as `worlds/` holds it.
pub fn embedded_world(name: &str) -> Result<World, ScenarioError> {
    let (file, text) =
        WORLDS
            .iter()
            .find(|(f, _)| *f == name)
            .ok_or_else(|| ScenarioError::Invalid {
                file: name.to_owned(),
                field: "world".into(),
                reason: format!("no embedded world {name:?}"),
            })?;
    World::parse(text, &format!("worlds/{file}"))
}

/// Loads the embedded default scenarios (worlds resolved among the embedded worlds).
pub fn default_scenarios() -> Result<Vec<Scenario>, ScenarioError> {
    SCENARIOS
        .iter()
        .map(|(file, text)| {
            Scenario::parse(text, file, |world: &Path| {
                let name = world
                    .file_name()
                    .and_then(|n| n.to_str())
                    .unwrap_or_default();
                embedded_world(name).map_err(|e| match e {
                    ScenarioError::Invalid { reason, .. } => ScenarioError::Invalid {
                        file: (*file).to_owned(),
                        field: "world".into(),
                        reason,
                    },
                    e => e,
                })
            })
        })
        .collect()
}

/// An embedded default scenario by its name (`field-test`).
pub fn embedded_scenario(name: &str) -> Result<Scenario, ScenarioError> {
    let all = default_scenarios()?;
    let known: Vec<String> = all.iter().map(|s| s.name.clone()).collect();
    all.into_iter()
        .find(|s| s.name == name)
        .ok_or_else(|| ScenarioError::Invalid {
            file: name.to_owned(),
            field: "scenario".into(),
            reason: format!(
                "no such file, and no embedded scenario of that name (embedded: {})",
                known.join(", ")
            ),
        })
}

/// A scenario as a user names it: a file when one exists at `arg` (or the name ends in
/// `.toml`), else an embedded default by name. The CLI and Python share this rule.
pub fn load_scenario(arg: &Path) -> Result<Scenario, ScenarioError> {
    let is_file = arg.exists() || arg.extension().is_some_and(|e| e == "toml");
    match arg.to_str() {
        Some(name) if !is_file && !name.contains(std::path::MAIN_SEPARATOR) => {
            embedded_scenario(name)
        }
        _ => Scenario::load(arg),
    }
}
