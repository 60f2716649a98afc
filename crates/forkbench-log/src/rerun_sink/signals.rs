//! Open-vocabulary signals in rerun: each kind maps to one archetype, under `map/` (spatial kinds) or `signals/` (scalars), whatever sent it.

use forkbench_core::signal::{Grid, Scan};
use forkbench_core::{Pose2, Signal, Style};

use super::RerunRecorder;
use super::columns::{rgba, strip};
use super::layout::*;

/// What a style leaves unset.
const DEFAULT_RGBA: [u8; 4] = [200, 200, 200, 255];
const DEFAULT_WIDTH_M: f64 = 0.02;
/// A pose's arrow length.
const POSE_ARROW_M: f64 = 0.4;

/// Per-step signals buffered until the next columns go out: poses and scalars by path.
#[derive(Default)]
pub(super) struct SignalColumns {
    poses: Vec<Series<Pose2>>,
    scalars: Vec<Series<f64>>,
}

/// One path's buffered values and their times.
struct Series<T> {
    path: String,
    style: Style,
    times: Vec<f64>,
    values: Vec<T>,
}

/// Appends (`t_s`, `value`) to `path`'s series, starting it with `style` if new.
fn push<T>(buf: &mut Vec<Series<T>>, path: &str, style: Style, t_s: f64, value: T) {
    let i = match buf.iter().position(|s| s.path == path) {
        Some(i) => i,
        None => {
            buf.push(Series {
                path: path.to_owned(),
                style,
                times: Vec::new(),
                values: Vec::new(),
            });
            buf.len() - 1
        }
    };
    buf[i].times.push(t_s);
    buf[i].values.push(value);
}

fn colour(style: &Style) -> rerun::Color {
    rgba(style.rgba.unwrap_or(DEFAULT_RGBA))
}

fn radius(style: &Style) -> f32 {
    (style.width_m.unwrap_or(DEFAULT_WIDTH_M) / 2.0) as f32
}

impl RerunRecorder {
    /// Records one signal: per-step kinds are buffered, the rest logged at `t_s`.
    pub(super) fn log_signal(&mut self, t_s: f64, path: &str, signal: &Signal<'_>, style: Style) {
        let map = format!("map/{path}");
        match signal {
            Signal::Pose(p) => push(&mut self.signal_cols.poses, path, style, t_s, *p),
            Signal::Scalar(v) => push(&mut self.signal_cols.scalars, path, style, t_s, *v),
            Signal::Text(text) => self.log_text(t_s, path, text),
            Signal::Path(points) => self.log_at(t_s, &map, &lines([strip(points)], &style)),
            Signal::Segments(segs) => {
                self.log_at(t_s, &map, &lines(segs.iter().map(|s| strip(s)), &style))
            }
            Signal::Points(points) => self.log_at(t_s, &map, &points_of(points, &style)),
            Signal::Boxes(boxes) => self.log_at(t_s, &map, &boxes_of(boxes, &style)),
            Signal::Scan(scan) => self.log_at(t_s, &map, &scan_points(scan, &style)),
            Signal::Grid(grid) => self.log_grid(t_s, &map, grid, &style),
        }
    }

    fn log_at(&mut self, t_s: f64, entity: &str, data: &dyn rerun::AsComponents) {
        self.at(t_s);
        let r = self.rec.log(entity, data);
        self.note(r);
    }

    fn log_text(&mut self, t_s: f64, path: &str, text: &str) {
        self.events.push(format!("{t_s:7.2} s  {path}: {text}"));
        self.log_at(
            t_s,
            "events",
            &rerun::TextLog::new(format!("{path}: {text}")).with_level(rerun::TextLogLevel::INFO),
        );
    }

    /// The grid's blocked cells as boxes; the metre grid and the racks grow to its extent.
    fn log_grid(&mut self, t_s: f64, entity: &str, grid: &Grid, style: &Style) {
        self.log_at(t_s, entity, &boxes_of(&grid.blocked_rects(), style));
        let [lo, hi] = grid.extent();
        let frame = super::scene::Frame::around([lo, hi]);
        let mirror = rerun::Transform3D::from_scale([1.0, -1.0, 1.0]);
        let lines = rerun::LineStrips2D::new(frame.grid())
            .with_colors([rgba(GRID_RGBA)])
            .with_radii([0.008])
            .with_draw_order(ORDER_GRID);
        let r = self
            .rec
            .log_static("map", &[&mirror as &dyn rerun::AsComponents, &lines]);
        self.note(r);
        self.draw_racks(&frame);
    }

    /// Sends the buffered poses (arrows) and scalars as columns.
    pub(super) fn send_signal_columns(&mut self) {
        let cols = std::mem::take(&mut self.signal_cols);
        for Series {
            path,
            style,
            times,
            values: poses,
        } in cols.poses
        {
            let (origins, vectors): (Vec<[f32; 2]>, Vec<[f32; 2]>) = poses
                .iter()
                .map(|p| {
                    let (s, c) = p.heading_rad.sin_cos();
                    let v = [(POSE_ARROW_M * c) as f32, (POSE_ARROW_M * s) as f32];
                    ([p.x_m as f32, p.y_m as f32], v)
                })
                .unzip();
            let data = rerun::Arrows2D::update_fields()
                .with_origins(origins)
                .with_vectors(vectors)
                .columns_of_unit_batches();
            let entity = format!("map/{path}");
            let first = rerun::Arrows2D::update_fields()
                .with_colors([colour(&style)])
                .with_radii([radius(&style)])
                .with_draw_order(ORDER_MARKERS);
            self.set_once(&entity, &first);
            self.send_cols(&entity, &times, data);
        }
        for Series {
            path,
            times,
            values,
            ..
        } in cols.scalars
        {
            let data = rerun::Scalars::new(values).columns_of_unit_batches();
            self.send_cols(&format!("signals/{path}"), &times, data);
        }
    }
}

fn lines(strips: impl IntoIterator<Item = Vec<[f32; 2]>>, style: &Style) -> rerun::LineStrips2D {
    rerun::LineStrips2D::new(strips)
        .with_colors([colour(style)])
        .with_radii([radius(style)])
        .with_draw_order(ORDER_PLAN)
}

fn points_of(points: &[[f64; 2]], style: &Style) -> rerun::Points2D {
    rerun::Points2D::new(strip(points))
        .with_colors([colour(style)])
        .with_radii([radius(style)])
        .with_draw_order(ORDER_MARKERS)
}

fn boxes_of(boxes: &[[[f64; 2]; 2]], style: &Style) -> rerun::Boxes2D {
    rerun::Boxes2D::from_mins_and_sizes(
        boxes.iter().map(|[lo, _]| [lo[0] as f32, lo[1] as f32]),
        boxes
            .iter()
            .map(|[lo, hi]| [(hi[0] - lo[0]) as f32, (hi[1] - lo[1]) as f32]),
    )
    .with_colors([colour(style)])
    .with_radii([radius(style)])
    .with_draw_order(ORDER_GRID)
}

/// A scan's returns as points, smaller than the default so the pallet's edges stay visible.
fn scan_points(scan: &Scan, style: &Style) -> rerun::Points2D {
    let style = Style {
        width_m: Some(style.width_m.unwrap_or(0.03)),
        ..*style
    };
    points_of(&scan.points(), &style)
}
