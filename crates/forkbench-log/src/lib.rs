//! Recording sinks for forkbench trials: MCAP (Foxglove schemas, JSON) and rerun (.rrd or a live viewer).

pub mod actuator_csv;
pub mod bag;
pub mod dataset_set;
pub mod detect;
pub mod mcap_sink;
#[cfg(feature = "rerun")]
pub mod rerun_sink;
pub mod ros2;
pub mod sinks;
mod writer;

use std::path::Path;

use forkbench_core::{PalletSpec, Pose2};

pub use actuator_csv::ActuatorCsv;
pub use mcap_sink::McapRecorder;
#[cfg(feature = "rerun")]
pub use rerun_sink::{RerunRecorder, RerunTarget};
pub use ros2::Ros2Recorder;
pub use sinks::{RecordError, RecordTargets, Recorded, Sinks, record_trial, run_recorded};

/// The rerun SDK this crate is built against (pinned with `=` in the workspace; a test
/// checks this against Cargo.lock), for the recordings' metadata.
pub const RERUN_VERSION: &str = "0.36.3";

/// Whether this build writes rerun recordings (.rrd files and viewers): the `rerun`
/// feature, off by default, for rerun's SDK is most of a cold build.
pub const HAS_RERUN: bool = cfg!(feature = "rerun");

/// The metadata record of a trial's MCAP file: what ran, the versions, and what log time
/// means.
pub fn mcap_metadata(
    [scenario, case, planner, tracker]: [&str; 4],
    seed: u64,
    forkbench_version: &str,
) -> std::collections::BTreeMap<String, String> {
    [
        ("scenario", scenario),
        ("case", case),
        ("planner", planner),
        ("tracker", tracker),
        ("seed", &seed.to_string()),
        ("forkbench_version", forkbench_version),
        ("rerun_version", RERUN_VERSION),
        ("time", "log time = simulation time in ns"),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_owned(), v.to_owned()))
    .collect()
}

/// A recording sink that could not be opened or written.
#[derive(Debug, thiserror::Error)]
pub enum LogError {
    #[error("{path}: exists (overwriting it needs force)")]
    Exists { path: String },
    #[error("{path}: {message}")]
    Io { path: String, message: String },
    #[error("rerun: {0}")]
    Rerun(String),
}

impl From<forkbench_core::files::FileError> for LogError {
    fn from(e: forkbench_core::files::FileError) -> Self {
        Self::Io {
            path: e.path().to_owned(),
            message: e.reason(),
        }
    }
}

/// Checks before a run that `path` can be written, without touching it: not standard
/// output (which carries the run's report), not a link, folder, FIFO or device, absent
/// unless `force`, in a folder that exists and takes a new file. Nothing is created at
/// `path` until its recording is complete.
pub fn check_writable(path: &Path, force: bool) -> Result<(), LogError> {
    let p = path.display().to_string();
    let refuse = |message: &str| LogError::Io {
        path: p.clone(),
        message: message.into(),
    };
    if forkbench_core::files::is_stdout(path) {
        return Err(refuse(
            "standard output carries the run's report; give a recording a file's path",
        ));
    }
    if let Ok(meta) = std::fs::symlink_metadata(path) {
        let t = meta.file_type();
        if t.is_symlink() {
            return Err(refuse(
                "is a symbolic link; a recording is not written through a link (give the \
                 file's own path)",
            ));
        }
        if t.is_dir() {
            return Err(refuse("is a directory; give a file name"));
        }
        // Opening a FIFO to write waits for a reader, and a device is not a recording.
        if !t.is_file() {
            return Err(refuse(
                "exists and is not a regular file (a FIFO, socket or device); give a file name",
            ));
        }
        if !force {
            return Err(LogError::Exists { path: p });
        }
    }
    let parent = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    if !parent.is_dir() {
        return Err(refuse(&format!(
            "directory {} does not exist",
            parent.display()
        )));
    }
    // Probe with a file of our own beside it (removed at once), so a read-only place
    // fails now and the file at `path` is left as it is.
    forkbench_core::files::Partial::create(path)
        .map(drop)
        .map_err(LogError::from)
}

/// Outlines of the truck at a fork-root pose: chassis and the two forks.
pub(crate) fn truck_outlines(
    truck: &forkbench_core::ForkliftSpec,
    root: &Pose2,
) -> Vec<[[f64; 2]; 5]> {
    truck.outlines(root)
}

/// Outlines of the pallet's solid parts (stringers or blocks) at its face pose.
pub(crate) fn pallet_outlines(pallet: &PalletSpec, face: &Pose2) -> Vec<[[f64; 2]; 5]> {
    pallet.outlines(face)
}
