//! The pick's drive as a `Steering` of the one drive loop: the re-estimates due on the way (maybe a replan), the tracker's command, the entry checks and the criteria observed each step, until docked or timed out.

use forkbench_core::Pose2;
use forkbench_core::profile::{self, Stage};
use forkbench_core::units::wrap_angle;
use forkbench_track::{Command, TrackerInput};

use super::SIGNAL_EVERY_STEPS;
use super::engine::Steering;
use super::judge::in_pallet_frame;
use super::link::Control;
use super::state::Trial;
use crate::recorder::{Level, Recorder};
use crate::stage_error::StageError;
use forkbench_core::{Signal, Style};

/// The pick's approach and insertion as a drive: the re-estimates due on the way (a
/// replan when the estimate moved), the scenario's tracker, the entry checks; it ends
/// docked, or for a caller's own commands once settled.
#[derive(Default)]
pub(super) struct PickDrive {
    /// Re-estimate ranges still ahead, nearest last: read from the trial when the drive
    /// begins (its first tick).
    reestimates: Option<Vec<f64>>,
}

impl<'a> Steering<'a, StageError> for PickDrive {
    fn sensed<R: Recorder + ?Sized>(
        &mut self,
        t: &mut Trial<'a>,
        pose: Pose2,
        rec: &mut R,
    ) -> Result<(), StageError> {
        let reestimates = self
            .reestimates
            .get_or_insert_with(|| reestimate_schedule(t));
        if let Some(est) = t.estimate_arrived() {
            t.take_estimate(&pose, est, rec);
        }
        if t.sense.on_prior {
            if t.frame_due() {
                let missed = t.verdict.out.estimates_missed;
                t.reestimate(&pose, rec)?;
                if t.verdict.out.estimates_missed == missed {
                    t.leave_prior();
                }
            }
            return Ok(());
        }
        if t.run.replan
            && reestimates
                .first()
                .is_some_and(|r| pose.distance_to(&t.sense.pallet_est) <= *r)
        {
            reestimates.remove(0);
            t.reestimate(&pose, rec)?;
        }
        Ok(())
    }

    fn command(
        &mut self,
        t: &mut Trial<'a>,
        control: Control,
        pose: Pose2,
    ) -> Result<Option<Command>, StageError> {
        if let Control::Command { .. } = control {
            // The caller steers; the scenario's tracker is not asked.
            return Ok(Some(crate::phase::open_loop(0.0, 0.0, &pose)));
        }
        let cmd = t.tracker_command(pose)?;
        if t.docked(&cmd) {
            t.verdict.timed_out = false;
            return Ok(None);
        }
        Ok(Some(cmd))
    }

    fn stepped<R: Recorder + ?Sized>(
        &mut self,
        t: &mut Trial<'a>,
        control: Control,
        _cmd: &Command,
        rec: &mut R,
    ) -> Result<bool, StageError> {
        t.check_entry(rec);
        let settled = matches!(control, Control::Command { .. }) && t.settled();
        if settled {
            t.verdict.timed_out = false;
        }
        Ok(settled)
    }
}

/// The re-estimate ranges still ahead of the truck when its pick begins (nearest last).
fn reestimate_schedule(t: &Trial<'_>) -> Vec<f64> {
    let start_range = t.loc.first_fix.distance_to(&t.sense.pallet_est);
    let schedule = t.scn.replan.reestimate_at_m.clone();
    let mut reestimates: Vec<f64> = schedule
        .unwrap_or_else(|| t.sense.estimator.reestimate_at_m())
        .into_iter()
        .filter(|r| *r < start_range)
        .collect();
    reestimates.sort_by(|a, b| b.total_cmp(a));
    reestimates
}

impl<'a> Trial<'a> {
    /// The scenario's tracker's command at the measured `pose`. Err: it failed.
    pub(super) fn tracker_command(&mut self, pose: Pose2) -> Result<Command, StageError> {
        let input = self.tracker_input(pose);
        let cmd = profile::timed(Stage::Track, || self.tracker.command(&input));
        match self.tracker.fault() {
            Some(reason) => Err(StageError::Tracker {
                tracker: self.tracker.name().to_owned(),
                reason,
            }),
            None => Ok(cmd),
        }
    }

    /// The pick's end: the tracker reports the goal reached and the truck moves slower
    /// than `[pick] docked_speed_mps`.
    pub(super) fn docked(&self, cmd: &Command) -> bool {
        cmd.done && self.world.sim.speed_mps().abs() < self.scn.pick.docked_speed_mps
    }

    /// The truck stands (under 0.01 m/s: how a drive ends).
    pub fn stands(&self) -> bool {
        self.world.sim.speed_mps().abs() < 0.01
    }

    /// What a tracker sees now, at the measured `pose`.
    pub(super) fn tracker_input(&self, pose: Pose2) -> TrackerInput<'a> {
        TrackerInput {
            t_s: self.world.sim.time_s(),
            pose,
            speed_mps: self.world.sim.speed_mps(),
            steer_rad: self.world.sim.steer_rad(),
            fix_measured_s: self.loc.last_fix_measured_s,
            truck: &self.run.truck,
        }
    }

    /// Contact force before full depth, and the entry errors once the tips cross the face
    /// plane within the face (not beside the pallet).
    pub(super) fn check_entry<R: Recorder + ?Sized>(&mut self, rec: &mut R) {
        let root = self.world.sim.fork_root_pose();
        let pallet_now = self.world.sim.pallet_pose();
        let depth = self
            .scn
            .truck
            .insertion_depth_m(&pallet_now, self.scn.pallet.depth_m, &root);
        let out = &mut self.verdict.out;
        out.mast_contact_force_n = out
            .mast_contact_force_n
            .max(self.world.sim.mast_contact_force_n());
        if depth < self.insertion_m - 0.01 {
            self.verdict.out.max_contact_force_n = self
                .verdict
                .out
                .max_contact_force_n
                .max(self.world.sim.pallet_contact_force_n());
        }
        self.observe_step_criteria(root, pallet_now, rec);
        let local = in_pallet_frame(&pallet_now, &root);
        if self.verdict.out.lateral_error_m.is_none()
            && depth >= 0.0
            && local.y_m.abs() < self.scn.pallet.width_m / 2.0
        {
            self.verdict.out.lateral_error_m = Some(local.y_m);
            self.verdict.out.heading_error_rad = Some(local.heading_rad);
            rec.event(
                self.world.sim.time_s(),
                Level::Info,
                &format!(
                    "fork entry: {:.4} m lateral, {:.4} rad heading",
                    local.y_m, local.heading_rad
                ),
            );
        }
    }

    /// Each step criterion's view of this step, and its measurement recorded at the
    /// signal rate under `criteria/<measure>`.
    fn observe_step_criteria<R: Recorder + ?Sized>(
        &mut self,
        fork_root: Pose2,
        pallet_pose: Pose2,
        rec: &mut R,
    ) {
        let t_s = self.world.sim.time_s();
        let view = crate::step_criteria::StepView {
            t_s,
            truck: &self.scn.truck,
            pallet: &self.scn.pallet,
            fork_root,
            pallet_pose,
            collision: self.world.collision,
            load: crate::step_criteria::LoadView::of(&self.world.sim),
        };
        let record =
            ((t_s / self.world.sim.dt_s()).round() as u64).is_multiple_of(SIGNAL_EVERY_STEPS);
        for c in &mut self.verdict.criteria {
            c.observe(&view);
            if let (true, Some(v), Some(key)) = (record, c.value(), c.measure()) {
                let path = format!("criteria/{key}");
                rec.signal(t_s, &path, &Signal::Scalar(v), Style::default());
            }
        }
    }

    /// A new pallet estimate at a re-estimate range; replans when it moved past the
    /// thresholds. A refused replan keeps the old plan: the truck cannot turn onto the new goal.
    fn reestimate<R: Recorder + ?Sized>(
        &mut self,
        pose: &Pose2,
        rec: &mut R,
    ) -> Result<(), StageError> {
        let range = pose.distance_to(&self.sense.pallet_est);
        let truth = self.world.sim.pallet_pose();
        let Some(new_est) = self.estimate(&truth, range, pose, rec)? else {
            rec.event(
                self.world.sim.time_s(),
                Level::Warn,
                &format!("no pallet found at {range:.2} m; keeping the last estimate"),
            );
            return Ok(());
        };
        let latency_s = self.run.pallet_sensing.latency_s();
        if latency_s > 0.0 {
            self.send_estimate(latency_s, new_est);
        } else {
            self.take_estimate(pose, new_est, rec);
        }
        Ok(())
    }

    /// A new pallet estimate reaching the controller with the truck at `pose`: a replan
    /// when it moved past the thresholds.
    fn take_estimate<R: Recorder + ?Sized>(&mut self, pose: &Pose2, new_est: Pose2, rec: &mut R) {
        let range = pose.distance_to(&self.sense.pallet_est);
        let truth = self.world.sim.pallet_pose();
        let moved = new_est.distance_to(&self.sense.pallet_est);
        let turned = wrap_angle(new_est.heading_rad - self.sense.pallet_est.heading_rad).abs();
        let limits = &self.scn.replan;
        if moved <= limits.position_threshold_m && turned <= limits.heading_threshold_rad {
            return;
        }
        let t = self.world.sim.time_s();
        let replan = self.replanned(pose, &new_est);
        match replan {
            Ok((path, polygon)) => {
                rec.plan(t, self.verdict.out.replans + 1, &path, polygon.as_deref());
                rec.event(
                    t,
                    Level::Info,
                    &format!(
                        "replan at {range:.2} m: estimate moved {moved:.3} m, {:.2}°",
                        turned.to_degrees()
                    ),
                );
                self.tracker.reset(&path, &self.scn.truck);
                self.set_path(path);
                self.adopt_estimate(new_est, &truth);
                self.verdict.out.replans += 1;
            }
            Err(e) => {
                rec.event(
                    t,
                    Level::Warn,
                    &format!("replan refused, keeping the old plan: {e}"),
                );
                self.verdict.out.replans_failed += 1;
            }
        }
    }
}

impl Trial<'_> {
    /// A caller-driven pick is over: a criterion whose breach is final is broken (the
    /// pick's own or a step criterion), or the truck stands with the forks at the
    /// required depth.
    fn settled(&self) -> bool {
        let now = self.standing();
        let judged = self.judged(self.pick_measures(&now, false));
        let for_good = self
            .verdict
            .criteria
            .iter()
            .any(|c| c.irreversible() && c.judge(&judged).is_some());
        for_good
            || (self.stands() && now.insertion_depth_m >= self.scn.tolerances.insertion_depth_m)
    }
}
