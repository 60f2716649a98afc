//! Trackers in any language: a child process speaking JSON lines (docs/external-tracker.md), one request per control tick, with the robustness of external planners: a deadline per request, and a crash, a hang or a bad answer fails only that trial.

use std::path::PathBuf;
use std::sync::LazyLock;

use forkbench_core::settings::{self, Settings, SettingsError};
use forkbench_core::{ForkliftSpec, Path, PathSample, Pose2};
use forkbench_ipc::{Breaker, Callee, clip};
use serde::{Deserialize, Serialize};

use crate::{Command, Tracker, TrackerInput};

/// Name of the protocol in both hello messages.
pub const PROTOCOL: &str = "forkbench-tracker";
/// The protocol version this forkbench speaks.
pub const VERSION: u64 = 1;
/// Settings of `[tracker] kind = "external"`: the shared command settings.
pub type ExternalTrackerConfig = forkbench_ipc::CommandConfig;

/// Consecutive timeouts per command, across worker threads.
static BREAKER: LazyLock<Breaker> = LazyLock::new(Breaker::default);

/// The truck as sent: its spec with its steering, drive and control always written (a
/// spec leaves them out at their defaults, which a tracker cannot know, and a stop or a
/// dead-time compensation needs them), plus the derived curvature limit.
fn truck_msg(truck: &ForkliftSpec) -> serde_json::Value {
    let mut v = serde_json::to_value(truck).unwrap_or(serde_json::Value::Null);
    if let Some(m) = v.as_object_mut() {
        let parts = [
            ("steering", serde_json::to_value(&truck.steering)),
            ("drive", serde_json::to_value(&truck.drive)),
            ("control", serde_json::to_value(&truck.control)),
            (
                "max_curvature_per_m",
                Ok(truck.max_curvature_per_m().into()),
            ),
        ];
        for (k, part) in parts {
            if let Ok(part) = part {
                m.insert(k.to_owned(), part);
            }
        }
    }
    v
}

/// The path as sent: samples as `[s_m, x_m, y_m, heading_rad, curvature_per_m]`, the
/// form an external planner answers with.
#[derive(Debug, Clone, Serialize)]
struct PathMsg {
    /// Driven backwards (forks trailing).
    reverse: bool,
    samples: Vec<[f64; 5]>,
}

/// What forkbench sends: a new path to follow, or one control tick.
#[derive(Debug, Clone, Serialize)]
#[serde(tag = "type", rename_all = "lowercase")]
enum RequestMsg {
    Reset {
        id: u64,
        path: PathMsg,
        truck: serde_json::Value,
    },
    Tick {
        id: u64,
        t_s: f64,
        pose: Pose2,
        /// When the newest localisation fix in `pose` was measured (null before one).
        fix_measured_s: Option<f64>,
        speed_mps: f64,
        steer_rad: f64,
    },
}

/// An answer: the reset taken, a command, or the tracker's own error.
#[derive(Debug, Clone, Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
enum ResponseMsg {
    Ok {
        id: u64,
    },
    Command {
        id: u64,
        speed_mps: f64,
        steer_rad: f64,
        done: bool,
        /// Signed offset from the path, for the recordings (left positive).
        #[serde(default)]
        cross_track_m: Option<f64>,
        /// The point it steers toward, for the recordings.
        #[serde(default)]
        target: Option<[f64; 2]>,
    },
    Error {
        id: u64,
        message: String,
    },
}

impl ResponseMsg {
    fn id(&self) -> u64 {
        match self {
            Self::Ok { id } | Self::Command { id, .. } | Self::Error { id, .. } => *id,
        }
    }
}

/// An external tracker, as configured; its process lives in this thread's pool. After
/// the first failure it commands a stop and reports the fault until the next trial's
/// reset.
#[derive(Debug, Clone)]
pub struct ExternalTracker {
    cfg: ExternalTrackerConfig,
    dir: PathBuf,
    name: String,
    fault: Option<String>,
}

impl ExternalTracker {
    /// From a `[tracker]` table; `dir` is where the command runs, `name` what results
    /// and errors are reported under.
    pub fn from_settings(s: &Settings, dir: PathBuf, name: &str) -> Result<Self, SettingsError> {
        let cfg: ExternalTrackerConfig = settings::parse(s)?;
        if let Some((field, why)) = cfg.problem("[\"python3\", \"tracker.py\"]") {
            return Err(SettingsError::field(field, why));
        }
        Ok(Self {
            cfg,
            dir,
            name: name.to_owned(),
            fault: None,
        })
    }

    /// One request on this thread's pooled tracker (a new one when none waits).
    fn request(&self, msg: impl FnOnce(u64) -> RequestMsg) -> Result<ResponseMsg, String> {
        let callee = Callee {
            dir: &self.dir,
            protocol: PROTOCOL,
            version: VERSION,
            what: "tracker",
            breaker: &BREAKER,
        };
        self.cfg
            .call_json(callee, msg, ResponseMsg::id)
            .map_err(|e| e.message)
    }

    /// The command from an answer, or why the answer cannot steer the truck.
    fn command_of(
        answer: ResponseMsg,
        truck: &ForkliftSpec,
        at: &Pose2,
    ) -> Result<Command, String> {
        match answer {
            ResponseMsg::Command {
                speed_mps,
                steer_rad,
                done,
                cross_track_m,
                target,
                ..
            } => {
                if !(speed_mps.is_finite() && steer_rad.is_finite()) {
                    return Err(format!(
                        "the command is not finite: speed {speed_mps}, steering {steer_rad}"
                    ));
                }
                let target = target.filter(|t| t.iter().all(|v| v.is_finite()));
                Ok(Command {
                    speed_mps: speed_mps.clamp(-truck.max_speed_mps, truck.max_speed_mps),
                    steer_rad: steer_rad.clamp(-truck.max_steer_rad, truck.max_steer_rad),
                    lookahead_point: target.unwrap_or([at.x_m, at.y_m]),
                    cross_track_m: cross_track_m.filter(|v| v.is_finite()).unwrap_or(0.0),
                    remaining_m: f64::NAN,
                    path_curvature_per_m: 0.0,
                    done,
                })
            }
            ResponseMsg::Error { message, .. } => Err(format!("it reported: {}", clip(&message))),
            ResponseMsg::Ok { .. } => Err("answered a tick with \"ok\", not a command".into()),
        }
    }
}

fn sample_row(p: &PathSample) -> [f64; 5] {
    [p.s_m, p.x_m, p.y_m, p.heading_rad, p.curvature_per_m]
}

/// Stand still: what the truck is told once the tracker has failed.
fn halt(at: &Pose2) -> Command {
    Command {
        speed_mps: 0.0,
        steer_rad: 0.0,
        lookahead_point: [at.x_m, at.y_m],
        cross_track_m: 0.0,
        remaining_m: f64::NAN,
        path_curvature_per_m: 0.0,
        done: false,
    }
}

impl Tracker for ExternalTracker {
    fn name(&self) -> &str {
        &self.name
    }

    fn reset(&mut self, path: &Path, truck: &ForkliftSpec) {
        self.fault = None;
        let msg = |id| RequestMsg::Reset {
            id,
            path: PathMsg {
                reverse: path.reverse,
                samples: path.samples.iter().map(sample_row).collect(),
            },
            truck: truck_msg(truck),
        };
        self.fault = match self.request(msg) {
            Ok(ResponseMsg::Ok { .. }) => None,
            Ok(ResponseMsg::Error { message, .. }) => {
                Some(format!("refused the path: {}", clip(&message)))
            }
            Ok(_) => Some("answered a reset with a command, not \"ok\"".into()),
            Err(e) => Some(e),
        };
    }

    fn command(&mut self, input: &TrackerInput) -> Command {
        if self.fault.is_some() {
            return halt(&input.pose);
        }
        let msg = |id| RequestMsg::Tick {
            id,
            t_s: input.t_s,
            pose: input.pose,
            fix_measured_s: input.fix_measured_s,
            speed_mps: input.speed_mps,
            steer_rad: input.steer_rad,
        };
        match self
            .request(msg)
            .and_then(|a| Self::command_of(a, input.truck, &input.pose))
        {
            Ok(cmd) => cmd,
            Err(why) => {
                self.fault = Some(why);
                halt(&input.pose)
            }
        }
    }

    fn fault(&self) -> Option<String> {
        self.fault.clone()
    }
}

#[cfg(test)]
mod wire_tests {
    use super::*;

    #[test]
    fn the_reset_carries_the_actuators_even_at_their_defaults() {
        let truck = ForkliftSpec::default();
        let v = truck_msg(&truck);
        assert_eq!(v["drive"]["dead_time_s"], truck.drive.dead_time_s);
        assert_eq!(v["drive"]["creep_speed_mps"], truck.drive.creep_speed_mps);
        assert_eq!(
            v["control"]["transport_delay_s"],
            truck.control.transport_delay_s
        );
        assert_eq!(v["steering"]["dead_time_s"], truck.steering.dead_time_s);
        assert_eq!(v["wheelbase_m"], truck.wheelbase_m);
        assert_eq!(v["max_curvature_per_m"], truck.max_curvature_per_m());
    }
}
