//! Laser scans and transforms read back from MCAP files, streamed with bounded memory: ROS 2 bags (`sensor_msgs/msg/LaserScan`, `tf2_msgs/msg/TFMessage`, CDR) and forkbench's own recordings (`foxglove.LaserScan`, JSON).

use std::collections::BTreeMap;
use std::io::Read as _;
use std::path::Path as FsPath;

use forkbench_core::Pose2;
use forkbench_core::signal::Scan;
use mcap::records::Record;
use mcap::sans_io::linear_reader::{LinearReadEvent, LinearReader, LinearReaderOptions};

use crate::LogError;
use crate::ros2::cdr::{CdrError, CdrReader};
use crate::ros2::msgs::decode_laser_scan;

/// The largest record (a chunk or a message) read: a bigger one is refused, so a corrupt
/// length cannot ask for more memory than this.
pub const MAX_RECORD_BYTES: usize = 256 << 20;

/// The most ranges one scan may have (real scanners have a few thousand).
pub const MAX_BEAMS: usize = 100_000;

/// One scan as the bag has it: the sensor at the origin of its own frame.
#[derive(Debug, Clone, PartialEq)]
pub struct BagScan {
    pub topic: String,
    /// Its header's stamp (s since the Unix epoch) and frame.
    pub stamp_s: f64,
    pub frame_id: String,
    /// In its frame: `sensor` is the origin for a ROS 2 scan, and the message's own pose
    /// in `frame_id` for a forkbench (Foxglove) scan; NaN for no return.
    pub scan: Scan,
}

/// What a bag yields, in file order.
#[derive(Debug, Clone, PartialEq)]
pub enum BagEvent {
    Scan(BagScan),
    /// A transform from `parent` to `child` (a 2-D pose: x, y and yaw).
    Transform {
        parent: String,
        child: String,
        pose: Pose2,
    },
    /// A scan message that could not be used, and why (the reading goes on).
    Malformed {
        topic: String,
        reason: ScanError,
    },
    /// A transform message that could not be decoded, and why (the reading goes on;
    /// scans that needed it find no transform).
    BadTransform {
        topic: String,
        reason: String,
    },
}

/// Why a scan message could not be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ScanError {
    #[error("not a LaserScan: {0}")]
    NotLaserScan(CdrError),
    #[error("not a foxglove.LaserScan: {0}")]
    NotFoxglove(String),
    #[error("range_min {min_m} m and range_max {max_m} m: not a range")]
    Range { min_m: f64, max_m: f64 },
    #[error("{0} ranges: a scan has 1 to {MAX_BEAMS}")]
    Beams(usize),
    #[error(
        "angle_min {lo}, angle_max {hi}, angle_increment {inc} rad: not finite, or no increment"
    )]
    Angles { lo: f64, hi: f64, inc: f64 },
    #[error(
        "angle_max − angle_min is {steps:.1} increments, but the scan has {n} ranges ({} increments)",
        n - 1
    )]
    Span { steps: f64, n: usize },
    #[error("the scan's pose is not finite")]
    Pose,
}

/// The kinds of topic read; others are passed over.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Ros2Scan,
    FoxgloveScan,
    Ros2Tf,
}

fn kind(schema: &str, encoding: &str) -> Option<Kind> {
    match (schema, encoding) {
        ("sensor_msgs/msg/LaserScan", "cdr") => Some(Kind::Ros2Scan),
        ("foxglove.LaserScan", "json") => Some(Kind::FoxgloveScan),
        ("tf2_msgs/msg/TFMessage", "cdr") => Some(Kind::Ros2Tf),
        _ => None,
    }
}

/// What a bag held: laser-scan topics and their message counts, every topic's type.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BagSummary {
    pub scan_topics: BTreeMap<String, usize>,
    pub topics: BTreeMap<String, String>,
    /// Transform messages that could not be decoded, and the first one's topic and reason.
    pub bad_transforms: usize,
    pub first_bad_transform: Option<String>,
}

/// The MCAP files of a recording: `path` itself, or a rosbag2 directory's `*.mcap` files
/// in name order (a split bag's parts).
pub fn bag_files(path: &FsPath) -> Result<Vec<std::path::PathBuf>, LogError> {
    if !path.is_dir() {
        return Ok(vec![path.to_owned()]);
    }
    let fail = |message: String| LogError::Io {
        path: path.display().to_string(),
        message,
    };
    let files = forkbench_core::files::files_with_extension(path, "mcap")
        .map_err(|e| fail(e.to_string()))?;
    if files.is_empty() {
        return Err(fail(
            "a directory without .mcap files (forkbench reads rosbag2's MCAP storage)".into(),
        ));
    }
    Ok(files)
}

/// Reads `path` record by record, calling `on` for each scan on `topics` (every laser-scan
/// topic when empty) and each transform. An error after some events (a truncated file)
/// comes after them: what was read is the caller's.
pub fn read_bag(
    path: &FsPath,
    topics: &[String],
    on: &mut dyn FnMut(BagEvent),
) -> Result<BagSummary, LogError> {
    let p = path.display().to_string();
    let fail = |message: String| LogError::Io {
        path: p.clone(),
        message,
    };
    let meta = std::fs::metadata(path).map_err(|e| fail(e.to_string()))?;
    if !meta.is_file() {
        return Err(fail("is not a regular file".into()));
    }
    let mut file = std::fs::File::open(path).map_err(|e| fail(e.to_string()))?;
    let opts = LinearReaderOptions::default().with_record_length_limit(MAX_RECORD_BYTES);
    let mut reader = LinearReader::new_with_options(opts);
    let mut state = State::default();
    while let Some(event) = reader.next_event() {
        match event.map_err(|e| fail(format!("not a readable MCAP file: {e}")))? {
            LinearReadEvent::ReadRequest(need) => {
                let n = file
                    .read(reader.insert(need))
                    .map_err(|e| fail(e.to_string()))?;
                reader.notify_read(n);
            }
            LinearReadEvent::Record { opcode, data } => {
                let record = mcap::parse_record(opcode, data)
                    .map_err(|e| fail(format!("a corrupt record: {e}")))?;
                state.take(record, topics, on);
            }
        }
    }
    Ok(state.summary)
}

#[derive(Default)]
struct State {
    /// Schema id → (name, encoding).
    schemas: BTreeMap<u16, (String, String)>,
    /// Channel id → (topic, kind) for the channels read.
    channels: BTreeMap<u16, (String, Kind)>,
    summary: BagSummary,
}

impl State {
    fn take(&mut self, record: Record<'_>, topics: &[String], on: &mut dyn FnMut(BagEvent)) {
        match record {
            Record::Schema { header, .. } => {
                self.schemas
                    .insert(header.id, (header.name, header.encoding));
            }
            Record::Channel(c) => {
                let name = self
                    .schemas
                    .get(&c.schema_id)
                    .map(|(n, _)| n.clone())
                    .unwrap_or_default();
                self.summary.topics.insert(c.topic.clone(), name.clone());
                let Some(k) = kind(&name, &c.message_encoding) else {
                    return;
                };
                let scan = k != Kind::Ros2Tf;
                if scan {
                    self.summary.scan_topics.entry(c.topic.clone()).or_insert(0);
                }
                if !scan || topics.is_empty() || topics.contains(&c.topic) {
                    self.channels.insert(c.id, (c.topic, k));
                }
            }
            Record::Message { header, data } => {
                let Some((topic, k)) = self.channels.get(&header.channel_id) else {
                    return;
                };
                if *k != Kind::Ros2Tf {
                    *self.summary.scan_topics.entry(topic.clone()).or_insert(0) += 1;
                }
                for e in decode(topic, *k, &data) {
                    on(e);
                }
            }
            _ => {}
        }
    }
}

fn decode(topic: &str, k: Kind, data: &[u8]) -> Vec<BagEvent> {
    let scan = match k {
        Kind::Ros2Tf => {
            return transforms(data, topic).unwrap_or_else(|e| {
                vec![BagEvent::BadTransform {
                    topic: topic.to_owned(),
                    reason: e.to_string(),
                }]
            });
        }
        Kind::Ros2Scan => ros2_scan(data),
        Kind::FoxgloveScan => foxglove_scan(data),
    };
    vec![match scan {
        Ok(mut s) => {
            s.topic = topic.to_owned();
            BagEvent::Scan(s)
        }
        Err(reason) => BagEvent::Malformed {
            topic: topic.to_owned(),
            reason,
        },
    }]
}

/// Ranges as forkbench takes them: a reading outside [min, max], NaN or ±∞ (what real
/// scanners send for no return) is no return.
fn ranges(raw: impl Iterator<Item = Option<f64>>, min_m: f64, max_m: f64) -> Vec<f64> {
    raw.map(|r| match r {
        Some(r) if r.is_finite() && r >= min_m && r <= max_m => r,
        _ => f64::NAN,
    })
    .collect()
}

fn ros2_scan(data: &[u8]) -> Result<BagScan, ScanError> {
    let m = decode_laser_scan(data).map_err(ScanError::NotLaserScan)?;
    let inc = f64::from(m.angle_increment_rad);
    let (lo, hi) = (f64::from(m.angle_min_rad), f64::from(m.angle_max_rad));
    let n = m.ranges_m.len();
    check_angles(lo, hi, inc, n)?;
    let (min_m, max_m) = (f64::from(m.range_min_m), f64::from(m.range_max_m));
    if !(min_m.is_finite() && max_m.is_finite() && 0.0 <= min_m && min_m < max_m) {
        return Err(ScanError::Range { min_m, max_m });
    }
    Ok(BagScan {
        topic: String::new(),
        stamp_s: m.stamp_s,
        frame_id: m.frame_id,
        scan: forwards(Scan {
            sensor: Pose2::new(0.0, 0.0, 0.0),
            angle_min_rad: lo,
            angle_step_rad: inc,
            range_min_m: min_m,
            range_max_m: max_m,
            ranges_m: ranges(m.ranges_m.iter().map(|r| Some(f64::from(*r))), min_m, max_m),
        }),
    })
}

/// `scan` with its beams in increasing angle: a scanner mounted upside down publishes
/// them clockwise (a negative increment), and the detectors read beams counter-clockwise.
fn forwards(mut scan: Scan) -> Scan {
    if scan.angle_step_rad < 0.0 {
        let n = scan.ranges_m.len();
        scan.angle_min_rad += scan.angle_step_rad * n.saturating_sub(1) as f64;
        scan.angle_step_rad = -scan.angle_step_rad;
        scan.ranges_m.reverse();
    }
    scan
}

/// The angle fields must describe the ranges: a non-zero finite increment, and
/// `angle_max − angle_min` within an increment and a half of (n − 1) increments.
fn check_angles(lo: f64, hi: f64, inc: f64, n: usize) -> Result<(), ScanError> {
    if n == 0 || n > MAX_BEAMS {
        return Err(ScanError::Beams(n));
    }
    if !(lo.is_finite() && hi.is_finite() && inc.is_finite() && inc != 0.0) {
        return Err(ScanError::Angles { lo, hi, inc });
    }
    let steps = (hi - lo) / inc;
    if n > 1 && (steps - (n - 1) as f64).abs() > 1.5 {
        return Err(ScanError::Span { steps, n });
    }
    Ok(())
}

/// A `foxglove.LaserScan` as forkbench writes it (and Foxglove's schema has it).
#[derive(serde::Deserialize)]
struct FoxScan {
    timestamp: FoxTime,
    frame_id: String,
    pose: FoxPose,
    start_angle: f64,
    end_angle: f64,
    ranges: Vec<Option<f64>>,
}

#[derive(serde::Deserialize)]
struct FoxTime {
    sec: u64,
    nsec: u64,
}

#[derive(serde::Deserialize)]
struct FoxPose {
    position: FoxVec,
    orientation: FoxQuat,
}

#[derive(serde::Deserialize)]
struct FoxVec {
    x: f64,
    y: f64,
}

#[derive(serde::Deserialize)]
struct FoxQuat {
    x: f64,
    y: f64,
    z: f64,
    w: f64,
}

fn yaw(x: f64, y: f64, z: f64, w: f64) -> f64 {
    (2.0 * (w * z + x * y)).atan2(1.0 - 2.0 * (y * y + z * z))
}

fn foxglove_scan(data: &[u8]) -> Result<BagScan, ScanError> {
    let m: FoxScan =
        serde_json::from_slice(data).map_err(|e| ScanError::NotFoxglove(e.to_string()))?;
    let n = m.ranges.len();
    let inc = if n > 1 {
        (m.end_angle - m.start_angle) / (n - 1) as f64
    } else {
        1.0
    };
    check_angles(m.start_angle, m.end_angle, inc, n)?;
    let q = &m.pose.orientation;
    let sensor = Pose2::new(
        m.pose.position.x,
        m.pose.position.y,
        yaw(q.x, q.y, q.z, q.w),
    );
    if !(sensor.x_m.is_finite() && sensor.y_m.is_finite() && sensor.heading_rad.is_finite()) {
        return Err(ScanError::Pose);
    }
    Ok(BagScan {
        topic: String::new(),
        stamp_s: m.timestamp.sec as f64 + m.timestamp.nsec as f64 * 1e-9,
        frame_id: m.frame_id,
        scan: forwards(Scan {
            sensor,
            angle_min_rad: m.start_angle,
            angle_step_rad: inc,
            range_min_m: 0.0,
            range_max_m: f64::MAX,
            ranges_m: ranges(m.ranges.into_iter(), 0.0, f64::MAX),
        }),
    })
}

/// The transforms of one `tf2_msgs/msg/TFMessage`, each as a 2-D pose.
fn transforms(data: &[u8], topic: &str) -> Result<Vec<BagEvent>, CdrError> {
    let mut r = CdrReader::new(data)?;
    let count = r.u32()? as usize;
    let mut out = Vec::with_capacity(count.min(data.len() / 64));
    for _ in 0..count {
        let _stamp = (r.i32()?, r.u32()?);
        let parent = r.string()?;
        let child = r.string()?;
        let mut v = [0.0; 7];
        for x in &mut v {
            *x = r.f64()?;
        }
        // A quaternion far from unit length (zero, or NaN) has no rotation to take.
        let norm = v[3..].iter().map(|q| q * q).sum::<f64>().sqrt();
        if !(v.iter().all(|x| x.is_finite()) && (0.5..=2.0).contains(&norm)) {
            out.push(BagEvent::BadTransform {
                topic: topic.to_owned(),
                reason: format!(
                    "{parent:?} → {child:?}: translation ({}, {}, {}) and rotation ({}, {}, {}, {}): \
                     not finite, or not a rotation (|q| = {norm})",
                    v[0], v[1], v[2], v[3], v[4], v[5], v[6]
                ),
            });
            continue;
        }
        out.push(BagEvent::Transform {
            parent: parent.trim_start_matches('/').to_owned(),
            child: child.trim_start_matches('/').to_owned(),
            pose: Pose2::new(v[0], v[1], yaw(v[3], v[4], v[5], v[6])),
        });
    }
    Ok(out)
}

/// The latest transform of each frame to its parent, to place scans in another frame.
#[derive(Debug, Clone, Default)]
pub struct Frames {
    parent: BTreeMap<String, (String, Pose2)>,
}

impl Frames {
    pub fn set(&mut self, parent: &str, child: &str, pose: Pose2) {
        self.parent
            .insert(child.to_owned(), (parent.to_owned(), pose));
    }

    /// The pose of `frame` in `target`, following parents up from `frame`; `None` when
    /// `target` is not above it (or not yet known).
    pub fn pose_in(&self, frame: &str, target: &str) -> Option<Pose2> {
        let mut pose = Pose2::new(0.0, 0.0, 0.0);
        let mut at = frame.trim_start_matches('/');
        for _ in 0..=self.parent.len() {
            if at == target {
                return Some(pose);
            }
            let (parent, link) = self.parent.get(at)?;
            pose = link.to_world(&pose);
            at = parent;
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A scan published clockwise (an inverted mount) reads as the same beams as the
    /// same scan published counter-clockwise.
    #[test]
    fn a_reversed_laser_scan_reads_as_the_forward_one() {
        let fwd = Scan {
            sensor: Pose2::new(0.0, 0.0, 0.0),
            angle_min_rad: -1.0,
            angle_step_rad: 0.5,
            range_min_m: 0.05,
            range_max_m: 10.0,
            ranges_m: vec![1.0, 2.0, 3.0, 4.0, 5.0],
        };
        let rev = Scan {
            angle_min_rad: 1.0,
            angle_step_rad: -0.5,
            ranges_m: vec![5.0, 4.0, 3.0, 2.0, 1.0],
            ..fwd.clone()
        };
        let a = ros2_scan(&crate::ros2::msgs::laser_scan(1.0, "laser", &fwd)).expect("forwards");
        let b = ros2_scan(&crate::ros2::msgs::laser_scan(1.0, "laser", &rev)).expect("reversed");
        assert!(b.scan.angle_step_rad > 0.0);
        assert!((a.scan.angle_min_rad - b.scan.angle_min_rad).abs() < 1e-6);
        assert_eq!(a.scan.ranges_m, b.scan.ranges_m);
        assert_eq!(b.scan.ranges_m, vec![1.0, 2.0, 3.0, 4.0, 5.0]);
    }

    /// A transform with a zero or NaN quaternion is reported as bad, not used as a yaw of
    /// 0; the good one beside it in the same message is used.
    #[test]
    fn a_degenerate_transform_is_counted_not_used() {
        let mut w = crate::ros2::cdr::CdrWriter::new();
        w.len(2);
        for (child, q) in [("base_link", [0.0; 4]), ("laser", [0.0, 0.0, 0.0, 1.0])] {
            w.i32(1);
            w.u32(0);
            w.string("map");
            w.string(child);
            for x in [1.0, 2.0, 0.0].into_iter().chain(q) {
                w.f64(x);
            }
        }
        let events = transforms(&w.into_bytes(), "/tf").expect("decodes");
        assert_eq!(events.len(), 2);
        assert!(
            matches!(&events[0], BagEvent::BadTransform { reason, .. } if reason.contains("not a rotation")),
            "{events:?}"
        );
        assert!(matches!(&events[1], BagEvent::Transform { child, .. } if child == "laser"));
    }
}
