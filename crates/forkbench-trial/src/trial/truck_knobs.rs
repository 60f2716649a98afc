//! A run's changes to the truck's actuators and timing: a named preset, single settings by their dotted names (a `--truck` file, a sweep), and their application to a scenario's truck.

use std::collections::BTreeMap;

use forkbench_core::ForkliftSpec;
use forkbench_core::actuators::{Actuators, PRESETS};

use crate::ScenarioError;
use crate::scenario::invalid;

pub use forkbench_core::run_settings::{TRUCK_KNOBS, truck_path};

fn bad(field: &str, reason: &str) -> ScenarioError {
    invalid("options", field, reason)
}

/// `truck` with `preset`'s actuators (if any), then each of `settings` (dotted paths of
/// [`TRUCK_KNOBS`]), checked as a truck file is.
pub fn apply_truck(
    truck: &ForkliftSpec,
    preset: Option<&str>,
    settings: &BTreeMap<String, f64>,
) -> Result<ForkliftSpec, ScenarioError> {
    let mut out = truck.clone();
    if let Some(name) = preset {
        let a = Actuators::preset(name).ok_or_else(|| {
            let known: Vec<&str> = PRESETS.iter().map(|(n, _)| *n).collect();
            bad(
                "truck_preset",
                &format!("unknown preset {name:?} (known: {})", known.join(", ")),
            )
        })?;
        out = out.with_actuators(a);
    }
    for (path, v) in settings {
        if !forkbench_core::run_settings::set(&mut out, path, *v) {
            let known: Vec<&str> = TRUCK_KNOBS.iter().map(|(_, p)| *p).collect();
            return Err(bad(
                path,
                &format!(
                    "not a setting a run may change (the geometry is the scenario's); known: {}",
                    known.join(", ")
                ),
            ));
        }
    }
    out.validate()
        .map_err(|e| bad(&format!("truck.{}", e.field.unwrap_or_default()), &e.reason))?;
    Ok(out)
}

/// A truck file (`--truck FILE`) as a run's changes: its `preset`, if it names one, and
/// every number under the settings a run may change; anything else is refused naming it.
pub fn truck_file_settings(
    text: &str,
) -> Result<(Option<String>, BTreeMap<String, f64>), ScenarioError> {
    let table: toml::Table = toml::from_str(text).map_err(|e| bad("truck", e.message()))?;
    let mut preset = None;
    let mut settings = BTreeMap::new();
    for (key, value) in &table {
        match (key.as_str(), value) {
            ("preset", toml::Value::String(name)) => preset = Some(name.clone()),
            (_, toml::Value::Table(inner)) => {
                for (k, v) in inner {
                    let path = format!("{key}.{k}");
                    settings.insert(path.clone(), number(&path, v)?);
                }
            }
            (_, v) => {
                settings.insert(key.clone(), number(key, v)?);
            }
        }
    }
    for path in settings.keys() {
        if truck_path(path) != Some(path.as_str()) {
            return Err(bad(
                path,
                "a truck file for a run changes only the actuators and control timing \
                 (the geometry is the scenario's [truck])",
            ));
        }
    }
    Ok((preset, settings))
}

/// The sensors' timing under `preset`: the `ideal` truck is the bench's first one as it
/// was sensed too, a NAV350 delivering each fix at once, scans taken in an instant,
/// their estimates used at once and the detector's own face taken unchecked (evidence
/// threshold 0), so it reproduces the records made before these were modelled; any other
/// preset leaves the sensors as configured.
pub(crate) fn sensor_timing_for(
    preset: Option<&str>,
    nav350: &mut forkbench_sensors::Nav350Config,
    sensing: &mut crate::scenario::sensors::PalletSensing,
) {
    if preset != Some("ideal") {
        return;
    }
    nav350.latency_s = 0.0;
    if let crate::scenario::sensors::PalletSensing::Scanner {
        sensors,
        latency_s,
        min_score,
        ..
    } = sensing
    {
        *latency_s = 0.0;
        *min_score = 0.0;
        for n in sensors {
            n.scanner.sweep_s = 0.0;
        }
    }
}

fn number(path: &str, v: &toml::Value) -> Result<f64, ScenarioError> {
    match v {
        toml::Value::Float(f) => Ok(*f),
        toml::Value::Integer(i) => Ok(*i as f64),
        _ => Err(bad(path, "must be a number")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_setting_lands_where_its_path_says_and_bad_ones_are_named() {
        let truck = ForkliftSpec::default();
        let mut s = BTreeMap::new();
        s.insert("steering.dead_time_s".to_owned(), 0.2);
        s.insert("drive.brake_limit_mps2".to_owned(), 1.5);
        let t = apply_truck(&truck, None, &s).expect("valid");
        assert_eq!(t.steering.dead_time_s, 0.2);
        assert_eq!(t.drive.brake_limit_mps2, Some(1.5));
        s.insert("steering.dead_time_s".to_owned(), 9.0);
        let e = apply_truck(&truck, None, &s).expect_err("9 s").to_string();
        assert!(e.contains("steering.dead_time_s"), "{e}");
        let mut g = BTreeMap::new();
        g.insert("wheelbase_m".to_owned(), 2.0);
        let e = apply_truck(&truck, None, &g)
            .expect_err("geometry")
            .to_string();
        assert!(e.contains("wheelbase_m") && e.contains("geometry"), "{e}");
    }

    /// A setting over the first truck keeps the rest of it (its unlimited rates too).
    #[test]
    fn a_setting_over_the_ideal_preset_keeps_the_rest_ideal() {
        let mut s = BTreeMap::new();
        s.insert("steering.dead_time_s".to_owned(), 0.1);
        let t = apply_truck(&ForkliftSpec::default(), Some("ideal"), &s).expect("valid");
        assert_eq!(t.steering.accel_limit_radps2, None);
        assert!(t.drive.is_ideal() && t.control.is_ideal());
        assert_eq!(t.steering.time_constant_s, 0.0);
    }

    #[test]
    fn a_preset_then_settings() {
        let truck = ForkliftSpec::default();
        let mut s = BTreeMap::new();
        s.insert("control.period_s".to_owned(), 0.05);
        let t = apply_truck(&truck, Some("realistic"), &s).expect("valid");
        assert_eq!(t.steering, Actuators::REALISTIC.steering);
        assert_eq!(t.control.period_s, Some(0.05));
        assert!(apply_truck(&truck, Some("sporty"), &s).is_err());
        let (p, s) = truck_file_settings("preset = \"ideal\"\n[steering]\ndead_time_s = 0.1\n")
            .expect("valid file");
        assert_eq!(p.as_deref(), Some("ideal"));
        assert_eq!(s.get("steering.dead_time_s"), Some(&0.1));
        assert!(truck_file_settings("wheelbase_m = 2.0").is_err());
    }
}
