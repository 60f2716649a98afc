//! A trial recorded as a ROS 2 bag: a rosbag2 directory (`metadata.yaml` and an MCAP with the `ros2` profile, `ros2msg` schemas and CDR messages: `/tf`, poses, plans, laser scans, maps, markers, `/rosout`, the outcome), so `ros2 bag play`, RViz and rosbags-based analysis read it.

pub mod bag_dir;
pub mod cdr;
pub mod msgs;
pub mod scan_bag;
mod signals;

pub use signals::topic;

use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::Path as FsPath;

use forkbench_core::{Path, Pose2, Signal, Style};
use forkbench_trial::{Level, Recorder, SceneInfo, StepRecord, TrialOutcome};

use crate::writer::with_causes;
use crate::{LogError, pallet_outlines, truck_outlines};
use msgs::{Marker, MsgType, Shape};

/// The map frame every pose is given in.
const MAP: &str = "map";

/// The commanded and the measured steering and speed at every physics step, what
/// `forkbench identify` reads from a bag.
const ACTUATORS_COMMAND: &str = "/forkbench/actuators/command";
const ACTUATORS_MEASURED: &str = "/forkbench/actuators/measured";

/// The fixed topics and their types; a scanner's `/scan/<name>` is added when it first
/// scans.
const TOPICS: [(&str, &MsgType); 10] = [
    ("/tf", &msgs::TF_MSG),
    (ACTUATORS_COMMAND, &msgs::ACKERMANN_MSG),
    (ACTUATORS_MEASURED, &msgs::ACKERMANN_MSG),
    ("/forkbench/scene", &msgs::MARKER_ARRAY_MSG),
    ("/forkbench/pose", &msgs::POSE_STAMPED_MSG),
    ("/forkbench/fix", &msgs::POSE_STAMPED_MSG),
    ("/forkbench/pallet_estimate", &msgs::POSE_STAMPED_MSG),
    ("/forkbench/plan", &msgs::PATH_MSG),
    ("/rosout", &msgs::LOG_MSG),
    ("/forkbench/outcome", &msgs::STRING_MSG),
];

/// Records a trial as a ROS 2 bag directory, its MCAP written as the trial runs.
pub struct Ros2Recorder {
    path: String,
    /// The MCAP's name in the directory, as `metadata.yaml` lists it.
    file_name: String,
    /// Every topic's type and message count, for `metadata.yaml`.
    counts: BTreeMap<String, (&'static str, u64)>,
    /// The first and last messages' stamps (ns since the Unix epoch).
    span_ns: Option<(u64, u64)>,
    writer: Option<mcap::Writer<BufWriter<File>>>,
    schemas: BTreeMap<&'static str, u16>,
    channels: BTreeMap<String, u16>,
    sequence: u32,
    /// The last pallet estimate written, so a new one is written when it changes.
    pallet_estimate: Option<Pose2>,
    error: Option<String>,
    /// The directory being built beside the path, renamed onto it when all went well.
    out: Option<forkbench_core::out_dir::OutDir>,
}

impl std::fmt::Debug for Ros2Recorder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Ros2Recorder({})", self.path)
    }
}

impl Ros2Recorder {
    /// Creates the bag directory for `path` (checked beforehand with
    /// [`check_bag_dir`]) with the trial's metadata record; it appears at `path` when
    /// [`Self::finish`] succeeds.
    pub fn create(path: &FsPath, metadata: BTreeMap<String, String>) -> Result<Self, LogError> {
        let p = path.display().to_string();
        let io = |e: &dyn std::error::Error| LogError::Io {
            path: p.clone(),
            message: with_causes(e),
        };
        let out = forkbench_core::out_dir::OutDir::create(path)?;
        let file_name = mcap_name(path);
        let file = File::create_new(out.file(&file_name)).map_err(|e| io(&e))?;
        let mut writer = mcap::WriteOptions::new()
            .profile("ros2")
            .chunk_size(Some(256 * 1024))
            .compression(Some(mcap::Compression::Lz4))
            .compression_threads(0)
            .create(BufWriter::new(file))
            .map_err(|e| io(&e))?;
        writer
            .write_metadata(&mcap::records::Metadata {
                name: "forkbench".into(),
                metadata,
            })
            .map_err(|e| io(&e))?;
        let mut me = Self {
            path: p,
            file_name,
            counts: BTreeMap::new(),
            span_ns: None,
            writer: Some(writer),
            schemas: BTreeMap::new(),
            channels: BTreeMap::new(),
            sequence: 0,
            pallet_estimate: None,
            error: None,
            out: Some(out),
        };
        for (topic, ty) in TOPICS {
            me.channel(topic, ty);
        }
        Ok(me)
    }

    /// Finishes the file (summary and footer); Err: the first error, naming the file.
    pub fn finish(&mut self) -> Result<(), LogError> {
        if let Some(mut w) = self.writer.take() {
            if let Err(e) = w.finish() {
                self.error.get_or_insert(with_causes(&e));
            }
            // The buffer's last bytes: flushed here, where an error is seen (a drop hides it).
            if let Err(e) = std::io::Write::flush(&mut w.into_inner()) {
                self.error.get_or_insert(e.to_string());
            }
        }
        let out = self.out.take();
        if self.error.is_none()
            && let Some(out) = out
        {
            let topics: Vec<bag_dir::TopicCount> = self
                .counts
                .iter()
                .map(|(name, (ty, count))| bag_dir::TopicCount {
                    name: name.clone(),
                    ty,
                    count: *count,
                })
                .collect();
            let yaml = bag_dir::metadata_yaml(&self.file_name, &topics, self.span_ns);
            let written =
                forkbench_core::files::write_atomic(&out.file("metadata.yaml"), yaml.as_bytes())
                    .and_then(|()| out.commit());
            if let Err(e) = written {
                self.error = Some(e.reason());
            }
        }
        match self.error.take() {
            Some(message) => Err(LogError::Io {
                path: self.path.clone(),
                message,
            }),
            None => Ok(()),
        }
    }

    /// The channel id of `topic`, added with its type's schema on first use.
    fn channel(&mut self, topic: &str, ty: &'static MsgType) -> Option<u16> {
        if let Some(id) = self.channels.get(topic) {
            return Some(*id);
        }
        let w = self.writer.as_mut()?;
        let schema = match self.schemas.get(ty.name) {
            Some(id) => Ok(*id),
            None => w.add_schema(ty.name, "ros2msg", ty.definition().as_bytes()),
        };
        let id = schema.and_then(|sid| {
            self.schemas.insert(ty.name, sid);
            w.add_channel(sid, topic, "cdr", &BTreeMap::new())
        });
        match id {
            Ok(id) => {
                self.channels.insert(topic.to_owned(), id);
                self.counts.insert(topic.to_owned(), (ty.name, 0));
                Some(id)
            }
            Err(e) => {
                self.error.get_or_insert(with_causes(&e));
                None
            }
        }
    }

    pub(crate) fn write(&mut self, topic: &str, ty: &'static MsgType, t_s: f64, data: &[u8]) {
        let Some(channel_id) = self.channel(topic, ty) else {
            return;
        };
        let Some(w) = self.writer.as_mut() else {
            return;
        };
        self.sequence += 1;
        let ns = msgs::unix_ns(t_s);
        if let Some((_, n)) = self.counts.get_mut(topic) {
            *n += 1;
        }
        self.span_ns = Some(
            self.span_ns
                .map_or((ns, ns), |(a, b)| (a.min(ns), b.max(ns))),
        );
        let header = mcap::records::MessageHeader {
            channel_id,
            sequence: self.sequence,
            log_time: ns,
            publish_time: ns,
        };
        if let Err(e) = w.write_to_known_channel(&header, data) {
            self.error.get_or_insert(with_causes(&e));
        }
    }
}

/// The MCAP's name inside the bag directory at `path`: rosbag2's `<bag>_0.mcap`, the
/// bag named by the directory without a `.ros2` ending.
fn mcap_name(path: &FsPath) -> String {
    let name = path
        .file_name()
        .map_or_else(|| "bag".to_owned(), |n| n.to_string_lossy().into_owned());
    let bag = name
        .strip_suffix(".ros2")
        .filter(|b| !b.is_empty())
        .unwrap_or(&name);
    format!("{bag}_0.mcap")
}

/// Checks before a run that a bag directory can be written at `path` without touching
/// it: a name not ending `.mcap` (a directory so named reads as a file), absent unless
/// `force`, and then a bag directory forkbench wrote.
pub fn check_bag_dir(path: &FsPath, force: bool) -> Result<(), LogError> {
    forkbench_core::out_dir::check_out_dir(path, force, forkbench_core::out_dir::is_rosbag2_file)?;
    if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("mcap"))
    {
        return Err(LogError::Io {
            path: path.display().to_string(),
            message: "--ros2 writes a rosbag2 directory (metadata.yaml and its MCAP, what \
                      `ros2 bag play` opens), so its name does not end .mcap; give a \
                      directory's name, e.g. trial.ros2 (--mcap writes one MCAP file)"
                .into(),
        });
    }
    Ok(())
}

/// The scene's markers: racks and walls as boxes in the map; the truck's and the pallet's
/// outlines in their own frames, locked to them, so `/tf` moves them.
fn scene_markers<'a>(s: &SceneInfo<'_>) -> Vec<Marker<'a>> {
    let origin = Pose2::new(0.0, 0.0, 0.0);
    let mut v: Vec<Marker<'a>> = s
        .obstacles
        .iter()
        .enumerate()
        .map(|(i, o)| Marker {
            frame: MAP,
            ns: "obstacles",
            id: i32::try_from(i).unwrap_or(i32::MAX),
            shape: Shape::Cube,
            pose: o.centre,
            scale: [o.length_m, o.width_m, 0.1],
            rgba: [128, 128, 128, 200],
            frame_locked: false,
            points: Vec::new(),
        })
        .collect();
    let outlines = [
        (
            "fork_root",
            "truck",
            truck_outlines(s.truck, &origin),
            [230, 190, 25, 255],
        ),
        (
            "pallet",
            "pallet",
            pallet_outlines(s.pallet, &origin),
            [150, 100, 50, 255],
        ),
    ];
    for (frame, ns, rects, rgba) in outlines {
        for (i, r) in rects.iter().enumerate() {
            v.push(Marker {
                frame,
                ns,
                id: i32::try_from(i).unwrap_or(i32::MAX),
                shape: Shape::LineStrip,
                pose: origin,
                scale: [0.02, 0.0, 0.0],
                rgba,
                frame_locked: true,
                points: r.to_vec(),
            });
        }
    }
    v.push(Marker {
        frame: MAP,
        ns: "start",
        id: 0,
        shape: Shape::Arrow,
        pose: s.start,
        scale: [0.6, 0.08, 0.08],
        rgba: [60, 180, 75, 255],
        frame_locked: false,
        points: Vec::new(),
    });
    v
}

impl Recorder for Ros2Recorder {
    fn plan(&mut self, t_s: f64, _index: u32, path: &Path, _polygon: Option<&[[f64; 2]]>) {
        let poses: Vec<Pose2> = path.samples.iter().map(|s| s.pose()).collect();
        let msg = msgs::path(t_s, MAP, &poses);
        self.write("/forkbench/plan", &msgs::PATH_MSG, t_s, &msg);
    }

    fn scene(&mut self, s: &SceneInfo<'_>) {
        let tf = msgs::tf(
            0.0,
            MAP,
            &[("pallet", s.pallet_pose), ("fork_root", s.start)],
        );
        self.write("/tf", &msgs::TF_MSG, 0.0, &tf);
        let msg = msgs::marker_array(0.0, &scene_markers(s));
        self.write("/forkbench/scene", &msgs::MARKER_ARRAY_MSG, 0.0, &msg);
    }

    fn signal(&mut self, t_s: f64, path: &str, signal: &Signal<'_>, style: Style) {
        self.write_signal(t_s, path, signal, style);
    }

    fn step(&mut self, s: &StepRecord) {
        let frames = [
            ("fork_root", s.truth),
            ("pallet", s.pallet),
            ("pallet_estimate", s.pallet_estimate),
        ];
        let tf = msgs::tf(s.t_s, MAP, &frames);
        self.write("/tf", &msgs::TF_MSG, s.t_s, &tf);
        let pose = msgs::pose_stamped(s.t_s, MAP, &s.estimate);
        self.write("/forkbench/pose", &msgs::POSE_STAMPED_MSG, s.t_s, &pose);
        let asked = msgs::ackermann(s.t_s, "fork_root", s.steer_cmd_rad, s.speed_cmd_mps);
        self.write(ACTUATORS_COMMAND, &msgs::ACKERMANN_MSG, s.t_s, &asked);
        let got = msgs::ackermann(s.t_s, "fork_root", s.steer_rad, s.speed_mps);
        self.write(ACTUATORS_MEASURED, &msgs::ACKERMANN_MSG, s.t_s, &got);
        if let Some(fix) = s.fix {
            let msg = msgs::pose_stamped(s.t_s, MAP, &fix);
            self.write("/forkbench/fix", &msgs::POSE_STAMPED_MSG, s.t_s, &msg);
        }
        if self.pallet_estimate != Some(s.pallet_estimate) {
            self.pallet_estimate = Some(s.pallet_estimate);
            let msg = msgs::pose_stamped(s.t_s, MAP, &s.pallet_estimate);
            self.write(
                "/forkbench/pallet_estimate",
                &msgs::POSE_STAMPED_MSG,
                s.t_s,
                &msg,
            );
        }
    }

    fn event(&mut self, t_s: f64, level: Level, text: &str) {
        let level = match level {
            Level::Info => 20,
            Level::Warn => 30,
            Level::Error => 40,
        };
        let msg = msgs::log(t_s, level, "forkbench", text);
        self.write("/rosout", &msgs::LOG_MSG, t_s, &msg);
    }

    fn outcome(&mut self, t_s: f64, outcome: &TrialOutcome) {
        match serde_json::to_string(outcome) {
            Ok(json) => {
                let msg = msgs::string(&json);
                self.write("/forkbench/outcome", &msgs::STRING_MSG, t_s, &msg);
            }
            Err(e) => {
                self.error.get_or_insert(e.to_string());
            }
        }
    }
}
