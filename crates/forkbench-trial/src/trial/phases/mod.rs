//! The phases after the pick (lift, reverse out, carry, place, return): each a unit with its own settings and criteria, built by name from a scenario's `phases` list.

mod criteria;
mod lift;
mod place;
mod return_leg;
mod reverse_out;
mod run;

use serde::Serialize;

use super::setup::Trial;
use crate::outcome::Failure;
use crate::recorder::Recorder;
use crate::scenario::World;
use forkbench_core::PalletSpec;

/// What a phase's settings are checked against: the world (its slots) and the pallet.
#[derive(Debug, Clone, Copy)]
pub struct Context<'a> {
    pub world: &'a World,
    pub pallet: &'a PalletSpec,
    /// The scenario's mission: its global planner, tracker and stations drive a return.
    pub mission: Option<&'a crate::scenario::mission::MissionSpec>,
}

/// A phase after the pick as a scenario lists it: its name and its `[phase.NAME]` settings.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PhaseSpec {
    pub name: String,
    pub settings: toml::Table,
}

/// Why a phase failed: its first failed criterion, with the value against the limit.
pub(crate) type Failed = (Failure, String);

/// One phase after the pick.
pub(crate) trait Phase: std::fmt::Debug {
    /// Drives the trial through the phase. Err: its first failed criterion.
    fn run(&self, trial: &mut Trial<'_>, rec: &mut dyn Recorder) -> Result<(), Failed>;
}

/// Builds a phase from its settings table, checked against the scenario's context.
type Build = fn(&toml::Table, &Context<'_>) -> Result<Box<dyn Phase>, String>;

/// A phase kind: its name, the phases it may follow, the load it needs and leaves, and
/// how its settings (and the world, for slots) build it.
struct Kind {
    name: &'static str,
    after: &'static [&'static str],
    /// Whether the pallet must be on the forks (`Some(true)`) or not, to start it.
    needs_loaded: Option<bool>,
    /// Whether the pallet is on the forks after it (`None`: as before).
    leaves_loaded: Option<bool>,
    build: Build,
    /// Its settings at their defaults (for the format document).
    defaults: fn() -> toml::Value,
}

/// Every phase by name: adding one is its file and a row here.
const KINDS: &[Kind] = &[
    Kind {
        name: "lift",
        after: &["pick"],
        needs_loaded: Some(false),
        leaves_loaded: Some(true),
        build: lift::build,
        defaults: defaults_of::<lift::Lift>,
    },
    Kind {
        name: "reverse_out",
        after: &["pick", "lift"],
        needs_loaded: None,
        leaves_loaded: None,
        build: reverse_out::build,
        defaults: defaults_of::<reverse_out::ReverseOut>,
    },
    Kind {
        name: "carry",
        after: &["lift", "reverse_out"],
        needs_loaded: Some(true),
        leaves_loaded: None,
        build: return_leg::build_carry,
        defaults: defaults_of::<return_leg::LegFile>,
    },
    Kind {
        name: "place",
        after: &["lift", "reverse_out", "carry"],
        needs_loaded: Some(true),
        leaves_loaded: Some(false),
        build: place::build,
        defaults: defaults_of::<place::PlaceFile>,
    },
    Kind {
        name: "return",
        after: &["place", "reverse_out"],
        needs_loaded: None,
        leaves_loaded: None,
        build: return_leg::build_return,
        defaults: defaults_of::<return_leg::LegFile>,
    },
];

/// Each phase after the pick with its settings at their defaults.
pub fn phase_defaults() -> Vec<(&'static str, toml::Value)> {
    KINDS.iter().map(|k| (k.name, (k.defaults)())).collect()
}

/// The phase list's name for the pick itself (approach and insertion), always first.
pub const PICK: &str = "pick";

/// Checks a scenario's phase list and settings: the pick first, then known phases each
/// after one it may follow and with the pallet on the forks or not as it needs, every
/// settings table valid (slots in `cx`'s world) and for a listed phase. Err: the field and why.
pub fn resolve(
    names: &[String],
    settings: &toml::Table,
    cx: &Context<'_>,
) -> Result<Vec<PhaseSpec>, (String, String)> {
    if names.first().map(String::as_str) != Some(PICK) {
        return Err((
            "phases".into(),
            format!("must start with {PICK:?}, the pick itself"),
        ));
    }
    let mut out = Vec::new();
    let mut loaded = false;
    for (i, pair) in names.windows(2).enumerate() {
        let (prev, name) = (pair[0].as_str(), pair[1].as_str());
        let field = format!("phases[{}]", i + 1);
        let kind = runnable(prev, name, loaded).map_err(|why| (field, why))?;
        loaded = kind.leaves_loaded.unwrap_or(loaded);
        let table = match settings.get(name) {
            Some(toml::Value::Table(t)) => t.clone(),
            Some(_) => return Err((format!("phase.{name}"), "must be a table".into())),
            None => toml::Table::new(),
        };
        (kind.build)(&table, cx).map_err(|e| (format!("phase.{name}"), e))?;
        out.push(PhaseSpec {
            name: name.to_owned(),
            settings: table,
        });
    }
    if let Some(extra) = settings.keys().find(|k| !names.contains(k)) {
        return Err((
            format!("phase.{extra}"),
            format!("settings for {extra:?}, which `phases` does not list"),
        ));
    }
    Ok(out)
}

/// The kind of phase `name`, if it can run after `prev` with the pallet on the forks or
/// not (`loaded`).
fn runnable(prev: &str, name: &str, loaded: bool) -> Result<&'static Kind, String> {
    let Some(kind) = KINDS.iter().find(|k| k.name == name) else {
        let known: Vec<_> = KINDS.iter().map(|k| k.name).collect();
        return Err(format!(
            "no phase {name:?} (phases after the pick: {})",
            known.join(", ")
        ));
    };
    if !kind.after.contains(&prev) {
        return Err(format!(
            "{name:?} cannot follow {prev:?} (it follows {})",
            kind.after.join(" or ")
        ));
    }
    match kind.needs_loaded {
        Some(true) if !loaded => Err(format!(
            "{name:?} needs the pallet on the forks: a \"lift\" before it"
        )),
        Some(false) if loaded => Err(format!("{name:?} needs empty forks")),
        _ => Ok(kind),
    }
}

/// A settings struct at its defaults as a TOML table (for the format document).
fn defaults_of<T: Serialize + Default>() -> toml::Value {
    toml::Value::try_from(T::default()).unwrap_or(toml::Value::Table(toml::Table::new()))
}

/// Each `(name, value, max)` a positive finite number of at most `max`.
pub(crate) fn positive_at_most(fields: &[(&str, f64, f64)]) -> Result<(), String> {
    for &(name, v, max) in fields {
        if !(v.is_finite() && v > 0.0 && v <= max) {
            return Err(format!(
                "{name} must be positive and at most {max} (got {v})"
            ));
        }
    }
    Ok(())
}

/// A phase's settings from its table, refusing unknown keys; `check` then the values.
pub(crate) fn settings<T: serde::de::DeserializeOwned>(table: &toml::Table) -> Result<T, String> {
    T::deserialize(toml::Value::Table(table.clone()))
        .map_err(|e| e.to_string().trim_end().to_owned())
}
