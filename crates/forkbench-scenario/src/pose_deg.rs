//! A pose as files write it (metres and degrees), and how far from the origin any may lie.

use forkbench_core::Pose2;
use serde::{Deserialize, Serialize};

/// Largest |x| or |y| anywhere in a world or scenario file.
pub const MAX_WORLD_EXTENT_M: f64 = 1e4;

/// A pose as written in files: metres and degrees.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PoseDeg {
    pub x_m: f64,
    pub y_m: f64,
    pub heading_deg: f64,
}

impl PoseDeg {
    pub fn to_pose(self) -> Pose2 {
        Pose2::new(self.x_m, self.y_m, self.heading_deg.to_radians())
    }
}
