//! Identifies the truck's actuators from logs of commands and measured responses (the dead time on a grid, the time constant and limits by output-error least squares, validated on held-out runs), and makes such logs by driving the simulated truck through a step test.

pub mod cdr;
pub mod check;
pub mod excite;
pub mod fit;
pub mod log;
pub mod mcap_log;
pub mod model;
pub mod rate;

use std::collections::BTreeMap;

use serde::Serialize;

pub use log::{ActuatorLog, Channel, LogError, Run, parse_csv, read_csv, to_csv};
pub use model::Kind;

/// Why a log could not be identified.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum IdentifyError {
    #[error(transparent)]
    Log(#[from] LogError),
    #[error(
        "{channel}: too short to fit ({samples} samples over {duration_s:.2} s; at least 100 samples and 2 s)"
    )]
    TooShort {
        channel: &'static str,
        samples: usize,
        duration_s: f64,
    },
    #[error(
        "{channel}: no excitation: the command spans only {span:.4} (at least {threshold} is needed to see a response)"
    )]
    NoExcitation {
        channel: &'static str,
        span: f64,
        threshold: f64,
    },
    #[error(
        "{channel}: no response: the measured value spans only {span:.4} while the command moves (at least {threshold} is needed; a wheel held at its stop or a stuck sensor tells nothing of the dynamics)"
    )]
    NoResponse {
        channel: &'static str,
        span: f64,
        threshold: f64,
    },
    #[error("the log has neither a steering nor a drive channel with runs to fit")]
    Empty,
}

/// The measured and fitted response of one validation run, for a plot.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Trace {
    pub t_s: Vec<f64>,
    pub command: Vec<f64>,
    pub measured: Vec<f64>,
    pub fitted: Vec<f64>,
}

/// One channel's fit: its settings by the truck file's names, and how well they predict.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ChannelFit {
    /// `steering` or `drive`.
    pub channel: String,
    /// Fitted values by the truck file's dotted names.
    pub settings: BTreeMap<String, f64>,
    /// Settings the log cannot tell: limits it never drove the actuator into, and fitted
    /// values a truck file would refuse (the reason is in `notes`).
    pub not_identified: Vec<String>,
    /// The spacing of the dead-time grid searched (the log's sample step, at least 10 ms).
    pub dead_time_step_s: f64,
    /// What was done to the log before the fit, and settings dropped after it.
    pub notes: Vec<String>,
    /// NRMSE fit % on the held-out runs (on the fitted runs when there is only one).
    pub fit_percent: f64,
    pub fit_runs: usize,
    pub held_out_runs: usize,
    pub samples: usize,
    /// RMS error at the end of open-loop rollouts of each horizon (s), on the held-out runs.
    pub rollout_rmse: Vec<(f64, Option<f64>)>,
    /// The first validation run, measured against fitted.
    #[serde(skip)]
    pub trace: Trace,
}

/// Every channel the log has, fitted.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Identified {
    pub channels: Vec<ChannelFit>,
}

/// Fits every channel `log` has.
pub fn identify(log: &ActuatorLog) -> Result<Identified, IdentifyError> {
    let mut channels = Vec::new();
    for kind in [Kind::Steering, Kind::Drive] {
        if log.runs.iter().any(|r| model::channel(r, kind).is_some()) {
            channels.push(fit::identify_channel(kind, log)?);
        }
    }
    if channels.is_empty() {
        return Err(IdentifyError::Empty);
    }
    Ok(Identified { channels })
}

impl Identified {
    /// A truck file `--truck` takes: the fitted settings. The fitted dead time is all the
    /// delay between the logged command and the response, so the transport delay is 0.
    pub fn truck_toml(&self) -> String {
        let mut top = String::from(
            "# Identified by forkbench identify: the delay between the logged command and the\n\
             # response is all in each channel's dead time.\n",
        );
        let mut tables: BTreeMap<&str, String> = BTreeMap::new();
        for c in &self.channels {
            for (k, v) in &c.settings {
                match k.split_once('.') {
                    Some((table, key)) => tables
                        .entry(table)
                        .or_default()
                        .push_str(&format!("{key} = {v:.4}\n")),
                    None => top.push_str(&format!("{k} = {v:.4}\n")),
                }
            }
        }
        tables
            .entry("control")
            .or_default()
            .push_str("transport_delay_s = 0.0\n");
        for (t, body) in tables {
            top.push_str(&format!("\n[{t}]\n{body}"));
        }
        top
    }

    /// The fit as text, a block per channel.
    pub fn text(&self) -> String {
        let mut s = String::new();
        for c in &self.channels {
            let on = match c.held_out_runs {
                0 => "on the fitted run itself (one run: none held out)".to_owned(),
                n => format!("on {n} held-out run(s)"),
            };
            s.push_str(&format!(
                "{}: fit {:.1} % {on} ({} fitted, {} samples)\n",
                c.channel, c.fit_percent, c.fit_runs, c.samples
            ));
            for (k, v) in &c.settings {
                s.push_str(&format!("  {k} = {v:.4}\n"));
            }
            s.push_str(&format!(
                "  dead time searched on a {:.3} s grid\n",
                c.dead_time_step_s
            ));
            for k in &c.not_identified {
                // A dropped fit says why in its note; a limit left out was never reached.
                if !c.notes.iter().any(|n| n.starts_with(&format!("{k}:"))) {
                    s.push_str(&format!("  {k}: not reached in the log, not identified\n"));
                }
            }
            for n in &c.notes {
                s.push_str(&format!("  note: {n}\n"));
            }
            let roll: Vec<String> = c
                .rollout_rmse
                .iter()
                .map(|(h, e)| match e {
                    Some(e) => format!("{h} s: {e:.4}"),
                    None => format!("{h} s: –"),
                })
                .collect();
            s.push_str(&format!("  rollout RMS error {}\n", roll.join(", ")));
        }
        s
    }
}
