//! Path tracking for a rear-steered forklift: pure pursuit on the fork root, a speed profile, odometry prediction.

mod predictor;
mod pursuit;

pub use predictor::PosePredictor;
pub use pursuit::{Command, PurePursuit, TrackerConfig};
