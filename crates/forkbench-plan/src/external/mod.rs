//! Planners in any language: a child process speaking newline-delimited JSON (docs/external-planner.md).

mod check;
mod process;
pub mod protocol;

use std::path::PathBuf;
use std::sync::LazyLock;

use forkbench_ipc::{Breaker, Callee, ExchangeError, clip};

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

    /// One request on this thread's pooled planner (a new one when none waits), counted
    /// by the circuit breaker.
    fn request(&self, req: &PlanRequest) -> Result<ResponseMsg, ExchangeError> {
        let callee = Callee {
            dir: &self.dir,
            protocol: PROTOCOL,
            version: VERSION.into(),
            what: "planner",
            breaker: &BREAKER,
        };
        let request = |id| {
            serde_json::to_string(&RequestMsg::new(id, req))
                .map_err(|e| ExchangeError::other(e.to_string()))
        };
        self.cfg.call(callee, request, read_answer)
    }
}

/// A planner's answer line and the request id it answers.
fn read_answer(answer: &str) -> Result<(u64, ResponseMsg), ExchangeError> {
    let msg: ResponseMsg = serde_json::from_str(answer).map_err(|e| {
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
            clip(answer)
        ))
    })?;
    let id = match &msg {
        ResponseMsg::Path { id, .. } | ResponseMsg::Error { id, .. } => *id,
    };
    Ok((id, msg))
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
        match self.request(req).map_err(|e| rejected(e.message))? {
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
