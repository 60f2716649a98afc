//! One scan of a scenario's world from the truck (its start or a given fork-root pose), with the detector's estimate beside the truth: what `forkbench scan` shows.

use forkbench_core::Pose2;
use forkbench_core::signal::Scan;
use forkbench_sensors::detect::Detection;
use forkbench_sensors::detector::{DetectorError, PalletDetector, Pockets, detect_in};
use forkbench_sensors::scan::{Errors, ScannerConfig, scan};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

use super::world::build_world;
use crate::scenario::sensors::PalletSensing;
use crate::scenario::{Case, Scenario};
use crate::stage_error::StageError;

/// The physics world a trial seeded `seed` starts in for `case`, as a one-off look or a
/// study sees it: the simulation, the truck's fork-root start and the pallet's true pose.
pub fn look_world(
    scn: &Scenario,
    case: &Case,
    seed: u64,
) -> Result<(forkbench_sim::Sim, Pose2, Pose2), StageError> {
    let (sim, root, truth, _) =
        build_world(scn, &scn.truck, case, (seed, &Default::default()), None)?;
    Ok((sim, root, truth))
}

/// One scan and what the detector made of it.
#[derive(Debug, Clone, Serialize)]
pub struct ScanReport {
    /// The detector that looked: the scenario's.
    pub detector: String,
    pub sensor: String,
    /// The fork-root pose the truck scanned from.
    pub fork_root: Pose2,
    pub scan: Scan,
    /// The pallet's true face pose (jittered as the trial with this seed places it).
    pub truth: Pose2,
    pub estimate: Option<Detection>,
}

/// Scans from `at` (a fork-root pose; the case's start when `None`) with the named
/// scanner, seeded by `seed`; `ideal` takes exact rays (no noise, bias or spot).
pub fn scan_once(
    scn: &Scenario,
    case: &Case,
    (sensor, cfg): (&str, &ScannerConfig),
    at: Option<Pose2>,
    seed: u64,
    ideal: bool,
) -> Result<ScanReport, StageError> {
    let (sim, root, truth, _) =
        build_world(scn, &scn.truck, case, (seed, &Default::default()), at)?;
    let pose = cfg.sensor_pose(&root);
    // Its own stream, so a scan does not shift the trial's other draws.
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ super::streams::SCAN_ONCE);
    let s = if ideal {
        scan::<ChaCha8Rng>(cfg, &sim, pose, Errors::Ideal)
    } else {
        let bias_m = cfg.draw_bias(&mut rng);
        scan(
            cfg,
            &sim,
            pose,
            Errors::Modelled {
                bias_m,
                rng: &mut rng,
            },
        )
    };
    // Where the pallet should stand is where the detector looks (as in a trial).
    let (detector, mut d) = scenario_detector(scn)?;
    let scans = [(sensor, s.clone())];
    let estimate = detect_in(&mut *d, &scans, &scn.pallet, Some(case.pallet))?.map(|f| f.detection);
    Ok(ScanReport {
        detector,
        sensor: sensor.to_owned(),
        fork_root: root,
        scan: s,
        truth,
        estimate,
    })
}

/// The scenario's own pallet detector (an external one too) and its name, or the built-in
/// pocket detector with the scenario's settings where it senses without scans.
pub fn scenario_detector(
    scn: &Scenario,
) -> Result<(String, Box<dyn PalletDetector>), DetectorError> {
    match &scn.pallet_sensing {
        PalletSensing::Scanner { detector, .. } => {
            let d = scn.registry.detector(detector).map_err(|e| DetectorError {
                detector: detector.name.clone(),
                reason: e.to_string(),
            })?;
            Ok((detector.name.clone(), d))
        }
        PalletSensing::Gaussian => {
            let cfg = scn.pallet_sensing.pocket_settings(scn.registry.as_ref());
            let name = crate::components::POCKET_DETECTOR.to_owned();
            Ok((name, Box::new(Pockets { cfg })))
        }
    }
}
