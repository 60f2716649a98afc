//! The JSON-lines messages between forkbench and an external planner (version 1; schemas in docs/).

use forkbench_core::geometry::Obstacle;
use forkbench_core::{ForkliftSpec, Path, PathSample, Pose2};
use serde::{Deserialize, Serialize};

use crate::PlanRequest;

/// Name of the protocol in both hello messages.
pub const PROTOCOL: &str = "forkbench-planner";

/// The protocol version this forkbench speaks (in the hello each way).
pub const VERSION: u32 = 1;

/// An obstacle as sent: its rectangle and, for convenience, its corners.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ObstacleMsg {
    pub centre: Pose2,
    pub length_m: f64,
    pub width_m: f64,
    pub corners_m: [[f64; 2]; 4],
}

impl From<&Obstacle> for ObstacleMsg {
    fn from(o: &Obstacle) -> Self {
        Self {
            centre: o.centre,
            length_m: o.length_m,
            width_m: o.width_m,
            corners_m: o.corners(),
        }
    }
}

/// The truck's limits as sent: its spec plus the derived curvature limit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TruckMsg {
    #[serde(flatten)]
    pub spec: ForkliftSpec,
    pub max_curvature_per_m: f64,
}

/// One plan request.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RequestMsg {
    #[serde(rename = "type")]
    pub kind: String,
    pub id: u64,
    pub start: Pose2,
    pub goal: Pose2,
    pub start_curvature_per_m: f64,
    pub truck: TruckMsg,
    pub obstacles: Vec<ObstacleMsg>,
    pub seed: u64,
}

impl RequestMsg {
    pub fn new(id: u64, req: &PlanRequest) -> Self {
        Self {
            kind: "plan".into(),
            id,
            start: req.start,
            goal: req.goal,
            start_curvature_per_m: req.start_curvature_per_m,
            truck: TruckMsg {
                spec: req.truck.clone(),
                max_curvature_per_m: req.truck.max_curvature_per_m(),
            },
            obstacles: req.obstacles.iter().map(ObstacleMsg::from).collect(),
            seed: req.seed,
        }
    }
}

/// The planner's answer: a path (samples `[s, x, y, heading, curvature]`) or an error.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "lowercase")]
pub enum ResponseMsg {
    Path {
        id: u64,
        samples: Vec<[f64; 5]>,
        #[serde(default)]
        cost: Option<f64>,
        #[serde(default)]
        info: Option<serde_json::Value>,
    },
    Error {
        id: u64,
        message: String,
    },
}

/// Samples as a path.
pub fn to_path(samples: &[[f64; 5]]) -> Path {
    Path::new(
        samples
            .iter()
            .map(
                |&[s_m, x_m, y_m, heading_rad, curvature_per_m]| PathSample {
                    s_m,
                    x_m,
                    y_m,
                    heading_rad,
                    curvature_per_m,
                },
            )
            .collect(),
    )
}
