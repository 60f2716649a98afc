//! A mission leg's drive: a follower's commands through the one drive loop until it stops at the path's end; a touch of a rack or wall ends the leg.

use forkbench_core::{Path, Pose2};
use forkbench_track::{Command, DelayCompensated, PurePursuit, Tracker, TrackerInput};

use super::engine::Steering;
use super::link::Control;
use super::mission::DriveStats;
use super::state::Trial;
use crate::recorder::Recorder;
use crate::scenario::mission::MissionSpec;
use crate::stage_error::LegError;

impl Trial<'_> {
    /// Follows `path` (forward or reverse) with the mission's pure pursuit, steering from
    /// where the truck will be once its command acts (a no-op for a truck without
    /// delays), until it stops at the end; a touch of a rack or wall ends the leg.
    pub(super) async fn drive_path<R: Recorder + ?Sized>(
        &mut self,
        path: &Path,
        m: &MissionSpec,
        stats: &mut DriveStats,
        rec: &mut R,
    ) -> Result<(), LegError> {
        let pursuit = Box::new(PurePursuit::with_config(m.tracker.clone()));
        let mut tracker = DelayCompensated::new(pursuit, "pure_pursuit_compensated");
        tracker.reset(path, &self.scn.truck);
        self.drive_with(|input| Tracker::command(&mut tracker, input), m, stats, rec)
            .await
    }

    /// Drives with `next` giving each tick's command until it reports done with the truck
    /// standing; a touch of a rack or wall ends the leg.
    pub(super) async fn drive_with<R: Recorder + ?Sized>(
        &mut self,
        next: impl FnMut(&TrackerInput) -> Command,
        m: &MissionSpec,
        stats: &mut DriveStats,
        rec: &mut R,
    ) -> Result<(), LegError> {
        let mut leg = LegDrive { next, stats };
        let stopped = self.drive_by(m.leg_timeout_s, &mut leg, rec).await?;
        if stopped {
            Ok(())
        } else {
            Err(LegError::NotStopped {
                timeout_s: m.leg_timeout_s,
            })
        }
    }
}

/// A leg's drive: its follower's commands until done with the truck standing; a touch of
/// a rack or wall ends it.
struct LegDrive<'s, F> {
    next: F,
    stats: &'s mut DriveStats,
}

impl<'a, F> Steering<'a, LegError> for LegDrive<'_, F>
where
    F: FnMut(&TrackerInput) -> Command,
{
    fn command(
        &mut self,
        t: &mut Trial<'a>,
        _control: Control,
        pose: Pose2,
    ) -> Result<Option<Command>, LegError> {
        let timed = forkbench_core::profile::enter_as(
            forkbench_core::profile::Stage::Track,
            "mission legs",
        );
        let cmd = (self.next)(&t.tracker_input(pose));
        drop(timed);
        Ok((!(cmd.done && t.stands())).then_some(cmd))
    }

    fn stepped<R: Recorder + ?Sized>(
        &mut self,
        t: &mut Trial<'a>,
        _control: Control,
        cmd: &Command,
        _rec: &mut R,
    ) -> Result<bool, LegError> {
        let stats = &mut *self.stats;
        stats.steps += 1;
        stats.cross_track_sum_m += cmd.cross_track_m.abs();
        stats.cross_track_max_m = stats.cross_track_max_m.max(cmd.cross_track_m.abs());
        if t.world.sim.obstacle_contact() {
            stats.collisions += 1;
            let p = t.world.sim.fork_root_pose();
            return Err(LegError::Struck {
                x_m: p.x_m,
                y_m: p.y_m,
            });
        }
        Ok(false)
    }
}
