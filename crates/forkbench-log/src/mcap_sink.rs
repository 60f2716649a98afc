//! MCAP recording: JSON messages with JSON-Schema schemas, Foxglove well-known names where they fit.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

use forkbench_core::{ForkliftSpec, Pose2};
use forkbench_sim::PalletSpec;
use forkbench_trial::{Level, Recorder, SceneInfo, StepRecord, TrialOutcome};
use serde_json::{Value, json};

use crate::{LogError, pallet_outlines, rect_corners, truck_outlines};

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

/// Scene geometry is redrawn every this many control steps (10 Hz at 100 Hz).
const SCENE_EVERY: u64 = 10;

/// Writes one trial to an indexed, chunked MCAP file.
pub struct McapRecorder {
    writer: Option<mcap::Writer<BufWriter<File>>>,
    path: String,
    channels: BTreeMap<&'static str, u16>,
    sequence: u32,
    steps: u64,
    truck: Option<ForkliftSpec>,
    pallet: Option<PalletSpec>,
    error: Option<String>,
}

impl std::fmt::Debug for McapRecorder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "McapRecorder({})", self.path)
    }
}

fn ns(t_s: f64) -> u64 {
    (t_s.max(0.0) * 1e9).round() as u64
}

fn stamp(t_s: f64) -> Value {
    let n = ns(t_s);
    json!({"sec": n / 1_000_000_000, "nsec": n % 1_000_000_000})
}

fn quat(yaw: f64) -> Value {
    json!({"x": 0.0, "y": 0.0, "z": (yaw / 2.0).sin(), "w": (yaw / 2.0).cos()})
}

fn pose_json(p: &Pose2) -> Value {
    json!({"position": {"x": p.x_m, "y": p.y_m, "z": 0.0}, "orientation": quat(p.heading_rad)})
}

fn line(points: &[[f64; 2]], rgba: [f64; 4], thickness: f64) -> Value {
    json!({
        "type": 0,
        "pose": pose_json(&Pose2::new(0.0, 0.0, 0.0)),
        "thickness": thickness,
        "scale_invariant": false,
        "points": points.iter().map(|p| json!({"x": p[0], "y": p[1], "z": 0.0})).collect::<Vec<_>>(),
        "color": {"r": rgba[0], "g": rgba[1], "b": rgba[2], "a": rgba[3]},
        "colors": [],
        "indices": [],
    })
}

fn entity(t_s: f64, id: &str, lines: Vec<Value>) -> Value {
    json!({
        "timestamp": stamp(t_s),
        "frame_id": "world",
        "id": id,
        "lifetime": {"sec": 0, "nsec": 0},
        "frame_locked": false,
        "metadata": [],
        "arrows": [], "cubes": [], "spheres": [], "cylinders": [],
        "lines": lines,
        "triangles": [], "texts": [], "models": [],
    })
}

impl McapRecorder {
    /// Opens `path` (checked beforehand with [`crate::check_writable`]) and writes the
    /// metadata record.
    pub fn create(path: &Path, metadata: BTreeMap<String, String>) -> Result<Self, LogError> {
        let p = path.display().to_string();
        let io = |e: &dyn std::fmt::Display| LogError::Io {
            path: p.clone(),
            message: e.to_string(),
        };
        let file = File::create(path).map_err(|e| io(&e))?;
        // Small chunks: a crash loses at most the chunk being written. lz4 rather than
        // the default zstd: recording must stay cheap next to the trial itself.
        let mut writer = mcap::WriteOptions::new()
            .chunk_size(Some(64 * 1024))
            .compression(Some(mcap::Compression::Lz4))
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
            writer: Some(writer),
            path: p,
            channels,
            sequence: 0,
            steps: 0,
            truck: None,
            pallet: None,
            error: None,
        })
    }

    fn write(&mut self, topic: &str, t_s: f64, msg: &Value) {
        let (Some(w), Some(&channel_id)) = (self.writer.as_mut(), self.channels.get(topic)) else {
            return;
        };
        self.sequence += 1;
        let header = mcap::records::MessageHeader {
            channel_id,
            sequence: self.sequence,
            log_time: ns(t_s),
            publish_time: ns(t_s),
        };
        let data = msg.to_string();
        if let Err(e) = w.write_to_known_channel(&header, data.as_bytes()) {
            self.error.get_or_insert(e.to_string());
        }
    }

    /// Finishes the file (summary and index); returns the first write error, if any.
    pub fn finish(&mut self) -> Result<(), LogError> {
        if let Some(mut w) = self.writer.take()
            && let Err(e) = w.finish()
        {
            self.error.get_or_insert(e.to_string());
        }
        match self.error.take() {
            Some(message) => Err(LogError::Io {
                path: self.path.clone(),
                message,
            }),
            None => Ok(()),
        }
    }

    /// Flushes the current chunk (used by tests to simulate a crash after it).
    pub fn flush(&mut self) -> Result<(), LogError> {
        if let Some(w) = self.writer.as_mut() {
            w.flush().map_err(|e| LogError::Io {
                path: self.path.clone(),
                message: e.to_string(),
            })?;
        }
        Ok(())
    }

    /// Drops the writer without finishing, as a crash would (tests).
    pub fn abandon(mut self) {
        if let Some(w) = self.writer.take() {
            std::mem::forget(w);
        }
    }
}

impl Drop for McapRecorder {
    fn drop(&mut self) {
        let _ = self.finish();
    }
}

impl Recorder for McapRecorder {
    fn scene(&mut self, s: &SceneInfo<'_>) {
        self.truck = Some(s.truck.clone());
        self.pallet = Some(s.pallet.clone());
        let mut entities: Vec<Value> = s
            .obstacles
            .iter()
            .enumerate()
            .map(|(i, o)| {
                entity(
                    0.0,
                    &format!("obstacle/{i}"),
                    vec![line(
                        &rect_corners(&o.centre, o.length_m, o.width_m),
                        [0.5, 0.5, 0.5, 1.0],
                        0.03,
                    )],
                )
            })
            .collect();
        entities.push(entity(
            0.0,
            "pallet",
            pallet_outlines(s.pallet, &s.pallet_pose)
                .iter()
                .map(|c| line(c, [0.8, 0.55, 0.2, 1.0], 0.02))
                .collect(),
        ));
        self.write(
            "/world",
            0.0,
            &json!({"deletions": [], "entities": entities}),
        );
    }

    fn plan(
        &mut self,
        t_s: f64,
        index: u32,
        path: &forkbench_core::Path,
        control_polygon: Option<&[[f64; 2]]>,
    ) {
        let msg = json!({
            "index": index,
            "t_s": t_s,
            "length_m": path.length_m(),
            "samples": path.samples.iter().map(|p| [p.s_m, p.x_m, p.y_m, p.heading_rad, p.curvature_per_m]).collect::<Vec<_>>(),
            "control_polygon_m": control_polygon,
        });
        self.write("/forkbench/plan", t_s, &msg);
        let pts: Vec<[f64; 2]> = path.samples.iter().map(|p| [p.x_m, p.y_m]).collect();
        let mut lines = vec![line(&pts, [0.1, 0.4, 0.9, 1.0], 0.02)];
        if let Some(c) = control_polygon {
            lines.push(line(c, [0.1, 0.4, 0.9, 0.4], 0.01));
        }
        let scene =
            json!({"deletions": [], "entities": [entity(t_s, &format!("plan/{index}"), lines)]});
        self.write("/world", t_s, &scene);
    }

    fn step(&mut self, s: &StepRecord) {
        self.steps += 1;
        let t = s.t_s;
        let tf = json!({
            "timestamp": stamp(t),
            "parent_frame_id": "world",
            "child_frame_id": "fork_root",
            "translation": {"x": s.truth.x_m, "y": s.truth.y_m, "z": 0.0},
            "rotation": quat(s.truth.heading_rad),
        });
        self.write("/tf", t, &tf);
        self.write(
            "/truck/pose_true",
            t,
            &json!({"timestamp": stamp(t), "frame_id": "world", "pose": pose_json(&s.truth)}),
        );
        if let Some(f) = &s.fix {
            self.write(
                "/truck/pose_measured",
                t,
                &json!({"timestamp": stamp(t), "frame_id": "world", "pose": pose_json(f)}),
            );
        }
        let telemetry = json!({
            "t_s": t,
            "estimate": [s.estimate.x_m, s.estimate.y_m, s.estimate.heading_rad],
            "pallet": [s.pallet.x_m, s.pallet.y_m, s.pallet.heading_rad],
            "pallet_estimate": [s.pallet_estimate.x_m, s.pallet_estimate.y_m, s.pallet_estimate.heading_rad],
            "steer_cmd_rad": s.steer_cmd_rad,
            "steer_rad": s.steer_rad,
            "speed_cmd_mps": s.speed_cmd_mps,
            "speed_mps": s.speed_mps,
            "lookahead_m": s.lookahead,
            "cross_track_m": s.cross_track_m,
            "path_curvature_per_m": s.path_curvature_per_m,
            "contact_force_n": s.contact_force_n,
        });
        self.write("/forkbench/telemetry", t, &telemetry);
        if self.steps % SCENE_EVERY == 1
            && let (Some(truck), Some(pallet)) = (self.truck.clone(), self.pallet.clone())
        {
            let mut lines: Vec<Value> = truck_outlines(&truck, &s.truth)
                .iter()
                .map(|c| line(c, [0.9, 0.75, 0.1, 1.0], 0.02))
                .collect();
            lines.extend(
                pallet_outlines(&pallet, &s.pallet)
                    .iter()
                    .map(|c| line(c, [0.8, 0.55, 0.2, 1.0], 0.02)),
            );
            self.write(
                "/truck/scene",
                t,
                &json!({"deletions": [], "entities": [entity(t, "truck_and_pallet", lines)]}),
            );
        }
    }

    fn event(&mut self, t_s: f64, level: Level, text: &str) {
        let level = match level {
            Level::Info => 2,
            Level::Warn => 3,
            Level::Error => 4,
        };
        self.write(
            "/log",
            t_s,
            &json!({"timestamp": stamp(t_s), "level": level, "message": text, "name": "forkbench", "file": "", "line": 0}),
        );
    }

    fn outcome(&mut self, t_s: f64, outcome: &TrialOutcome) {
        match serde_json::to_value(outcome) {
            Ok(v) => self.write("/forkbench/outcome", t_s, &v),
            Err(e) => {
                self.error.get_or_insert(e.to_string());
            }
        }
    }
}

const SCENE_UPDATE_SCHEMA: &str = r#"{"title":"foxglove.SceneUpdate","type":"object","properties":{"deletions":{"type":"array","items":{"type":"object"}},"entities":{"type":"array","items":{"type":"object","properties":{"timestamp":{"type":"object"},"frame_id":{"type":"string"},"id":{"type":"string"},"lifetime":{"type":"object"},"frame_locked":{"type":"boolean"},"metadata":{"type":"array"},"arrows":{"type":"array"},"cubes":{"type":"array"},"spheres":{"type":"array"},"cylinders":{"type":"array"},"lines":{"type":"array","items":{"type":"object","properties":{"type":{"type":"integer"},"pose":{"type":"object"},"thickness":{"type":"number"},"scale_invariant":{"type":"boolean"},"points":{"type":"array"},"color":{"type":"object"},"colors":{"type":"array"},"indices":{"type":"array"}}}},"triangles":{"type":"array"},"texts":{"type":"array"},"models":{"type":"array"}}}}}}"#;

const FRAME_TRANSFORM_SCHEMA: &str = r#"{"title":"foxglove.FrameTransform","type":"object","properties":{"timestamp":{"type":"object"},"parent_frame_id":{"type":"string"},"child_frame_id":{"type":"string"},"translation":{"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"}}},"rotation":{"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"},"w":{"type":"number"}}}}}"#;

const POSE_IN_FRAME_SCHEMA: &str = r#"{"title":"foxglove.PoseInFrame","type":"object","properties":{"timestamp":{"type":"object"},"frame_id":{"type":"string"},"pose":{"type":"object","properties":{"position":{"type":"object"},"orientation":{"type":"object"}}}}}"#;

const LOG_SCHEMA: &str = r#"{"title":"foxglove.Log","type":"object","properties":{"timestamp":{"type":"object"},"level":{"type":"integer","minimum":0,"maximum":5},"message":{"type":"string"},"name":{"type":"string"},"file":{"type":"string"},"line":{"type":"integer","minimum":0}}}"#;

const TELEMETRY_SCHEMA: &str = r#"{"title":"forkbench.Telemetry","description":"One control step, SI units","type":"object","properties":{"t_s":{"type":"number"},"estimate":{"type":"array","items":{"type":"number"},"description":"x_m, y_m, heading_rad the controller used"},"pallet":{"type":"array","items":{"type":"number"}},"pallet_estimate":{"type":"array","items":{"type":"number"}},"steer_cmd_rad":{"type":"number"},"steer_rad":{"type":"number"},"speed_cmd_mps":{"type":"number"},"speed_mps":{"type":"number"},"lookahead_m":{"type":"array","items":{"type":"number"}},"cross_track_m":{"type":"number"},"path_curvature_per_m":{"type":"number"},"contact_force_n":{"type":"number"}}}"#;

const PLAN_SCHEMA: &str = r#"{"title":"forkbench.Plan","type":"object","properties":{"index":{"type":"integer"},"t_s":{"type":"number"},"length_m":{"type":"number"},"samples":{"type":"array","description":"[s_m, x_m, y_m, heading_rad, curvature_per_m]","items":{"type":"array","items":{"type":"number"}}},"control_polygon_m":{"type":["array","null"]}}}"#;

const OUTCOME_SCHEMA: &str = r#"{"title":"forkbench.Outcome","description":"The judged trial outcome (forkbench_trial::TrialOutcome), SI units","type":"object","properties":{"scenario":{"type":"string"},"case":{"type":"string"},"planner":{"type":"string"},"seed":{"type":"integer"},"success":{"type":"boolean"},"failure":{"type":["string","null"]},"lateral_error_m":{"type":["number","null"]},"heading_error_rad":{"type":["number","null"]},"insertion_depth_m":{"type":["number","null"]},"sim_time_s":{"type":"number"}}}"#;
