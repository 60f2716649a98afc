//! Setup stage: a trial built once from its scenario and run: the world, the components, the sensors with their own random streams; then the first fix and estimate.

use forkbench_core::hash::fnv1a;
use forkbench_core::{Pose2, SettingsError};
use forkbench_plan::Planner;
use forkbench_sensors::Localizer;
use forkbench_track::{PosePredictor, Tracker};

use super::Resolved;
use super::loc_stats::LocStats;
use super::localize::record_reflectors;
use super::state::{Localization, Perception, ScannerState, Trial, Verdict, WorldState};
use super::streams::{self, stream};
use super::world::build_world;
use crate::components::LocalizerContext;
use crate::outcome::{Failure, TrialOutcome};
use crate::recorder::{Level, Recorder, SceneInfo};
use crate::scenario::sensors::PalletSensing;
use crate::scenario::{Case, Scenario};

/// A scanner model's stream salt for `what` (its bias, its per-beam noise): for the first
/// model the bench had, the salts it always used (bias 4, noise 2, the estimate's stream);
/// for others the FNV-1a hash of `name/what`. Streams are keyed by what they are for, so
/// adding a sensor, or listing them in another order, leaves every other draw unchanged.
fn scanner_salt(name: &str, what: &str) -> u64 {
    match (name, what) {
        ("tim561", "bias") => streams::TIM561_BIAS,
        ("tim561", "noise") => streams::ESTIMATE,
        // The bias salt predates the keyed noise streams; kept so outcomes stay paired.
        (_, "bias") => fnv1a(name.bytes()),
        _ => fnv1a(name.bytes().chain(b"/".iter().copied()).chain(what.bytes())),
    }
}

/// Each scanner's systematic range error for one trial and the stream of its per-beam
/// noise, each keyed by the scanner's name (nothing for the Gaussian model; no bias with
/// noise off, where scans draw nothing).
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
        nav350: &run.nav350,
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
        run.odometry.draw(&mut stream(run.seed, streams::ODOMETRY))
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
    if !run.uncertain.is_empty() {
        // A reviewer of a searched or sampled trial sees what was drawn beside the verdict.
        let drawn: Vec<String> = run
            .uncertain
            .iter()
            .map(|(name, v)| format!("{name} = {v:.4}"))
            .collect();
        let text = format!("uncertain parameters drawn: {}", drawn.join(", "));
        rec.event(0.0, Level::Info, &text);
    }
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
        out.uncertain = run.uncertain.clone();
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
        let (sim, start, true_pallet, obstacles) =
            match build_world(scn, &run.truck, case, (run.seed, &run.shift), None) {
                Ok(w) => w,
                Err(e) => {
                    fail(&mut out, e.to_string());
                    return Err(Box::new(out));
                }
            };
        let safety = match super::safety_run::SafetyRun::new(scn, run) {
            Ok(s) => s,
            Err(e) => {
                fail(&mut out, format!("the safety function: {e}"));
                return Err(Box::new(out));
            }
        };
        record_scene(rec, scn, case, run, (start, true_pallet), &obstacles);
        let pallet0 = sim.pallet_pose();
        let mut trial = Trial {
            scn,
            run,
            world: WorldState {
                sim,
                obstacles,
                footprints: scn.world.footprint_obstacles(),
                pallet0,
                pallet_nominal: case.pallet,
                collision: false,
                travelled_m: 0.0,
                travelled_loaded_m: 0.0,
                trail: Default::default(),
            },
            loc: localization(localizer, run, start),
            sense: perception(scn, run, detector, true_pallet),
            verdict: Verdict::new(out, scn.registry.step_criteria()),
            planner,
            tracker,
            path: forkbench_core::Path::default(),
            path_version: 0,
            insertion_m: scn.insertion_m(),
            link: None,
            stage: super::link::Stage::Leg,
            wall_start: std::time::Instant::now(),
            safety,
        };
        if scn.mission.is_none()
            && let Err(e) = trial.first_fix_and_estimate(&true_pallet, rec)
        {
            let why = e.to_string();
            rec.event(0.0, Level::Error, &why);
            trial.verdict.out.fail(Failure::Error, why);
            trial.judge_safety();
            return Err(Box::new(trial.verdict.out));
        }
        Ok(trial)
    }
}

/// The localisation at the start: the localiser, its stream, odometry from `start`.
fn localization(localizer: Box<dyn Localizer>, run: &Resolved, start: Pose2) -> Localization {
    Localization {
        localizer,
        nav_rng: stream(run.seed, streams::LOCALISATION),
        predictor: PosePredictor::new(),
        odometry: odometry_from(start),
        first_fix: start,
        odometry_error: odometry_error(run),
        stats: LocStats::new(0.0),
        leg_stats: LocStats::new(0.0),
        fix_lost: false,
        last_fix_measured_s: None,
    }
}

/// The perception at the start: the estimator, the scanners' streams, the detector, and
/// the estimate (the truth until a first look).
fn perception(
    scn: &Scenario,
    run: &Resolved,
    detector: Option<Box<dyn forkbench_sensors::detector::PalletDetector>>,
    pallet_est: Pose2,
) -> Perception {
    Perception {
        estimator: scn.registry.estimator(&run.pallet_estimate),
        est_rng: stream(run.seed, streams::ESTIMATE),
        scanners: scanner_streams(run),
        detector,
        pallet_est,
        on_prior: false,
        in_flight: None,
    }
}
