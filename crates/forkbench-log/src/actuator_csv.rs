//! A trial's actuator log as CSV: the commanded and measured steering and speed at every physics step, in the columns `forkbench identify` reads.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use forkbench_trial::{Recorder, StepRecord};

use crate::LogError;

/// The log's header: the columns `forkbench identify` reads.
const HEADER: &str = "t_s,steer_cmd_rad,steer_rad,speed_cmd_mps,speed_mps\n";

/// Most bytes a log holds: far more than hours of 100 Hz rows, so a runaway run cannot
/// take the machine's memory.
const MAX_LOG_BYTES: usize = 256 << 20;

/// Collects a trial's steps and writes them at the end, atomically.
#[derive(Debug)]
pub struct ActuatorCsv {
    path: PathBuf,
    text: String,
    /// The cap was reached: the log would be cut short, so it is not written.
    overflowed: bool,
}

impl ActuatorCsv {
    /// A log to be written to `path` (checked writable before the run).
    pub fn create(path: &Path) -> Self {
        Self {
            path: path.to_path_buf(),
            text: HEADER.to_owned(),
            overflowed: false,
        }
    }

    /// Writes the log (a reader sees the old file or the whole new one).
    pub fn finish(&mut self) -> Result<(), LogError> {
        let path = self.path.display().to_string();
        if self.overflowed {
            return Err(LogError::Io {
                path,
                message: format!("the log passed {MAX_LOG_BYTES} bytes; not written"),
            });
        }
        forkbench_core::files::write_atomic(&self.path, self.text.as_bytes()).map_err(|e| {
            LogError::Io {
                path,
                message: e.to_string(),
            }
        })
    }
}

impl Recorder for ActuatorCsv {
    fn step(&mut self, s: &StepRecord) {
        if self.overflowed {
            return;
        }
        let _ = writeln!(
            self.text,
            "{},{},{},{},{}",
            s.t_s, s.steer_cmd_rad, s.steer_rad, s.speed_cmd_mps, s.speed_mps
        );
        if self.text.len() > MAX_LOG_BYTES {
            self.overflowed = true;
            self.text = String::new();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each step is one row of the five columns, written when the trial ends.
    #[test]
    fn steps_become_rows() {
        let dir = std::env::temp_dir().join(format!("fb-actuator-csv-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("dir");
        let path = dir.join("log.csv");
        let mut log = ActuatorCsv::create(&path);
        let at = forkbench_core::Pose2::new(0.0, 0.0, 0.0);
        let step = |t_s: f64| StepRecord {
            t_s,
            truth: at,
            fix: None,
            estimate: at,
            pallet: at,
            pallet_estimate: at,
            steer_cmd_rad: 0.1,
            steer_rad: 0.05,
            speed_cmd_mps: 0.5,
            speed_mps: 0.25,
            lookahead: [0.0, 0.0],
            cross_track_m: 0.0,
            path_curvature_per_m: 0.0,
            contact_force_n: 0.0,
        };
        log.step(&step(0.0));
        log.step(&step(0.01));
        log.finish().expect("written");
        let text = std::fs::read_to_string(&path).expect("read");
        assert_eq!(
            text,
            format!("{HEADER}0,0.1,0.05,0.5,0.25\n0.01,0.1,0.05,0.5,0.25\n")
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}
