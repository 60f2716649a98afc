//! Shared vocabulary of forkbench: poses, units, the forklift and pallet specs, sampled paths.

pub mod actuators;
pub mod axle_loads;
pub mod exact;
pub mod files;
pub mod geometry;
pub mod hash;
pub mod layout;
pub mod mounts;
pub mod out_dir;
pub mod pallet;
pub mod path;
pub mod pose;
pub mod profile;
pub mod quantile;
pub mod run_settings;
pub mod settings;
pub mod signal;
pub mod units;
pub mod vehicle;

pub use layout::TruckLayout;
pub use pallet::PalletSpec;
pub use path::{Path, PathMetrics, PathSample};
pub use pose::{Pose2, PoseParseError};
pub use settings::{Settings, SettingsError, UnknownChoice};
pub use signal::{Signal, Style};
pub use vehicle::{ForkliftSpec, SpecError};
