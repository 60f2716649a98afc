//! A manoeuvre followed segment by segment: steer before moving off, pure pursuit along each forward or backward segment, a stop at every cusp.

use forkbench_core::{ForkliftSpec, Path};

use crate::pursuit::above_creep;
use crate::{Command, PurePursuit, Tracker, TrackerConfig, TrackerInput};

/// Steering within this of the segment's first curvature counts as set.
const STEER_SET_RAD: f64 = 0.02;
/// A steering lag this large slows the truck to its crawl.
const STEER_LAG_STOP_RAD: f64 = 0.3;
/// The crawl: the least share of the pursuit's speed while the wheel catches up.
const MIN_SPEED_SHARE: f64 = 0.1;
/// Below this speed the truck counts as stopped at a cusp.
const STOPPED_MPS: f64 = 0.01;

/// Follows segments in turn. At each segment's start it stands and turns the wheel to the
/// segment's first curvature (a rear-steered truck can: the moves at full lock leave no
/// room to steer on the way), then pursues the segment to its end and stops.
#[derive(Debug, Clone)]
pub struct SegmentFollower {
    segments: Vec<Path>,
    current: usize,
    pursuit: PurePursuit,
    steer_set: bool,
}

/// The steering angle that puts the fork root on a circle of curvature `kappa_root`: the
/// truck turns about a point on its front axle's line, and the root sits ahead of it.
pub fn steer_for_root_curvature(truck: &ForkliftSpec, kappa_root: f64) -> f64 {
    if kappa_root.abs() < 1e-9 {
        return 0.0;
    }
    let r_root = 1.0 / kappa_root.abs();
    let d = truck.fork_root_ahead_of_front_axle_m;
    let r_axle = (r_root * r_root - d * d).max(1e-9).sqrt();
    truck
        .steer_for_curvature(kappa_root.signum() / r_axle)
        .clamp(-truck.max_steer_rad, truck.max_steer_rad)
}

impl SegmentFollower {
    pub fn new(segments: Vec<Path>, cfg: TrackerConfig, truck: &ForkliftSpec) -> Self {
        let mut pursuit = PurePursuit::with_config(cfg);
        if let Some(first) = segments.first() {
            pursuit.reset(first, truck);
        }
        Self {
            segments,
            current: 0,
            pursuit,
            steer_set: false,
        }
    }

    /// The segment being driven (its index).
    pub fn segment(&self) -> usize {
        self.current
    }

    /// Whether the last segment was driven to its end.
    pub fn finished(&self) -> bool {
        self.current >= self.segments.len()
    }

    /// The command for this tick. `done` once the last segment is driven and the truck
    /// stands; between segments the truck stops and the next begins.
    pub fn command(&mut self, input: &TrackerInput) -> Command {
        let Some(seg) = self.segments.get(self.current) else {
            return hold(input, true);
        };
        if !self.steer_set {
            let first = seg.samples.first().map_or(0.0, |s| s.curvature_per_m);
            let want = steer_for_root_curvature(input.truck, first);
            if (input.steer_rad - want).abs() > STEER_SET_RAD || input.speed_mps.abs() > STOPPED_MPS
            {
                return Command {
                    steer_rad: want,
                    ..hold(input, false)
                };
            }
            self.steer_set = true;
        }
        let cmd = Tracker::command(&mut self.pursuit, input);
        if !(cmd.done && input.speed_mps.abs() < STOPPED_MPS) {
            // The wheel turns at a bounded rate: slow down while it lags, so a change from
            // full lock one way to the other happens over centimetres, not a metre.
            let lag = (cmd.steer_rad - input.steer_rad).abs();
            let scale = (1.0 - lag / STEER_LAG_STOP_RAD).clamp(MIN_SPEED_SHARE, 1.0);
            return Command {
                done: false,
                speed_mps: above_creep(cmd.speed_mps * scale, input.truck),
                ..cmd
            };
        }
        self.current += 1;
        self.steer_set = false;
        match self.segments.get(self.current) {
            Some(next) => {
                self.pursuit.reset(next, input.truck);
                hold(input, false)
            }
            None => hold(input, true),
        }
    }
}

/// Stand still, the wheel where it is.
fn hold(input: &TrackerInput, done: bool) -> Command {
    Command {
        speed_mps: 0.0,
        steer_rad: input.steer_rad,
        lookahead_point: [input.pose.x_m, input.pose.y_m],
        cross_track_m: 0.0,
        remaining_m: 0.0,
        path_curvature_per_m: 0.0,
        done,
    }
}
