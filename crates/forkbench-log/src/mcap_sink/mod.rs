//! MCAP recording: JSON messages with JSON-Schema schemas, Foxglove well-known names where they fit.

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::mpsc::sync_channel;

use forkbench_core::Pose2;
use forkbench_trial::{Level, Recorder, SceneInfo, StepRecord, TrialOutcome};
use serde::Serialize;
use serde_json::json;

mod entry;
mod messages;
pub use messages::SIM_EPOCH_UNIX_S;
mod schemas;
mod signals;
mod sink;

use messages::*;
use sink::{Cmd, Item, Sink};

use crate::writer::WriterThread;
use crate::{LogError, pallet_outlines, truck_outlines};
use forkbench_core::geometry::rect_outline;

/// Steps and messages are handed to the writer thread in batches of this many (about
/// 0.5 s simulated), so the threads do not wake each other at every step.
const STEP_BATCH: usize = 50;

/// The driven trajectory keeps a point every `TRAJECTORY_POINT_EVERY` steps; it and the
/// look-ahead point are re-sent every `TRAJECTORY_EVERY` steps (10 Hz at the 100 Hz control
/// rate), in segments of at most `TRAJECTORY_SEGMENT_POINTS` points, so each update stays
/// short (JSON serialisation is most of this sink's cost).
const TRAJECTORY_POINT_EVERY: u64 = 2;
const TRAJECTORY_EVERY: u64 = 10;
const TRAJECTORY_SEGMENT_POINTS: usize = 40;
const TRAJECTORY_RGBA: [f64; 4] = [0.12, 0.63, 0.24, 1.0];
const LOOKAHEAD_RGBA: [f64; 4] = [0.85, 0.1, 0.75, 1.0];
const START_RGBA: [f64; 4] = [0.2, 0.2, 0.2, 1.0];
const GOAL_RGBA: [f64; 4] = [0.1, 0.4, 0.9, 1.0];

/// What the trial thread keeps to draw: the trajectory segment being driven and the plan
/// on screen.
#[derive(Default)]
struct DrawState {
    steps: u64,
    segment: Vec<[f64; 2]>,
    segment_index: u32,
    lookahead: [f64; 2],
    /// The fork root now: the end of the drawn trajectory.
    truck: [f64; 2],
    current_plan: Option<u32>,
}

/// `forkbench.Outcome`: the verdict as one line, then the judged outcome's fields.
#[derive(Serialize)]
struct OutcomeMsg {
    verdict: String,
    #[serde(flatten)]
    outcome: TrialOutcome,
}

/// Writes one trial to an indexed, chunked MCAP file.
///
/// Serialising and compressing ~3,000 messages per trial cost more than the trial itself,
/// so a writer thread does it, from the file's header on: the trial thread only hands over
/// each step's record and the other messages, unserialised, through a bounded channel,
/// which also bounds memory when the disk is slower than the simulation.
pub struct McapRecorder {
    writer: WriterThread<Cmd>,
    /// Steps not yet handed over.
    pending: Vec<Item>,
    draw: DrawState,
    /// Topics of signals registered so far, and the scalar signals' by path.
    signal_topics: std::collections::BTreeSet<String>,
    scalar_topics: Vec<(String, std::sync::Arc<str>)>,
    entry: entry::EntryPlot,
}

impl std::fmt::Debug for McapRecorder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "McapRecorder({:?})", self.writer)
    }
}

impl McapRecorder {
    /// Creates `path` (checked beforehand with [`crate::check_writable`]) and starts the
    /// writer thread, which writes the header, schemas and metadata record.
    pub fn create(path: &Path, metadata: BTreeMap<String, String>) -> Result<Self, LogError> {
        let writer = WriterThread::spawn(
            path,
            "mcap-writer",
            "the MCAP writer thread",
            1024,
            Box::new(move |file, rx| match Sink::open(file, metadata) {
                Ok(sink) => sink.run(rx),
                Err(e) => Some(crate::writer::with_causes(&e)),
            }),
        )?;
        Ok(Self {
            writer,
            pending: Vec::with_capacity(STEP_BATCH),
            draw: DrawState::default(),
            signal_topics: Default::default(),
            scalar_topics: Vec::new(),
            entry: entry::EntryPlot::default(),
        })
    }

    /// Queues `msg` for the writer thread, which serialises it.
    fn send<M: Serialize + Send + 'static>(
        &mut self,
        topic: impl Into<std::borrow::Cow<'static, str>>,
        t_s: f64,
        msg: M,
    ) {
        self.queue(Item::Json {
            topic: topic.into(),
            t_s,
            msg: Box::new(move |buf: &mut Vec<u8>| serde_json::to_writer(buf, &msg)),
        });
    }

    fn queue(&mut self, item: Item) {
        self.pending.push(item);
        if self.pending.len() >= STEP_BATCH {
            self.send_pending();
        }
    }

    fn send_pending(&mut self) {
        if !self.pending.is_empty() {
            let items = std::mem::replace(&mut self.pending, Vec::with_capacity(STEP_BATCH));
            self.writer.send(Cmd::Batch(items));
        }
    }

    fn command(&mut self, cmd: Cmd) {
        // Keep messages in order: those queued so far go first.
        self.send_pending();
        self.writer.send(cmd);
    }

    /// Finishes the file (summary and index); returns the first write error, if any.
    pub fn finish(&mut self) -> Result<(), LogError> {
        self.send_pending();
        self.writer.finish()
    }

    /// Flushes the current chunk to disk and waits for it (used by tests to simulate a
    /// crash after it).
    pub fn flush(&mut self) -> Result<(), LogError> {
        let (ack, done) = sync_channel(1);
        self.command(Cmd::Flush(ack));
        match done.recv() {
            Ok(None) => Ok(()),
            Ok(Some(message)) => Err(self.writer.io_error(message)),
            Err(_) => Err(self.writer.stopped()),
        }
    }

    /// Stops writing without finishing the file, as a crash would (tests): the bytes
    /// written stay in the temporary file beside the path, whose path is returned.
    pub fn abandon(mut self) -> Option<std::path::PathBuf> {
        // What a crash would lose: messages not yet handed over.
        self.pending.clear();
        self.command(Cmd::Abandon);
        self.writer.abandon()
    }
}

impl McapRecorder {
    /// Re-sends the trajectory segment being driven and the look-ahead point; a full
    /// segment is left as it is and a new one starts at its last point, so each update
    /// stays short however long the trial.
    fn send_trajectory(&mut self, t_s: f64) {
        let d = &mut self.draw;
        if d.segment.is_empty() {
            return;
        }
        let mut points = d.segment.clone();
        points.push(d.truck);
        let trajectory = entity(
            t_s,
            &format!("trajectory/{}", d.segment_index),
            vec![line_at(&points, 0.02, TRAJECTORY_RGBA, 0.03)],
        );
        let mut lookahead = entity(t_s, "lookahead", Vec::new());
        lookahead
            .spheres
            .push(sphere(d.lookahead, 0.12, LOOKAHEAD_RGBA));
        if d.segment.len() >= TRAJECTORY_SEGMENT_POINTS {
            let last = d.segment[d.segment.len() - 1];
            d.segment = vec![last];
            d.segment_index += 1;
        }
        let scene = SceneUpdate {
            deletions: Vec::new(),
            entities: vec![trajectory, lookahead],
        };
        self.send("/world", t_s, scene);
    }
}

impl McapRecorder {
    /// The start pose and the pallet where it stood, kept while the truck moves.
    fn send_markers(&mut self, s: &SceneInfo<'_>) {
        let mut start = entity(0.0, "start", Vec::new());
        start.arrows.push(pose_arrow(&s.start, START_RGBA));
        let pallet0 = pallet_outlines(s.pallet, &s.pallet_pose)
            .iter()
            .map(|c| line(c, [0.8, 0.55, 0.2, 0.3], 0.01))
            .collect();
        let pallet0 = entity(0.0, "pallet_initial", pallet0);
        let update = SceneUpdate {
            deletions: Vec::new(),
            entities: vec![start, pallet0],
        };
        self.send("/world", 0.0, update);
    }
}

impl Drop for McapRecorder {
    fn drop(&mut self) {
        let _ = self.finish();
    }
}

impl Recorder for McapRecorder {
    fn scene(&mut self, s: &SceneInfo<'_>) {
        self.entry.limits = [s.tolerances.lateral_m, s.tolerances.heading_deg()];
        self.entry.fork_length_m = s.truck.fork_length_m;
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
                deletions: Vec::new(),
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
                deletions: Vec::new(),
                entities,
            },
        );
        self.send_markers(s);
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
        let mut goal = entity(t_s, "goal", Vec::new());
        if let Some(end) = path.samples.last() {
            let end = Pose2::new(end.x_m, end.y_m, end.heading_rad);
            goal.arrows.push(pose_arrow(&end, GOAL_RGBA));
        }
        // The superseded plan goes: only the plan being driven is on screen.
        let deletions = self
            .draw
            .current_plan
            .replace(index)
            .map(|old| Deletion::of(t_s, format!("plan/{old}")))
            .into_iter()
            .collect();
        let plan = entity(t_s, &format!("plan/{index}"), lines);
        let scene = SceneUpdate {
            deletions,
            entities: vec![plan, goal],
        };
        self.send("/world", t_s, scene);
    }

    fn signal(
        &mut self,
        t_s: f64,
        path: &str,
        signal: &forkbench_core::Signal<'_>,
        style: forkbench_core::Style,
    ) {
        self.send_signal(t_s, path, signal, style);
    }

    fn step(&mut self, s: &StepRecord) {
        self.pending.push(Item::Step(*s));
        self.entry_step(s);
        self.draw.steps += 1;
        if self.draw.steps % TRAJECTORY_POINT_EVERY == 1 {
            self.draw.segment.push([s.truth.x_m, s.truth.y_m]);
        }
        self.draw.truck = [s.truth.x_m, s.truth.y_m];
        self.draw.lookahead = s.lookahead;
        if self.draw.steps.is_multiple_of(TRAJECTORY_EVERY) {
            self.send_trajectory(s.t_s);
        }
        if self.pending.len() >= STEP_BATCH {
            self.send_pending();
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
        self.send_trajectory(t_s);
        self.entry_limits(t_s);
        let verdict = outcome.verdict_line();
        let level = if outcome.success { 2 } else { 4 };
        self.send(
            "/log",
            t_s,
            json!({"timestamp": Stamp::at(t_s), "level": level, "message": format!("outcome: {verdict}"), "name": "forkbench", "file": "", "line": 0}),
        );
        let msg = OutcomeMsg {
            verdict,
            outcome: outcome.clone(),
        };
        self.send("/forkbench/outcome", t_s, msg);
        // The outcome is the trial's last message: let the writer thread finish the file
        // (last chunk, summary, index) now, while the other sinks finish theirs;
        // `finish` then only joins it.
        self.send_pending();
        self.writer.close();
    }
}
