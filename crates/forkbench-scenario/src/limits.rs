//! The SI form of a scenario's replanning thresholds, converted once at load; it serialises back to the file's form (degrees) for manifests.

use serde::{Deserialize, Serialize};

use super::file::ReplanFile;
use crate::tolerances::deg_of;

/// Replanning on a new pallet estimate, in SI units.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(from = "ReplanFile", into = "ReplanFile")]
pub struct Replan {
    /// Off reproduces the papers: plan once from the first estimate.
    pub enabled: bool,
    pub position_threshold_m: f64,
    pub heading_threshold_rad: f64,
    written_heading_deg: f64,
    /// Ranges at which a new estimate is taken (the trial's schedule, not the sensor's);
    /// `None`: the pallet-estimate settings' own list.
    pub reestimate_at_m: Option<Vec<f64>>,
    pub method: super::file::ReplanMethod,
}

impl Default for Replan {
    fn default() -> Self {
        ReplanFile::default().into()
    }
}

impl From<ReplanFile> for Replan {
    fn from(r: ReplanFile) -> Self {
        Self {
            enabled: r.enabled,
            position_threshold_m: r.position_threshold_m,
            heading_threshold_rad: r.heading_threshold_deg.to_radians(),
            written_heading_deg: r.heading_threshold_deg,
            reestimate_at_m: r.reestimate_at_m,
            method: r.method,
        }
    }
}

impl From<Replan> for ReplanFile {
    fn from(r: Replan) -> Self {
        ReplanFile {
            enabled: r.enabled,
            position_threshold_m: r.position_threshold_m,
            heading_threshold_deg: deg_of(r.heading_threshold_rad, r.written_heading_deg),
            reestimate_at_m: r.reestimate_at_m,
            method: r.method,
        }
    }
}
