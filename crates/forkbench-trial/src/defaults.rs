//! The default scenario set, embedded in the binary so the main job runs from anywhere.

use std::path::Path;

use crate::ScenarioError;
use crate::scenario::{Scenario, World};
use forkbench_scenario::truck_file::{TruckSettings, read_truck_text};

const SCENARIOS: [(&str, &str); 10] = [
    (
        "scenarios/field-test.toml",
        include_str!("../data/scenarios/field-test.toml"),
    ),
    (
        "scenarios/field-test-efg-316k.toml",
        include_str!("../data/scenarios/field-test-efg-316k.toml"),
    ),
    (
        "scenarios/field-test-stacker.toml",
        include_str!("../data/scenarios/field-test-stacker.toml"),
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

/// The library trucks the embedded scenarios name, by file name (`trucks/` holds them).
const TRUCKS: [(&str, &str); 2] = [
    (
        "jungheinrich-efg-316k.toml",
        include_str!("../data/trucks/jungheinrich-efg-316k.toml"),
    ),
    (
        "class-pallet-stacker-1.2t.toml",
        include_str!("../data/trucks/class-pallet-stacker-1.2t.toml"),
    ),
];

/// The text of `name` in an embedded `table` (with the name it is held under), or an error
/// for `field` naming what was asked for (`asked_as`).
fn embedded<'t>(
    table: &'t [(&'t str, &'t str)],
    name: &str,
    asked_as: &str,
    field: &str,
) -> Result<&'t (&'t str, &'t str), ScenarioError> {
    table
        .iter()
        .find(|(f, _)| *f == name)
        .ok_or_else(|| ScenarioError::Invalid {
            file: asked_as.to_owned(),
            field: field.into(),
            reason: format!("no embedded {field} {name:?}"),
        })
}

/// An embedded truck file by the path an embedded scenario names (its file name counts).
fn embedded_truck(path: &str) -> Result<TruckSettings, ScenarioError> {
    let name = Path::new(path)
        .file_name()
        .and_then(|n| n.to_str())
        .unwrap_or_default();
    let (file, text) = embedded(&TRUCKS, name, path, "truck")?;
    read_truck_text(text, &format!("trucks/{file}"))
}

/// An embedded world by file name (`warehouse.toml`), as `worlds/` holds it.
pub fn embedded_world(name: &str) -> Result<World, ScenarioError> {
    let (file, text) = embedded(&WORLDS, name, name, "world")?;
    World::parse(text, &format!("worlds/{file}"))
}

/// Loads the embedded default scenarios (worlds resolved among the embedded worlds).
pub fn default_scenarios() -> Result<Vec<Scenario>, ScenarioError> {
    SCENARIOS
        .iter()
        .map(|(file, text)| {
            let load_world = |world: &Path| {
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
            };
            Scenario::parse_embedded(text, file, load_world, &embedded_truck)
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
