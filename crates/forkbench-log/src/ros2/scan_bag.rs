//! A ROS 2 bag of laser scans alone (MCAP, ros2 profile, CDR `sensor_msgs/msg/LaserScan`), built in memory and written atomically: what `forkbench dataset` hands a detector team.

use std::collections::BTreeMap;
use std::io::Cursor;
use std::path::Path as FsPath;

use forkbench_core::signal::Scan;

use super::msgs;
use crate::LogError;
use crate::writer::with_causes;

/// Scans a bag may hold in memory before it is written: 1 GiB of ranges.
pub const MAX_BAG_BYTES: u64 = 1 << 30;

/// A bag of `scans` (each at its stamp, s, in `frame`) on `topic`, with `metadata` as the
/// file's `forkbench` metadata record; refused when its ranges would pass
/// [`MAX_BAG_BYTES`].
pub fn write_scan_bag(
    path: &FsPath,
    topic: &str,
    frame: &str,
    scans: &[(f64, Scan)],
    metadata: BTreeMap<String, String>,
) -> Result<(), LogError> {
    let p = path.display().to_string();
    let io = |message: String| LogError::Io {
        path: p.clone(),
        message,
    };
    let bytes: u64 = scans
        .iter()
        .map(|(_, s)| 4 * s.ranges_m.len() as u64 + 64)
        .sum();
    if bytes > MAX_BAG_BYTES {
        return Err(io(format!(
            "{bytes} bytes of scans: a bag is built in memory, at most {MAX_BAG_BYTES}"
        )));
    }
    let mut buf = Cursor::new(Vec::with_capacity(bytes as usize + 4096));
    {
        let mut w = mcap::WriteOptions::new()
            .profile("ros2")
            .chunk_size(Some(1 << 20))
            .compression(Some(mcap::Compression::Lz4))
            .compression_threads(0)
            .create(&mut buf)
            .map_err(|e| io(with_causes(&e)))?;
        let ty = &msgs::LASER_SCAN_MSG;
        let schema = w
            .add_schema(ty.name, "ros2msg", ty.definition().as_bytes())
            .map_err(|e| io(with_causes(&e)))?;
        let channel = w
            .add_channel(schema, topic, "cdr", &BTreeMap::new())
            .map_err(|e| io(with_causes(&e)))?;
        w.write_metadata(&mcap::records::Metadata {
            name: "forkbench".into(),
            metadata,
        })
        .map_err(|e| io(with_causes(&e)))?;
        for (k, (t_s, scan)) in scans.iter().enumerate() {
            let ns = msgs::unix_ns(*t_s);
            let header = mcap::records::MessageHeader {
                channel_id: channel,
                sequence: u32::try_from(k).unwrap_or(u32::MAX),
                log_time: ns,
                publish_time: ns,
            };
            w.write_to_known_channel(&header, &msgs::laser_scan(*t_s, frame, scan))
                .map_err(|e| io(with_causes(&e)))?;
        }
        w.finish().map_err(|e| io(with_causes(&e)))?;
    }
    forkbench_core::files::write_atomic(path, buf.get_ref()).map_err(|e| io(e.to_string()))
}
