//! Pallet-pick path planners: cubic B-spline (Lü et al. 2019) and quartic polynomial spiral (Shen et al. 2022).

pub mod bspline;
pub mod external;
pub mod numeric;
mod planner;
pub mod reproduce;
pub mod spiral;

use forkbench_core::geometry::Obstacle;
use forkbench_core::{ForkliftSpec, Path, Pose2};
use serde::{Deserialize, Serialize};

pub use bspline::{BsplineConfig, BsplinePlan};
pub use planner::{BsplinePlanner, Planner, SpiralPlanner};
pub use spiral::{SpiralConfig, SpiralParams, SpiralPlan};

/// What to plan: a forward path of the fork root from `start` to `goal`.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanRequest {
    pub start: Pose2,
    pub goal: Pose2,
    /// Path curvature at the start (from the current steering angle); the B-spline
    /// always starts at zero curvature and ignores it.
    pub start_curvature_per_m: f64,
    pub truck: ForkliftSpec,
    /// Racks and walls of the world, for planners that avoid obstacles (the pick planners
    /// ignore them; the trial checks every plan's swept body against them).
    pub obstacles: Vec<Obstacle>,
    /// The trial's seed, for planners that draw random numbers.
    pub seed: u64,
}

impl PlanRequest {
    pub fn new(start: Pose2, goal: Pose2) -> Self {
        Self {
            start,
            goal,
            start_curvature_per_m: 0.0,
            truck: ForkliftSpec::default(),
            obstacles: Vec::new(),
            seed: 0,
        }
    }

    /// Checks what every planner needs: finite poses, a valid truck, distinct start and goal.
    pub fn validate(&self) -> Result<(), PlanError> {
        if !self.start.is_finite() {
            return Err(PlanError::InvalidInput {
                what: "start",
                reason: "pose has a non-finite component".into(),
            });
        }
        if !self.goal.is_finite() {
            return Err(PlanError::InvalidInput {
                what: "goal",
                reason: "pose has a non-finite component".into(),
            });
        }
        if !self.start_curvature_per_m.is_finite() {
            return Err(PlanError::InvalidInput {
                what: "start_curvature_per_m",
                reason: "must be finite".into(),
            });
        }
        self.truck.validate().map_err(|e| PlanError::InvalidInput {
            what: "truck",
            reason: e.to_string(),
        })?;
        let limit = self.truck.max_curvature_per_m();
        if self.start_curvature_per_m.abs() > limit {
            return Err(PlanError::StartCurvature {
                curvature_per_m: self.start_curvature_per_m,
                limit_per_m: limit,
            });
        }
        for (what, pose) in [("start", &self.start), ("goal", &self.goal)] {
            if pose.x_m.abs().max(pose.y_m.abs()) > MAX_COORDINATE_M {
                return Err(PlanError::InvalidInput {
                    what,
                    reason: format!(
                        "({}, {}) m lies beyond ±{MAX_COORDINATE_M} m; a pick planner works \
                         over metres (this bounds the path and its samples)",
                        pose.x_m, pose.y_m
                    ),
                });
            }
        }
        let d = self.start.distance_to(&self.goal);
        if d > MAX_GOAL_DISTANCE_M {
            return Err(PlanError::InvalidInput {
                what: "goal",
                reason: format!(
                    "{d:.1} m from the start; pick paths are planned over at most \
                     {MAX_GOAL_DISTANCE_M} m"
                ),
            });
        }
        if d < MIN_GOAL_DISTANCE_M {
            return Err(PlanError::GoalTooClose {
                distance_m: d,
                min_m: MIN_GOAL_DISTANCE_M,
            });
        }
        Ok(())
    }
}

/// Below this start–goal distance no forward pick path is meaningful.
pub const MIN_GOAL_DISTANCE_M: f64 = 0.05;

/// Largest |x| or |y| of a start or goal pose: keeps the numbers well inside f64's exact
/// range for sub-millimetre work.
pub const MAX_COORDINATE_M: f64 = 1e4;

/// Longest start–goal distance a pick planner takes: bounds the path's length and so
/// the samples (and memory) one plan can cause.
pub const MAX_GOAL_DISTANCE_M: f64 = 200.0;

/// Smallest sample spacing: with [`MAX_GOAL_DISTANCE_M`] it bounds a path's samples.
pub const MIN_SAMPLE_SPACING_M: f64 = 1e-4;

/// Why a plan could not be made. Every variant names the limit that failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlanError {
    #[error("invalid {what}: {reason}")]
    InvalidInput { what: &'static str, reason: String },
    /// The planner's own settings are out of range.
    #[error("planner setting {0}")]
    Settings(#[from] forkbench_core::SettingsError),
    #[error("goal is {distance_m:.3} m from the start; a pick path needs at least {min_m} m")]
    GoalTooClose { distance_m: f64, min_m: f64 },
    #[error(
        "start curvature {curvature_per_m:.4} m⁻¹ exceeds κ_max {limit_per_m:.4} m⁻¹ of the truck"
    )]
    StartCurvature {
        curvature_per_m: f64,
        limit_per_m: f64,
    },
    #[error(
        "{planner} path needs max |κ| {needed_per_m:.4} m⁻¹ > κ_max {limit_per_m:.4} m⁻¹ \
         (steering {needed_steer_rad:.4} rad > α_max {limit_steer_rad:.4} rad)"
    )]
    CurvatureLimit {
        planner: String,
        needed_per_m: f64,
        limit_per_m: f64,
        needed_steer_rad: f64,
        limit_steer_rad: f64,
    },
    #[error("{planner} cannot reach the goal: {reason}")]
    Unreachable { planner: String, reason: String },
    /// The planner misbehaved or returned a path that breaks the contract (external
    /// planners: a crash, a hang, bad JSON, a path off the start or goal).
    #[error("{planner}: {reason}")]
    Rejected { planner: String, reason: String },
}

impl PlanError {
    pub(crate) fn curvature(planner: &str, needed_per_m: f64, truck: &ForkliftSpec) -> Self {
        PlanError::CurvatureLimit {
            planner: planner.to_owned(),
            needed_per_m,
            limit_per_m: truck.max_curvature_per_m(),
            needed_steer_rad: truck.steer_for_curvature(needed_per_m),
            limit_steer_rad: truck.max_steer_rad,
        }
    }
}

/// Planner-specific parameters of a finished plan.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum PlanParams {
    Bspline {
        l1_m: f64,
        l2_m: f64,
        control_points_m: [[f64; 2]; 6],
    },
    Spiral(SpiralParams),
    /// A planner outside the workspace: whatever it reported about its plan.
    Other(serde_json::Value),
}

/// A planned path with the planner's parameters and objective value.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// Name of the planner that made it.
    pub planner: String,
    pub params: PlanParams,
    /// The planner's own objective: max |κ| (m⁻¹) for bspline, normalised ∫½κ² for spiral.
    pub cost: f64,
    pub path: Path,
    /// A control polygon the recorder draws beside the path (the B-spline's), if any.
    pub control_polygon_m: Option<Vec<[f64; 2]>>,
}

/// Arc length of the first cusp in a sampled forward path, if any: a heading change
/// between neighbouring samples far beyond what the curvature limit allows, or a step
/// that runs against the samples' heading (the path doubles back on itself).
pub fn find_cusp(path: &Path, max_curvature_per_m: f64) -> Option<f64> {
    path.samples.windows(2).find_map(|w| {
        let (a, b) = (&w[0], &w[1]);
        let ds = b.s_m - a.s_m;
        let turn = forkbench_core::units::wrap_angle(b.heading_rad - a.heading_rad).abs();
        let (dx, dy) = (b.x_m - a.x_m, b.y_m - a.y_m);
        let along = dx * a.heading_rad.cos() + dy * a.heading_rad.sin();
        let reversed = dx.hypot(dy) > 1e-9 && along < 0.0;
        (turn > 0.1 + 10.0 * max_curvature_per_m * ds || reversed).then_some(a.s_m)
    })
}
