//! An actuator log from an MCAP recording or ROS 2 bag: JSON or CDR messages (decoded by the bag's own definitions), each column a field of a named topic, the others held at their latest value at each message of the time's topic.

use std::collections::{BTreeSet, HashMap};
use std::path::Path;

use serde_json::Value;

use crate::cdr::{CdrError, Schema};
use crate::log::{ActuatorLog, COLUMNS, LogError, parse_csv};

/// Where forkbench's recordings keep each control step.
pub const TELEMETRY_TOPIC: &str = "/forkbench/telemetry";

/// Where forkbench's ROS 2 bags keep the commanded and measured steering and speed
/// (`ackermann_msgs/msg/AckermannDriveStamped`).
pub const ROS2_COMMAND_TOPIC: &str = "/forkbench/actuators/command";
pub const ROS2_MEASURED_TOPIC: &str = "/forkbench/actuators/measured";

/// Most bytes a log's chunks may decompress to: a small file of highly compressed chunks
/// must not take the machine's memory.
pub const MAX_DECODED_BYTES: u64 = 512 << 20;

/// Most messages read on a log's topics: hours of a 100 Hz controller, and a bound on the
/// samples held however small each message is.
pub const MAX_MESSAGES: usize = 2_000_000;

/// A time field that is the message's log time, not one of its fields.
pub const LOG_TIME: &str = "@log_time";

/// The fields of forkbench's own ROS 2 bags, in [`COLUMNS`]' order.
pub fn ros2_fields() -> [String; 5] {
    let m = ROS2_MEASURED_TOPIC;
    [
        "header.stamp".to_owned(),
        "drive.steering_angle".to_owned(),
        format!("{m}:drive.steering_angle"),
        "drive.speed".to_owned(),
        format!("{m}:drive.speed"),
    ]
}

/// Why an MCAP file or rosbag2 directory gives no actuator log.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum McapError {
    #[error("not an MCAP file: {0}")]
    NotMcap(String),
    #[error("reading a record: {0}")]
    Record(String),
    #[error("reading a message: {0}")]
    Message(String),
    #[error(
        "its chunks decompress to more than {MAX_DECODED_BYTES} bytes, the most identify reads"
    )]
    Decompressed,
    #[error(
        "more than {MAX_MESSAGES} messages on its topics, the most identify reads (cut the log \
         to the runs to fit)"
    )]
    TooManyMessages,
    #[error("a directory without .mcap files (identify reads rosbag2's MCAP storage)")]
    NoParts,
    #[error(
        "its {parts} .mcap files hold {bytes} bytes, more than the {} a log may",
        crate::log::MAX_LOG_BYTES
    )]
    PartsTooLarge { parts: usize, bytes: u64 },
    #[error("the time field (the first of --fields) is required")]
    NoTimeField,
    #[error("no messages on topic {0}")]
    NoTopic(String),
    #[error("a message on {topic} is not JSON: {reason}")]
    NotJson { topic: String, reason: String },
    #[error("a message on {topic}: {error}")]
    Cdr { topic: String, error: CdrError },
    #[error("topic {topic} is {encoding:?}-encoded; identify reads JSON and CDR")]
    Encoding { topic: String, encoding: String },
    #[error("topic {topic} has no number at {path:?}")]
    NoNumber { topic: String, path: String },
    #[error("topic {0} is CDR without a ros2msg schema")]
    NoSchema(String),
    #[error("topic {0}: schema not UTF-8")]
    SchemaNotUtf8(String),
    #[error("topic {topic}: schema {name}: {error}")]
    Schema {
        topic: String,
        name: String,
        error: CdrError,
    },
}

/// One column's source: a topic and a dotted path into its messages.
#[derive(Debug, Clone, PartialEq)]
struct Source {
    topic: String,
    path: String,
}

/// `/topic:path` names its own topic; a bare path is on `topic`.
fn source(spec: &str, topic: &str) -> Source {
    match spec.split_once(':') {
        Some((t, p)) if t.starts_with('/') => Source {
            topic: t.to_owned(),
            path: p.to_owned(),
        },
        _ => Source {
            topic: topic.to_owned(),
            path: spec.to_owned(),
        },
    }
}

/// The number at `path` (dots between names, array indices as numbers) of `v`; a
/// `builtin_interfaces/Time` (`sec`, `nanosec`) as seconds.
fn number_at(v: &Value, path: &str) -> Option<f64> {
    let mut at = v;
    for key in path.split('.').filter(|k| !k.is_empty()) {
        at = match at {
            Value::Array(a) => a.get(key.parse::<usize>().ok()?)?,
            _ => at.get(key)?,
        };
    }
    match at {
        Value::Object(o) => Some(o.get("sec")?.as_f64()? + o.get("nanosec")?.as_f64()? * 1e-9),
        _ => at.as_f64(),
    }
}

/// Reads a log from the MCAP at `path`: `fields` name the time, steering command and
/// response, speed command and response (in [`COLUMNS`]' order; an empty name leaves
/// that channel out), each a path into `topic`'s messages or `/other:path`. A row is
/// made at each message of the time's topic, the other topics' fields at their latest
/// values by then. forkbench's own ROS 2 bag is read with [`ros2_fields`] when the
/// defaults name a telemetry topic it does not have.
///
/// `path` may be a rosbag2 directory (what `ros2 bag record` writes): its `*.mcap` files
/// are read in name order (a split bag's parts), each part's runs after the last's, and
/// together they are held to the one file's size cap.
pub fn read_mcap(path: &Path, topic: &str, fields: &[String; 5]) -> Result<ActuatorLog, LogError> {
    if !path.is_dir() {
        return read_one(path, topic, fields);
    }
    let file = path.display().to_string();
    let bad = |reason: McapError| LogError::Mcap {
        file: file.clone(),
        reason,
    };
    let parts =
        forkbench_core::files::files_with_extension(path, "mcap").map_err(|e| LogError::File {
            file: file.clone(),
            reason: e.to_string(),
        })?;
    if parts.is_empty() {
        return Err(bad(McapError::NoParts));
    }
    let total: u64 = parts
        .iter()
        .map(|p| std::fs::metadata(p).map_or(0, |m| m.len()))
        .sum();
    if total > crate::log::MAX_LOG_BYTES {
        return Err(bad(McapError::PartsTooLarge {
            parts: parts.len(),
            bytes: total,
        }));
    }
    let mut log = ActuatorLog { runs: Vec::new() };
    for p in &parts {
        log.runs.extend(read_one(p, topic, fields)?.runs);
    }
    Ok(log)
}

fn read_one(path: &Path, topic: &str, fields: &[String; 5]) -> Result<ActuatorLog, LogError> {
    let file = path.display().to_string();
    let bad = |reason: McapError| LogError::Mcap {
        file: file.clone(),
        reason,
    };
    let bytes =
        forkbench_core::files::read_bytes(path, crate::log::MAX_LOG_BYTES).map_err(|e| {
            LogError::File {
                file: file.clone(),
                reason: e.to_string(),
            }
        })?;
    check_decoded_size(&bytes).map_err(&bad)?;
    let topics = topics_in(&bytes).map_err(&bad)?;
    let defaults = COLUMNS.map(str::to_owned);
    let (topic, fields) = if topic == TELEMETRY_TOPIC
        && *fields == defaults
        && !topics.contains(TELEMETRY_TOPIC)
        && topics.contains(ROS2_COMMAND_TOPIC)
    {
        (ROS2_COMMAND_TOPIC, ros2_fields())
    } else {
        (topic, fields.clone())
    };
    if fields[0].is_empty() {
        return Err(bad(McapError::NoTimeField));
    }
    let used: Vec<(usize, Source)> = fields
        .iter()
        .enumerate()
        .filter(|(_, f)| !f.is_empty())
        .map(|(i, f)| (i, source(f, topic)))
        .collect();
    for (_, s) in &used {
        if !topics.contains(&s.topic) {
            return Err(bad(McapError::NoTopic(s.topic.clone())));
        }
    }
    let csv = rows(&bytes, &used).map_err(bad)?;
    parse_csv(&csv, &format!("{file} (topic {topic})"))
}

/// The chunks' declared sizes (what decompressing them allocates) within
/// [`MAX_DECODED_BYTES`], before any is decompressed.
fn check_decoded_size(bytes: &[u8]) -> Result<(), McapError> {
    let mut total = 0u64;
    for record in mcap::read::LinearReader::new(bytes).map_err(not_mcap)? {
        if let mcap::records::Record::Chunk { header, .. } =
            record.map_err(|e| McapError::Record(e.to_string()))?
        {
            total = total.saturating_add(header.uncompressed_size);
        }
        if total > MAX_DECODED_BYTES {
            return Err(McapError::Decompressed);
        }
    }
    Ok(())
}

fn not_mcap(e: mcap::McapError) -> McapError {
    McapError::NotMcap(e.to_string())
}

/// The topics that carry messages.
fn topics_in(bytes: &[u8]) -> Result<BTreeSet<String>, McapError> {
    let summary = mcap::Summary::read(bytes).map_err(not_mcap)?;
    let mut topics = BTreeSet::new();
    if let Some(s) = summary {
        topics.extend(s.channels.values().map(|c| c.topic.clone()));
        return Ok(topics);
    }
    for m in mcap::MessageStream::new(bytes).map_err(not_mcap)? {
        topics.insert(
            m.map_err(|e| McapError::Message(e.to_string()))?
                .channel
                .topic
                .clone(),
        );
    }
    Ok(topics)
}

/// Each needed message's log time, its topic and the values of the columns it feeds.
type Sample = (u64, String, Vec<(usize, f64)>);

/// The log as CSV text (so the one reader's checks apply): a row per message of the
/// time's topic once every column has a value.
fn rows(bytes: &[u8], used: &[(usize, Source)]) -> Result<String, McapError> {
    let mut samples = samples(bytes, used)?;
    samples.sort_by_key(|s| s.0);
    let row_topic = &used[0].1.topic;
    let mut latest: Vec<Option<f64>> = vec![None; used.len()];
    let mut csv = used
        .iter()
        .map(|(i, _)| COLUMNS[*i])
        .collect::<Vec<_>>()
        .join(",")
        + "\n";
    // Messages logged at the same instant are one sample: a row sees all of them.
    for group in samples.chunk_by(|a, b| a.0 == b.0) {
        for (_, _, values) in group {
            for (k, v) in values {
                latest[*k] = Some(*v);
            }
        }
        if group.iter().any(|(_, t, _)| t == row_topic) && latest.iter().all(Option::is_some) {
            let cells: Vec<String> = latest.iter().flatten().map(f64::to_string).collect();
            csv.push_str(&cells.join(","));
            csv.push('\n');
        }
    }
    Ok(csv)
}

/// The needed messages decoded (JSON, or CDR by their channel's `ros2msg` schema).
fn samples(bytes: &[u8], used: &[(usize, Source)]) -> Result<Vec<Sample>, McapError> {
    let mut schemas: HashMap<u16, Schema> = HashMap::new();
    let mut out = Vec::new();
    let stream = mcap::MessageStream::new(bytes).map_err(not_mcap)?;
    for m in stream {
        let m = m.map_err(|e| McapError::Message(e.to_string()))?;
        let topic = &m.channel.topic;
        if !used.iter().any(|(_, s)| &s.topic == topic) {
            continue;
        }
        if out.len() == MAX_MESSAGES {
            return Err(McapError::TooManyMessages);
        }
        let v = match m.channel.message_encoding.as_str() {
            "json" => serde_json::from_slice(&m.data).map_err(|e| McapError::NotJson {
                topic: topic.clone(),
                reason: e.to_string(),
            })?,
            "cdr" => {
                let schema = match schemas.entry(m.channel.id) {
                    std::collections::hash_map::Entry::Occupied(e) => e.into_mut(),
                    std::collections::hash_map::Entry::Vacant(e) => e.insert(schema_of(&m)?),
                };
                schema.decode(&m.data).map_err(|error| McapError::Cdr {
                    topic: topic.clone(),
                    error,
                })?
            }
            other => {
                return Err(McapError::Encoding {
                    topic: topic.clone(),
                    encoding: other.to_owned(),
                });
            }
        };
        let values = used
            .iter()
            .enumerate()
            .filter(|(_, (_, s))| &s.topic == topic)
            .map(|(k, (_, s))| {
                let x = if s.path == LOG_TIME {
                    Some(m.log_time as f64 * 1e-9)
                } else {
                    number_at(&v, &s.path)
                };
                x.map(|x| (k, x)).ok_or_else(|| McapError::NoNumber {
                    topic: topic.clone(),
                    path: s.path.clone(),
                })
            })
            .collect::<Result<Vec<_>, McapError>>()?;
        out.push((m.log_time, topic.clone(), values));
    }
    Ok(out)
}

/// The `ros2msg` schema of a CDR message's channel.
fn schema_of(m: &mcap::Message<'_>) -> Result<Schema, McapError> {
    let topic = &m.channel.topic;
    let s = m
        .channel
        .schema
        .as_ref()
        .filter(|s| s.encoding == "ros2msg")
        .ok_or_else(|| McapError::NoSchema(topic.clone()))?;
    let text = std::str::from_utf8(&s.data).map_err(|_| McapError::SchemaNotUtf8(topic.clone()))?;
    Schema::parse(&s.name, text).map_err(|error| McapError::Schema {
        topic: topic.clone(),
        name: s.name.clone(),
        error,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_reach_numbers_times_and_other_topics() {
        let v = serde_json::json!({"h": {"stamp": {"sec": 2, "nanosec": 500_000_000}}, "a": [1.0, 2.5]});
        assert_eq!(number_at(&v, "h.stamp"), Some(2.5));
        assert_eq!(number_at(&v, "a.1"), Some(2.5));
        assert_eq!(number_at(&v, "a.7"), None);
        assert_eq!(source("/m:drive.speed", "/c").topic, "/m");
        assert_eq!(source("drive.speed", "/c").topic, "/c");
    }
}
