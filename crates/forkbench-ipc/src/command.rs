//! The settings every external component shares: the command, its answer deadline and the environment it gets; checked once here for planners and detectors alike.

use std::path::PathBuf;
use std::time::Duration;

use serde::Deserialize;

use crate::pool::PoolKey;
use crate::process::EnvPolicy;

/// Longest answer time a scenario may allow an external component.
pub const MAX_TIMEOUT_S: f64 = 600.0;

/// `command`, `timeout_s` and `pass_env` of an `external` component's table.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CommandConfig {
    /// Program and arguments, run in the directory of the file that names them.
    pub command: Vec<String>,
    /// Longest wait for the hello and for each answer (sending the request included);
    /// past it the process group is killed and that trial's request fails.
    #[serde(default = "default_timeout")]
    pub timeout_s: f64,
    /// Environment variables passed: all of forkbench's when absent, only these when
    /// given (an allow-list, e.g. `["PATH", "HOME"]`).
    #[serde(default)]
    pub pass_env: Option<Vec<String>>,
}

fn default_timeout() -> f64 {
    10.0
}

impl CommandConfig {
    /// The field at fault and why, if any: an empty command or a timeout out of range.
    /// `example` shows a command for the message (`["python3", "planner.py"]`).
    pub fn problem(&self, example: &str) -> Option<(&'static str, String)> {
        if self.command.is_empty() || self.command[0].trim().is_empty() {
            return Some(("command", format!("must name a program: {example}")));
        }
        if !(self.timeout_s.is_finite() && self.timeout_s > 0.0 && self.timeout_s <= MAX_TIMEOUT_S)
        {
            return Some(("timeout_s", format!("must lie in (0, {MAX_TIMEOUT_S}] s")));
        }
        None
    }

    pub fn timeout(&self) -> Duration {
        Duration::from_secs_f64(self.timeout_s)
    }

    pub fn env(&self) -> EnvPolicy {
        self.pass_env
            .clone()
            .map_or(EnvPolicy::Inherit, EnvPolicy::Only)
    }

    /// The pool key of this command speaking `protocol`, run in `dir`.
    pub(crate) fn pool_key(&self, protocol: &'static str, dir: &std::path::Path) -> PoolKey {
        (
            protocol,
            self.command.clone(),
            PathBuf::from(dir),
            self.env(),
        )
    }

    /// The command as the circuit breaker counts it.
    pub(crate) fn breaker_key(&self, dir: &std::path::Path) -> String {
        format!("{:?} in {}", self.command, dir.display())
    }
}
