//! The pallet detector's accuracy study (Lü et al. 2019's estimate figure): bias, σ and miss rate of the fused scanners and the scenario's detector over range, pallet angle and lateral offset, in the simulated world.

use forkbench_core::Pose2;
use forkbench_core::units::wrap_angle;
use forkbench_sensors::detector::detect_in;
use forkbench_sensors::scan::{Errors, scan};
use serde::Serialize;

use forkbench_trial::ScenarioError;
use forkbench_trial::scenario::sensors::{NamedScanner, PalletSensing};
use forkbench_trial::scenario::{Case, Scenario};
use forkbench_trial::trial::{StageError, accuracy_stream, look_world, scenario_detector};

/// Ranges (fork root to face, m), pallet angles (rad) and lateral offsets (m) studied.
pub const RANGES_M: [f64; 9] = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 6.5, 7.0, 8.0];
pub const ANGLES_DEG: [f64; 3] = [0.0, 15.0, 30.0];
pub const LATERALS_M: [f64; 3] = [0.0, 0.75, 1.5];

/// Bias (mean) and σ of one error component over the draws that found the pallet.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Spread {
    pub bias: f64,
    pub sigma: f64,
}

impl Spread {
    fn of(v: &[f64]) -> Self {
        let n = v.len() as f64;
        let bias = v.iter().sum::<f64>() / n;
        let var = v.iter().map(|x| (x - bias).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
        Self {
            bias,
            sigma: var.sqrt(),
        }
    }

    /// The error bound most draws stay within: |bias| + 2σ.
    pub fn bound(&self) -> f64 {
        self.bias.abs() + 2.0 * self.sigma
    }
}

/// One cell of the study: a pallet placement and what the detector made of it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AccuracyRow {
    pub range_m: f64,
    pub angle_rad: f64,
    pub lateral_m: f64,
    pub draws: u32,
    pub missed: u32,
    /// Errors of the estimate in the true pallet's frame (NaN when every draw missed).
    pub lateral: Spread,
    pub along: Spread,
    pub heading: Spread,
    /// Draws decided by each sensor, in the sensing's order.
    pub by_sensor: Vec<u32>,
}

/// The study's pallet: a truck at the origin facing +x, the face centre `range_m` ahead
/// and `lateral_m` to the left, turned by `angle_rad`.
fn placement(range_m: f64, angle_rad: f64, lateral_m: f64) -> Case {
    Case {
        name: format!("{range_m} m, {:.0}°, {lateral_m} m", angle_rad.to_degrees()),
        start: Pose2::new(0.0, 0.0, 0.0),
        pallet: Pose2::new(range_m, lateral_m, angle_rad),
    }
}

/// Runs the study with `scn`'s pallet, world and scanner sensing: `draws` scans per cell
/// (each its own noise and bias), seeded by `seed`. The detector looks where the pallet
/// stands, as a trial's first estimate looks at the slot.
pub fn accuracy_study(
    scn: &Scenario,
    draws: u32,
    seed: u64,
) -> Result<Vec<AccuracyRow>, ScenarioError> {
    let PalletSensing::Scanner { sensors, .. } = &scn.pallet_sensing else {
        return Err(forkbench_trial::scenario::invalid(
            &scn.file,
            "sensors.pallet.kind",
            "the accuracy study needs scanners (tim561, kinect2, tim561+kinect2), not gaussian",
        ));
    };
    let mut rows = Vec::new();
    for &range_m in &RANGES_M {
        for &angle_deg in &ANGLES_DEG {
            for &lateral_m in &LATERALS_M {
                let case = placement(range_m, angle_deg.to_radians(), lateral_m);
                let row = study_cell(scn, sensors, &case, (draws, seed)).map_err(|e| {
                    ScenarioError::Invalid {
                        file: scn.file.clone(),
                        field: "world".into(),
                        reason: e.to_string(),
                    }
                })?;
                rows.push(row);
            }
        }
    }
    Ok(rows)
}

/// One placement, `draws` scans from the truck's start.
fn study_cell(
    scn: &Scenario,
    sensors: &[NamedScanner],
    case: &Case,
    (draws, seed): (u32, u64),
) -> Result<AccuracyRow, StageError> {
    let (sim, root, truth) = look_world(scn, case, seed)?;
    // The scenario's own detector (the pocket detector where it senses without scans).
    let (_, mut detector) = scenario_detector(scn)?;
    let (mut lat, mut along, mut head) = (Vec::new(), Vec::new(), Vec::new());
    let mut by_sensor = vec![0u32; sensors.len()];
    for k in 0..u64::from(draws) {
        let mut rng = accuracy_stream(seed, k);
        let scans: Vec<(&str, forkbench_core::signal::Scan)> = sensors
            .iter()
            .filter(|s| s.scanner.reaches(&s.scanner.sensor_pose(&root), &truth))
            .map(|s| {
                let bias_m = s.scanner.draw_bias(&mut rng);
                let errors = Errors::Modelled {
                    bias_m,
                    rng: &mut rng,
                };
                (
                    s.name.as_str(),
                    scan(&s.scanner, &sim, s.scanner.sensor_pose(&root), errors),
                )
            })
            .collect();
        if let Ok(Some(found)) =
            detect_in(detector.as_mut(), &scans, &scn.pallet, Some(case.pallet))
        {
            let e = truth.to_local(&found.detection.face);
            lat.push(e.y_m);
            along.push(e.x_m);
            head.push(wrap_angle(e.heading_rad));
            let name = scans[found.sensor].0;
            if let Some(i) = sensors.iter().position(|s| s.name == name) {
                by_sensor[i] += 1;
            }
        }
    }
    Ok(AccuracyRow {
        range_m: case.pallet.x_m,
        angle_rad: case.pallet.heading_rad,
        lateral_m: case.pallet.y_m,
        draws,
        missed: draws - lat.len() as u32,
        lateral: Spread::of(&lat),
        along: Spread::of(&along),
        heading: Spread::of(&head),
        by_sensor,
    })
}
