//! Planners in any language: a child process speaking newline-delimited JSON (docs/external-planner.md).

mod check;
mod process;
pub mod protocol;

use std::path::PathBuf;
use std::sync::LazyLock;
use std::time::Duration;

use forkbench_ipc::{Breaker, EnvPolicy, ExchangeError, PoolKey, Process, Spawn, clip};

use forkbench_core::settings::{self, Settings, SettingsError};
use serde::Deserialize;

pub use check::{ENDPOINT_TOLERANCE_M, ENDPOINT_TOLERANCE_RAD, MAX_SPACING_M, path_violation};
pub use forkbench_ipc::release_pooled;
pub use process::dir_of;
use protocol::{PROTOCOL, RequestMsg, ResponseMsg, VERSION, to_path};

use crate::{Plan, PlanError, PlanParams, PlanRequest, Planner};

/// Longest answer time a scenario may allow a planner.
pub const MAX_TIMEOUT_S: f64 = 600.0;

/// Settings of `[planner] kind = "external"`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExternalConfig {
    /// Program and arguments, run in the directory of the file that names them.
    pub command: Vec<String>,
    /// Longest wait for the hello and for each plan (sending the request included); past
    /// it the process group is killed and the trial's plan fails.
    #[serde(default = "default_timeout")]
    pub timeout_s: f64,
    /// Environment variables passed to the planner: all of forkbench's when absent, only
    /// these when given (an allow-list, e.g. `["PATH", "HOME"]`).
    #[serde(default)]
    pub pass_env: Option<Vec<String>>,
}

fn default_timeout() -> f64 {
    10.0
}

/// Consecutive timeouts per command, across worker threads.
static BREAKER: LazyLock<Breaker> = LazyLock::new(Breaker::default);

/// An external planner, as configured; the process lives in this thread's pool.
#[derive(Debug, Clone)]
pub struct ExternalPlanner {
    cfg: ExternalConfig,
    dir: PathBuf,
    /// What its plans and errors are reported under.
    name: String,
}

impl ExternalPlanner {
    /// From a `[planner]` table; `dir` is where the command runs.
    pub fn from_settings(s: &Settings, dir: PathBuf) -> Result<Self, SettingsError> {
        let cfg: ExternalConfig = settings::parse(s)?;
        if cfg.command.is_empty() || cfg.command[0].trim().is_empty() {
            return Err(SettingsError::field(
                "command",
                "must name a program: [\"python3\", \"planner.py\"]",
            ));
        }
        if !(cfg.timeout_s.is_finite() && cfg.timeout_s > 0.0 && cfg.timeout_s <= MAX_TIMEOUT_S) {
            return Err(SettingsError::field(
                "timeout_s",
                format!("must lie in (0, {MAX_TIMEOUT_S}] s"),
            ));
        }
        Ok(Self {
            cfg,
            dir,
            name: "external".into(),
        })
    }

    /// The same planner reported under `name` (a scenario's `[planner] name`).
    pub fn named(mut self, name: &str) -> Self {
        self.name = name.to_owned();
        self
    }

    fn timeout(&self) -> Duration {
        Duration::from_secs_f64(self.cfg.timeout_s)
    }

    fn env(&self) -> EnvPolicy {
        self.cfg
            .pass_env
            .clone()
            .map_or(EnvPolicy::Inherit, EnvPolicy::Only)
    }

    /// The command as the circuit breaker knows it.
    fn breaker_key(&self) -> String {
        format!("{:?} in {}", self.cfg.command, self.dir.display())
    }

    fn pool_key(&self) -> PoolKey {
        (
            PROTOCOL,
            self.cfg.command.clone(),
            self.dir.clone(),
            self.env(),
        )
    }

    /// This thread's pooled process for the planner, or a new one that answered the hello.
    fn take_process(&self) -> Result<(Process, u64), ExchangeError> {
        if let Some(p) = forkbench_ipc::take_pooled(&self.pool_key()) {
            return Ok(p);
        }
        let spawn = Spawn {
            command: &self.cfg.command,
            dir: &self.dir,
            env: &self.env(),
            what: "planner",
        };
        let p = forkbench_ipc::start_with_hello(spawn, PROTOCOL, VERSION.into(), self.timeout())?;
        Ok((p, 0))
    }

    /// One request, counted by the circuit breaker.
    fn request(&self, req: &PlanRequest) -> Result<ResponseMsg, String> {
        let key = self.breaker_key();
        BREAKER.check(&key)?;
        let r = self.exchange(req);
        BREAKER.record(&key, r.as_ref().is_err_and(|e| e.timed_out));
        r.map_err(String::from)
    }

    /// One request on a (possibly new) process; the process goes back to the pool only
    /// when the exchange kept to the protocol.
    fn exchange(&self, req: &PlanRequest) -> Result<ResponseMsg, ExchangeError> {
        let (mut proc, id) = self.take_process()?;
        let line = serde_json::to_string(&RequestMsg::new(id, req))
            .map_err(|e| ExchangeError::other(e.to_string()))?;
        let answer = proc.exchange(&line, self.timeout())?;
        let msg: ResponseMsg = serde_json::from_str(&answer).map_err(|e| {
            // Python's json writes NaN and Infinity, which JSON has no numbers for.
            let hint = if ["NaN", "Infinity", "null"]
                .iter()
                .any(|t| answer.contains(t))
            {
                "; a non-finite value (NaN, Infinity) in the path?"
            } else {
                ""
            };
            ExchangeError::other(format!(
                "invalid JSON in the answer ({e}{hint}): {:?}",
                clip(&answer)
            ))
        })?;
        let got = match &msg {
            ResponseMsg::Path { id, .. } | ResponseMsg::Error { id, .. } => *id,
        };
        if got != id {
            return Err(ExchangeError::other(format!(
                "answered request {got}, expected {id}"
            )));
        }
        forkbench_ipc::put_back(self.pool_key(), proc, id + 1);
        Ok(msg)
    }
}

impl Planner for ExternalPlanner {
    fn name(&self) -> &str {
        &self.name
    }

    fn plan(&mut self, req: &PlanRequest) -> Result<Plan, PlanError> {
        let name = self.name().to_owned();
        let rejected = |reason: String| PlanError::Rejected {
            planner: name.clone(),
            reason,
        };
        match self.request(req).map_err(rejected)? {
            ResponseMsg::Error { message, .. } => Err(PlanError::Unreachable {
                planner: name,
                reason: clip(&message),
            }),
            ResponseMsg::Path {
                samples,
                cost,
                info,
                ..
            } => {
                let path = to_path(&samples);
                if let Some(why) = path_violation(&path, req) {
                    return Err(rejected(why));
                }
                Ok(Plan {
                    planner: name,
                    params: PlanParams::Other(info.unwrap_or(serde_json::Value::Null)),
                    cost: cost.unwrap_or(f64::NAN),
                    path,
                    control_polygon_m: None,
                })
            }
        }
    }
}
