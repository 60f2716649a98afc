//! The `Tracker` trait: a path follower that turns the measured state into steering and speed.

use forkbench_core::{ForkliftSpec, Path, Pose2};

use crate::Command;

/// What a tracker sees at each control tick.
#[derive(Debug, Clone, Copy)]
pub struct TrackerInput<'a> {
    /// Simulation time.
    pub t_s: f64,
    /// Measured (NAV350 fix, odometry-predicted) fork-root pose.
    pub pose: Pose2,
    /// Measured speed of the front axle (forward positive).
    pub speed_mps: f64,
    /// Measured equivalent steering angle.
    pub steer_rad: f64,
    /// When the newest localisation fix in `pose` was measured: `pose` is that fix
    /// carried forward to `t_s` over the odometry. None before any fix.
    pub fix_measured_s: Option<f64>,
    pub truck: &'a ForkliftSpec,
}

/// A path tracker for the rear-steered truck. One instance drives one trial at a time.
pub trait Tracker: Send {
    /// The name results are reported under.
    fn name(&self) -> &str;

    /// Starts following `path` (planned for the fork root) from its beginning: called with
    /// the first plan and again with every replan, so no progress carries over.
    fn reset(&mut self, path: &Path, truck: &ForkliftSpec);

    /// Steering and speed for this tick; `done` once the goal is reached.
    fn command(&mut self, input: &TrackerInput) -> Command;

    /// Why this tracker can no longer steer (an external one hung, crashed or broke its
    /// protocol): the trial stops there as an error. In-process trackers never fail.
    fn fault(&self) -> Option<String> {
        None
    }
}
