//! What a phase sees: the scenario's site when its settings are checked ([`Context`], the format's), and the running trial when it drives ([`PhaseHost`]), both as traits so phases need nothing of the trial engine's own types.

use std::future::Future;
use std::pin::Pin;

use forkbench_core::{ForkliftSpec, PalletSpec, Path, Pose2};
use forkbench_geom::Footprint;
use forkbench_plan::Plan;
use forkbench_sim::Sim;
use forkbench_track::Command;

use super::Failed;
use crate::outcome::LegOutcome;
use crate::recorder::Recorder;
use crate::stage_error::StageError;
use crate::tolerances::Limits;

pub use forkbench_scenario::Context;

/// A phase's command at the controller's pose each tick: `None` ends the drive.
pub type Steer<'s> =
    dyn FnMut(&mut dyn PhaseHost, Pose2) -> Result<Option<Command>, Failed> + Send + 's;

/// A drive under a phase's commands: `Ok(true)` when they ended it, `Ok(false)` when its
/// time ran out.
pub type DriveRun<'s> = Pin<Box<dyn Future<Output = Result<bool, Failed>> + Send + 's>>;

/// A mission leg driven inside the cycle, measured.
pub type LegRun<'s> = Pin<Box<dyn Future<Output = Result<LegOutcome, Failed>> + Send + 's>>;

/// The running trial as a phase drives it: the physics, the scenario's truck, pallet,
/// planner and tracker, the one drive loop (which holds the criteria every phase holds
/// at every step and yields to a session's caller), and the phase's measures.
pub trait PhaseHost: Send {
    /// The physics world: the truck, the pallet, the mast.
    fn sim(&self) -> &Sim;
    /// The physics world, to lift or lower the pallet.
    fn sim_mut(&mut self) -> &mut Sim;
    fn truck(&self) -> &ForkliftSpec;
    fn pallet(&self) -> &PalletSpec;
    /// How far past the fork root the pick drove the pallet's face (the insertion).
    fn insertion_m(&self) -> f64;
    /// The scenario's tolerances (a pallet left standing may be dragged only within the
    /// pick's displacement and rotation limits).
    fn tolerances(&self) -> &Limits;
    /// The truth now, as a step criterion sees it after a physics step.
    fn step_view(&self) -> crate::step_criteria::StepView<'_>;
    /// Records `value` as the running phase's measure `name` (its outcome's `measures`).
    fn record_measure(&mut self, name: &str, value: f64);
    /// The truck stands (how a drive ends).
    fn stands(&self) -> bool;
    /// Steps the truck under `command` until it returns `None`, `limit_s` passes, or a
    /// criterion every phase holds at every step breaks (Err).
    fn drive_under<'s>(
        &'s mut self,
        limit_s: f64,
        rec: &'s mut dyn Recorder,
        command: &'s mut Steer<'_>,
    ) -> DriveRun<'s>;
    /// The localiser's reading now, as the controller's pose. Err: what stopped the
    /// trial (a non-finite state, a wall-time budget spent).
    fn sense(&mut self, rec: &mut dyn Recorder) -> Result<Pose2, StageError>;
    /// A plan by the scenario's pick planner from `pose` (path curvature `curvature`) to
    /// insert the forks into a pallet face at `face`.
    /// Err: the planner refused ([`StageError::Plan`]).
    fn plan_to_face(
        &mut self,
        pose: Pose2,
        curvature: f64,
        face: &Pose2,
    ) -> Result<Plan, StageError>;
    /// Where the truck body swept along `path` would hit a rack or wall, if it would
    /// ([`StageError::Clash`]).
    fn clash(&self, path: &Path) -> Option<StageError>;
    /// How many plans the trial has recorded after its first (to number the next).
    fn replans(&self) -> u32;
    /// Follows `path` with the scenario's tracker from now on.
    fn follow(&mut self, path: Path);
    /// The tracker's command at the measured `pose`. Err: it failed
    /// ([`StageError::Tracker`]).
    fn tracker_command(&mut self, pose: Pose2) -> Result<Command, StageError>;
    /// The room between `footprint` at `at` and the nearest rack or wall, up to `max_m`.
    fn clearance_m(&self, footprint: &Footprint, at: &Pose2, max_m: f64) -> f64;
    /// Drives a mission leg (the mission's global planner and tracker) from where the
    /// truck stands to `to` (name, fork-root pose), numbered after the mission's legs.
    fn drive_leg<'s>(&'s mut self, to: (&'s str, Pose2), rec: &'s mut dyn Recorder) -> LegRun<'s>;
}

/// A command holding `speed_mps` and `steer_rad`, for phases that drive without a path.
pub fn open_loop(speed_mps: f64, steer_rad: f64, pose: &Pose2) -> Command {
    Command {
        speed_mps,
        steer_rad,
        lookahead_point: [pose.x_m, pose.y_m],
        cross_track_m: 0.0,
        remaining_m: 0.0,
        path_curvature_per_m: 0.0,
        done: false,
    }
}

/// Holds the truck standing (steering where it is) for `time_s`, as while the mast
/// lifts or lowers; the every-step criteria still hold.
pub async fn stand_for(
    host: &mut dyn PhaseHost,
    time_s: f64,
    rec: &mut dyn Recorder,
) -> Result<(), Failed> {
    let end_s = host.sim().time_s() + time_s;
    host.drive_under(time_s + 1.0, rec, &mut |h, pose| {
        Ok((h.sim().time_s() < end_s).then(|| open_loop(0.0, h.sim().steer_rad(), &pose)))
    })
    .await?;
    Ok(())
}
