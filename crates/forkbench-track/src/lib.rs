//! Path tracking for a rear-steered forklift: the `Tracker` trait, pure pursuit, regulated pure pursuit, trackers in other languages (`external`), odometry prediction.

mod compensation;
pub mod external;
mod predictor;
mod pursuit;
mod regulated;
mod segments;
mod tracker;

pub use compensation::DelayCompensated;
pub use external::ExternalTracker;
pub use predictor::{PosePredictor, advance_pose};
pub use pursuit::{Command, PurePursuit, TrackerConfig};
pub use regulated::{RegulatedConfig, RegulatedPurePursuit};
pub use segments::{SegmentFollower, steer_for_root_curvature};
pub use tracker::{Tracker, TrackerInput};

use forkbench_core::settings::{self, Settings, SettingsError};

impl PurePursuit {
    /// From a scenario's `[tracker]` table: [`TrackerConfig`]'s fields.
    pub fn from_settings(s: &Settings) -> Result<Self, SettingsError> {
        let cfg: TrackerConfig = settings::parse(s)?;
        cfg.validate()?;
        Ok(Self::with_config(cfg))
    }
}
