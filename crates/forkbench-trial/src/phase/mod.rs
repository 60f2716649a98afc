//! The phases after the pick (lift, reverse out, carry, place, return): each a unit with its own settings and criteria, built by name from a scenario's `phases` list and driven through a [`PhaseHost`].

mod criteria;
mod host;
mod lift;
mod place;
mod return_leg;
mod reverse_out;

pub use criteria::{held, judge_now, load_held};
pub use host::{Context, DriveRun, LegRun, PhaseHost, Steer, open_loop, stand_for};

use forkbench_core::SettingsError;
use std::sync::Arc;

use serde::Serialize;

use crate::outcome::Failure;
use crate::recorder::Recorder;
use crate::stage_error::StageError;

/// A phase after the pick as a scenario lists it, built by this crate's phases.
pub type PhaseSpec = forkbench_scenario::PhaseSpec<Arc<dyn Phase>>;

/// Why a phase (or the pick's staging) failed: the outcome's failure, and its cause.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}: {cause}", failure.name())]
pub struct Failed {
    pub failure: Failure,
    pub cause: Cause,
}

/// What made a phase fail: a check in its own words (a criterion's value against its
/// limit), or a stage of the trial that could not go on (a component's fault, a
/// non-finite state, a refused plan), kept typed so a phase can tell them apart.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Cause {
    #[error("{0}")]
    Detail(String),
    #[error(transparent)]
    Stage(#[from] StageError),
}

impl Failed {
    /// A failure in the phase's own words.
    pub fn new(failure: Failure, detail: impl Into<String>) -> Self {
        Failed {
            failure,
            cause: Cause::Detail(detail.into()),
        }
    }

    /// A stage that could not go on, failing as `failure`.
    pub fn stage(failure: Failure, e: StageError) -> Self {
        Failed {
            failure,
            cause: Cause::Stage(e),
        }
    }

    /// The outcome's failure detail: the cause's message.
    pub fn detail(&self) -> String {
        self.cause.to_string()
    }
}

/// A stage that could not go on fails the phase as an error.
impl From<StageError> for Failed {
    fn from(e: StageError) -> Self {
        Failed::stage(Failure::Error, e)
    }
}

/// A phase's run: it drives the trial tick by tick, yielding where a session's caller
/// takes a tick.
pub type PhaseRun<'t> =
    std::pin::Pin<Box<dyn std::future::Future<Output = Result<(), Failed>> + Send + 't>>;

/// One phase after the pick. A phase drives the truck with [`PhaseHost::drive_under`] and
/// [`stand_for`] (the trial's one drive loop), measures with
/// [`PhaseHost::record_measure`] and judges with its own criteria; `run` returns
/// `Box::pin(async move { … })`.
pub trait Phase: std::fmt::Debug + Send + Sync {
    /// Drives the trial through the phase. Err: its first failed criterion.
    fn run<'t>(&'t self, host: &'t mut dyn PhaseHost, rec: &'t mut dyn Recorder) -> PhaseRun<'t>;
}

/// Builds a phase from its settings table, checked against the scenario's context.
pub type PhaseCtor =
    Arc<dyn Fn(&toml::Table, &dyn Context) -> Result<Box<dyn Phase>, SettingsError> + Send + Sync>;

/// A phase kind: its name, the phases it may follow, the load it needs and leaves, and
/// how its settings (and the world, for slots) build it. Registered with
/// [`crate::Registry::with_phase`].
#[derive(Clone)]
pub struct PhaseKind {
    pub name: String,
    /// The phases (or `pick`) it may follow.
    pub after: Vec<String>,
    /// Whether the pallet must be on the forks (`Some(true)`) or not, to start it.
    pub needs_loaded: Option<bool>,
    /// Whether the pallet is on the forks after it (`None`: as before).
    pub leaves_loaded: Option<bool>,
    pub build: PhaseCtor,
    /// Its settings at their defaults (for the format document).
    pub defaults: toml::Value,
}

impl std::fmt::Debug for PhaseKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PhaseKind")
            .field("name", &self.name)
            .field("after", &self.after)
            .finish_non_exhaustive()
    }
}

impl PhaseKind {
    /// A kind from its parts (`after`: the phases it may follow).
    pub fn new(
        name: &str,
        after: &[&str],
        (needs_loaded, leaves_loaded): (Option<bool>, Option<bool>),
        build: impl Fn(&toml::Table, &dyn Context) -> Result<Box<dyn Phase>, SettingsError>
        + Send
        + Sync
        + 'static,
        defaults: toml::Value,
    ) -> Self {
        PhaseKind {
            name: name.to_owned(),
            after: after.iter().map(|a| (*a).to_owned()).collect(),
            needs_loaded,
            leaves_loaded,
            build: Arc::new(build),
            defaults,
        }
    }
}

/// The phases forkbench ships: adding one is its file and a row here.
pub fn builtin_phases() -> Vec<PhaseKind> {
    vec![
        PhaseKind::new(
            "lift",
            &["pick"],
            (Some(false), Some(true)),
            lift::build,
            defaults_of::<lift::Lift>(),
        ),
        PhaseKind::new(
            "reverse_out",
            &["pick", "lift"],
            (None, None),
            reverse_out::build,
            defaults_of::<reverse_out::ReverseOut>(),
        ),
        PhaseKind::new(
            "carry",
            &["lift", "reverse_out"],
            (Some(true), None),
            return_leg::build_carry,
            defaults_of::<return_leg::LegFile>(),
        ),
        PhaseKind::new(
            "place",
            &["lift", "reverse_out", "carry"],
            (Some(true), Some(false)),
            place::build,
            defaults_of::<place::PlaceFile>(),
        ),
        PhaseKind::new(
            "return",
            &["place", "reverse_out"],
            (None, None),
            return_leg::build_return,
            defaults_of::<return_leg::LegFile>(),
        ),
    ]
}

/// Each built-in phase after the pick with its settings at their defaults.
pub fn phase_defaults() -> Vec<(String, toml::Value)> {
    builtin_phases()
        .into_iter()
        .map(|k| (k.name, k.defaults))
        .collect()
}

pub use forkbench_scenario::PICK;

/// Checks a scenario's phase list and settings: the pick first, then known phases each
/// after one it may follow and with the pallet on the forks or not as it needs, every
/// settings table valid (slots in `cx`'s world) and for a listed phase. Err: the field and why.
pub fn resolve(
    names: &[String],
    settings: &toml::Table,
    cx: &dyn Context,
    kinds: &[PhaseKind],
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
        let kind = runnable(kinds, (prev, name), loaded).map_err(|why| (field, why))?;
        loaded = kind.leaves_loaded.unwrap_or(loaded);
        let table = match settings.get(name) {
            Some(toml::Value::Table(t)) => t.clone(),
            Some(_) => return Err((format!("phase.{name}"), "must be a table".into())),
            None => toml::Table::new(),
        };
        let phase =
            (kind.build)(&table, cx).map_err(|e| (format!("phase.{name}"), e.to_string()))?;
        out.push(PhaseSpec {
            name: name.to_owned(),
            settings: table,
            phase: phase.into(),
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
fn runnable<'k>(
    kinds: &'k [PhaseKind],
    (prev, name): (&str, &str),
    loaded: bool,
) -> Result<&'k PhaseKind, String> {
    let Some(kind) = kinds.iter().find(|k| k.name == name) else {
        let known: Vec<_> = kinds.iter().map(|k| k.name.as_str()).collect();
        return Err(format!(
            "no phase {name:?} (phases after the pick: {})",
            known.join(", ")
        ));
    };
    if !kind.after.iter().any(|a| a == prev) {
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
pub fn defaults_of<T: Serialize + Default>() -> toml::Value {
    toml::Value::try_from(T::default()).unwrap_or(toml::Value::Table(toml::Table::new()))
}

/// Each `(name, value, max)` a positive finite number of at most `max`.
pub fn positive_at_most(fields: &[(&str, f64, f64)]) -> Result<(), SettingsError> {
    for &(name, v, max) in fields {
        if !(v.is_finite() && v > 0.0 && v <= max) {
            return Err(SettingsError::field(
                name,
                format!("must be positive and at most {max} (got {v})"),
            ));
        }
    }
    Ok(())
}

/// A phase's settings from its table, refusing unknown keys; `check` then the values.
pub fn settings<T: serde::de::DeserializeOwned>(table: &toml::Table) -> Result<T, SettingsError> {
    T::deserialize(toml::Value::Table(table.clone())).map_err(|e| SettingsError {
        field: None,
        reason: e.to_string().trim_end().to_owned(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_stage_s_fault_stays_typed_and_reads_as_before() {
        let tracker = StageError::Tracker {
            tracker: "mine".into(),
            reason: "no answer in 0.2 s".into(),
        };
        let f = Failed::from(tracker.clone());
        assert_eq!(f.failure, Failure::Error);
        assert!(matches!(f.cause, Cause::Stage(StageError::Tracker { .. })));
        assert_eq!(f.detail(), tracker.to_string());
        let nan = Failed::from(StageError::NonFinite { t_s: 1.5 });
        assert!(matches!(
            nan.cause,
            Cause::Stage(StageError::NonFinite { .. })
        ));
        assert_eq!(nan.detail(), "non-finite state at t = 1.500 s");
        let own = Failed::new(Failure::Timeout, "not stopped after 20 s");
        assert_eq!(own.to_string(), "timeout: not stopped after 20 s");
    }
}
