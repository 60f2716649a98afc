//! The environment's observation vector (what the truck's controller knows, never the truth) and its default reward (the truth's progress and the bench's verdict).

use forkbench_core::units::wrap_angle;
use forkbench_core::{Path, Pose2};
use forkbench_trial::TrialOutcome;
use forkbench_trial::trial::{Observation, SessionEnd, Stage, Truth};

/// The fixed part of an observation, in order; `path_points` (x, y) pairs of the planned
/// path ahead in the truck's frame follow when asked for.
pub const FIELDS: [&str; 13] = [
    "x_m",
    "y_m",
    "heading_rad",
    "pallet_x_m",
    "pallet_y_m",
    "pallet_heading_rad",
    "goal_dx_m",
    "goal_dy_m",
    "goal_dheading_rad",
    "speed_mps",
    "steer_rad",
    "time_left_s",
    "fix",
];

/// The field a whole-cycle episode adds after the fixed ones: [`stage_code`].
pub const STAGE_FIELD: &str = "stage";

/// The part of the cycle as a number: 0 a mission leg, 1 staging, 2 the pick, 2 + k the
/// k-th phase after it.
pub fn stage_code(stage: Stage) -> f64 {
    match stage {
        Stage::Leg => 0.0,
        Stage::Staging => 1.0,
        Stage::Pick => 2.0,
        Stage::Phase(k) => 2.0 + f64::from(k),
    }
}

/// What an observation holds beyond the fixed fields.
#[derive(Debug, Clone, Copy)]
pub struct ObsConfig {
    /// The stage field (whole-cycle episodes).
    pub stage: bool,
    /// Points of the planned path ahead (0: none).
    pub path_points: usize,
    /// Arc length between them.
    pub path_spacing_m: f64,
}

impl ObsConfig {
    pub fn size(&self) -> usize {
        FIELDS.len() + usize::from(self.stage) + 2 * self.path_points
    }
}

/// Writes the observation into `out` (`cfg.size()` long).
pub fn write(o: &Observation, path: Option<&Path>, cfg: &ObsConfig, out: &mut [f32]) {
    let goal = o.pose.to_local(&o.goal);
    let fixed = [
        o.pose.x_m,
        o.pose.y_m,
        o.pose.heading_rad,
        o.pallet_estimate.x_m,
        o.pallet_estimate.y_m,
        o.pallet_estimate.heading_rad,
        goal.x_m,
        goal.y_m,
        wrap_angle(goal.heading_rad),
        o.speed_mps,
        o.steer_rad,
        o.time_left_s,
        f64::from(u8::from(o.fix)),
    ];
    for (slot, v) in out.iter_mut().zip(fixed) {
        *slot = v as f32;
    }
    let mut at = FIELDS.len();
    if cfg.stage {
        out[at] = stage_code(o.stage) as f32;
        at += 1;
    }
    let ahead = &mut out[at..];
    path_ahead(&o.pose, path, cfg, ahead);
}

/// The path's points every `path_spacing_m` from the sample nearest the truck, in the
/// truck's frame (the last sample repeated past the end; zeros without a path).
fn path_ahead(pose: &Pose2, path: Option<&Path>, cfg: &ObsConfig, out: &mut [f32]) {
    out.fill(0.0);
    if cfg.path_points == 0 {
        return;
    }
    let Some(samples) = path.map(|p| &p.samples).filter(|s| !s.is_empty()) else {
        return;
    };
    let d2 = |i: usize| (samples[i].x_m - pose.x_m).powi(2) + (samples[i].y_m - pose.y_m).powi(2);
    let nearest = (0..samples.len())
        .min_by(|a, b| d2(*a).total_cmp(&d2(*b)))
        .unwrap_or(0);
    let mut i = nearest;
    for (k, xy) in out.chunks_exact_mut(2).enumerate() {
        let s = samples[nearest].s_m + (k + 1) as f64 * cfg.path_spacing_m;
        while i + 1 < samples.len() && samples[i].s_m < s {
            i += 1;
        }
        let p = pose.to_local(&samples[i].pose());
        xy[0] = p.x_m as f32;
        xy[1] = p.y_m as f32;
    }
}

/// The default reward's weights.
#[derive(Debug, Clone, Copy)]
pub struct RewardConfig {
    /// Added when the trial is judged a success.
    pub success: f64,
    /// Subtracted when it is judged a failure before the time limit.
    pub failure: f64,
    /// Subtracted per second of simulated time.
    pub time_per_s: f64,
    /// Metres of distance one radian of heading error counts as.
    pub heading_m_per_rad: f64,
    /// Added for each part of a whole cycle judged a success (the pick and each phase).
    pub phase: f64,
}

impl RewardConfig {
    /// How far the true fork root is from the true goal: the potential whose decrease is
    /// rewarded.
    pub fn distance(&self, t: &Truth) -> f64 {
        t.fork_root.distance_to(&t.goal)
            + self.heading_m_per_rad
                * wrap_angle(t.fork_root.heading_rad - t.goal.heading_rad).abs()
    }

    /// The reward at the end of an episode.
    pub fn terminal(&self, out: &TrialOutcome, end: SessionEnd) -> f64 {
        match (out.success, end) {
            (true, _) => self.success,
            (false, SessionEnd::TimeLimit) => 0.0,
            (false, SessionEnd::Judged) => -self.failure,
        }
    }
}
