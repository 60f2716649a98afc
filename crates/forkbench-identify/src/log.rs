//! An actuator log: runs of timestamped commands and measured responses, read from CSV with named columns and checked before any fit.

use std::path::Path;

/// Largest log read: far more than hours of 100 Hz samples.
pub const MAX_LOG_BYTES: u64 = 512 << 20;
/// Fewest samples a run must have to take part in a fit.
pub const MIN_RUN_SAMPLES: usize = 20;

/// One actuator's command and measured response, sample by sample.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Channel {
    pub cmd: Vec<f64>,
    pub measured: Vec<f64>,
}

/// One run: a stretch of driving logged without a break.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Run {
    pub t_s: Vec<f64>,
    pub steer: Option<Channel>,
    pub speed: Option<Channel>,
}

/// Runs of an actuator log, in the order read.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ActuatorLog {
    pub runs: Vec<Run>,
}

/// Why a log cannot be fitted, naming the file and, where one is to blame, its line and column.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LogError {
    #[error("{file}: {reason}")]
    File { file: String, reason: String },
    #[error("{file}: {reason}")]
    Mcap {
        file: String,
        reason: crate::mcap_log::McapError,
    },
    #[error("{file}:{line}: column {column}: {reason}")]
    Cell {
        file: String,
        line: u64,
        column: String,
        reason: String,
    },
}

/// The columns an actuator log names: time, then each channel's command and response.
pub const COLUMNS: [&str; 5] = [
    "t_s",
    "steer_cmd_rad",
    "steer_rad",
    "speed_cmd_mps",
    "speed_mps",
];

/// Reads the CSV log at `path` (header row naming the columns; other columns ignored;
/// an optional `run` column starts a new run where its value changes).
pub fn read_csv(path: &Path) -> Result<ActuatorLog, LogError> {
    let file = path.display().to_string();
    let text =
        forkbench_core::files::read_text(path, MAX_LOG_BYTES).map_err(|e| LogError::File {
            file: file.clone(),
            reason: e.to_string(),
        })?;
    parse_csv(&text, &file)
}

/// Where each named column stands in the header.
struct Header {
    t: usize,
    run: Option<usize>,
    steer: Option<(usize, usize)>,
    speed: Option<(usize, usize)>,
}

fn header(rec: &csv::StringRecord, file: &str) -> Result<Header, LogError> {
    let find = |name: &str| rec.iter().position(|h| h.trim() == name);
    let bad = |reason: String| LogError::File {
        file: file.to_owned(),
        reason,
    };
    let t = find("t_s").ok_or_else(|| {
        bad(format!(
            "no `t_s` column in the header (an actuator log names {})",
            COLUMNS.join(", ")
        ))
    })?;
    let pair = |cmd: &str, got: &str| match (find(cmd), find(got)) {
        (Some(c), Some(m)) => Ok(Some((c, m))),
        (None, None) => Ok(None),
        (Some(_), None) => Err(bad(format!("`{cmd}` without `{got}`: a fit needs both"))),
        (None, Some(_)) => Err(bad(format!("`{got}` without `{cmd}`: a fit needs both"))),
    };
    let h = Header {
        t,
        run: find("run"),
        steer: pair("steer_cmd_rad", "steer_rad")?,
        speed: pair("speed_cmd_mps", "speed_mps")?,
    };
    if h.steer.is_none() && h.speed.is_none() {
        return Err(bad(
            "neither channel: a log needs `steer_cmd_rad` and `steer_rad`, or \
             `speed_cmd_mps` and `speed_mps`"
                .into(),
        ));
    }
    Ok(h)
}

/// The largest magnitude a column may hold, and why: a value beyond it is a unit slip or
/// a corrupt cell, and would overflow the fit's sums.
fn bound(column: &str) -> (f64, &'static str) {
    match column {
        "t_s" => (1e10, "s, past any clock's epoch time"),
        "steer_cmd_rad" | "steer_rad" => (7.0, "rad, more than a full turn of the wheel"),
        _ => (100.0, "m/s, beyond any forklift"),
    }
}

/// Parses a CSV log's text; `file` names it in errors.
pub fn parse_csv(text: &str, file: &str) -> Result<ActuatorLog, LogError> {
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(true)
        .flexible(false)
        .from_reader(text.as_bytes());
    let head = reader.headers().map_err(|e| LogError::File {
        file: file.to_owned(),
        reason: format!("reading the header: {e}"),
    })?;
    let h = header(head, file)?;
    let names: Vec<String> = head.iter().map(|s| s.trim().to_owned()).collect();
    let mut log = ActuatorLog::default();
    let mut run_id: Option<String> = None;
    for (i, rec) in reader.records().enumerate() {
        let line = i as u64 + 2;
        let rec = rec.map_err(|e| LogError::File {
            file: file.to_owned(),
            reason: format!("line {line}: {e}"),
        })?;
        let cell = |col: usize| -> Result<f64, LogError> {
            let text = rec.get(col).unwrap_or("").trim();
            let bad = |reason: &str| LogError::Cell {
                file: file.to_owned(),
                line,
                column: names[col].clone(),
                reason: format!("{reason} (got {text:?})"),
            };
            let v: f64 = text.parse().map_err(|_| bad("not a number"))?;
            if !v.is_finite() {
                return Err(bad("not a finite number"));
            }
            let (most, what) = bound(&names[col]);
            if v.abs() > most {
                return Err(bad(&format!("beyond ±{most} {what}")));
            }
            Ok(v)
        };
        let id = h.run.map(|c| rec.get(c).unwrap_or("").trim().to_owned());
        if log.runs.is_empty() || id != run_id {
            log.runs.push(Run {
                steer: h.steer.map(|_| Channel::default()),
                speed: h.speed.map(|_| Channel::default()),
                ..Run::default()
            });
            run_id = id;
        }
        let t = cell(h.t)?;
        let run = log.runs.last_mut().expect("pushed above");
        if let Some(&prev) = run.t_s.last()
            && t <= prev
        {
            return Err(LogError::Cell {
                file: file.to_owned(),
                line,
                column: "t_s".into(),
                reason: format!(
                    "time must increase within a run ({t} after {prev}); mark separate runs \
                     with a `run` column"
                ),
            });
        }
        run.t_s.push(t);
        for (cols, ch) in [(h.steer, &mut run.steer), (h.speed, &mut run.speed)] {
            if let (Some((c, m)), Some(ch)) = (cols, ch.as_mut()) {
                ch.cmd.push(cell(c)?);
                ch.measured.push(cell(m)?);
            }
        }
    }
    Ok(log)
}

/// A log as CSV with the columns a fit reads (and `run`): what forkbench writes. A channel
/// no run has is left out.
pub fn to_csv(log: &ActuatorLog) -> String {
    let steer = log.runs.iter().any(|r| r.steer.is_some());
    let speed = log.runs.iter().any(|r| r.speed.is_some());
    let mut s = String::from("run,t_s");
    if steer {
        s.push_str(",steer_cmd_rad,steer_rad");
    }
    if speed {
        s.push_str(",speed_cmd_mps,speed_mps");
    }
    s.push('\n');
    for (r, run) in log.runs.iter().enumerate() {
        for (i, t) in run.t_s.iter().enumerate() {
            s.push_str(&format!("{r},{t}"));
            for (on, ch) in [(steer, &run.steer), (speed, &run.speed)] {
                if on {
                    let (c, m) = ch
                        .as_ref()
                        .map_or((f64::NAN, f64::NAN), |c| (c.cmd[i], c.measured[i]));
                    s.push_str(&format!(",{c},{m}"));
                }
            }
            s.push('\n');
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_split_on_the_run_column_and_bad_cells_are_named() {
        let text =
            "run,t_s,steer_cmd_rad,steer_rad,other\n0,0,0.1,0,x\n0,0.01,0.1,0.01,y\n1,0,0,0,z\n";
        let log = parse_csv(text, "log.csv").expect("valid");
        assert_eq!(log.runs.len(), 2);
        assert!(log.runs[0].speed.is_none());
        assert_eq!(
            log.runs[0].steer.as_ref().expect("steer").measured,
            vec![0.0, 0.01]
        );
        let e = parse_csv("t_s,steer_cmd_rad,steer_rad\n0,0,0\n0.01,NaN,0\n", "l.csv")
            .expect_err("NaN");
        assert_eq!(
            e.to_string(),
            "l.csv:3: column steer_cmd_rad: not a finite number (got \"NaN\")"
        );
        let e = parse_csv("t_s,steer_cmd_rad,steer_rad\n0,0,0\n0,0,0\n", "l.csv")
            .expect_err("repeated time");
        assert!(e.to_string().contains("time must increase"), "{e}");
        let e = parse_csv("t_s,steer_cmd_rad\n0,0\n", "l.csv").expect_err("half a channel");
        assert!(e.to_string().contains("without `steer_rad`"), "{e}");
    }
}
