//! The phases after the pick (lift, reverse out): each a unit with its own settings and criteria, built by name from a scenario's `phases` list.

mod criteria;
mod lift;
mod reverse_out;

use forkbench_core::{Pose2, Signal, Style};
use forkbench_track::Command;
use serde::Serialize;

use super::setup::Trial;
use crate::outcome::{Failure, PhaseOutcome};
use crate::recorder::{Level, Recorder};

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

/// A phase kind: its name, the phases it may follow, and how its settings build it.
struct Kind {
    name: &'static str,
    after: &'static [&'static str],
    build: fn(&toml::Table) -> Result<Box<dyn Phase>, String>,
    /// Its settings at their defaults (for the format document).
    defaults: fn() -> toml::Value,
}

/// Every phase by name: adding one is its file and a row here.
const KINDS: &[Kind] = &[
    Kind {
        name: "lift",
        after: &["pick"],
        build: lift::build,
        defaults: lift::defaults,
    },
    Kind {
        name: "reverse_out",
        after: &["pick", "lift"],
        build: reverse_out::build,
        defaults: reverse_out::defaults,
    },
];

/// Each phase after the pick with its settings at their defaults.
pub fn phase_defaults() -> Vec<(&'static str, toml::Value)> {
    KINDS.iter().map(|k| (k.name, (k.defaults)())).collect()
}

/// The phase list's name for the pick itself (approach and insertion), always first.
pub const PICK: &str = "pick";

/// Checks a scenario's phase list and settings: the pick first, then known phases each
/// after one it may follow, every settings table valid and for a listed phase. Err: the
/// field and why.
pub fn resolve(
    names: &[String],
    settings: &toml::Table,
) -> Result<Vec<PhaseSpec>, (String, String)> {
    if names.first().map(String::as_str) != Some(PICK) {
        return Err((
            "phases".into(),
            format!("must start with {PICK:?}, the pick itself"),
        ));
    }
    let mut out = Vec::new();
    for (i, pair) in names.windows(2).enumerate() {
        let (prev, name) = (pair[0].as_str(), pair[1].as_str());
        let field = format!("phases[{}]", i + 1);
        let Some(kind) = KINDS.iter().find(|k| k.name == name) else {
            let known: Vec<_> = KINDS.iter().map(|k| k.name).collect();
            return Err((
                field,
                format!(
                    "no phase {name:?} (phases after the pick: {})",
                    known.join(", ")
                ),
            ));
        };
        if !kind.after.contains(&prev) {
            return Err((
                field,
                format!(
                    "{name:?} cannot follow {prev:?} (it follows {})",
                    kind.after.join(" or ")
                ),
            ));
        }
        let table = match settings.get(name) {
            Some(toml::Value::Table(t)) => t.clone(),
            Some(_) => return Err((format!("phase.{name}"), "must be a table".into())),
            None => toml::Table::new(),
        };
        (kind.build)(&table).map_err(|e| (format!("phase.{name}"), e))?;
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

/// A phase's settings from its table, refusing unknown keys; `check` then the values.
pub(crate) fn settings<T: serde::de::DeserializeOwned>(table: &toml::Table) -> Result<T, String> {
    T::deserialize(toml::Value::Table(table.clone()))
        .map_err(|e| e.to_string().trim_end().to_owned())
}

/// Hands a generic recorder to phases as a trait object.
struct DynRec<'r, R: ?Sized>(&'r mut R);

impl<R: Recorder + ?Sized> Recorder for DynRec<'_, R> {
    fn scene(&mut self, s: &crate::recorder::SceneInfo<'_>) {
        self.0.scene(s);
    }
    fn plan(&mut self, t: f64, i: u32, p: &forkbench_core::Path, c: Option<&[[f64; 2]]>) {
        self.0.plan(t, i, p, c);
    }
    fn signal(&mut self, t: f64, path: &str, signal: &Signal<'_>, style: Style) {
        self.0.signal(t, path, signal, style);
    }
    fn step(&mut self, s: &crate::recorder::StepRecord) {
        self.0.step(s);
    }
    fn event(&mut self, t: f64, l: Level, text: &str) {
        self.0.event(t, l, text);
    }
    fn outcome(&mut self, t: f64, o: &crate::outcome::TrialOutcome) {
        self.0.outcome(t, o);
    }
}

impl Trial<'_> {
    /// After the judged pick: the pick's phase result, then each listed phase in order
    /// up to the first that fails, whose criterion becomes the trial's verdict.
    pub(in crate::trial) fn run_phases<R: Recorder + ?Sized>(&mut self, rec: &mut R) {
        if self.scn.phases.is_empty() {
            return;
        }
        let (t0, d0) = self.pick_started;
        self.out.phases.push(PhaseOutcome {
            name: PICK.to_owned(),
            success: self.out.success,
            failure: self.out.failure,
            failure_detail: self.out.failure_detail.clone(),
            time_s: self.sim.time_s() - t0,
            distance_m: self.travelled_m - d0,
            loaded: false,
        });
        let mut rec = DynRec(rec);
        let scn = self.scn;
        for spec in &scn.phases {
            if !self.out.success {
                break;
            }
            self.run_phase(spec, &mut rec);
        }
        self.out.sim_time_s = self.sim.time_s();
    }

    /// One phase: built from its spec, run, timed and judged.
    fn run_phase(&mut self, spec: &PhaseSpec, rec: &mut dyn Recorder) {
        let (t0, d0, loaded) = (self.sim.time_s(), self.travelled_m, self.sim.carrying());
        rec.event(t0, Level::Info, &format!("phase {}: start", spec.name));
        rec.signal(t0, "phase", &Signal::Text(&spec.name), Style::default());
        let result = KINDS
            .iter()
            .find(|k| k.name == spec.name)
            .ok_or_else(|| (Failure::Error, format!("no phase {:?}", spec.name)))
            .and_then(|k| (k.build)(&spec.settings).map_err(|e| (Failure::Error, e)))
            .and_then(|phase| phase.run(self, rec));
        let t = self.sim.time_s();
        let mut done = PhaseOutcome {
            name: spec.name.clone(),
            success: result.is_ok(),
            failure: None,
            failure_detail: None,
            time_s: t - t0,
            distance_m: self.travelled_m - d0,
            loaded: loaded || self.sim.carrying(),
        };
        match result {
            Ok(()) => rec.event(t, Level::Info, &format!("phase {}: done", spec.name)),
            Err((failure, why)) => {
                let why = crate::text::compact_numbers(&why);
                rec.event(
                    t,
                    Level::Error,
                    &format!("phase {} failed: {}: {why}", spec.name, failure.name()),
                );
                (done.failure, done.failure_detail) = (Some(failure), Some(why.clone()));
                self.out.fail(failure, format!("{}: {why}", spec.name));
            }
        }
        self.out.phases.push(done);
    }

    /// Steps the truck under `command` (speed and steering from the controller's pose)
    /// until it returns `None` (Ok(true)), `limit_s` passes (Ok(false)), or a criterion
    /// every phase holds at every step breaks (Err).
    pub(crate) fn drive_by(
        &mut self,
        limit_s: f64,
        rec: &mut dyn Recorder,
        mut command: impl FnMut(&Self, Pose2) -> Option<(f64, f64)>,
    ) -> Result<bool, Failed> {
        let deadline = self.sim.time_s() + limit_s;
        while self.sim.time_s() < deadline {
            let (fix, pose) = self
                .sense(rec)
                .map_err(|e| (Failure::Error, e.to_string()))?;
            let Some((speed_mps, steer_rad)) = command(self, pose) else {
                return Ok(true);
            };
            let cmd = Command {
                speed_mps,
                steer_rad,
                lookahead_point: [pose.x_m, pose.y_m],
                cross_track_m: 0.0,
                remaining_m: 0.0,
                path_curvature_per_m: 0.0,
                done: false,
            };
            self.physics_step(&cmd, fix, pose, rec);
            criteria::every_step(self)?;
            let t = self.sim.time_s();
            let step = (t / self.sim.dt_s()).round() as u64;
            if step.is_multiple_of(super::drive::SIGNAL_EVERY_STEPS) {
                let [front, rear] = self.sim.axle_loads_n();
                let none = Style::default();
                rec.signal(t, "load/front_axle_n", &Signal::Scalar(front), none);
                rec.signal(t, "load/rear_axle_n", &Signal::Scalar(rear), none);
            }
        }
        Ok(false)
    }
}
