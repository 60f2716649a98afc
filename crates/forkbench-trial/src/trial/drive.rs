//! Drive stage: each control tick (fix, replan check, tracker command, physics step, record) until stopped or timed out.

use forkbench_core::Pose2;
use forkbench_core::units::wrap_angle;
use forkbench_track::{Command, TrackerInput};

use super::error::StageError;
use super::judge::in_pallet_frame;
use super::setup::Trial;
use crate::recorder::{Level, Recorder, StepRecord};
use forkbench_core::{Signal, Style};

/// Where a drive stands between control ticks.
#[derive(Debug, Clone)]
pub(crate) struct DriveState {
    /// Re-estimate ranges still ahead, nearest last.
    reestimates: Vec<f64>,
    pub(super) deadline_s: f64,
    /// This tick's localiser fix (none between sweeps) and the controller's pose.
    pub(super) fix: Option<Pose2>,
    pub(super) pose: Pose2,
}

/// The trial's own scalar signals go out every this many control steps.
pub(in crate::trial) const SIGNAL_EVERY_STEPS: u64 = 10;

impl<'a> Trial<'a> {
    /// Drives until the tracker reports the goal reached and the truck stands, or the
    /// scenario's time limit. Err: the state went non-finite, or the tracker failed.
    pub(super) fn drive<R: Recorder + ?Sized>(&mut self, rec: &mut R) -> Result<(), StageError> {
        let mut at = self.begin_drive();
        while self.sim.time_s() < at.deadline_s {
            self.sense_tick(&mut at, rec)?;
            let cmd = self.tracker_command(at.pose)?;
            if self.docked(&cmd) {
                self.timed_out = false;
                break;
            }
            self.step(&cmd, at.fix, at.pose, rec);
        }
        Ok(())
    }

    /// The drive's schedule: re-estimate ranges still ahead of the truck (nearest last)
    /// and the deadline.
    pub(super) fn begin_drive(&self) -> DriveState {
        let start_range = self.first_fix.distance_to(&self.pallet_est);
        let schedule = self.scn.replan.reestimate_at_m.clone();
        let mut reestimates: Vec<f64> = schedule
            .unwrap_or_else(|| self.estimator.reestimate_at_m())
            .into_iter()
            .filter(|r| *r < start_range)
            .collect();
        reestimates.sort_by(|a, b| b.total_cmp(a));
        DriveState {
            reestimates,
            deadline_s: self.sim.time_s() + self.scn.timeout_s,
            fix: None,
            pose: self.first_fix,
        }
    }

    /// The start of a control tick: the localiser's reading, and a re-estimate (maybe a
    /// replan) when the truck came within the next re-estimate range.
    pub(super) fn sense_tick<R: Recorder + ?Sized>(
        &mut self,
        at: &mut DriveState,
        rec: &mut R,
    ) -> Result<(), StageError> {
        let (fix, pose) = self.sense(rec)?;
        (at.fix, at.pose) = (fix, pose);
        if self.on_prior {
            if self.frame_due() {
                let missed = self.out.estimates_missed;
                self.reestimate(&pose, rec)?;
                self.on_prior = self.out.estimates_missed > missed;
            }
            return Ok(());
        }
        if self.run.replan
            && at
                .reestimates
                .first()
                .is_some_and(|r| pose.distance_to(&self.pallet_est) <= *r)
        {
            at.reestimates.remove(0);
            self.reestimate(&pose, rec)?;
        }
        Ok(())
    }

    /// The scenario's tracker's command at the measured `pose`. Err: it failed.
    pub(super) fn tracker_command(&mut self, pose: Pose2) -> Result<Command, StageError> {
        let cmd = self.tracker.command(&self.tracker_input(pose));
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
        cmd.done && self.sim.speed_mps().abs() < self.scn.pick.docked_speed_mps
    }

    /// The truck stands (for the end of a drive).
    pub(super) fn stands(&self) -> bool {
        self.sim.speed_mps().abs() < 0.01
    }

    /// One physics step under `cmd`, its record, and the entry check.
    pub(super) fn step<R: Recorder + ?Sized>(
        &mut self,
        cmd: &Command,
        fix: Option<Pose2>,
        pose: Pose2,
        rec: &mut R,
    ) {
        self.physics_step(cmd, fix, pose, rec);
        self.check_entry(rec);
    }

    /// What a tracker sees now, at the measured `pose`.
    pub(super) fn tracker_input(&self, pose: Pose2) -> TrackerInput<'a> {
        TrackerInput {
            t_s: self.sim.time_s(),
            pose,
            speed_mps: self.sim.speed_mps(),
            steer_rad: self.sim.steer_rad(),
            truck: &self.scn.truck,
        }
    }

    /// One physics step under `cmd`, the odometry update, collisions and the record.
    pub(super) fn physics_step<R: Recorder + ?Sized>(
        &mut self,
        cmd: &Command,
        fix: Option<Pose2>,
        pose: Pose2,
        rec: &mut R,
    ) {
        let truck = &self.scn.truck;
        let before = self.sim.fork_root_pose();
        self.sim.step(cmd.speed_mps, cmd.steer_rad);
        let moved_m = before.distance_to(&self.sim.fork_root_pose());
        self.travelled_m += moved_m;
        if self.sim.carrying() {
            self.travelled_loaded_m += moved_m;
        }
        let (scale, offset) = self.odometry_error;
        let (v, steer) = (
            self.sim.speed_mps() * (1.0 + scale),
            self.sim.steer_rad() + offset,
        );
        for p in [&mut self.predictor, &mut self.odometry] {
            p.propagate(
                v,
                steer,
                truck.wheelbase_m,
                truck.fork_root_ahead_of_front_axle_m,
                self.sim.dt_s(),
            );
        }
        self.out.max_steer_rad = self.out.max_steer_rad.max(self.sim.steer_rad().abs());
        if self.sim.obstacle_contact() && !self.collision {
            rec.event(
                self.sim.time_s(),
                Level::Error,
                "truck touched a rack or wall",
            );
        }
        self.collision |= self.sim.obstacle_contact();
        let t = self.sim.time_s();
        let truth = self.sim.fork_root_pose();
        // What a failed entry is most often traced to: how far off the localisation
        // was, and how far off the path the tracker let the truck run; at 10 Hz, which
        // shows both and costs a recording a tenth of the control rate.
        let step = (t / self.sim.dt_s()).round() as u64;
        if step.is_multiple_of(SIGNAL_EVERY_STEPS) {
            let loc_error = (pose.x_m - truth.x_m).hypot(pose.y_m - truth.y_m);
            let none = Style::default();
            rec.signal(
                t,
                "localisation/position_error_m",
                &Signal::Scalar(loc_error),
                none,
            );
            rec.signal(
                t,
                "track/cross_track_m",
                &Signal::Scalar(cmd.cross_track_m),
                none,
            );
        }
        rec.step(&StepRecord {
            t_s: self.sim.time_s(),
            truth: self.sim.fork_root_pose(),
            fix,
            estimate: pose,
            pallet: self.sim.pallet_pose(),
            pallet_estimate: self.pallet_est,
            steer_cmd_rad: cmd.steer_rad,
            steer_rad: self.sim.steer_rad(),
            speed_cmd_mps: cmd.speed_mps,
            speed_mps: self.sim.speed_mps(),
            lookahead: cmd.lookahead_point,
            cross_track_m: cmd.cross_track_m,
            path_curvature_per_m: cmd.path_curvature_per_m,
            contact_force_n: self.sim.fork_contact_force_n(),
        });
    }

    /// Contact force before full depth, and the entry errors once the tips cross the face
    /// plane within the face (not beside the pallet).
    fn check_entry<R: Recorder + ?Sized>(&mut self, rec: &mut R) {
        let root = self.sim.fork_root_pose();
        let pallet_now = self.sim.pallet_pose();
        let depth = self.scn.truck.insertion_depth_m(&pallet_now, &root);
        if depth < self.insertion_m - 0.01 {
            self.out.max_contact_force_n = self
                .out
                .max_contact_force_n
                .max(self.sim.fork_contact_force_n());
        }
        self.observe_step_criteria(root, pallet_now, rec);
        let local = in_pallet_frame(&pallet_now, &root);
        if self.out.lateral_error_m.is_none()
            && depth >= 0.0
            && local.y_m.abs() < self.scn.pallet.width_m / 2.0
        {
            self.out.lateral_error_m = Some(local.y_m);
            self.out.heading_error_rad = Some(local.heading_rad);
            rec.event(
                self.sim.time_s(),
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
        let t_s = self.sim.time_s();
        let view = super::step_criteria::StepView {
            t_s,
            truck: &self.scn.truck,
            pallet: &self.scn.pallet,
            fork_root,
            pallet_pose,
        };
        let record = ((t_s / self.sim.dt_s()).round() as u64).is_multiple_of(SIGNAL_EVERY_STEPS);
        for c in &mut self.step_criteria {
            c.observe(&view);
            if let (true, Some(v)) = (record, c.value()) {
                let path = format!("criteria/{}", c.measure());
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
        let range = pose.distance_to(&self.pallet_est);
        let truth = self.sim.pallet_pose();
        let Some(new_est) = self.estimate(&truth, range, pose, rec)? else {
            rec.event(
                self.sim.time_s(),
                Level::Warn,
                &format!("no pallet found at {range:.2} m; keeping the last estimate"),
            );
            return Ok(());
        };
        let moved = new_est.distance_to(&self.pallet_est);
        let turned = wrap_angle(new_est.heading_rad - self.pallet_est.heading_rad).abs();
        let limits = &self.scn.replan;
        if moved <= limits.position_threshold_m && turned <= limits.heading_threshold_rad {
            return Ok(());
        }
        let t = self.sim.time_s();
        let replan = self.replanned(pose, &new_est);
        match replan {
            Ok((path, polygon)) => {
                rec.plan(t, self.out.replans + 1, &path, polygon.as_deref());
                rec.event(
                    t,
                    Level::Info,
                    &format!(
                        "replan at {range:.2} m: estimate moved {moved:.3} m, {:.2}°",
                        turned.to_degrees()
                    ),
                );
                self.tracker.reset(&path, &self.scn.truck);
                self.path = path;
                self.adopt_estimate(new_est, &truth);
                self.out.replans += 1;
            }
            Err(e) => {
                rec.event(
                    t,
                    Level::Warn,
                    &format!("replan refused, keeping the old plan: {e}"),
                );
                self.out.replans_failed += 1;
            }
        }
        Ok(())
    }
}
