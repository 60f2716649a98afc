//! An actuator log from an MCAP recording: one topic's JSON messages, with the fields that hold the time, commands and responses named (forkbench's own telemetry by default).

use std::path::Path;

use crate::log::{ActuatorLog, COLUMNS, LogError, parse_csv};

/// Where forkbench's recordings keep each control step.
pub const TELEMETRY_TOPIC: &str = "/forkbench/telemetry";

/// Reads `topic`'s JSON messages in `path` as a log: `fields` name the time, steering
/// command and response, speed command and response (in [`COLUMNS`]' order; an empty
/// name leaves that channel out). Messages in another encoding are refused.
pub fn read_mcap(path: &Path, topic: &str, fields: &[String; 5]) -> Result<ActuatorLog, LogError> {
    let file = path.display().to_string();
    let bad = |reason: String| LogError::File {
        file: file.clone(),
        reason,
    };
    let bytes = forkbench_core::files::read_bytes(path, crate::log::MAX_LOG_BYTES)
        .map_err(|e| bad(e.to_string()))?;
    let stream =
        mcap::MessageStream::new(&bytes).map_err(|e| bad(format!("not an MCAP file: {e}")))?;
    // Rebuilt as CSV text, so the one reader's checks (time, NaN, channels) apply.
    let used: Vec<(usize, &String)> = fields
        .iter()
        .enumerate()
        .filter(|(_, f)| !f.is_empty())
        .collect();
    let mut csv = used
        .iter()
        .map(|(i, _)| COLUMNS[*i])
        .collect::<Vec<_>>()
        .join(",")
        + "\n";
    let mut found = 0usize;
    for m in stream {
        let m = m.map_err(|e| bad(format!("reading a message: {e}")))?;
        if m.channel.topic != topic {
            continue;
        }
        if m.channel.message_encoding != "json" {
            return Err(bad(format!(
                "topic {topic} is {:?}-encoded; identify reads JSON messages",
                m.channel.message_encoding
            )));
        }
        let v: serde_json::Value = serde_json::from_slice(&m.data)
            .map_err(|e| bad(format!("a message on {topic} is not JSON: {e}")))?;
        let cells: Vec<String> = used
            .iter()
            .map(|(_, name)| {
                v.get(name.as_str())
                    .and_then(serde_json::Value::as_f64)
                    .map_or("NaN".to_owned(), |x| x.to_string())
            })
            .collect();
        csv.push_str(&cells.join(","));
        csv.push('\n');
        found += 1;
    }
    if found == 0 {
        return Err(bad(format!("no messages on topic {topic}")));
    }
    parse_csv(&csv, &format!("{file} (topic {topic})"))
}
