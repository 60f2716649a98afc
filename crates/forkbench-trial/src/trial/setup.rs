//! Setup stage: the simulated world, sensors with their own random streams, the components, the first fix and estimate.

use forkbench_core::hash::fnv1a;
use forkbench_core::{Pose2, SettingsError};
use forkbench_plan::Planner;
use forkbench_sensors::{Localizer, PalletEstimator};
use forkbench_sim::Sim;
use forkbench_track::{PosePredictor, Tracker};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use super::error::StageError;
use super::judge::jitter;
use super::localize::{LocStats, record_reflectors};
use super::{Resolved, target_insertion_m};
use crate::components::LocalizerContext;
use crate::outcome::{Failure, TrialOutcome};
use crate::recorder::{Level, Recorder, SceneInfo};
use crate::scenario::sensors::PalletSensing;
use crate::scenario::{Case, Scenario};

/// Independent random streams per sensor, so changing one sensor's settings does not
/// change the other's draws.
pub(super) fn stream(seed: u64, salt: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed ^ salt.wrapping_mul(0x9E37_79B9_7F4A_7C15))
}

/// A trial in progress: its world, sensors, components and what it has measured so far.
pub struct Trial<'a> {
    /// When the trial began, for its wall-time budget.
    pub(super) wall_start: std::time::Instant,
    pub(super) scn: &'a Scenario,
    pub(super) run: &'a Resolved,
    pub(super) out: TrialOutcome,
    pub(super) sim: Sim,
    pub(super) planner: Box<dyn Planner>,
    pub(super) tracker: Box<dyn Tracker>,
    pub(super) localizer: Box<dyn Localizer>,
    pub(super) estimator: Box<dyn PalletEstimator>,
    pub(super) nav_rng: ChaCha8Rng,
    pub(super) est_rng: ChaCha8Rng,
    pub(super) predictor: PosePredictor,
    /// The truck's odometry alone from its start, never reset by a fix (a NAV350's speed
    /// input).
    pub(super) odometry: PosePredictor,
    pub(super) first_fix: Pose2,
    /// The pallet pose the current plan aims at.
    pub(super) pallet_est: Pose2,
    /// The path the tracker follows now (the first plan or the last replan).
    pub(super) path: forkbench_core::Path,
    /// Depth the forks are driven to past the face.
    pub(super) insertion_m: f64,
    pub(super) obstacles: Vec<forkbench_sim::Obstacle>,
    /// Racks and walls for the swept-body check of every plan, built once per trial.
    pub(super) footprints: (forkbench_geom::Obstacles, Vec<String>),
    /// Pallet pose before the truck moved: displacement is measured from it.
    pub(super) pallet0: Pose2,
    /// Where the pallet should stand (the case's placement, before any jitter): the
    /// region a detector looks in before its first estimate.
    pub(super) pallet_nominal: Pose2,
    /// Each scanner's bias, noise stream and frame timing, in the sensing's order.
    pub(super) scanners: Vec<ScannerState>,
    /// The pallet detector, when the sensing scans.
    pub(super) detector: Option<Box<dyn forkbench_sensors::detector::PalletDetector>>,
    pub(super) collision: bool,
    pub(super) timed_out: bool,
    /// The pick's criteria that measure at every step.
    pub(super) step_criteria: Vec<Box<dyn super::step_criteria::StepCriterion>>,
    /// The odometry's speed-scale error and steering offset for this trial.
    pub(super) odometry_error: (f64, f64),
    /// Localisation over the whole trial, and over the current mission leg.
    pub(super) loc: LocStats,
    pub(super) leg_loc: LocStats,
    /// The last reading gave no pose (the log says so once, and again when one returns).
    pub(super) fix_lost: bool,
    /// The plan aims at the prior (`[pick] when_not_seen = "prior"`): every scanner frame
    /// is looked at until the face is found, then the truck replans once onto it.
    pub(super) on_prior: bool,
    /// Distance the fork root has travelled, over every physics step, and of that with
    /// the pallet on the forks.
    pub(super) travelled_m: f64,
    pub(super) travelled_loaded_m: f64,
    /// Simulated time and distance travelled when the pick's drive began.
    pub(super) pick_started: (f64, f64),
    /// What the running phase measured, by name (see `PhaseOutcome::measures`).
    pub(super) phase_measures: std::collections::BTreeMap<String, f64>,
}

impl std::fmt::Debug for Trial<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Trial")
            .field("out", &self.out)
            .finish_non_exhaustive()
    }
}

/// The physics world of a trial: the truck at its start (a mission's first place, else the
/// case's start, or `start_at`), the pallet where it really stands (jittered on its own
/// random stream).
pub(super) fn build_world(
    scn: &Scenario,
    case: &Case,
    seed: u64,
    start_at: Option<Pose2>,
) -> Result<(Sim, Pose2, Pose2, Vec<forkbench_sim::Obstacle>), StageError> {
    let true_pallet = jitter(&case.pallet, &scn.pallet_jitter, &mut stream(seed, 3));
    let obstacles = scn.world.obstacles();
    let start =
        start_at.unwrap_or_else(|| scn.mission.as_ref().map_or(case.start, |m| m.start.pose));
    let sim = Sim::new(
        &scn.truck,
        &start,
        &scn.pallet,
        &true_pallet,
        &obstacles,
        &scn.sim,
    )?;
    Ok((sim, start, true_pallet, obstacles))
}

/// A scanner model's stream salt for `what` (its bias, its per-beam noise): for the first
/// model the bench had, the salts it always used (bias 4, noise 2, the estimate's stream);
/// for others the FNV-1a hash of `name/what`. Streams are keyed by what they are for, so
/// adding a sensor, or listing them in another order, leaves every other draw unchanged.
fn scanner_salt(name: &str, what: &str) -> u64 {
    match (name, what) {
        ("tim561", "bias") => 4,
        ("tim561", "noise") => 2,
        // The bias salt predates the keyed noise streams; kept so outcomes stay paired.
        (_, "bias") => fnv1a(name.bytes()),
        _ => fnv1a(name.bytes().chain(b"/".iter().copied()).chain(what.bytes())),
    }
}

/// Each scanner's systematic range error for one trial and the stream of its per-beam
/// noise, each keyed by the scanner's name (nothing for the Gaussian model; no bias with
/// noise off, where scans draw nothing).
/// One pallet scanner through a trial: its range bias (the systematic error), the stream
/// its per-beam noise draws from, and when its next frame is ready.
pub(super) struct ScannerState {
    pub(super) bias_m: f64,
    pub(super) rng: ChaCha8Rng,
    /// A look before this time gets no new frame from this scanner (its `rate_hz`).
    pub(super) next_frame_s: f64,
}

fn scanner_streams(run: &Resolved) -> Vec<ScannerState> {
    match &run.pallet_sensing {
        PalletSensing::Scanner { sensors, .. } => sensors
            .iter()
            .map(|s| {
                let bias = if run.noise {
                    let salt = scanner_salt(&s.name, "bias");
                    s.scanner.draw_bias(&mut stream(run.seed, salt))
                } else {
                    0.0
                };
                ScannerState {
                    bias_m: bias,
                    rng: stream(run.seed, scanner_salt(&s.name, "noise")),
                    next_frame_s: f64::NEG_INFINITY,
                }
            })
            .collect(),
        PalletSensing::Gaussian => Vec::new(),
    }
}

/// The scenario's planner, tracker, localiser and (when it scans) pallet detector, from
/// its registry.
type Built = (
    Box<dyn Planner>,
    Box<dyn Tracker>,
    Box<dyn Localizer>,
    Option<Box<dyn forkbench_sensors::detector::PalletDetector>>,
);

fn build_components(scn: &Scenario, run: &Resolved) -> Result<Built, SettingsError> {
    let planner = scn.registry.planner(&run.planner)?;
    let tracker = scn.registry.tracker(&run.tracker)?;
    let surfaces = scn.world.fixed_surfaces();
    let cx = LocalizerContext {
        nav350: &scn.noise.nav350,
        noise: run.noise,
        noise_scale: run.localization_noise_scale,
        reflectors: &scn.world.reflector,
        surfaces: &surfaces,
        truck: &scn.truck,
    };
    let localizer = scn.registry.localizer(&run.localizer, &cx)?;
    let detector = match &run.pallet_sensing {
        PalletSensing::Scanner { detector, .. } => Some(scn.registry.detector(detector)?),
        PalletSensing::Gaussian => None,
    };
    Ok((planner, tracker, localizer, detector))
}

/// Dead reckoning from `start` alone (never reset by a fix).
fn odometry_from(start: Pose2) -> PosePredictor {
    let mut o = PosePredictor::new();
    o.fix(start);
    o
}

/// The odometry's speed-scale error and steering offset for one trial, on a stream of
/// their own (none with noise off).
fn odometry_error(run: &Resolved) -> (f64, f64) {
    if run.noise {
        run.odometry.draw(&mut stream(run.seed, 6))
    } else {
        (0.0, 0.0)
    }
}

/// The reflectors a localiser's settings say are missing from the world.
fn missing_reflectors(run: &Resolved) -> Vec<String> {
    match run.localizer.settings.get("missing_reflectors") {
        Some(toml::Value::Array(a)) => a
            .iter()
            .filter_map(|v| v.as_str().map(str::to_owned))
            .collect(),
        _ => Vec::new(),
    }
}

/// The scene a recording opens with: the world, the truck's start, the true pallet, the
/// reflectors.
fn record_scene<R: Recorder + ?Sized>(
    rec: &mut R,
    scn: &Scenario,
    case: &Case,
    run: &Resolved,
    (start, pallet_pose): (Pose2, Pose2),
    obstacles: &[forkbench_sim::Obstacle],
) {
    rec.scene(&SceneInfo {
        scenario: &scn.name,
        case: &case.name,
        planner: &run.planner.name,
        tracker: &run.tracker.name,
        seed: run.seed,
        truck: &scn.truck,
        pallet: &scn.pallet,
        pallet_pose,
        obstacles,
        start,
        tolerances: &scn.tolerances,
    });
    record_reflectors(rec, &scn.world, &missing_reflectors(run));
}

impl<'a> Trial<'a> {
    /// Builds the world and components and takes the first fix and pallet estimate. A
    /// world that cannot be built ends the trial here, as an `error` outcome.
    pub fn setup<R: Recorder + ?Sized>(
        scn: &'a Scenario,
        case: &Case,
        run: &'a Resolved,
        rec: &mut R,
    ) -> Result<Self, Box<TrialOutcome>> {
        let names = (run.planner.name.as_str(), run.tracker.name.as_str());
        let mut out = TrialOutcome::blank(&scn.name, &case.name, names, run.seed, run.noise);
        let mut fail = |out: &mut TrialOutcome, why: String| {
            rec.event(0.0, Level::Error, &why);
            out.fail(Failure::Error, why);
        };
        let (planner, tracker, localizer, detector) = match build_components(scn, run) {
            Ok(c) => c,
            Err(e) => {
                fail(&mut out, format!("building the components: {e}"));
                return Err(Box::new(out));
            }
        };
        let (sim, start, true_pallet, obstacles) = match build_world(scn, case, run.seed, None) {
            Ok(w) => w,
            Err(e) => {
                fail(&mut out, e.to_string());
                return Err(Box::new(out));
            }
        };
        record_scene(rec, scn, case, run, (start, true_pallet), &obstacles);
        let pallet0 = sim.pallet_pose();
        let mut trial = Trial {
            scn,
            run,
            out,
            sim,
            planner,
            tracker,
            localizer,
            estimator: scn.registry.estimator(&run.pallet_estimate),
            nav_rng: stream(run.seed, 1),
            est_rng: stream(run.seed, 2),
            predictor: PosePredictor::new(),
            odometry: odometry_from(start),
            first_fix: start,
            pallet_est: true_pallet,
            path: forkbench_core::Path::default(),
            insertion_m: target_insertion_m(&scn.truck, &scn.pallet),
            obstacles,
            footprints: scn.world.footprint_obstacles(),
            pallet0,
            pallet_nominal: case.pallet,
            scanners: scanner_streams(run),
            detector,
            collision: false,
            timed_out: true,
            step_criteria: super::step_criteria::build_all(),
            odometry_error: odometry_error(run),
            loc: LocStats::new(0.0),
            leg_loc: LocStats::new(0.0),
            fix_lost: false,
            on_prior: false,
            travelled_m: 0.0,
            travelled_loaded_m: 0.0,
            pick_started: (0.0, 0.0),
            phase_measures: std::collections::BTreeMap::new(),
            wall_start: std::time::Instant::now(),
        };
        if scn.mission.is_none()
            && let Err(e) = trial.first_fix_and_estimate(&true_pallet, rec)
        {
            let why = e.to_string();
            rec.event(0.0, Level::Error, &why);
            trial.out.fail(Failure::Error, why);
            return Err(Box::new(trial.out));
        }
        Ok(trial)
    }

    /// The fix the pick plans from (the odometry-predicted pose when no fix is due) and
    /// the first pallet estimate.
    pub(super) fn first_fix_and_estimate<R: Recorder + ?Sized>(
        &mut self,
        true_pallet: &Pose2,
        rec: &mut R,
    ) -> Result<(), StageError> {
        let (fix, _) = self.sense(rec)?;
        self.first_fix = fix.or(self.predictor.pose()).unwrap_or(self.first_fix);
        self.predictor.fix(self.first_fix);
        let range = self.first_fix.distance_to(true_pallet);
        let believed = self.first_fix;
        if let Some(est) = self.estimate(true_pallet, range, &believed, rec)? {
            self.adopt_estimate(est, true_pallet);
        }
        Ok(())
    }
}
