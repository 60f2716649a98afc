//! Running the phases after the pick: each timed, judged and recorded, the truck stepped under a phase's commands.

use std::collections::BTreeMap;

use forkbench_core::{Pose2, Signal, Style};
use forkbench_track::Command;

use super::{Failed, KINDS, PICK, PhaseSpec};
use crate::outcome::{Failure, PhaseOutcome};
use crate::recorder::{Level, Recorder};
use crate::trial::setup::Trial;

/// A command holding `speed_mps` and `steer_rad`, for phases that drive without a path.
pub(crate) fn open_loop(speed_mps: f64, steer_rad: f64, pose: &Pose2) -> Command {
    Command {
        speed_mps,
        steer_rad,
        lookahead_point: [pose.x_m, pose.y_m],
        cross_track_m: 0.0,
        remaining_m: 0.0,
        path_curvature_per_m: 0.0,
        done: false,
    }
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
            measures: BTreeMap::new(),
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
        self.out.cycle = Some(crate::outcome::CycleTotals {
            time_s: self.sim.time_s(),
            distance_loaded_m: self.travelled_loaded_m,
            distance_unloaded_m: self.travelled_m - self.travelled_loaded_m,
        });
    }

    /// One phase: built from its spec, run, timed and judged.
    fn run_phase(&mut self, spec: &PhaseSpec, rec: &mut dyn Recorder) {
        let (t0, d0, loaded) = (self.sim.time_s(), self.travelled_m, self.sim.carrying());
        self.phase_measures.clear();
        rec.event(t0, Level::Info, &format!("phase {}: start", spec.name));
        rec.signal(t0, "phase", &Signal::Text(&spec.name), Style::default());
        let result = KINDS
            .iter()
            .find(|k| k.name == spec.name)
            .ok_or_else(|| (Failure::Error, format!("no phase {:?}", spec.name)))
            .and_then(|k| {
                let cx = super::Context {
                    world: &self.scn.world,
                    pallet: &self.scn.pallet,
                    mission: self.scn.mission.as_ref(),
                };
                (k.build)(&spec.settings, &cx).map_err(|e| (Failure::Error, e))
            })
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
            measures: std::mem::take(&mut self.phase_measures),
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

    /// Holds the truck standing (steering where it is) for `time_s`, as while the mast
    /// lifts or lowers; the every-step criteria still hold.
    pub(crate) fn stand_for(&mut self, time_s: f64, rec: &mut dyn Recorder) -> Result<(), Failed> {
        let end_s = self.sim.time_s() + time_s;
        self.drive_by(time_s + 1.0, rec, |t, pose| {
            Ok((t.sim.time_s() < end_s).then(|| open_loop(0.0, t.sim.steer_rad(), &pose)))
        })?;
        Ok(())
    }

    /// Steps the truck under `command` (from the controller's pose) until it returns
    /// `None` (Ok(true)), `limit_s` passes (Ok(false)), it fails, or a criterion every
    /// phase holds at every step breaks (Err).
    pub(crate) fn drive_by(
        &mut self,
        limit_s: f64,
        rec: &mut dyn Recorder,
        mut command: impl FnMut(&mut Self, Pose2) -> Result<Option<Command>, Failed>,
    ) -> Result<bool, Failed> {
        let deadline = self.sim.time_s() + limit_s;
        while self.sim.time_s() < deadline {
            let (fix, pose) = self
                .sense(rec)
                .map_err(|e| (Failure::Error, e.to_string()))?;
            let Some(cmd) = command(self, pose)? else {
                return Ok(true);
            };
            self.physics_step(&cmd, fix, pose, rec);
            super::criteria::every_step(self)?;
            let t = self.sim.time_s();
            let step = (t / self.sim.dt_s()).round() as u64;
            if step.is_multiple_of(crate::trial::drive::SIGNAL_EVERY_STEPS) {
                let [front, rear] = self.sim.axle_loads_n();
                let none = Style::default();
                rec.signal(t, "load/front_axle_n", &Signal::Scalar(front), none);
                rec.signal(t, "load/rear_axle_n", &Signal::Scalar(rear), none);
            }
        }
        Ok(false)
    }
}
