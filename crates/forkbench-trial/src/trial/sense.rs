//! Pallet estimates as the scenario's sensing makes them: the Gaussian model around the truth, or a scan of the world from the truck and the pocket detector on it, placed in the map with the truck's believed pose.

use forkbench_core::units::wrap_angle;
use forkbench_core::{Pose2, Signal, Style};
use forkbench_sensors::detect::detect;
use forkbench_sensors::scan::{Errors, scan};
use rand_chacha::ChaCha8Rng;

use super::setup::Trial;
use crate::recorder::Recorder;
use crate::scenario::sensors::PalletSensing;

/// How a scan and its detection are drawn in recordings.
const SCAN_STYLE: Style = Style::rgba([90, 200, 255, 255]).width(0.04);
const DETECTION_STYLE: Style = Style::rgb(255, 60, 60).width(0.03);

impl Trial<'_> {
    /// A pallet estimate when the fork root is `range_m` from the face: the scenario's
    /// fixed bias on top of the sensing's own error. `believed` is the fork-root pose
    /// the truck thinks it has: a scanner's detection, made in the sensor's frame, is
    /// placed in the map with it, and its scan and detection are recorded. `None`: the
    /// detector found no pallet.
    pub(super) fn estimate<R: Recorder + ?Sized>(
        &mut self,
        truth: &Pose2,
        range_m: f64,
        believed: &Pose2,
        rec: &mut R,
    ) -> Option<Pose2> {
        self.out.estimates += 1;
        let est = match &self.scn.pallet_sensing {
            PalletSensing::Gaussian => Some(self.gaussian_estimate(truth, range_m)),
            PalletSensing::Scanner { .. } => self.scanned_estimate(believed, rec),
        };
        if est.is_none() {
            self.out.estimates_missed += 1;
        }
        est
    }

    fn gaussian_estimate(&mut self, truth: &Pose2, range_m: f64) -> Pose2 {
        let biased = truth.to_world(&self.scn.estimate_bias);
        if self.run.noise {
            self.estimator.estimate(&biased, range_m, &mut self.est_rng)
        } else {
            biased
        }
    }

    fn scanned_estimate<R: Recorder + ?Sized>(
        &mut self,
        believed: &Pose2,
        rec: &mut R,
    ) -> Option<Pose2> {
        let PalletSensing::Scanner {
            name,
            scanner,
            detector,
        } = &self.scn.pallet_sensing
        else {
            return None;
        };
        let sensor = scanner.sensor_pose(&self.sim.fork_root_pose());
        let s = if self.run.noise {
            let bias_m = self.scan_bias_m;
            scan(
                scanner,
                &self.sim,
                sensor,
                Errors::Modelled {
                    bias_m,
                    rng: &mut self.est_rng,
                },
            )
        } else {
            scan::<ChaCha8Rng>(scanner, &self.sim, sensor, Errors::Ideal)
        };
        let t = self.sim.time_s();
        rec.signal(t, &format!("sensors/{name}"), &Signal::Scan(&s), SCAN_STYLE);
        // Where to look: the last estimate, or before the first, where the pallet should
        // stand (a warehouse system knows the slot, not the placement error).
        let prior = if self.out.estimates > 1 {
            self.pallet_est
        } else {
            self.pallet_nominal
        };
        let found = detect(detector, &s, &self.scn.pallet, Some(&prior))?;
        rec.signal(
            t,
            "sensors/pallet_detection",
            &Signal::Pose(found.face),
            DETECTION_STYLE,
        );
        // Seen from the sensor, placed from where the truck believes the sensor is.
        let local = sensor.to_local(&found.face);
        let est = scanner.sensor_pose(believed).to_world(&local);
        Some(est.to_world(&self.scn.estimate_bias))
    }

    /// Makes `est` the estimate the truck aims at, and records its error against the
    /// true face `truth`.
    pub(super) fn adopt_estimate(&mut self, est: Pose2, truth: &Pose2) {
        self.pallet_est = est;
        let e = truth.to_local(&est);
        self.out.estimate_lateral_error_m = Some(e.y_m);
        self.out.estimate_heading_error_rad = Some(wrap_angle(e.heading_rad));
    }
}
