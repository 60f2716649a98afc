//! The first line each way of every forkbench child protocol: `{"type": "hello", "protocol", "version"}`, checked before any request.

use std::time::Duration;

use crate::process::{ExchangeError, Process, Spawn, clip};

/// Starts a child and exchanges hellos within `timeout`: ours names `protocol` and
/// `version`; theirs must name the same.
pub(crate) fn start_with_hello(
    s: Spawn,
    protocol: &str,
    version: u64,
    timeout: Duration,
) -> Result<Process, ExchangeError> {
    let mut p = Process::start(s)?;
    let ours = serde_json::json!({
        "type": "hello",
        "protocol": protocol,
        "version": version,
        "name": "forkbench",
    });
    let line = p.exchange(&ours.to_string(), timeout)?;
    let theirs: serde_json::Value = serde_json::from_str(&line)
        .map_err(|e| ExchangeError::other(format!("invalid hello {:?}: {e}", clip(&line))))?;
    if theirs["type"] != "hello" || theirs["protocol"] != protocol {
        return Err(ExchangeError::other(format!(
            "the first line must be a {protocol} hello, got {:?}",
            clip(&line)
        )));
    }
    if theirs["version"].as_u64() != Some(version) {
        return Err(ExchangeError::other(format!(
            "the {} speaks protocol version {}, forkbench speaks {version}",
            s.what, theirs["version"]
        )));
    }
    Ok(p)
}
