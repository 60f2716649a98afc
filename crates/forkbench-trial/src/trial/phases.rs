//! Running the phases after the pick: each timed, judged and recorded, the truck stepped under a phase's commands.

use std::collections::BTreeMap;

use forkbench_core::{Pose2, Signal, Style};
use forkbench_track::Command;

use crate::outcome::PhaseOutcome;
use crate::phase::{Failed, PICK, PhaseSpec, Steer};
use crate::recorder::{Level, Recorder};
use crate::step_criteria::StepCriterion;
use crate::trial::engine::Steering;
use crate::trial::link::{Control, Stage};
use crate::trial::state::Trial;

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

impl<'a> Trial<'a> {
    /// After the judged pick: the pick's phase result, then each listed phase in order
    /// up to the first that fails, whose criterion becomes the trial's verdict.
    pub(in crate::trial) async fn run_phases<R: Recorder + ?Sized>(&mut self, rec: &mut R) {
        if self.scn.phases.is_empty() {
            return;
        }
        let (t0, d0) = self.verdict.pick_started;
        self.verdict.out.phases.push(PhaseOutcome {
            name: PICK.to_owned(),
            success: self.verdict.out.success,
            failure: self.verdict.out.failure.clone(),
            failure_detail: self.verdict.out.failure_detail.clone(),
            time_s: self.world.sim.time_s() - t0,
            distance_m: self.world.travelled_m - d0,
            loaded: false,
            measures: BTreeMap::new(),
        });
        let mut rec = DynRec(rec);
        let scn = self.scn;
        for (i, spec) in scn.phases.iter().enumerate() {
            if !self.verdict.out.success {
                break;
            }
            self.enter(Stage::Phase(u16::try_from(i + 1).unwrap_or(u16::MAX)));
            self.run_phase(spec, &mut rec).await;
        }
        self.stamp_time();
        self.verdict.out.cycle = Some(crate::outcome::CycleTotals {
            time_s: self.world.sim.time_s(),
            distance_loaded_m: self.world.travelled_loaded_m,
            distance_unloaded_m: self.world.travelled_m - self.world.travelled_loaded_m,
        });
    }

    /// One phase (built when the scenario loaded): run, timed and judged.
    async fn run_phase(&mut self, spec: &PhaseSpec, rec: &mut dyn Recorder) {
        let (t0, d0, loaded) = (
            self.world.sim.time_s(),
            self.world.travelled_m,
            self.world.sim.carrying(),
        );
        self.take_phase_measures();
        rec.event(t0, Level::Info, &format!("phase {}: start", spec.name));
        rec.signal(t0, "phase", &Signal::Text(&spec.name), Style::default());
        let result = spec.phase.run(self, rec).await;
        let t = self.world.sim.time_s();
        let mut done = PhaseOutcome {
            name: spec.name.clone(),
            success: result.is_ok(),
            failure: None,
            failure_detail: None,
            time_s: t - t0,
            distance_m: self.world.travelled_m - d0,
            loaded: loaded || self.world.sim.carrying(),
            measures: self.take_phase_measures(),
        };
        match result {
            Ok(()) => rec.event(t, Level::Info, &format!("phase {}: done", spec.name)),
            Err(Failed { failure, cause }) => {
                let why = crate::text::compact_numbers(&cause.to_string());
                rec.event(
                    t,
                    Level::Error,
                    &format!("phase {} failed: {}: {why}", spec.name, failure.name()),
                );
                (done.failure, done.failure_detail) = (Some(failure.clone()), Some(why.clone()));
                self.verdict
                    .out
                    .fail(failure, format!("{}: {why}", spec.name));
            }
        }
        self.verdict.out.phases.push(done);
    }

    /// Steps the truck under a phase's `command` (from the controller's pose) until it
    /// returns `None` (Ok(true)), `limit_s` passes (Ok(false)), it fails, or a criterion
    /// every phase holds at every step breaks (Err).
    pub(super) async fn drive_phase<R: Recorder + ?Sized>(
        &mut self,
        limit_s: f64,
        rec: &mut R,
        command: &mut Steer<'_>,
    ) -> Result<bool, Failed> {
        let criteria = crate::step_criteria::PHASE_CRITERIA
            .iter()
            .map(|c| c())
            .collect();
        self.drive_by(limit_s, &mut PhaseDrive(command, criteria), rec)
            .await
    }
}

/// A phase's drive: its commands, the criteria every phase holds at every step
/// (`PHASE_CRITERIA`, fresh for the drive), and the axle loads recorded.
struct PhaseDrive<'c, 's>(&'c mut Steer<'s>, Vec<Box<dyn StepCriterion>>);

impl<'a> Steering<'a, Failed> for PhaseDrive<'_, '_> {
    fn command(
        &mut self,
        t: &mut Trial<'a>,
        _control: Control,
        pose: Pose2,
    ) -> Result<Option<Command>, Failed> {
        (self.0)(t, pose)
    }

    fn stepped<R: Recorder + ?Sized>(
        &mut self,
        t: &mut Trial<'a>,
        _control: Control,
        _cmd: &Command,
        rec: &mut R,
    ) -> Result<bool, Failed> {
        let view = t.step_view();
        for c in &mut self.1 {
            c.observe(&view);
            crate::phase::held(c.as_ref())?;
        }
        let now = t.world.sim.time_s();
        let step = (now / t.world.sim.dt_s()).round() as u64;
        if step.is_multiple_of(crate::trial::SIGNAL_EVERY_STEPS) {
            let [front, rear] = t.world.sim.axle_loads_n();
            let none = Style::default();
            rec.signal(now, "load/front_axle_n", &Signal::Scalar(front), none);
            rec.signal(now, "load/rear_axle_n", &Signal::Scalar(rear), none);
        }
        Ok(false)
    }
}
