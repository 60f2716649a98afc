//! Shared vocabulary of forkbench: poses, units, the forklift and pallet specs, sampled paths.

pub mod path;
pub mod pose;
pub mod units;
pub mod vehicle;

pub use path::{Path, PathMetrics, PathSample};
pub use pose::{Pose2, PoseParseError};
pub use vehicle::{ForkliftSpec, SpecError};
