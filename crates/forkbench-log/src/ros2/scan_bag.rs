//! A ROS 2 bag of laser scans alone (MCAP, ros2 profile, CDR `sensor_msgs/msg/LaserScan`), streamed to a temporary file beside its path and renamed into place when finished: what `forkbench dataset` hands a detector team.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::Path as FsPath;

use forkbench_core::files::Partial;
use forkbench_core::signal::Scan;

use super::msgs;
use crate::LogError;
use crate::writer::with_causes;

/// A bag being written scan by scan: memory holds one chunk, not the set.
pub struct ScanBag {
    path: String,
    writer: mcap::Writer<BufWriter<File>>,
    channel: u16,
    frame: String,
    topic: String,
    written: u32,
    /// The first and last scans' stamps (ns since the Unix epoch).
    span_ns: Option<(u64, u64)>,
    partial: Partial,
}

impl std::fmt::Debug for ScanBag {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "ScanBag({}, {} scans)", self.path, self.written)
    }
}

impl ScanBag {
    /// Starts the bag for `path` (appearing there at [`Self::finish`]) with scans on
    /// `topic` in `frame`, and `metadata` as the file's `forkbench` metadata record.
    pub fn create(
        path: &FsPath,
        topic: &str,
        frame: &str,
        metadata: BTreeMap<String, String>,
    ) -> Result<Self, LogError> {
        let p = path.display().to_string();
        let io = |message: String| LogError::Io {
            path: p.clone(),
            message,
        };
        let (partial, file) = Partial::create(path)?;
        let mut w = mcap::WriteOptions::new()
            .profile("ros2")
            .chunk_size(Some(1 << 20))
            .compression(Some(mcap::Compression::Lz4))
            .compression_threads(0)
            .create(BufWriter::new(file))
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
        Ok(Self {
            path: p,
            writer: w,
            channel,
            frame: frame.to_owned(),
            topic: topic.to_owned(),
            written: 0,
            span_ns: None,
            partial,
        })
    }

    /// Appends `scan`, stamped `t_s`.
    pub fn write(&mut self, t_s: f64, scan: &Scan) -> Result<(), LogError> {
        let ns = msgs::unix_ns(t_s);
        self.span_ns = Some(
            self.span_ns
                .map_or((ns, ns), |(a, b)| (a.min(ns), b.max(ns))),
        );
        let header = mcap::records::MessageHeader {
            channel_id: self.channel,
            sequence: self.written,
            log_time: ns,
            publish_time: ns,
        };
        self.written = self.written.saturating_add(1);
        self.writer
            .write_to_known_channel(&header, &msgs::laser_scan(t_s, &self.frame, scan))
            .map_err(|e| LogError::Io {
                path: self.path.clone(),
                message: with_causes(&e),
            })
    }

    /// The `metadata.yaml` that makes the bag's folder a rosbag2 directory (what `ros2
    /// bag play` and rosbags' reader open), the bag being `file` in it: rosbag2's
    /// version 5 layout (ROS 2 Humble), MCAP storage, the scan topic with its count.
    pub fn rosbag2_metadata(&self, file: &str) -> String {
        let topic = super::bag_dir::TopicCount {
            name: self.topic.clone(),
            ty: msgs::LASER_SCAN_MSG.name,
            count: u64::from(self.written),
        };
        super::bag_dir::metadata_yaml(file, &[topic], self.span_ns)
    }

    /// Finishes the file and moves it into place; on an error nothing appears at the path.
    pub fn finish(mut self) -> Result<(), LogError> {
        let io = |message: String| LogError::Io {
            path: self.path.clone(),
            message,
        };
        self.writer.finish().map_err(|e| io(with_causes(&e)))?;
        // The buffer's last bytes: flushed here, where an error is seen (a drop hides it).
        std::io::Write::flush(&mut self.writer.into_inner()).map_err(|e| io(e.to_string()))?;
        Ok(self.partial.commit()?)
    }
}
