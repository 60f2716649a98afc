//! What makes a folder a rosbag2 directory: its `metadata.yaml` (rosbag2's version 5 layout, ROS 2 Humble) naming the MCAP file beside it, each topic with its type and count.

/// One topic as `metadata.yaml` lists it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TopicCount {
    pub name: String,
    /// The ROS 2 type, `pkg/msg/Name`.
    pub ty: &'static str,
    pub count: u64,
}

/// The `metadata.yaml` for a bag stored in `file` (MCAP, beside it), its messages
/// stamped from `span_ns.0` to `span_ns.1` (ns since the Unix epoch).
pub fn metadata_yaml(file: &str, topics: &[TopicCount], span_ns: Option<(u64, u64)>) -> String {
    let (start, end) = span_ns.unwrap_or((0, 0));
    let duration = end.saturating_sub(start);
    let n: u64 = topics.iter().map(|t| t.count).sum();
    let mut s = format!(
        "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: mcap\n  \
         duration:\n    nanoseconds: {duration}\n  starting_time:\n    \
         nanoseconds_since_epoch: {start}\n  message_count: {n}\n  topics_with_message_count:\n"
    );
    for t in topics {
        s.push_str(&format!(
            "    - topic_metadata:\n        name: {}\n        type: {}\n        \
             serialization_format: cdr\n        offered_qos_profiles: \"\"\n      \
             message_count: {}\n",
            t.name, t.ty, t.count
        ));
    }
    s.push_str(&format!(
        "  compression_format: \"\"\n  compression_mode: \"\"\n  relative_file_paths:\n    \
         - {file}\n  files:\n    - path: {file}\n      starting_time:\n        \
         nanoseconds_since_epoch: {start}\n      duration:\n        nanoseconds: {duration}\n      \
         message_count: {n}\n"
    ));
    s
}
