//! Planners in any language: a child process speaking newline-delimited JSON (docs/external-planner.md).

mod check;
mod process;
pub mod protocol;

use std::path::PathBuf;
use std::sync::LazyLock;

use forkbench_ipc::{Breaker, ExchangeError, Process, Spawn, clip};

use forkbench_core::settings::{self, Settings, SettingsError};

pub use check::{ENDPOINT_TOLERANCE_M, ENDPOINT_TOLERANCE_RAD, MAX_SPACING_M, path_violation};
pub use forkbench_ipc::release_pooled;
pub use process::dir_of;
use protocol::{PROTOCOL, RequestMsg, ResponseMsg, VERSION, to_path};

use crate::{Plan, PlanError, PlanParams, PlanRequest, Planner};

pub use forkbench_ipc::MAX_TIMEOUT_S;

/// Settings of `[planner] kind = "external"`: the shared command settings.
pub type ExternalConfig = forkbench_ipc::CommandConfig;

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
        if let Some((field, why)) = cfg.problem("[\"python3\", \"planner.py\"]") {
            return Err(SettingsError::field(field, why));
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

    /// This thread's pooled process for the planner, or a new one that answered the hello.
    fn take_process(&self) -> Result<(Process, u64), ExchangeError> {
        if let Some(p) = forkbench_ipc::take_pooled(&self.cfg.pool_key(PROTOCOL, &self.dir)) {
            return Ok(p);
        }
        let spawn = Spawn {
            command: &self.cfg.command,
            dir: &self.dir,
            env: &self.cfg.env(),
            what: "planner",
        };
        let p =
            forkbench_ipc::start_with_hello(spawn, PROTOCOL, VERSION.into(), self.cfg.timeout())?;
        Ok((p, 0))
    }

    /// One request, counted by the circuit breaker.
    fn request(&self, req: &PlanRequest) -> Result<ResponseMsg, String> {
        let key = self.cfg.breaker_key(&self.dir);
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
        let answer = proc.exchange(&line, self.cfg.timeout())?;
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
        forkbench_ipc::put_back(self.cfg.pool_key(PROTOCOL, &self.dir), proc, id + 1);
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
