//! MCAP recording: JSON messages with JSON-Schema schemas, Foxglove well-known names where they fit.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::Path;
use std::sync::mpsc::{Receiver, SyncSender, sync_channel};
use std::thread::JoinHandle;

use forkbench_core::Pose2;
use forkbench_trial::{Level, Recorder, SceneInfo, StepRecord, TrialOutcome};
use serde::Serialize;
use serde_json::json;

use crate::{LogError, pallet_outlines, truck_outlines};
use forkbench_core::geometry::rect_outline;

/// Topics, schemas and how often they are written.
const CHANNELS: [(&str, &str, &str); 9] = [
    ("/world", "foxglove.SceneUpdate", SCENE_UPDATE_SCHEMA),
    ("/truck/scene", "foxglove.SceneUpdate", SCENE_UPDATE_SCHEMA),
    ("/tf", "foxglove.FrameTransform", FRAME_TRANSFORM_SCHEMA),
    (
        "/truck/pose_true",
        "foxglove.PoseInFrame",
        POSE_IN_FRAME_SCHEMA,
    ),
    (
        "/truck/pose_measured",
        "foxglove.PoseInFrame",
        POSE_IN_FRAME_SCHEMA,
    ),
    ("/log", "foxglove.Log", LOG_SCHEMA),
    (
        "/forkbench/telemetry",
        "forkbench.Telemetry",
        TELEMETRY_SCHEMA,
    ),
    ("/forkbench/plan", "forkbench.Plan", PLAN_SCHEMA),
    ("/forkbench/outcome", "forkbench.Outcome", OUTCOME_SCHEMA),
];

/// Steps are handed to the writer thread in batches of this many (0.5 s simulated), so
/// the threads do not wake each other at every step.
const STEP_BATCH: usize = 50;

/// A pallet (or its estimate) moving less than this since its last transform is not
/// re-sent: it is pushed only on contact, so most trials send one transform each.
const PALLET_MOVE_M: f64 = 5e-4;
const PALLET_TURN_RAD: f64 = 1e-4;

/// Writes one trial to an indexed, chunked MCAP file.
///
/// Serialising and compressing ~3,000 messages per trial cost more than the trial itself,
/// so a writer thread does it, from the file's header on: the trial thread only hands over
/// each step's record and the other messages, unserialised, through a bounded channel,
/// which also bounds memory when the disk is slower than the simulation.
pub struct McapRecorder {
    path: String,
    tx: Option<SyncSender<Cmd>>,
    thread: Option<JoinHandle<Option<String>>>,
    /// Steps not yet handed over.
    steps: Vec<StepRecord>,
    error: Option<String>,
}

/// A message, serialised by the writer thread into its buffer.
type JsonMsg = Box<dyn FnOnce(&mut Vec<u8>) -> serde_json::Result<()> + Send>;

/// Work for the writer thread.
enum Cmd {
    Json {
        topic: &'static str,
        t_s: f64,
        msg: JsonMsg,
    },
    Steps(Vec<StepRecord>),
    /// Flush the current chunk and acknowledge.
    Flush(SyncSender<Option<String>>),
    /// Stop without finishing the file, as a crash would.
    Abandon,
}

/// The writer thread's state.
struct Sink {
    writer: mcap::Writer<BufWriter<File>>,
    channels: BTreeMap<&'static str, u16>,
    sequence: u32,
    /// Last transforms sent for the pallet and its estimate.
    pallet_sent: Option<Pose2>,
    estimate_sent: Option<Pose2>,
    buf: Vec<u8>,
    error: Option<String>,
}

impl std::fmt::Debug for McapRecorder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "McapRecorder({})", self.path)
    }
}

/// An error and its causes: the mcap crate's own message ("I/O error from writing…")
/// hides the reason ("No space left on device") in its source.
fn with_causes(e: &dyn std::error::Error) -> String {
    let mut text = e.to_string();
    let mut cause = e.source();
    while let Some(c) = cause {
        text.push_str(": ");
        text.push_str(&c.to_string());
        cause = c.source();
    }
    text
}

fn ns(t_s: f64) -> u64 {
    (t_s.max(0.0) * 1e9).round() as u64
}

fn moved(last: Option<Pose2>, now: &Pose2) -> bool {
    last.is_none_or(|l| {
        (l.x_m - now.x_m).hypot(l.y_m - now.y_m) > PALLET_MOVE_M
            || (l.heading_rad - now.heading_rad).abs() > PALLET_TURN_RAD
    })
}

/// Typed forms of the per-step messages: serialised straight into a reused buffer, no
/// `Value` tree (the trial writes three of these per 100 Hz step).
#[derive(Serialize)]
struct Stamp {
    sec: u64,
    nsec: u64,
}

impl Stamp {
    fn at(t_s: f64) -> Self {
        let n = ns(t_s);
        Self {
            sec: n / 1_000_000_000,
            nsec: n % 1_000_000_000,
        }
    }
}

#[derive(Serialize)]
struct Vec3 {
    x: f32,
    y: f32,
    z: f32,
}

#[derive(Serialize)]
struct Quat {
    x: f32,
    y: f32,
    z: f32,
    w: f32,
}

impl Quat {
    fn yaw(yaw_rad: f64) -> Self {
        let (s, c) = (yaw_rad / 2.0).sin_cos();
        Self {
            x: 0.0,
            y: 0.0,
            z: s as f32,
            w: c as f32,
        }
    }
}

#[derive(Serialize)]
struct FoxPose {
    position: Vec3,
    orientation: Quat,
}

impl FoxPose {
    fn of(p: &Pose2) -> Self {
        Self {
            position: Vec3 {
                x: p.x_m as f32,
                y: p.y_m as f32,
                z: 0.0,
            },
            orientation: Quat::yaw(p.heading_rad),
        }
    }
}

#[derive(Serialize)]
struct FrameTransform {
    timestamp: Stamp,
    parent_frame_id: &'static str,
    child_frame_id: &'static str,
    translation: Vec3,
    rotation: Quat,
}

impl FrameTransform {
    /// `child`'s pose in the world frame.
    fn world(t_s: f64, child: &'static str, p: &Pose2) -> Self {
        let FoxPose {
            position,
            orientation,
        } = FoxPose::of(p);
        Self {
            timestamp: Stamp::at(t_s),
            parent_frame_id: "world",
            child_frame_id: child,
            translation: position,
            rotation: orientation,
        }
    }
}

#[derive(Serialize)]
struct PoseInFrame {
    timestamp: Stamp,
    frame_id: &'static str,
    pose: FoxPose,
}

impl PoseInFrame {
    fn world(t_s: f64, p: &Pose2) -> Self {
        Self {
            timestamp: Stamp::at(t_s),
            frame_id: "world",
            pose: FoxPose::of(p),
        }
    }
}

#[derive(Serialize)]
struct Telemetry {
    t_s: f64,
    truth: [f32; 3],
    estimate: [f32; 3],
    pallet: [f32; 3],
    pallet_estimate: [f32; 3],
    steer_cmd_rad: f32,
    steer_rad: f32,
    speed_cmd_mps: f32,
    speed_mps: f32,
    lookahead_m: [f32; 2],
    cross_track_m: f32,
    path_curvature_per_m: f32,
    contact_force_n: f32,
}

fn xyh(p: &Pose2) -> [f32; 3] {
    [p.x_m as f32, p.y_m as f32, p.heading_rad as f32]
}

/// An empty JSON array, for the SceneEntity primitive lists we do not use.
type None0 = [u8; 0];

#[derive(Serialize)]
struct Color {
    r: f64,
    g: f64,
    b: f64,
    a: f64,
}

#[derive(Serialize)]
struct LinePrimitive {
    #[serde(rename = "type")]
    kind: u8,
    pose: FoxPose,
    thickness: f64,
    scale_invariant: bool,
    points: Vec<Vec3>,
    color: Color,
    colors: None0,
    indices: None0,
}

#[derive(Serialize)]
struct SceneEntity {
    timestamp: Stamp,
    frame_id: &'static str,
    id: String,
    lifetime: Stamp,
    frame_locked: bool,
    metadata: None0,
    arrows: None0,
    cubes: None0,
    spheres: None0,
    cylinders: None0,
    lines: Vec<LinePrimitive>,
    triangles: None0,
    texts: None0,
    models: None0,
}

#[derive(Serialize)]
struct SceneUpdate {
    deletions: None0,
    entities: Vec<SceneEntity>,
}

impl SceneUpdate {
    fn one(e: SceneEntity) -> Self {
        Self {
            deletions: [],
            entities: vec![e],
        }
    }
}

#[derive(Serialize)]
struct PlanMsg {
    index: u32,
    t_s: f64,
    length_m: f64,
    /// [s_m, x_m, y_m, heading_rad, curvature_per_m]
    samples: Vec<[f64; 5]>,
    control_polygon_m: Option<Vec<[f64; 2]>>,
}

/// A line strip (type 0) in world coordinates.
fn line(points: &[[f64; 2]], rgba: [f64; 4], thickness: f64) -> LinePrimitive {
    LinePrimitive {
        kind: 0,
        pose: FoxPose::of(&Pose2::new(0.0, 0.0, 0.0)),
        thickness,
        scale_invariant: false,
        points: points
            .iter()
            .map(|p| Vec3 {
                x: p[0] as f32,
                y: p[1] as f32,
                z: 0.0,
            })
            .collect(),
        color: Color {
            r: rgba[0],
            g: rgba[1],
            b: rgba[2],
            a: rgba[3],
        },
        colors: [],
        indices: [],
    }
}

fn entity(t_s: f64, id: &str, lines: Vec<LinePrimitive>) -> SceneEntity {
    entity_in("world", t_s, id, lines)
}

/// An entity drawn in `frame`; frame-locked, so it follows that frame's /tf.
fn entity_in(frame: &'static str, t_s: f64, id: &str, lines: Vec<LinePrimitive>) -> SceneEntity {
    SceneEntity {
        timestamp: Stamp::at(t_s),
        frame_id: frame,
        id: id.to_owned(),
        lifetime: Stamp { sec: 0, nsec: 0 },
        frame_locked: frame != "world",
        metadata: [],
        arrows: [],
        cubes: [],
        spheres: [],
        cylinders: [],
        lines,
        triangles: [],
        texts: [],
        models: [],
    }
}

impl Sink {
    /// Starts the MCAP file in `file`: header, schemas, channels and the metadata record.
    fn open(file: File, metadata: BTreeMap<String, String>) -> Result<Self, String> {
        let io = |e: &dyn std::error::Error| with_causes(e);
        // Small chunks: a crash loses at most the chunk being written. LZ4 on this thread
        // only (no compressor threads, which would take the trial's core): on the field
        // test it costs 8.7 M instructions less per trial than zstd level 1 (49.5 vs
        // 58.2 M over the plain trial, callgrind), for files 1.5× larger (422 vs 276 KB).
        let mut writer = mcap::WriteOptions::new()
            .chunk_size(Some(64 * 1024))
            .compression(Some(mcap::Compression::Lz4))
            .compression_level(1)
            .compression_threads(0)
            .create(BufWriter::new(file))
            .map_err(|e| io(&e))?;
        let mut schemas = BTreeMap::new();
        let mut channels = BTreeMap::new();
        for (topic, name, schema) in CHANNELS {
            let sid = match schemas.get(name) {
                Some(id) => *id,
                None => {
                    let id = writer
                        .add_schema(name, "jsonschema", schema.as_bytes())
                        .map_err(|e| io(&e))?;
                    schemas.insert(name, id);
                    id
                }
            };
            let cid = writer
                .add_channel(sid, topic, "json", &BTreeMap::new())
                .map_err(|e| io(&e))?;
            channels.insert(topic, cid);
        }
        writer
            .write_metadata(&mcap::records::Metadata {
                name: "forkbench".into(),
                metadata,
            })
            .map_err(|e| io(&e))?;
        Ok(Self {
            writer,
            channels,
            sequence: 0,
            pallet_sent: None,
            estimate_sent: None,
            buf: Vec::with_capacity(1024),
            error: None,
        })
    }

    /// Runs the writer thread's commands, then finishes the file; returns the first error.
    fn run(mut self, rx: Receiver<Cmd>) -> Option<String> {
        for cmd in rx {
            match cmd {
                Cmd::Json { topic, t_s, msg } => self.write_json(topic, t_s, msg),
                Cmd::Steps(steps) => steps.iter().for_each(|s| self.step(s)),
                Cmd::Flush(ack) => {
                    let r = self.writer.flush().err().map(|e| with_causes(&e));
                    let _ = ack.send(r);
                }
                Cmd::Abandon => {
                    std::mem::forget(self);
                    return None;
                }
            }
        }
        if let Err(e) = self.writer.finish() {
            self.error.get_or_insert(with_causes(&e));
        }
        self.error
    }
}

impl McapRecorder {
    /// Creates `path` (checked beforehand with [`crate::check_writable`]) and starts the
    /// writer thread, which writes the header, schemas and metadata record: only creating
    /// the file, the step that fails on a bad path, holds up the trial.
    pub fn create(path: &Path, metadata: BTreeMap<String, String>) -> Result<Self, LogError> {
        let p = path.display().to_string();
        let io = |e: &dyn std::error::Error| LogError::Io {
            path: p.clone(),
            message: with_causes(e),
        };
        let file = File::create(path).map_err(|e| io(&e))?;
        let (tx, rx) = sync_channel::<Cmd>(1024);
        let thread = std::thread::Builder::new()
            .name("mcap-writer".into())
            .spawn(move || match Sink::open(file, metadata) {
                Ok(sink) => sink.run(rx),
                Err(e) => Some(e),
            })
            .map_err(|e| io(&e))?;
        Ok(Self {
            path: p,
            tx: Some(tx),
            thread: Some(thread),
            steps: Vec::with_capacity(STEP_BATCH),
            error: None,
        })
    }

    /// Hands `msg` to the writer thread, which serialises it.
    fn send<M: Serialize + Send + 'static>(&mut self, topic: &'static str, t_s: f64, msg: M) {
        self.command(Cmd::Json {
            topic,
            t_s,
            msg: Box::new(move |buf: &mut Vec<u8>| serde_json::to_writer(buf, &msg)),
        });
    }

    fn send_steps(&mut self) {
        if !self.steps.is_empty() {
            let steps = std::mem::replace(&mut self.steps, Vec::with_capacity(STEP_BATCH));
            self.command(Cmd::Steps(steps));
        }
    }

    fn command(&mut self, cmd: Cmd) {
        if !matches!(cmd, Cmd::Steps(_)) {
            // Keep messages in order: steps collected so far go first.
            self.send_steps();
        }
        if let Some(tx) = &self.tx
            && tx.send(cmd).is_err()
        {
            self.error
                .get_or_insert_with(|| "the MCAP writer thread stopped".to_owned());
        }
    }

    /// Finishes the file (summary and index); returns the first write error, if any.
    pub fn finish(&mut self) -> Result<(), LogError> {
        self.send_steps();
        self.tx = None;
        if let Some(t) = self.thread.take() {
            match t.join() {
                // The thread's own error is the cause of a "stopped" noted here.
                Ok(Some(e)) => self.error = Some(e),
                Ok(None) => {}
                Err(_) => {
                    self.error
                        .get_or_insert_with(|| "the MCAP writer thread panicked".to_owned());
                }
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

    /// Flushes the current chunk to disk and waits for it (used by tests to simulate a
    /// crash after it).
    pub fn flush(&mut self) -> Result<(), LogError> {
        let (ack, done) = sync_channel(1);
        self.command(Cmd::Flush(ack));
        match done.recv() {
            Ok(None) => Ok(()),
            Ok(Some(message)) => Err(LogError::Io {
                path: self.path.clone(),
                message,
            }),
            Err(_) => Err(LogError::Io {
                path: self.path.clone(),
                message: "the MCAP writer thread stopped".to_owned(),
            }),
        }
    }

    /// Stops writing without finishing the file, as a crash would (tests).
    pub fn abandon(mut self) {
        // What a crash would lose: steps not yet handed over.
        self.steps.clear();
        self.command(Cmd::Abandon);
        self.tx = None;
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

impl Sink {
    fn write(&mut self, topic: &str, t_s: f64, msg: &impl Serialize) {
        self.write_json(topic, t_s, |buf| serde_json::to_writer(buf, msg));
    }

    /// Serialises a message with `to_json` into the reused buffer and writes it.
    fn write_json(
        &mut self,
        topic: &str,
        t_s: f64,
        to_json: impl FnOnce(&mut Vec<u8>) -> serde_json::Result<()>,
    ) {
        let mut buf = std::mem::take(&mut self.buf);
        buf.clear();
        match to_json(&mut buf) {
            Ok(()) => self.write_bytes(topic, t_s, &buf),
            Err(e) => {
                self.error.get_or_insert(e.to_string());
            }
        }
        self.buf = buf;
    }

    fn write_bytes(&mut self, topic: &str, t_s: f64, data: &[u8]) {
        let Some(&channel_id) = self.channels.get(topic) else {
            return;
        };
        self.sequence += 1;
        let header = mcap::records::MessageHeader {
            channel_id,
            sequence: self.sequence,
            log_time: ns(t_s),
            publish_time: ns(t_s),
        };
        if let Err(e) = self.writer.write_to_known_channel(&header, data) {
            self.error.get_or_insert(with_causes(&e));
        }
    }

    fn transform(&mut self, t_s: f64, child: &'static str, p: &Pose2) {
        self.write("/tf", t_s, &FrameTransform::world(t_s, child, p));
    }

    fn step(&mut self, s: &StepRecord) {
        let t = s.t_s;
        self.transform(t, "fork_root", &s.truth);
        if moved(self.pallet_sent, &s.pallet) {
            self.transform(t, "pallet", &s.pallet);
            self.pallet_sent = Some(s.pallet);
        }
        if moved(self.estimate_sent, &s.pallet_estimate) {
            self.transform(t, "pallet_estimate", &s.pallet_estimate);
            self.estimate_sent = Some(s.pallet_estimate);
        }
        // True and measured poses side by side at each NAV350 fix (the true pose at the
        // full rate is /tf and the telemetry's `truth`).
        if let Some(f) = &s.fix {
            self.write("/truck/pose_measured", t, &PoseInFrame::world(t, f));
            self.write("/truck/pose_true", t, &PoseInFrame::world(t, &s.truth));
        }
        let telemetry = Telemetry {
            t_s: t,
            truth: xyh(&s.truth),
            estimate: xyh(&s.estimate),
            pallet: xyh(&s.pallet),
            pallet_estimate: xyh(&s.pallet_estimate),
            steer_cmd_rad: s.steer_cmd_rad as f32,
            steer_rad: s.steer_rad as f32,
            speed_cmd_mps: s.speed_cmd_mps as f32,
            speed_mps: s.speed_mps as f32,
            lookahead_m: s.lookahead.map(|v| v as f32),
            cross_track_m: s.cross_track_m as f32,
            path_curvature_per_m: s.path_curvature_per_m as f32,
            contact_force_n: s.contact_force_n as f32,
        };
        self.write("/forkbench/telemetry", t, &telemetry);
    }
}

impl Drop for McapRecorder {
    fn drop(&mut self) {
        let _ = self.finish();
    }
}

impl Recorder for McapRecorder {
    fn scene(&mut self, s: &SceneInfo<'_>) {
        let entities: Vec<SceneEntity> = s
            .obstacles
            .iter()
            .enumerate()
            .map(|(i, o)| {
                entity(
                    0.0,
                    &format!("obstacle/{i}"),
                    vec![line(
                        &rect_outline(&o.centre, o.length_m, o.width_m),
                        [0.5, 0.5, 0.5, 1.0],
                        0.03,
                    )],
                )
            })
            .collect();
        self.send(
            "/world",
            0.0,
            SceneUpdate {
                deletions: [],
                entities,
            },
        );
        // Truck and pallets are drawn once in their own frames and moved by /tf.
        let origin = Pose2::new(0.0, 0.0, 0.0);
        let outlines = |o: Vec<[[f64; 2]; 5]>, rgba: [f64; 4]| -> Vec<LinePrimitive> {
            o.iter().map(|c| line(c, rgba, 0.02)).collect()
        };
        let entities = vec![
            entity_in(
                "fork_root",
                0.0,
                "truck",
                outlines(truck_outlines(s.truck, &origin), [0.9, 0.75, 0.1, 1.0]),
            ),
            entity_in(
                "pallet",
                0.0,
                "pallet",
                outlines(pallet_outlines(s.pallet, &origin), [0.8, 0.55, 0.2, 1.0]),
            ),
            entity_in(
                "pallet_estimate",
                0.0,
                "pallet_estimate",
                outlines(pallet_outlines(s.pallet, &origin), [0.85, 0.15, 0.15, 0.6]),
            ),
        ];
        self.send(
            "/truck/scene",
            0.0,
            SceneUpdate {
                deletions: [],
                entities,
            },
        );
        for (child, pose) in [("fork_root", &s.start), ("pallet", &s.pallet_pose)] {
            self.send("/tf", 0.0, FrameTransform::world(0.0, child, pose));
        }
    }

    fn plan(
        &mut self,
        t_s: f64,
        index: u32,
        path: &forkbench_core::Path,
        control_polygon: Option<&[[f64; 2]]>,
    ) {
        let msg = PlanMsg {
            index,
            t_s,
            length_m: path.length_m(),
            samples: path
                .samples
                .iter()
                .map(|p| [p.s_m, p.x_m, p.y_m, p.heading_rad, p.curvature_per_m])
                .collect(),
            control_polygon_m: control_polygon.map(<[_]>::to_vec),
        };
        self.send("/forkbench/plan", t_s, msg);
        let pts: Vec<[f64; 2]> = path.samples.iter().map(|p| [p.x_m, p.y_m]).collect();
        let mut lines = vec![line(&pts, [0.1, 0.4, 0.9, 1.0], 0.02)];
        if let Some(c) = control_polygon {
            lines.push(line(c, [0.1, 0.4, 0.9, 0.4], 0.01));
        }
        let scene = SceneUpdate::one(entity(t_s, &format!("plan/{index}"), lines));
        self.send("/world", t_s, scene);
    }

    fn step(&mut self, s: &StepRecord) {
        self.steps.push(*s);
        if self.steps.len() >= STEP_BATCH {
            self.send_steps();
        }
    }

    fn event(&mut self, t_s: f64, level: Level, text: &str) {
        let level = match level {
            Level::Info => 2,
            Level::Warn => 3,
            Level::Error => 4,
        };
        self.send(
            "/log",
            t_s,
            json!({"timestamp": Stamp::at(t_s), "level": level, "message": text, "name": "forkbench", "file": "", "line": 0}),
        );
    }

    fn outcome(&mut self, t_s: f64, outcome: &TrialOutcome) {
        // `send` hands over the steps collected so far first.
        self.send("/forkbench/outcome", t_s, outcome.clone());
        // The outcome is the trial's last message: let the writer thread finish the file
        // (last chunk, summary, index) now, while the other sinks finish theirs;
        // `finish` then only joins it.
        self.tx = None;
    }
}

const SCENE_UPDATE_SCHEMA: &str = r#"{"title":"foxglove.SceneUpdate","type":"object","properties":{"deletions":{"type":"array","items":{"type":"object"}},"entities":{"type":"array","items":{"type":"object","properties":{"timestamp":{"type":"object"},"frame_id":{"type":"string"},"id":{"type":"string"},"lifetime":{"type":"object"},"frame_locked":{"type":"boolean"},"metadata":{"type":"array"},"arrows":{"type":"array"},"cubes":{"type":"array"},"spheres":{"type":"array"},"cylinders":{"type":"array"},"lines":{"type":"array","items":{"type":"object","properties":{"type":{"type":"integer"},"pose":{"type":"object"},"thickness":{"type":"number"},"scale_invariant":{"type":"boolean"},"points":{"type":"array"},"color":{"type":"object"},"colors":{"type":"array"},"indices":{"type":"array"}}}},"triangles":{"type":"array"},"texts":{"type":"array"},"models":{"type":"array"}}}}}}"#;

const FRAME_TRANSFORM_SCHEMA: &str = r#"{"title":"foxglove.FrameTransform","type":"object","properties":{"timestamp":{"type":"object"},"parent_frame_id":{"type":"string"},"child_frame_id":{"type":"string"},"translation":{"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"}}},"rotation":{"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"},"w":{"type":"number"}}}}}"#;

const POSE_IN_FRAME_SCHEMA: &str = r#"{"title":"foxglove.PoseInFrame","type":"object","properties":{"timestamp":{"type":"object"},"frame_id":{"type":"string"},"pose":{"type":"object","properties":{"position":{"type":"object"},"orientation":{"type":"object"}}}}}"#;

const LOG_SCHEMA: &str = r#"{"title":"foxglove.Log","type":"object","properties":{"timestamp":{"type":"object"},"level":{"type":"integer","minimum":0,"maximum":5},"message":{"type":"string"},"name":{"type":"string"},"file":{"type":"string"},"line":{"type":"integer","minimum":0}}}"#;

const TELEMETRY_SCHEMA: &str = r#"{"title":"forkbench.Telemetry","description":"One control step, SI units","type":"object","properties":{"t_s":{"type":"number"},"truth":{"type":"array","items":{"type":"number"},"description":"true fork-root x_m, y_m, heading_rad"},"estimate":{"type":"array","items":{"type":"number"},"description":"x_m, y_m, heading_rad the controller used"},"pallet":{"type":"array","items":{"type":"number"}},"pallet_estimate":{"type":"array","items":{"type":"number"}},"steer_cmd_rad":{"type":"number"},"steer_rad":{"type":"number"},"speed_cmd_mps":{"type":"number"},"speed_mps":{"type":"number"},"lookahead_m":{"type":"array","items":{"type":"number"}},"cross_track_m":{"type":"number"},"path_curvature_per_m":{"type":"number"},"contact_force_n":{"type":"number"}}}"#;

const PLAN_SCHEMA: &str = r#"{"title":"forkbench.Plan","type":"object","properties":{"index":{"type":"integer"},"t_s":{"type":"number"},"length_m":{"type":"number"},"samples":{"type":"array","description":"[s_m, x_m, y_m, heading_rad, curvature_per_m]","items":{"type":"array","items":{"type":"number"}}},"control_polygon_m":{"type":["array","null"]}}}"#;

const OUTCOME_SCHEMA: &str = r#"{"title":"forkbench.Outcome","description":"The judged trial outcome (forkbench_trial::TrialOutcome), SI units","type":"object","properties":{"scenario":{"type":"string"},"case":{"type":"string"},"planner":{"type":"string"},"seed":{"type":"integer"},"success":{"type":"boolean"},"failure":{"type":["string","null"]},"lateral_error_m":{"type":["number","null"]},"heading_error_rad":{"type":["number","null"]},"insertion_depth_m":{"type":["number","null"]},"sim_time_s":{"type":"number"}}}"#;
