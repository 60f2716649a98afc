//! Localisation in a trial: each reading into the controller's pose, dead reckoning on the truck's imperfect odometry between fixes, the fix statistics an outcome reports, and what a recording shows of each fix.

use forkbench_core::{Pose2, Signal, Style};
use forkbench_sensors::{LocalizerInput, Reading};

use forkbench_sensors::reflectors::Reflector;

use super::state::{Localization, Trial, WorldState};
use crate::recorder::{Level, Recorder};
use crate::stage_error::StageError;

const REFLECTOR: Style = Style::rgb(250, 250, 250).width(0.3);
const MISSING: Style = Style::rgba([255, 60, 60, 220]).width(0.3);
const RAY: Style = Style::rgba([120, 255, 140, 150]).width(0.02);

impl Localization {
    /// The localisation's record of a new mission leg, from `t0_s`.
    pub(super) fn begin_leg(&mut self, t0_s: f64) {
        self.leg_stats = super::loc_stats::LocStats::new(t0_s);
    }
}

impl Trial<'_> {
    /// The tick's sensing: within the wall-time budget, the localiser's reading at this
    /// instant (if one is due) into the controller's pose, recorded; Err when the budget
    /// is spent or the state went non-finite. Returns the fix delivered (if any) and the
    /// pose the controller uses.
    pub(super) fn sense<R: Recorder + ?Sized>(
        &mut self,
        rec: &mut R,
    ) -> Result<(Option<Pose2>, Pose2), StageError> {
        let budget_s = self.run.wall_budget_s;
        if self.wall_start.elapsed().as_secs_f64() > budget_s {
            return Err(StageError::WallBudget { budget_s });
        }
        let _timed = forkbench_core::profile::enter(forkbench_core::profile::Stage::Localise);
        let occluders = self.movers_in_sight();
        let reflectors = &self.scn.world.reflector;
        localize(&mut self.loc, &self.world, occluders, reflectors, rec)
    }
}

/// The localiser's reading (`loc`, measuring the `world` past the people and vehicles
/// `occluders` hide) into the controller's pose, carried from when it was measured; the
/// localisation error kept.
fn localize<R: Recorder + ?Sized>(
    loc: &mut Localization,
    world: &WorldState,
    occluders: Vec<[[f64; 2]; 2]>,
    reflectors: &[Reflector],
    rec: &mut R,
) -> Result<(Option<Pose2>, Pose2), StageError> {
    let truth = world.sim.fork_root_pose();
    let t_s = world.sim.time_s();
    let input = LocalizerInput {
        t_s,
        truth,
        predicted: loc.predictor.pose(),
        odometry: loc.odometry.pose(),
        occluders,
    };
    let reading = loc.localizer.update(&input, &mut loc.nav_rng);
    let fix = reading.as_ref().and_then(|r| r.pose);
    if let Some(r) = &reading {
        take_reading(loc, reflectors, (t_s, r), rec);
        if let Some(fix) = r.pose {
            // Carried from when it was measured: a late fix is not the pose now.
            loc.predictor.fix_measured_ago(fix, t_s - r.measured_s);
            loc.last_fix_measured_s = Some(r.measured_s);
        }
    }
    let pose = loc.predictor.pose().unwrap_or(loc.first_fix);
    if !(pose.is_finite() && truth.is_finite()) {
        return Err(StageError::NonFinite { t_s });
    }
    let error_m = pose.distance_to(&truth);
    loc.stats.error(error_m);
    loc.leg_stats.error(error_m);
    Ok((fix, pose))
}

/// Counts a reading, logs a fix lost or regained, and records the reflectors used.
fn take_reading<R: Recorder + ?Sized>(
    loc: &mut Localization,
    reflectors: &[Reflector],
    (t_s, r): (f64, &Reading),
    rec: &mut R,
) {
    let got = r.pose.is_some();
    match (got, loc.fix_lost) {
        (false, false) => {
            loc.fix_lost = true;
            let text = format!(
                "{}: no fix ({} reflectors detected); dead reckoning on odometry",
                loc.localizer.name(),
                r.detected
            );
            rec.event(t_s, Level::Warn, &text);
        }
        (true, true) => {
            loc.fix_lost = false;
            let text = format!(
                "{}: fix regained after {:.2} s",
                loc.localizer.name(),
                t_s - loc.stats.last_fix_s
            );
            rec.event(t_s, Level::Info, &text);
        }
        _ => {}
    }
    loc.stats.reading(t_s, got);
    loc.leg_stats.reading(t_s, got);
    let name = loc.localizer.name().to_owned();
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
        .filter_map(|n| reflectors.iter().find(|r| &r.name == n))
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
