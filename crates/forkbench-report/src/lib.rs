//! Reports and figures: the HTML page of a batch directory (no drawing library) and, with the `figures` feature, every plot.

#[cfg(feature = "figures")]
pub mod accuracy;
#[cfg(feature = "figures")]
pub mod corridor;
#[cfg(feature = "figures")]
pub mod coverage;
#[cfg(feature = "figures")]
pub mod detect;
#[cfg(feature = "figures")]
pub mod detect_curve;
#[cfg(feature = "figures")]
pub mod figure;
pub mod html;
#[cfg(feature = "figures")]
pub mod identify;
#[cfg(feature = "figures")]
pub mod map;
#[cfg(feature = "figures")]
pub mod plans;
#[cfg(feature = "figures")]
pub mod prm;
#[cfg(feature = "figures")]
pub mod scan;
#[cfg(feature = "figures")]
pub mod sweep;

use std::path::PathBuf;

/// The colours of every chart, the HTML report's and the figures' (matplotlib's tab10:
/// blue, orange, green, red, purple, brown, pink, grey, olive, cyan), readable on white.
pub const TAB10: [(u8, u8, u8); 10] = [
    (31, 119, 180),
    (255, 127, 14),
    (44, 160, 44),
    (214, 39, 40),
    (148, 103, 189),
    (140, 86, 75),
    (227, 119, 194),
    (127, 127, 127),
    (188, 189, 34),
    (23, 190, 207),
];

/// What went wrong making a report or a figure.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    /// A figure's file refused before drawing (its extension, or not a regular file).
    #[error("{}: {reason}", file.display())]
    File { file: PathBuf, reason: String },
    /// Drawing or writing a figure failed.
    #[error("drawing {}: {reason}", file.display())]
    Drawing { file: PathBuf, reason: String },
    /// The plotting backend's own error, before the figure's file is known.
    #[error("{0}")]
    Backend(String),
    /// A batch directory's files could not be read.
    #[error(transparent)]
    Batch(#[from] forkbench_batch::BatchError),
    /// A batch directory without the manifest the report reads its settings from.
    #[error("{}: no manifest.json", dir.display())]
    NoManifest { dir: PathBuf },
}

/// The crate's results.
pub type Result<T, E = ReportError> = std::result::Result<T, E>;

/// What a knob's scale of 1 means, for the sweep's axis.
pub fn knob_axis(knob: &str) -> String {
    let what = match knob {
        "pallet_noise" => "pallet-sensing error (estimate σ, scanner noise and bias)",
        "localization_noise" => "localisation error (NAV350 or Gaussian σ)",
        "odometry_noise" => "odometry error (speed scale and steering σ)",
        other => {
            if let Some(path) = forkbench_trial::trial::truck_path(other) {
                return format!("truck {path}, as set");
            }
            other
        }
    };
    format!("scale of the {what}; 1 = the scenario's own")
}
