//! One pick trial as named stages: setup, plan, drive (with replans), judge.

mod drive;
mod engine;
mod judge;
mod leg_drive;
mod link;
mod loc_stats;
mod localize;
mod look;
mod manoeuvre_leg;
mod mission;
mod movers_view;
mod options;
mod phase_host;
mod phases;
mod plan;
mod safety;
mod safety_run;
mod sense;
mod session;
mod session_view;
mod setup;
mod staging;
mod state;
mod streams;
mod truck_knobs;
mod uncertain_apply;
mod world;

use std::time::Instant;

use forkbench_core::{ForkliftSpec, Pose2};

use crate::ScenarioError;
use crate::outcome::{Failure, TrialOutcome};
use crate::recorder::{Level, NoRecorder, Recorder};
use crate::scenario::{Case, Scenario};
use state::Trial;

/// The trial's own scalar signals go out every this many control steps.
pub(in crate::trial) const SIGNAL_EVERY_STEPS: u64 = 10;

pub use crate::scenario::APPROACH_GAP_M;
pub use crate::stage_error::{LegError, StageError};

/// The criterion a trial fails when the moving truck touches a person or vehicle
/// (critical: it is the verdict whatever else the trial did).
pub const PERSON_CONTACT: &str = "person_contact";
/// The name of the leg a pick drives to its staging pose when the face is not seen from
/// where it begins (a mission's own legs may end at a waypoint called "staging").
pub const STAGING_LEG: &str = "pick start → staging";
pub use crate::step_criteria::{
    Criterion, Judged, PICK_CRITERIA, PickMeasures, Reading, STEP_CRITERIA, StepCriterion,
    StepCtor, StepView, step_criterion_name, step_measures,
};
pub use link::{Control, Episode, Observation, Stage, Truth};
pub use look::{ScanReport, look_world, scan_once, scenario_detector};
pub use options::{MAX_NOISE_SCALE, NOISE_KNOBS, Overrides, Resolved, TrialOptions};
pub use session::{Session, SessionEnd};
pub use session_view::SceneView;
pub use streams::accuracy_stream;
pub use truck_knobs::{
    TRUCK_GEOMETRY, TRUCK_KNOBS, TruckSettings, apply_truck, is_geometry, read_truck_text,
    truck_path,
};
pub use uncertain_apply::Shift;

/// Fork-root pose that puts the fork tips `insertion_m` past the pallet face
/// (negative: before it).
pub fn goal_for(face: &Pose2, truck: &ForkliftSpec, insertion_m: f64) -> Pose2 {
    face.to_world(&Pose2::new(insertion_m - truck.fork_length_m, 0.0, 0.0))
}

/// Runs one case of a scenario to its judged outcome.
pub fn run_trial(scn: &Scenario, case: &Case, opts: &TrialOptions) -> TrialOutcome {
    run_trial_recorded(scn, case, opts, &mut NoRecorder)
}

/// Runs one case and reports every step to `rec`: the same engine a [`Session`] steps,
/// run to its end with nobody taking the ticks.
pub fn run_trial_recorded<R: Recorder + ?Sized>(
    scn: &Scenario,
    case: &Case,
    opts: &TrialOptions,
    rec: &mut R,
) -> TrialOutcome {
    let wall = Instant::now();
    let mut out = match opts
        .resolve(scn)
        .and_then(|run| Ok((scenario_for(scn, &run)?, run)))
    {
        Ok((scn, run)) => link::run_to_end(run_stages(&scn, case, &run, None, rec)),
        Err(e) => unresolved(scn, case, opts, &e),
    };
    out.wall_time_ms = wall.elapsed().as_secs_f64() * 1e3;
    rec.outcome(out.sim_time_s, &out);
    out
}

/// Runs `trial` (a [`run_trial`] or [`run_trial_recorded`]) gathering where its time
/// went into the outcome's `profile`, the planner's and tracker's stages named after
/// them.
pub fn profiled(trial: impl FnOnce() -> TrialOutcome) -> TrialOutcome {
    let (mut out, p) = forkbench_core::profile::gather(trial);
    attach_profile(&mut out, p);
    out
}

/// Puts `p`, gathered over `out`'s trial, into `out`, the planner's and tracker's
/// stages named after them.
pub fn attach_profile(out: &mut TrialOutcome, mut p: forkbench_core::profile::Profile) {
    p.label(forkbench_core::profile::Stage::Plan, &out.planner);
    p.label(forkbench_core::profile::Stage::Track, &out.tracker);
    out.profile = Some(p);
}

/// `scn` as a run's truck makes it: itself when the run keeps its geometry, else the
/// scenario checked anew with the run's truck ([`Scenario::with_truck`]), so a truck
/// given by a run gives the outcome the same `[truck]` table in the file would.
pub fn scenario_for<'s>(
    scn: &'s Scenario,
    run: &Resolved,
) -> Result<std::borrow::Cow<'s, Scenario>, ScenarioError> {
    scenario_with(scn, &run.truck)
}

/// `scn` with `truck` for its own: itself when the geometry (mounts included) is the
/// same, else checked anew ([`Scenario::with_truck`]).
pub(crate) fn scenario_with<'s>(
    scn: &'s Scenario,
    truck: &forkbench_core::ForkliftSpec,
) -> Result<std::borrow::Cow<'s, Scenario>, ScenarioError> {
    if truck.same_geometry(&scn.truck) {
        return Ok(std::borrow::Cow::Borrowed(scn));
    }
    scn.with_truck(truck).map(std::borrow::Cow::Owned)
}

/// The outcome of a run whose options do not resolve.
fn unresolved(scn: &Scenario, case: &Case, opts: &TrialOptions, e: &ScenarioError) -> TrialOutcome {
    let names = (
        opts.planner.as_deref().unwrap_or(&scn.planner.name),
        opts.tracker.as_deref().unwrap_or(&scn.tracker.name),
    );
    let seed = opts.seed.unwrap_or(scn.seed);
    let mut out = TrialOutcome::blank(&scn.name, &case.name, names, seed, false);
    out.fail(Failure::Error, e.to_string());
    out
}

/// The whole trial: setup, the mission's legs, staging, the pick and its verdict, and
/// (unless a session takes the pick alone) the phases after it.
pub(crate) async fn run_stages<R: Recorder + ?Sized>(
    scn: &Scenario,
    case: &Case,
    run: &Resolved,
    link: Option<link::Link>,
    rec: &mut R,
) -> TrialOutcome {
    let mut out = stages(scn, case, run, link, rec).await;
    out.settle_robustness();
    out
}

async fn stages<R: Recorder + ?Sized>(
    scn: &Scenario,
    case: &Case,
    run: &Resolved,
    link: Option<link::Link>,
    rec: &mut R,
) -> TrialOutcome {
    let pick_only = link.as_ref().is_some_and(link::Link::pick_only);
    let mut trial = match prepare(scn, case, run, link, rec).await {
        Ok(t) => t,
        Err(out) => return *out,
    };
    trial.enter(link::Stage::Pick);
    let mut pick = drive::PickDrive::default();
    if let Err(why) = trial.drive_by(scn.timeout_s, &mut pick, rec).await {
        let why = why.to_string();
        rec.event(trial.world.sim.time_s(), Level::Error, &why);
        trial.measure();
        trial.verdict.out.fail(Failure::Error, why);
        trial.judge_safety();
        return trial.verdict.out;
    }
    trial.conclude();
    if !pick_only {
        trial.run_phases(rec).await;
    }
    trial.judge_safety();
    trial.verdict.out
}

/// A trial up to its drive: the world and components, the mission's legs, the first fix
/// and estimate, the first plan handed to the tracker. Err: the outcome of a trial that
/// ended before driving to the pallet.
async fn prepare<'a, R: Recorder + ?Sized>(
    scn: &'a Scenario,
    case: &Case,
    run: &'a Resolved,
    link: Option<link::Link>,
    rec: &mut R,
) -> Result<Trial<'a>, Box<TrialOutcome>> {
    let mut trial = Trial::setup(scn, case, run, rec)?;
    trial.link = link;
    let end = |mut trial: Trial<'a>, failure: Failure, why: String| {
        trial.measure_time();
        trial.verdict.out.fail(failure, why);
        trial.judge_safety();
        Err::<Trial<'a>, _>(Box::new(trial.verdict.out))
    };
    if let Some(m) = &scn.mission {
        let staging = crate::scenario::mission::Waypoint {
            name: if case.name == "default" {
                "staging".to_owned()
            } else {
                format!("staging ({})", case.name)
            },
            pose: case.start,
        };
        if let Err(why) = trial.run_legs(m, &staging, rec).await {
            return end(trial, Failure::LegFailed, why.to_string());
        }
        let pallet = trial.world.sim.pallet_pose();
        if let Err(e) = trial.first_fix_and_estimate(&pallet, rec) {
            let why = e.to_string();
            rec.event(trial.world.sim.time_s(), Level::Error, &why);
            return end(trial, Failure::Error, why);
        }
    }
    if trial.verdict.out.estimates_missed == trial.verdict.out.estimates
        && trial.verdict.out.estimates > 0
        && let Err(f) = trial.stage_and_look(rec).await
    {
        let why = f.detail();
        rec.event(trial.world.sim.time_s(), Level::Error, &why);
        return end(trial, f.failure, why);
    }
    let path = match trial.first_plan(rec) {
        Ok(p) => p,
        Err(f) => {
            let why = f.detail();
            return end(trial, f.failure, why);
        }
    };
    trial.tracker.reset(&path, &scn.truck);
    trial.set_path(path);
    // The pick began when the truck stood waiting for its first fix and estimate.
    let began = trial.world.sim.time_s() - trial.verdict.pick_waited_s;
    trial.verdict.pick_started = (began, trial.world.travelled_m);
    Ok(trial)
}
