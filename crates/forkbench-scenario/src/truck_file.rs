//! Truck files: one file for a truck (geometry, mass, actuators, timing, its name and source), read into settings by dotted path and applied over a truck.

use std::collections::BTreeMap;
use std::path::{Path as FsPath, PathBuf};

use forkbench_core::actuators::{Actuators, PRESETS};
use forkbench_core::run_settings::{TRUCK_GEOMETRY, TRUCK_KNOBS};
use forkbench_core::{ForkliftSpec, TruckLayout};

use crate::{ScenarioError, World, invalid};

/// A truck file as read: what it names and every number it sets.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TruckSettings {
    /// The actuator preset its numbers apply over (`ideal`, `realistic`), if it names one.
    pub preset: Option<String>,
    /// The truck's name (`name = "…"`), for people.
    pub name: Option<String>,
    /// Where its figures come from (`source = "…"`): a type sheet, a measurement.
    pub source: Option<String>,
    /// Every number, by dotted path (`wheelbase_m`, `steering.dead_time_s`).
    pub settings: BTreeMap<String, f64>,
}

/// Every key a truck file may hold, for messages.
fn known_keys() -> String {
    let mut k: Vec<&str> = vec!["name", "source", "preset"];
    k.extend(TRUCK_GEOMETRY);
    k.extend(TRUCK_KNOBS.iter().map(|(_, p)| *p));
    k.push("mount.<sensor>.{x_m, y_m, heading_rad}");
    k.join(", ")
}

/// The 1-based line of the first line of `text` that sets `key` (its last dotted part),
/// inside `[table]` when the key is nested.
fn line_of(text: &str, path: &str) -> Option<usize> {
    let (table, key) = match path.rsplit_once('.') {
        Some((t, k)) => (Some(t), k),
        None => (None, path),
    };
    let mut current: Option<String> = None;
    for (i, line) in text.lines().enumerate() {
        let t = line.trim();
        if let Some(h) = t.strip_prefix('[') {
            current = Some(h.trim_end_matches(']').trim().to_owned());
            continue;
        }
        let k = t
            .split(['=', ' ', '\t'])
            .next()
            .unwrap_or("")
            .trim_matches('"');
        if k == key && current.as_deref() == table {
            return Some(i + 1);
        }
    }
    None
}

/// `file:line` for `path` in `text`, or the file alone.
fn at(file: &str, text: &str, path: &str) -> String {
    match line_of(text, path) {
        Some(l) => format!("{file}:{l}"),
        None => file.to_owned(),
    }
}

/// A truck file's text as its settings; an unknown key, a value that is not a number
/// and a number out of its range are refused naming the file, its line and the key.
pub fn read_truck_text(text: &str, file: &str) -> Result<TruckSettings, ScenarioError> {
    let table: toml::Table = toml::from_str(text).map_err(|e| ScenarioError::Parse {
        file: file.to_owned(),
        message: crate::text::compact_numbers(e.message()),
    })?;
    let mut out = TruckSettings::default();
    let mut numbers = table.clone();
    for key in ["preset", "name", "source"] {
        let Some(v) = numbers.remove(key) else {
            continue;
        };
        let s = v
            .as_str()
            .map(str::to_owned)
            .ok_or_else(|| invalid(&at(file, text, key), key, "must be a string"))?;
        match key {
            "preset" => out.preset = Some(s),
            "name" => out.name = Some(s),
            _ => out.source = Some(s),
        }
    }
    flatten(&numbers, &mut out.settings, &|path, why| {
        invalid(&at(file, text, path), path, why)
    })?;
    // Applying them refuses a key that is no truck setting and a value out of its range;
    // the error is placed at the key's line.
    let truck = apply_truck(
        &ForkliftSpec::default(),
        out.preset.as_deref(),
        &out.settings,
    )
    .map_err(|e| match e {
        ScenarioError::Invalid { field, reason, .. } => {
            let path = field.strip_prefix("truck.").unwrap_or(&field).to_owned();
            invalid(&at(file, text, &path), &path, &reason)
        }
        other => other,
    })?;
    if let Some((name, why)) = crate::sensors::unknown_mount(&truck) {
        let header = format!("[mount.{name}]");
        let place = match text.lines().position(|l| l.trim() == header) {
            Some(i) => format!("{file}:{}", i + 1),
            None => file.to_owned(),
        };
        return Err(invalid(&place, &format!("mount.{name}"), &why));
    }
    Ok(out)
}

/// The truck file at `path`, read within the scenario reader's byte cap.
pub fn read_truck_file(path: &FsPath) -> Result<TruckSettings, ScenarioError> {
    let text = crate::input::read(path)?;
    read_truck_text(&text, &path.display().to_string())
}

/// `truck` with `preset`'s actuators (if any), then each of `settings` (dotted paths of
/// the geometry and [`TRUCK_KNOBS`]), checked as a truck is at load.
pub fn apply_truck(
    truck: &ForkliftSpec,
    preset: Option<&str>,
    settings: &BTreeMap<String, f64>,
) -> Result<ForkliftSpec, ScenarioError> {
    let bad = |field: &str, reason: &str| invalid("options", field, reason);
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
            return Err(bad(
                path,
                &format!("not a truck setting (known: {})", known_keys()),
            ));
        }
    }
    out.validate()
        .map_err(|e| bad(&format!("truck.{}", e.field.unwrap_or_default()), &e.reason))?;
    Ok(out)
}

/// The spec a scenario's `truck` entry gives: a `[truck]` table, `truck = "FILE"` (a truck
/// file beside the scenario), or a table with `file = "FILE"` whose other keys override
/// that file's. Errors name the scenario's or the truck file's line.
pub(crate) fn resolve_entry(
    entry: Option<&toml::Spanned<toml::Value>>,
    load_truck: &dyn Fn(&str) -> Result<TruckSettings, ScenarioError>,
    (file, text): (&str, &str),
) -> Result<ForkliftSpec, ScenarioError> {
    let Some(entry) = entry else {
        return Ok(ForkliftSpec::default());
    };
    let line = text[..entry.span().start.min(text.len())]
        .matches('\n')
        .count()
        + 1;
    let here = format!("{file}:{line}");
    let (base, table) = match entry.get_ref() {
        toml::Value::String(p) => (Some(p.clone()), toml::Table::new()),
        toml::Value::Table(t) => {
            let mut t = t.clone();
            let p = match t.remove("file") {
                Some(toml::Value::String(p)) => Some(p),
                Some(_) => return Err(invalid(&here, "truck.file", "must be a path (a string)")),
                None => None,
            };
            (p, t)
        }
        _ => {
            return Err(invalid(
                &here,
                "truck",
                "must be a [truck] table or the path of a truck file",
            ));
        }
    };
    let mut truck = match base {
        Some(p) => {
            let s = load_truck(&p)
                .map_err(|e| invalid(&here, "truck", &format!("truck file {p} refused: {e}")))?;
            apply_truck(&ForkliftSpec::default(), s.preset.as_deref(), &s.settings)?
        }
        None => ForkliftSpec::default(),
    };
    if !table.is_empty() {
        let mut settings = BTreeMap::new();
        flatten(&table, &mut settings, &|path, why| {
            invalid(&here, &format!("truck.{path}"), why)
        })?;
        // A refusal names the scenario and the line of the key it refuses (a check over
        // several keys names the one it reports), else the `truck` entry's line.
        truck = apply_truck(&truck, None, &settings).map_err(|e| match e {
            ScenarioError::Invalid { field, reason, .. } => {
                let place = line_of(text, &field).map_or(here.clone(), |l| format!("{file}:{l}"));
                invalid(&place, &field, &reason)
            }
            other => other,
        })?;
    }
    Ok(truck)
}

/// Every number of `table` by dotted path, one level of tables deep (two for a sensor's
/// `[mount.<sensor>]`); `refuse` makes the error for a path and its reason.
fn flatten(
    table: &toml::Table,
    out: &mut BTreeMap<String, f64>,
    refuse: &dyn Fn(&str, &str) -> ScenarioError,
) -> Result<(), ScenarioError> {
    for (key, value) in table {
        let mut put = |path: String, v: &toml::Value| {
            let n = match v {
                toml::Value::Float(f) => *f,
                toml::Value::Integer(i) => *i as f64,
                // The one key that is a name: it rides among the numbers as its code.
                toml::Value::String(name) if path == "layout" => TruckLayout::from_key(name)
                    .ok_or_else(|| {
                        let why =
                            format!("unknown layout {name:?} (known: {})", TruckLayout::keys());
                        refuse(&path, &why)
                    })?
                    .code(),
                _ => return Err(refuse(&path, "must be a number")),
            };
            out.insert(path, n);
            Ok(())
        };
        match value {
            toml::Value::Table(inner) => {
                for (k, v) in inner {
                    match v {
                        // `[mount.<sensor>]`: the one table two levels deep.
                        toml::Value::Table(pose) if key == "mount" => {
                            for (f, v) in pose {
                                put(format!("{key}.{k}.{f}"), v)?;
                            }
                        }
                        v => put(format!("{key}.{k}"), v)?,
                    }
                }
            }
            v => put(key.clone(), v)?,
        }
    }
    Ok(())
}

impl<R: crate::Catalogue> crate::Scenario<R> {
    /// As [`crate::Scenario::parse`], its truck files read by `load_truck` (by the path the
    /// scenario names): how embedded scenarios name embedded trucks.
    pub fn parse_embedded(
        text: &str,
        file: &str,
        load_world: impl FnOnce(&FsPath) -> Result<World, ScenarioError>,
        load_truck: &dyn Fn(&str) -> Result<TruckSettings, ScenarioError>,
    ) -> Result<Self, ScenarioError> {
        let s = Self::parse_layout(text, file, load_world, load_truck, None)?;
        s.with_components(text, R::builtin(), PathBuf::from("."))
    }

    /// The same scenario with `truck` for its own, checked as if its `[truck]` table said
    /// so: every load-time check that reads the truck (forks in the pockets, the depth and
    /// the insertion, the payload, the sensors' mounts, the safety fields, each case's
    /// layout) runs again, and what a run derives from the truck follows it. How a run's
    /// geometry (`--truck FILE`, a sweep) reaches its trials.
    pub fn with_truck(&self, truck: &ForkliftSpec) -> Result<Self, ScenarioError>
    where
        Self: Clone,
    {
        let Some(src) = &self.source else {
            return Err(invalid(
                &self.file,
                "truck",
                "this scenario was built, not read: its truck cannot be checked anew",
            ));
        };
        // The run's truck stands for the file's own, so no truck file is read again.
        let no_file = |_: &str| Ok(TruckSettings::default());
        let world = |_: &FsPath| Ok(self.world.clone());
        let checked = Self::parse_layout(src, &self.file, world, &no_file, Some(truck))?;
        Ok(Self {
            truck: checked.truck,
            // Its scanners on the run's truck's mounts.
            pallet_sensing: checked.pallet_sensing,
            ..self.clone()
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_whole_truck_file_reads_its_geometry_and_actuators() {
        let s = read_truck_text(
            "name = \"x\"\nsource = \"y\"\nwheelbase_m = 1.4\nmass_kg = 3100\n[steering]\ndead_time_s = 0.1\n",
            "t.toml",
        )
        .expect("valid");
        assert_eq!(s.settings["wheelbase_m"], 1.4);
        assert_eq!(s.settings["mass_kg"], 3100.0);
        assert_eq!(s.settings["steering.dead_time_s"], 0.1);
        assert_eq!(s.name.as_deref(), Some("x"));
    }

    #[test]
    fn an_unknown_key_is_named_at_its_line() {
        let e = read_truck_text("wheelbase_m = 1.4\nwheel_base = 2\n", "t.toml")
            .expect_err("unknown")
            .to_string();
        assert!(e.contains("t.toml:2") && e.contains("wheel_base"), "{e}");
        let e = read_truck_text("[steering]\ndead_time = 0.1\n", "t.toml")
            .expect_err("unknown nested")
            .to_string();
        assert!(
            e.contains("t.toml:2") && e.contains("steering.dead_time"),
            "{e}"
        );
    }

    #[test]
    fn a_truck_file_mounts_its_sensors_and_names_an_unknown_one_at_its_line() {
        let s = read_truck_text(
            "wheelbase_m = 1.4\n[mount.tim561]\nx_m = 0.05\ny_m = 0.1\n[mount.nav350]\nx_m = -0.4\n",
            "t.toml",
        )
        .expect("valid");
        assert_eq!(s.settings["mount.tim561.y_m"], 0.1);
        let t = apply_truck(&ForkliftSpec::default(), None, &s.settings).expect("applies");
        let m = t.mounts.get("nav350").expect("mounted");
        assert_eq!((m.x_m, m.y_m, m.heading_rad), (-0.4, 0.0, 0.0));
        let e = read_truck_text("name = \"x\"\n[mount.tim651]\nx_m = 0.1\n", "t.toml")
            .expect_err("no such sensor")
            .to_string();
        assert!(e.contains("t.toml:2") && e.contains("tim651"), "{e}");
        let e = read_truck_text("[mount.tim561]\nx_m = 30\n", "t.toml")
            .expect_err("far off")
            .to_string();
        assert!(
            e.contains("t.toml:2") && e.contains("mount.tim561.x_m"),
            "{e}"
        );
    }

    #[test]
    fn an_unknown_layout_is_named_at_its_line_with_the_known_ones() {
        let e = read_truck_text("name = \"x\"\nlayout = \"sideways\"\n", "t.toml")
            .expect_err("no such layout")
            .to_string();
        assert!(
            e.contains("t.toml:2")
                && e.contains("unknown layout \"sideways\"")
                && e.contains("pallet_stacker"),
            "{e}"
        );
        let e = read_truck_text("wheelbase_m = \"long\"\n", "t.toml")
            .expect_err("not a number")
            .to_string();
        assert!(
            e.contains("t.toml:1") && e.contains("must be a number"),
            "{e}"
        );
    }

    #[test]
    fn a_value_out_of_range_is_named_at_its_line() {
        let e = read_truck_text("name = \"x\"\nwheelbase_m = -1\n", "t.toml")
            .expect_err("negative")
            .to_string();
        assert!(e.contains("t.toml:2") && e.contains("wheelbase_m"), "{e}");
    }

    #[test]
    fn a_table_over_a_file_keeps_the_file_and_overrides_its_keys() {
        let dir = std::env::temp_dir().join(format!("fb-truck-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        std::fs::write(
            dir.join("t.toml"),
            "preset = \"ideal\"\nwheelbase_m = 1.4\n",
        )
        .expect("written");
        let text =
            "[truck]\nfile = \"t.toml\"\nmass_kg = 3000\n[truck.steering]\ndead_time_s = 0.2\n";
        #[derive(serde::Deserialize)]
        struct F {
            truck: toml::Spanned<toml::Value>,
        }
        let f: F = toml::from_str(text).expect("toml");
        let load = |p: &str| read_truck_file(&dir.join(p));
        let out = resolve_entry(Some(&f.truck), &load, ("s.toml", text)).expect("merges");
        let ideal = Actuators::preset("ideal").expect("preset");
        assert_eq!(out.wheelbase_m, 1.4);
        assert_eq!(out.mass_kg, 3000.0);
        assert_eq!(out.steering.dead_time_s, 0.2);
        // The file's preset stays under what the table does not set.
        assert_eq!(out.drive, ideal.drive);
        std::fs::remove_dir_all(&dir).ok();
    }
}
