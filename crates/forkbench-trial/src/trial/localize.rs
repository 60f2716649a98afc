//! Localisation in a trial: each reading into the controller's pose, dead reckoning on the truck's imperfect odometry between fixes, the fix statistics an outcome reports, and what a recording shows of each fix.

use forkbench_core::{Pose2, Signal, Style};
use forkbench_sensors::{LocalizerInput, Reading};

use super::error::StageError;
use super::state::Trial;
use crate::outcome::{LegOutcome, TrialOutcome};
use crate::recorder::{Level, Recorder};

const REFLECTOR: Style = Style::rgb(250, 250, 250).width(0.3);
const MISSING: Style = Style::rgba([255, 60, 60, 220]).width(0.3);
const RAY: Style = Style::rgba([120, 255, 140, 150]).width(0.02);

/// How localisation went over a stretch of a trial (the whole of it, or one leg).
#[derive(Debug, Clone, Copy)]
pub(super) struct LocStats {
    start_s: f64,
    fixes: u32,
    missed: u32,
    last_fix_s: f64,
    largest_gap_s: f64,
    error_sum_m: f64,
    steps: u32,
    error_max_m: f64,
}

impl LocStats {
    pub(super) fn new(start_s: f64) -> Self {
        Self {
            start_s,
            fixes: 0,
            missed: 0,
            last_fix_s: start_s,
            largest_gap_s: 0.0,
            error_sum_m: 0.0,
            steps: 0,
            error_max_m: 0.0,
        }
    }

    fn reading(&mut self, t_s: f64, got_pose: bool) {
        if got_pose {
            self.fixes += 1;
            self.largest_gap_s = self.largest_gap_s.max(t_s - self.last_fix_s);
            self.last_fix_s = t_s;
        } else {
            self.missed += 1;
        }
    }

    fn error(&mut self, error_m: f64) {
        self.error_sum_m += error_m;
        self.steps += 1;
        self.error_max_m = self.error_max_m.max(error_m);
    }

    /// The longest gap between fixes up to `t_s`, the open one included.
    fn largest_gap_until(&self, t_s: f64) -> f64 {
        self.largest_gap_s.max(t_s - self.last_fix_s)
    }

    fn mean_error_m(&self) -> f64 {
        if self.steps == 0 {
            f64::NAN
        } else {
            self.error_sum_m / f64::from(self.steps)
        }
    }

    /// Writes the stretch's figures into a trial outcome, ending at `t_s`.
    pub(super) fn finish_trial(&self, t_s: f64, period_s: f64, out: &mut TrialOutcome) {
        out.fixes = self.fixes;
        out.fixes_missed = self.missed;
        out.time_without_fix_s = f64::from(self.missed) * period_s;
        out.largest_fix_gap_s = self.largest_gap_until(t_s);
        out.localization_error_mean_m = self.mean_error_m();
        out.localization_error_max_m = self.error_max_m;
    }

    /// Writes the stretch's figures into a leg's outcome, ending at `t_s`.
    pub(super) fn finish_leg(&self, t_s: f64, leg: &mut LegOutcome) {
        leg.fixes_missed = self.missed;
        leg.largest_fix_gap_s = self.largest_gap_until(t_s.max(self.start_s));
        leg.localization_error_max_m = self.error_max_m;
    }
}

impl Trial<'_> {
    /// The localiser's reading at this instant (if one is due) into the controller's
    /// pose, recorded; Err when the state went non-finite. Returns the fix delivered
    /// (if any) and the pose the controller uses.
    pub(super) fn sense<R: Recorder + ?Sized>(
        &mut self,
        rec: &mut R,
    ) -> Result<(Option<Pose2>, Pose2), StageError> {
        let budget_s = self.run.wall_budget_s;
        if self.wall_start.elapsed().as_secs_f64() > budget_s {
            return Err(StageError::WallBudget { budget_s });
        }
        let truth = self.world.sim.fork_root_pose();
        let t_s = self.world.sim.time_s();
        let input = LocalizerInput {
            t_s,
            truth,
            predicted: self.loc.predictor.pose(),
            odometry: self.loc.odometry.pose(),
            occluders: self.movers_in_sight(),
        };
        let reading = self.loc.localizer.update(&input, &mut self.loc.nav_rng);
        let fix = reading.as_ref().and_then(|r| r.pose);
        if let Some(r) = &reading {
            self.take_reading(t_s, r, rec);
        }
        if let Some(fix) = fix {
            self.loc.predictor.fix(fix);
        }
        let pose = self.loc.predictor.pose().unwrap_or(self.loc.first_fix);
        if !(pose.is_finite() && truth.is_finite()) {
            return Err(StageError::NonFinite { t_s });
        }
        let error_m = pose.distance_to(&truth);
        self.loc.stats.error(error_m);
        self.loc.leg_stats.error(error_m);
        Ok((fix, pose))
    }

    /// Counts a reading, logs a fix lost or regained, and records the reflectors used.
    fn take_reading<R: Recorder + ?Sized>(&mut self, t_s: f64, r: &Reading, rec: &mut R) {
        let got = r.pose.is_some();
        match (got, self.loc.fix_lost) {
            (false, false) => {
                self.loc.fix_lost = true;
                let text = format!(
                    "{}: no fix ({} reflectors detected); dead reckoning on odometry",
                    self.loc.localizer.name(),
                    r.detected
                );
                rec.event(t_s, Level::Warn, &text);
            }
            (true, true) => {
                self.loc.fix_lost = false;
                let text = format!(
                    "{}: fix regained after {:.2} s",
                    self.loc.localizer.name(),
                    t_s - self.loc.stats.last_fix_s
                );
                rec.event(t_s, Level::Info, &text);
            }
            _ => {}
        }
        self.loc.stats.reading(t_s, got);
        self.loc.leg_stats.reading(t_s, got);
        let name = self.loc.localizer.name().to_owned();
        let none = Style::default();
        let at = |key: &str| format!("{name}/{key}");
        let Some(fix) = &r.fix else {
            if r.pose.is_none() {
                rec.signal(t_s, &at("reflectors_used"), &Signal::Scalar(0.0), none);
                rec.signal(t_s, &at("rays"), &Signal::Segments(&[]), RAY);
            }
            return;
        };
        let s = [fix.pose.x_m, fix.pose.y_m];
        let rays: Vec<[[f64; 2]; 2]> = fix
            .used
            .iter()
            .filter_map(|n| self.scn.world.reflector.iter().find(|r| &r.name == n))
            .map(|r| [s, [r.x_m, r.y_m]])
            .collect();
        rec.signal(t_s, &at("rays"), &Signal::Segments(&rays), RAY);
        let n = fix.used.len() as f64;
        rec.signal(t_s, &at("reflectors_used"), &Signal::Scalar(n), none);
        let dev = Signal::Scalar(fix.mean_deviation_m);
        rec.signal(t_s, "localisation/fix_mean_deviation_m", &dev, none);
        let sigma = Signal::Scalar(fix.sigma_m);
        rec.signal(t_s, "localisation/fix_sigma_m", &sigma, none);
    }
}

/// Draws the world's reflectors once: present ones white, the missing ones red.
pub(super) fn record_reflectors<R: Recorder + ?Sized>(
    rec: &mut R,
    world: &crate::scenario::World,
    missing: &[String],
) {
    if world.reflector.is_empty() {
        return;
    }
    let (gone, here): (Vec<_>, Vec<_>) = world
        .reflector
        .iter()
        .partition(|r| missing.contains(&r.name));
    let pts = |v: &[&forkbench_sensors::reflectors::Reflector]| -> Vec<[f64; 2]> {
        v.iter().map(|r| [r.x_m, r.y_m]).collect()
    };
    rec.signal(
        0.0,
        "nav350/reflectors",
        &Signal::Points(&pts(&here)),
        REFLECTOR,
    );
    if !gone.is_empty() {
        let p = pts(&gone);
        rec.signal(
            0.0,
            "nav350/reflectors_missing",
            &Signal::Points(&p),
            MISSING,
        );
    }
}
