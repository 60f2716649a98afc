//! Open-vocabulary signals in MCAP: shapes as `/world` scene entities named by their path; poses, scans, grids and scalars on topics of their own (`foxglove.PoseInFrame`, `LaserScan`, `Grid`, `forkbench.Scalar`); text in `/log`.

use base64::Engine as _;
use forkbench_core::signal::{Grid, Scan};
use forkbench_core::{Pose2, Signal, Style};
use serde::Serialize;
use serde_json::json;

use super::McapRecorder;
use super::messages::*;
use super::schemas::{GRID_SCHEMA, LASER_SCAN_SCHEMA, POSE_IN_FRAME_SCHEMA, SCALAR_SCHEMA};
use super::sink::{Cmd, Item};
use std::sync::Arc;

/// What a style leaves unset.
const DEFAULT_RGBA: [u8; 4] = [200, 200, 200, 255];
const DEFAULT_WIDTH_M: f64 = 0.02;

fn rgba(style: &Style) -> [f64; 4] {
    style
        .rgba
        .unwrap_or(DEFAULT_RGBA)
        .map(|c| f64::from(c) / 255.0)
}

fn width(style: &Style) -> f64 {
    style.width_m.unwrap_or(DEFAULT_WIDTH_M)
}

/// `foxglove.LaserScan` in the world frame; `null` ranges are beams without a return.
#[derive(Serialize)]
struct LaserScanMsg {
    timestamp: Stamp,
    frame_id: &'static str,
    pose: FoxPose,
    start_angle: f64,
    end_angle: f64,
    ranges: Vec<Option<f64>>,
    intensities: None0,
}

#[derive(Serialize)]
struct PackedField {
    name: &'static str,
    offset: u32,
    /// 1 = UINT8.
    #[serde(rename = "type")]
    kind: u8,
}

/// `foxglove.Grid`: one UINT8 occupancy field per cell, rows from the origin; `data` in base64.
#[derive(Serialize)]
struct GridMsg {
    timestamp: Stamp,
    frame_id: &'static str,
    pose: FoxPose,
    column_count: usize,
    cell_size: Vec2,
    row_stride: usize,
    cell_stride: usize,
    fields: [PackedField; 1],
    data: String,
}

#[derive(Serialize)]
struct Vec2 {
    x: f64,
    y: f64,
}

impl McapRecorder {
    /// Records one signal on the topic its kind maps to.
    pub(super) fn send_signal(&mut self, t_s: f64, path: &str, signal: &Signal<'_>, style: Style) {
        let (c, w) = (rgba(&style), width(&style));
        let lines = match signal {
            Signal::Scalar(v) => return self.send_scalar(t_s, path, *v),
            Signal::Text(text) => return self.send_text(t_s, path, text),
            Signal::Scan(scan) => {
                self.send_scan(t_s, path, scan);
                let mut e = entity(t_s, path, Vec::new());
                e.spheres = scan
                    .points()
                    .into_iter()
                    .map(|p| sphere(p, w.max(0.03) as f32, c))
                    .collect();
                return self.send_entity(t_s, e);
            }
            Signal::Grid(grid) => {
                self.send_grid(t_s, path, grid);
                boxes(&grid.blocked_rects(), c, w)
            }
            Signal::Pose(p) => {
                let topic =
                    self.topic("/pose/", path, "foxglove.PoseInFrame", POSE_IN_FRAME_SCHEMA);
                return self.send(topic, t_s, PoseInFrame::world(t_s, p));
            }
            Signal::Points(points) => {
                let mut e = entity(t_s, path, Vec::new());
                e.spheres = points.iter().map(|p| sphere(*p, w as f32, c)).collect();
                return self.send_entity(t_s, e);
            }
            Signal::Path(points) => vec![line_at(points, 0.02, c, w)],
            Signal::Segments(segs) => vec![line_list(segs.iter().copied(), c, w)],
            Signal::Boxes(b) => boxes(b, c, w),
        };
        self.send_entity(t_s, entity(t_s, path, lines));
    }

    /// Queues a scalar; its topic is registered and named once per path.
    pub(super) fn send_scalar(&mut self, t_s: f64, path: &str, value: f64) {
        let topic = match self.scalar_topics.iter().find(|(p, _)| p == path) {
            Some((_, t)) => t.clone(),
            None => {
                let t: Arc<str> = self
                    .topic("/signals/", path, "forkbench.Scalar", SCALAR_SCHEMA)
                    .into();
                self.scalar_topics.push((path.to_owned(), t.clone()));
                t
            }
        };
        self.queue(Item::Scalar { topic, t_s, value });
    }

    fn send_entity(&mut self, t_s: f64, e: SceneEntity) {
        let update = SceneUpdate {
            deletions: Vec::new(),
            entities: vec![e],
        };
        self.send("/world", t_s, update);
    }

    fn send_text(&mut self, t_s: f64, path: &str, text: &str) {
        self.send(
            "/log",
            t_s,
            json!({"timestamp": Stamp::at(t_s), "level": 2, "message": text, "name": path, "file": "", "line": 0}),
        );
    }

    /// `prefix` + `path` as a topic, registered with the writer thread on first use.
    fn topic(
        &mut self,
        prefix: &str,
        path: &str,
        schema_name: &'static str,
        schema: &'static str,
    ) -> String {
        let topic = format!("{prefix}{path}");
        if !self.signal_topics.contains(&topic) {
            self.signal_topics.insert(topic.clone());
            self.command(Cmd::Channel {
                topic: topic.clone(),
                schema_name,
                schema,
            });
        }
        topic
    }

    fn send_scan(&mut self, t_s: f64, path: &str, scan: &Scan) {
        let topic = self.topic("/scan/", path, "foxglove.LaserScan", LASER_SCAN_SCHEMA);
        let n = scan.ranges_m.len();
        let msg = LaserScanMsg {
            timestamp: Stamp::at(t_s),
            frame_id: "world",
            pose: FoxPose::of(&scan.sensor),
            start_angle: scan.angle_min_rad,
            end_angle: scan.angle_min_rad + n.saturating_sub(1) as f64 * scan.angle_step_rad,
            ranges: scan
                .ranges_m
                .iter()
                .map(|r| r.is_finite().then_some(*r))
                .collect(),
            intensities: [],
        };
        self.send(topic, t_s, msg);
    }

    fn send_grid(&mut self, t_s: f64, path: &str, grid: &Grid) {
        let topic = self.topic("/grid/", path, "foxglove.Grid", GRID_SCHEMA);
        let [x, y] = grid.origin_m;
        let msg = GridMsg {
            timestamp: Stamp::at(t_s),
            frame_id: "world",
            pose: FoxPose::of(&Pose2::new(x, y, 0.0)),
            column_count: grid.cols,
            cell_size: Vec2 {
                x: grid.cell_m,
                y: grid.cell_m,
            },
            row_stride: grid.cols,
            cell_stride: 1,
            fields: [PackedField {
                name: "occupancy",
                offset: 0,
                kind: 1,
            }],
            data: base64::engine::general_purpose::STANDARD.encode(&grid.cells),
        };
        self.send(topic, t_s, msg);
    }
}

/// Boxes' outlines as one line list.
fn boxes(b: &[[[f64; 2]; 2]], c: [f64; 4], w: f64) -> Vec<LinePrimitive> {
    let segments = b.iter().flat_map(|&[lo, hi]| {
        let k = [lo, [hi[0], lo[1]], hi, [lo[0], hi[1]]];
        (0..4).map(move |i| [k[i], k[(i + 1) % 4]])
    });
    vec![line_list(segments, c, w)]
}
