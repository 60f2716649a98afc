//! A trial's state by concern: the physical world, the localisation, the perception of the pallet, and the verdict being built.

use std::collections::BTreeMap;

use forkbench_core::Pose2;
use forkbench_sensors::detector::PalletDetector;
use forkbench_sensors::{Localizer, PalletEstimator};
use forkbench_sim::Sim;
use forkbench_track::PosePredictor;
use rand_chacha::ChaCha8Rng;

use super::localize::LocStats;
use super::setup::ScannerState;
use crate::outcome::TrialOutcome;
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
}

/// Where the truck believes it is: the localiser, the odometry and their record.
pub(crate) struct Localisation {
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
    /// Localisation over the whole trial, and over the current mission leg.
    pub(crate) stats: LocStats,
    pub(crate) leg_stats: LocStats,
    /// The last reading gave no pose (the log says so once, and again when one returns).
    pub(crate) fix_lost: bool,
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
}

/// The outcome being built and what judges it.
pub(crate) struct Verdict {
    pub(crate) out: TrialOutcome,
    /// The pick's criteria that measure at every step.
    pub(crate) step_criteria: Vec<Box<dyn StepCriterion>>,
    /// The pick's drive ran out of time (until it docks or settles).
    pub(crate) timed_out: bool,
    /// Simulated time and distance travelled when the pick's drive began.
    pub(crate) pick_started: (f64, f64),
    /// What the running phase measured, by name (see `PhaseOutcome::measures`).
    pub(crate) phase_measures: BTreeMap<String, f64>,
}
