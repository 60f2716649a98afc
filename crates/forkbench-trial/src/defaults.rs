//! The default scenario set, embedded in the binary so the main job runs from anywhere.

use std::path::Path;

use crate::TrialError;
use crate::scenario::{Scenario, World};

const SCENARIOS: [(&str, &str); 4] = [
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
];

const WORLDS: [(&str, &str); 2] = [
    (
        "open-floor.toml",
        include_str!("../data/worlds/open-floor.toml"),
    ),
    (
        "rack-bay.toml",
        include_str!("../data/worlds/rack-bay.toml"),
    ),
];

/// Loads the embedded default scenarios (worlds resolved among the embedded worlds).
pub fn default_scenarios() -> Result<Vec<Scenario>, TrialError> {
    SCENARIOS
        .iter()
        .map(|(file, text)| {
            Scenario::parse(text, file, |world: &Path| {
                let name = world
                    .file_name()
                    .and_then(|n| n.to_str())
                    .unwrap_or_default();
                let (wfile, wtext) =
                    WORLDS
                        .iter()
                        .find(|(f, _)| *f == name)
                        .ok_or_else(|| TrialError::Invalid {
                            file: (*file).to_owned(),
                            field: "world".into(),
                            reason: format!("no embedded world {name:?}"),
                        })?;
                World::parse(wtext, &format!("worlds/{wfile}"))
            })
        })
        .collect()
}
