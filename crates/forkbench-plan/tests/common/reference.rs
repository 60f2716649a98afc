//! The spiral's committed independent reference (`tools/spiral_reference.py`), shared by the optimality test and the plan-time bench.

use forkbench_core::Pose2;
use forkbench_plan::PlanRequest;
use serde::Deserialize;

#[derive(Debug, Deserialize)]
pub struct Reference {
    pub kappa_max_per_m: f64,
    pub goals: Vec<Goal>,
}

#[derive(Debug, Deserialize)]
pub struct Goal {
    pub name: String,
    pub goal_x_m: f64,
    pub goal_y_m: f64,
    pub goal_heading_rad: f64,
    pub start_curvature_per_m: f64,
    pub length_window: bool,
    pub window: [f64; 2],
    pub cost: Option<f64>,
    pub sf: Option<f64>,
}

pub fn reference() -> Reference {
    serde_json::from_str(include_str!("../data/spiral_reference.json"))
        .expect("tests/data/spiral_reference.json parses")
}

impl Goal {
    /// The goal as a request from the origin, heading along +x.
    pub fn request(&self) -> PlanRequest {
        let mut req = PlanRequest::new(
            Pose2::new(0.0, 0.0, 0.0),
            Pose2::new(self.goal_x_m, self.goal_y_m, self.goal_heading_rad),
        );
        req.start_curvature_per_m = self.start_curvature_per_m;
        req
    }
}
