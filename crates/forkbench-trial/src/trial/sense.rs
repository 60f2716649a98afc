//! Pallet estimates as the scenario's sensing makes them: the Gaussian model around the truth, or scans of the world from the truck and a detector on them, placed in the map with the truck's believed pose.

use forkbench_core::profile::{self, Stage};
use forkbench_core::signal::Scan;
use forkbench_core::units::wrap_angle;
use forkbench_core::{Pose2, Signal, Style};
use forkbench_sensors::detector::{DetectRequest, SensorScan};
use forkbench_sensors::evidence::verified;
use forkbench_sensors::scan::{Errors, WorldView, scan_swept};
use rand_chacha::ChaCha8Rng;

use super::movers_view::WithMovers;
use super::state::Trial;
use crate::recorder::Recorder;
use crate::scenario::sensors::{NamedScanner, PalletSensing};
use crate::stage_error::StageError;

/// How scans (a colour per sensor, in the order sensors are listed) and a detection are
/// drawn in recordings.
const SCAN_STYLES: [Style; 3] = [
    Style::rgba([90, 200, 255, 255]).width(0.04),
    Style::rgba([255, 170, 40, 255]).width(0.04),
    Style::rgba([170, 110, 255, 255]).width(0.04),
];
const DETECTION_STYLE: Style = Style::rgb(255, 60, 60).width(0.03);

impl Trial<'_> {
    /// The fix the pick plans from (the odometry-predicted pose when no fix is due) and
    /// the first pallet estimate.
    pub(super) fn first_fix_and_estimate<R: Recorder + ?Sized>(
        &mut self,
        true_pallet: &Pose2,
        rec: &mut R,
    ) -> Result<(), StageError> {
        let from = self.world.sim.time_s();
        let fix = self.wait_for_fix(rec)?;
        self.loc.first_fix = fix
            .or(self.loc.predictor.pose())
            .unwrap_or(self.loc.first_fix);
        self.loc.predictor.fix(self.loc.first_fix);
        let range = self.loc.first_fix.distance_to(true_pallet);
        let believed = self.loc.first_fix;
        if let Some(est) = self.estimate(true_pallet, range, &believed, rec)? {
            self.await_detector(rec)?;
            self.adopt_estimate(est, true_pallet);
        }
        self.verdict.pick_waited_s = self.world.sim.time_s() - from;
        Ok(())
    }

    /// The truck stands while the detector's first estimate is on its way.
    fn await_detector<R: Recorder + ?Sized>(&mut self, rec: &mut R) -> Result<(), StageError> {
        let due_s = self.world.sim.time_s() + self.run.pallet_sensing.latency_s();
        while self.world.sim.time_s() + 1e-9 < due_s {
            let (_, pose) = self.sense(rec)?;
            self.stand_step(pose, rec);
        }
        Ok(())
    }

    /// One physics step standing, the wheel where it is, at the believed `pose`.
    fn stand_step<R: Recorder + ?Sized>(&mut self, pose: Pose2, rec: &mut R) {
        let steer = self.world.sim.steer_rad();
        self.physics_step(&crate::phase::open_loop(0.0, steer, &pose), None, pose, rec);
    }

    /// Before the localiser's first reading ever (a NAV350 delivers it a latency after its
    /// first sweep), the truck stands until it arrives, at most a period and a second;
    /// later, a look takes what is there. The fix, if the reading had one.
    fn wait_for_fix<R: Recorder + ?Sized>(
        &mut self,
        rec: &mut R,
    ) -> Result<Option<Pose2>, StageError> {
        let until = self.world.sim.time_s() + self.loc.localizer.period_s() + 1.0;
        let readings = |t: &Self| t.loc.stats.fixes + t.loc.stats.missed;
        let first = readings(self) == 0;
        loop {
            let (fix, pose) = self.sense(rec)?;
            if !first || readings(self) > 0 || self.world.sim.time_s() >= until {
                return Ok(fix);
            }
            self.stand_step(pose, rec);
        }
    }

    /// A pallet estimate when the fork root is `range_m` from the face: the scenario's
    /// fixed bias on top of the sensing's own error. `believed` is the fork-root pose
    /// the truck thinks it has: scans are placed in the map with it, so a detection is
    /// where the truck believes the pallet is; scans and detection are recorded.
    /// `Ok(None)`: no pallet found. Err: the detector could not answer.
    pub(super) fn estimate<R: Recorder + ?Sized>(
        &mut self,
        truth: &Pose2,
        range_m: f64,
        believed: &Pose2,
        rec: &mut R,
    ) -> Result<Option<Pose2>, StageError> {
        self.verdict.out.estimates += 1;
        let est = match &self.run.pallet_sensing {
            PalletSensing::Gaussian => Some(self.gaussian_estimate(truth, range_m)),
            PalletSensing::Scanner { .. } => self.scanned_estimate(believed, rec)?,
        };
        if est.is_none() {
            self.verdict.out.estimates_missed += 1;
        }
        Ok(est)
    }

    /// Whether some scanner has a new frame for a look now.
    pub(super) fn frame_due(&self) -> bool {
        let t = self.world.sim.time_s();
        self.sense.scanners.iter().any(|s| t >= s.next_frame_s)
    }

    fn gaussian_estimate(&mut self, truth: &Pose2, range_m: f64) -> Pose2 {
        let biased = truth.to_world(&self.scn.estimate_bias);
        if self.run.noise {
            self.sense
                .estimator
                .estimate(&biased, range_m, &mut self.sense.est_rng)
        } else {
            biased
        }
    }

    /// One scan from `sensor` as it truly moved over its sweep (ending now), placed at
    /// `placed` (its believed pose now).
    fn scan_from(&mut self, k: usize, s: &NamedScanner, placed: Pose2) -> Scan {
        let (t, sweep_s) = (self.world.sim.time_s(), s.scanner.sweep_s);
        let world = &self.world;
        let sensor_at = |f: f64| {
            let root = world.root_at(t - sweep_s * (1.0 - f));
            s.scanner.sensor_pose(&root)
        };
        // People and vehicles stand in the scanners' way (they occlude the pallet).
        let with_movers;
        let view: &dyn WorldView = match &self.safety {
            Some(safety) if !safety.movers.is_empty() => {
                with_movers = WithMovers {
                    sim: &self.world.sim,
                    movers: &safety.movers,
                };
                &with_movers
            }
            _ => &self.world.sim,
        };
        let mut out = if self.run.noise {
            let state = &mut self.sense.scanners[k];
            let errors = Errors::Modelled {
                bias_m: state.bias_m,
                rng: &mut state.rng,
            };
            scan_swept(&s.scanner, view, &sensor_at, errors)
        } else {
            scan_swept::<ChaCha8Rng>(&s.scanner, view, &sensor_at, Errors::Ideal)
        };
        out.sensor = placed;
        out
    }

    fn scanned_estimate<R: Recorder + ?Sized>(
        &mut self,
        believed: &Pose2,
        rec: &mut R,
    ) -> Result<Option<Pose2>, StageError> {
        let PalletSensing::Scanner { sensors, .. } = &self.run.pallet_sensing else {
            return Ok(None);
        };
        // Where to look: the last estimate, or before the first, where the pallet should
        // stand (a warehouse system knows the slot, not the placement error).
        let prior = if self.verdict.out.estimates > 1 {
            self.sense.pallet_est
        } else {
            self.world.pallet_nominal
        };
        let t = self.world.sim.time_s();
        let mut scans = Vec::with_capacity(sensors.len());
        for (k, s) in sensors.iter().enumerate() {
            let placed = s.scanner.sensor_pose(believed);
            // A scanner gives a look its latest frame only once: a look sooner than its
            // frame period after the last gets nothing new from it.
            if !s.scanner.reaches(&placed, &prior) || t < self.sense.scanners[k].next_frame_s {
                continue;
            }
            self.sense.scanners[k].next_frame_s = t + 1.0 / s.scanner.rate_hz;
            let timed = profile::enter_as(Stage::Scan, &s.name);
            let sc = self.scan_from(k, s, placed);
            drop(timed);
            let style = SCAN_STYLES[k % SCAN_STYLES.len()];
            rec.signal(t, &format!("sensors/{}", s.name), &Signal::Scan(&sc), style);
            scans.push((s.name.as_str(), sc));
        }
        let Some(detector) = self.sense.detector.as_mut() else {
            return Ok(None);
        };
        let views: Vec<SensorScan<'_>> = scans
            .iter()
            .map(|(sensor, scan)| SensorScan { sensor, scan })
            .collect();
        let req = DetectRequest {
            scans: &views,
            pallet: &self.scn.pallet,
            prior: Some(prior),
        };
        let min_score = self.run.pallet_sensing.min_score();
        let timed = profile::enter_as(Stage::Detect, detector.name());
        let verdict = verified(detector.as_mut(), &req, min_score);
        drop(timed);
        let Some((found, _)) = verdict?.chosen else {
            return Ok(None);
        };
        let face = found.detection.face;
        rec.signal(
            t,
            "sensors/pallet_detection",
            &Signal::Pose(face),
            DETECTION_STYLE,
        );
        Ok(Some(face.to_world(&self.scn.estimate_bias)))
    }

    /// The estimate on its way from the detector, once it has reached the controller.
    pub(super) fn estimate_arrived(&mut self) -> Option<Pose2> {
        let (due_s, est) = self.sense.in_flight?;
        (self.world.sim.time_s() + 1e-9 >= due_s).then(|| {
            self.sense.in_flight = None;
            est
        })
    }

    /// The detector's answer reaches the controller `latency_s` later: a newer one
    /// replaces it on its way.
    pub(super) fn send_estimate(&mut self, latency_s: f64, est: Pose2) {
        self.sense.in_flight = Some((self.world.sim.time_s() + latency_s, est));
    }

    /// Plans on the pallet's prior (`[pick] when_not_seen = "prior"`): every frame is
    /// looked at until the face is found.
    pub(super) fn aim_at_prior(&mut self) {
        self.sense.pallet_est = self.world.pallet_nominal;
        self.sense.on_prior = true;
    }

    /// The face was found while aiming at the prior: the re-estimates go by range again.
    pub(super) fn leave_prior(&mut self) {
        self.sense.on_prior = false;
    }

    /// Makes `est` the estimate the truck aims at, and records its error against the
    /// true face `truth`.
    pub(super) fn adopt_estimate(&mut self, est: Pose2, truth: &Pose2) {
        self.sense.pallet_est = est;
        let e = truth.to_local(&est);
        self.verdict.out.estimate_lateral_error_m = Some(e.y_m);
        self.verdict.out.estimate_heading_error_rad = Some(wrap_angle(e.heading_rad));
    }
}
