//! One external planner process: the shared child-process machinery (`forkbench-ipc`) plus the planner protocol's hello.

use std::path::{Path as FsPath, PathBuf};
use std::time::Duration;

use forkbench_ipc::Spawn;
pub use forkbench_ipc::{EnvPolicy, ExchangeError, clip};

use super::protocol::{Hello, PROTOCOL, VERSION};

/// A running planner that has answered the hello.
#[derive(Debug)]
pub struct Process(forkbench_ipc::Process);

impl Process {
    /// Starts `command` in `dir` and exchanges hellos within `timeout`.
    pub fn start(
        command: &[String],
        dir: &FsPath,
        env: &EnvPolicy,
        timeout: Duration,
    ) -> Result<Self, ExchangeError> {
        let p = forkbench_ipc::Process::start(Spawn {
            command,
            dir,
            env,
            what: "planner",
        })
        .map_err(ExchangeError::other)?;
        let mut p = Self(p);
        p.handshake(timeout)?;
        Ok(p)
    }

    fn handshake(&mut self, timeout: Duration) -> Result<(), ExchangeError> {
        let hello = serde_json::to_string(&Hello::ours())
            .map_err(|e| ExchangeError::other(e.to_string()))?;
        let line = self.exchange(&hello, timeout)?;
        let theirs: Hello = serde_json::from_str(&line)
            .map_err(|e| ExchangeError::other(format!("invalid hello {:?}: {e}", clip(&line))))?;
        if theirs.kind != "hello" || theirs.protocol != PROTOCOL {
            return Err(ExchangeError::other(format!(
                "the first line must be a {PROTOCOL} hello, got {:?}",
                clip(&line)
            )));
        }
        if theirs.version != VERSION {
            return Err(ExchangeError::other(format!(
                "the planner speaks protocol version {}, forkbench speaks {VERSION}",
                theirs.version
            )));
        }
        Ok(())
    }

    /// Sends one line and waits at most `timeout`, sending included, for the answer line.
    pub fn exchange(&mut self, line: &str, timeout: Duration) -> Result<String, ExchangeError> {
        self.0.exchange(line, timeout)
    }

    /// Whether it printed while it waited in the pool (a protocol violation).
    pub fn has_idle_output(&mut self) -> bool {
        self.0.has_idle_output()
    }
}

/// Where a planner defined in `file` runs: that file's directory.
pub fn dir_of(file: &FsPath) -> PathBuf {
    file.parent()
        .filter(|p| !p.as_os_str().is_empty())
        .map_or_else(|| PathBuf::from("."), FsPath::to_path_buf)
}
