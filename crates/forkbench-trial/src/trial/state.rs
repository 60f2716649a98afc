//! A trial in progress and its state by concern: the physical world, the localisation, the perception of the pallet, and the verdict being built.

use std::collections::BTreeMap;

use forkbench_core::Pose2;
use forkbench_plan::Planner;
use forkbench_sensors::detector::PalletDetector;
use forkbench_sensors::{Localizer, PalletEstimator};
use forkbench_sim::Sim;
use forkbench_track::PosePredictor;
use forkbench_track::Tracker;
use rand_chacha::ChaCha8Rng;

use super::Resolved;
use super::loc_stats::LocStats;
use crate::outcome::TrialOutcome;
use crate::scenario::Scenario;
use crate::step_criteria::StepCriterion;

/// The physical world and what happened in it.
pub(crate) struct WorldState {
    pub(crate) sim: Sim,
    pub(crate) obstacles: Vec<forkbench_sim::Obstacle>,
    /// Racks and walls for the swept-body check of every plan, built once per trial.
    pub(crate) footprints: (forkbench_geom::Obstacles, Vec<String>),
    /// Pallet pose before the truck moved: displacement is measured from it.
    pub(crate) pallet0: Pose2,
    /// Where the pallet should stand (the case's placement, before any jitter): the
    /// region a detector looks in before its first estimate, and the staging prior.
    pub(crate) pallet_nominal: Pose2,
    /// The truck has touched a rack or wall.
    pub(crate) collision: bool,
    /// Distance the fork root has travelled, over every physics step, and of that with
    /// the pallet on the forks.
    pub(crate) travelled_m: f64,
    pub(crate) travelled_loaded_m: f64,
    /// The true fork-root pose after each recent physics step: where a scanner's beams
    /// left from over its sweep.
    pub(crate) trail: std::collections::VecDeque<(f64, Pose2)>,
}

/// How far back the trail of true poses reaches: a scanner's longest sweep.
const TRAIL_S: f64 = forkbench_sensors::scan::MAX_SWEEP_S;

impl WorldState {
    /// Keeps the fork root's true pose now in the trail.
    pub(crate) fn mark(&mut self) {
        let t = self.sim.time_s();
        self.trail.push_back((t, self.sim.fork_root_pose()));
        while self.trail.front().is_some_and(|(t0, _)| *t0 < t - TRAIL_S) {
            self.trail.pop_front();
        }
    }

    /// The fork root's true pose at `t_s`, between the trail's marks (its oldest before
    /// them, now after them).
    pub(crate) fn root_at(&self, t_s: f64) -> Pose2 {
        let now = self.sim.fork_root_pose();
        let Some(i) = self.trail.iter().position(|(t, _)| *t >= t_s) else {
            return now;
        };
        let (t1, p1) = self.trail[i];
        if i == 0 || t1 <= t_s {
            return p1;
        }
        let (t0, p0) = self.trail[i - 1];
        let u = (t_s - t0) / (t1 - t0);
        let dh = forkbench_core::units::wrap_angle(p1.heading_rad - p0.heading_rad);
        Pose2::new(
            p0.x_m + u * (p1.x_m - p0.x_m),
            p0.y_m + u * (p1.y_m - p0.y_m),
            p0.heading_rad + u * dh,
        )
    }
}

/// Where the truck believes it is: the localiser, the odometry and their record.
pub(crate) struct Localization {
    pub(crate) localizer: Box<dyn Localizer>,
    pub(crate) nav_rng: ChaCha8Rng,
    pub(crate) predictor: PosePredictor,
    /// The truck's odometry alone from its start, never reset by a fix (a NAV350's speed
    /// input).
    pub(crate) odometry: PosePredictor,
    /// The fix the pick planned from.
    pub(crate) first_fix: Pose2,
    /// The odometry's speed-scale error and steering offset for this trial.
    pub(crate) odometry_error: (f64, f64),
    /// Localization over the whole trial, and over the current mission leg.
    pub(crate) stats: LocStats,
    pub(crate) leg_stats: LocStats,
    /// The last reading gave no pose (the log says so once, and again when one returns).
    pub(crate) fix_lost: bool,
    /// When the newest fix taken was measured.
    pub(crate) last_fix_measured_s: Option<f64>,
}

/// Where the truck believes the pallet is: the sensing and the estimate.
pub(crate) struct Perception {
    pub(crate) estimator: Box<dyn PalletEstimator>,
    pub(crate) est_rng: ChaCha8Rng,
    /// Each scanner's bias, noise stream and frame timing, in the sensing's order.
    pub(crate) scanners: Vec<ScannerState>,
    /// The pallet detector, when the sensing scans.
    pub(crate) detector: Option<Box<dyn PalletDetector>>,
    /// The pallet pose the current plan aims at.
    pub(crate) pallet_est: Pose2,
    /// The plan aims at the prior (`[pick] when_not_seen = "prior"`): every scanner frame
    /// is looked at until the face is found, then the truck replans once onto it.
    pub(crate) on_prior: bool,
    /// An estimate on its way from the detector: when it reaches the controller, and it.
    pub(crate) in_flight: Option<(f64, Pose2)>,
}

/// The outcome being built and what judges it.
pub(crate) struct Verdict {
    pub(crate) out: TrialOutcome,
    /// The pick's criteria in the order of blame: the fixed ones, then those that measure
    /// at every step.
    pub(crate) criteria: Vec<Box<dyn StepCriterion>>,
    /// The pick's drive ran out of time (until it docks or settles).
    pub(crate) timed_out: bool,
    /// Simulated time and distance travelled when the pick's drive began.
    pub(crate) pick_started: (f64, f64),
    /// How long the truck stood for the pick's first fix and estimate: part of the pick.
    pub(crate) pick_waited_s: f64,
    /// What the running phase measured, by name (see `PhaseOutcome::measures`).
    pub(crate) phase_measures: BTreeMap<String, f64>,
}

impl Verdict {
    /// A verdict not yet reached: the pick not started, its drive timed out until it ends.
    pub(crate) fn new(out: TrialOutcome, criteria: Vec<Box<dyn StepCriterion>>) -> Self {
        Self {
            out,
            criteria,
            timed_out: true,
            pick_started: (0.0, 0.0),
            pick_waited_s: 0.0,
            phase_measures: BTreeMap::new(),
        }
    }
}

/// A trial in progress: its scenario and run, the controllers and the plan they follow,
/// and its state by concern (the world, the localisation, the perception, the verdict
/// being built).
pub(crate) struct Trial<'a> {
    /// When the trial began, for its wall-time budget.
    pub(super) wall_start: std::time::Instant,
    pub(super) scn: &'a Scenario,
    pub(super) run: &'a Resolved,
    pub(super) world: WorldState,
    pub(super) loc: Localization,
    pub(super) sense: Perception,
    pub(super) verdict: Verdict,
    pub(super) planner: Box<dyn Planner>,
    pub(super) tracker: Box<dyn Tracker>,
    /// The path the tracker follows now (the first plan, the last replan, a phase's).
    pub(super) path: forkbench_core::Path,
    /// Counts the changes of `path`, so a session copies it only when it changed.
    pub(super) path_version: u64,
    /// Depth the forks are driven to past the face.
    pub(super) insertion_m: f64,
    /// The session whose caller takes the ticks, if one does.
    pub(super) link: Option<super::link::Link>,
    /// The part of the cycle being driven.
    pub(super) stage: super::link::Stage,
    /// People, other vehicles and the safety function, when the scenario has them.
    pub(super) safety: Option<super::safety_run::SafetyRun>,
}

impl std::fmt::Debug for Trial<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Trial")
            .field("out", &self.verdict.out)
            .finish_non_exhaustive()
    }
}

/// One pallet scanner through a trial: its range bias (the systematic error), the stream
/// its per-beam noise draws from, and when its next frame is ready.
pub(super) struct ScannerState {
    pub(super) bias_m: f64,
    pub(super) rng: ChaCha8Rng,
    /// A look before this time gets no new frame from this scanner (its `rate_hz`).
    pub(super) next_frame_s: f64,
}
