//! Per-step data buffered and sent as columns on `sim_time`: truck, pallet, sensors, trajectory, look-ahead and plots.

use forkbench_core::Pose2;

use super::RerunRecorder;
use super::layout::*;

/// The driven trajectory keeps a point every this many steps; the whole strip is re-sent
/// every `TRAJECTORY_EVERY` steps and, at every step, a short tail from its last point to
/// the truck, so the drawn trajectory keeps up with the truck at the control rate while
/// its size grows only with the square of the trial's length divided by that period.
const TRAJECTORY_POINT_EVERY: u64 = 2;
const TRAJECTORY_EVERY: u64 = 50;
/// Length of a fix's arrow along its heading.
const FIX_ARROW_M: f64 = 0.3;

/// Buffers of the per-step data not yet sent.
#[derive(Default)]
pub(super) struct Columns {
    pub steps: u64,
    /// Trajectory points so far, and how many of them the last whole strip held.
    trajectory: Vec<[f32; 2]>,
    sent_points: usize,
    pub times: Vec<f64>,
    /// One flat vector per plot entity, its series interleaved per step, and the times of
    /// its rows (a plot with no values at a step has no row there).
    plots: [Vec<f64>; PLOTS.len()],
    plot_times: [Vec<f64>; PLOTS.len()],
    truth: Vec<Pose2>,
    /// The truck's pose before the first step, sent with the first columns.
    pub truck_start: Option<Pose2>,
    /// Pallet poses and estimates, only when they change; NAV350 fixes when they arrive.
    pub pallet_pose: (Vec<f64>, Vec<Pose2>),
    estimates: (Vec<f64>, Vec<Pose2>),
    fixes: (Vec<f64>, Vec<Pose2>),
    pub last_pallet: Option<Pose2>,
    last_estimate: Option<Pose2>,
    /// Whole trajectory strips and tails not yet sent.
    strips: (Vec<f64>, Vec<Vec<[f32; 2]>>),
    tails: Vec<Vec<[f32; 2]>>,
    lookahead: Vec<[f32; 2]>,
    /// Data set once (outlines, styles, series names) per entity: it rides as the first row
    /// of the entity's first columns instead of costing a chunk of its own.
    first_rows: Vec<(String, Vec<rerun::SerializedComponentColumn>)>,
}

/// `col` (one row) as the first row of a column of `rows` rows, null after it: rerun reads
/// a null as "nothing logged at this row", so the value holds from the first row on.
fn first_row_only(
    col: rerun::SerializedComponentColumn,
    rows: usize,
) -> Result<rerun::SerializedComponentColumn, rerun::external::arrow::error::ArrowError> {
    use rerun::external::arrow::array::{Array as _, ListArray};
    use rerun::external::arrow::buffer::{NullBuffer, OffsetBuffer};
    let (field, _, values, _) = col.list_array.into_parts();
    let rest = rows.saturating_sub(1);
    let offsets = OffsetBuffer::from_lengths(
        std::iter::once(values.len()).chain(std::iter::repeat_n(0, rest)),
    );
    let nulls =
        NullBuffer::from_iter(std::iter::once(true).chain(std::iter::repeat_n(false, rest)));
    Ok(rerun::SerializedComponentColumn::new(
        ListArray::try_new(field, offsets, values, Some(nulls))?,
        col.descriptor,
    ))
}

pub(super) fn color(rgb: [u8; 3]) -> rerun::Color {
    rerun::Color::from_rgb(rgb[0], rgb[1], rgb[2])
}

pub(super) fn rgba(c: [u8; 4]) -> rerun::Color {
    rerun::Color::from_unmultiplied_rgba(c[0], c[1], c[2], c[3])
}

pub(super) fn strip(points: &[[f64; 2]]) -> Vec<[f32; 2]> {
    points.iter().map(|p| [p[0] as f32, p[1] as f32]).collect()
}

fn xy(p: &Pose2) -> [f32; 2] {
    [p.x_m as f32, p.y_m as f32]
}

impl Columns {
    /// Buffers one step; `values` holds each plot's series, in [`PLOTS`] order, or nothing
    /// for a plot without a value at this step.
    pub fn push(&mut self, s: &forkbench_trial::StepRecord, values: [&[f64]; PLOTS.len()]) {
        self.steps += 1;
        self.times.push(s.t_s);
        for ((v, series), times) in values
            .iter()
            .zip(self.plots.iter_mut())
            .zip(self.plot_times.iter_mut())
        {
            if !v.is_empty() {
                series.extend_from_slice(v);
                times.push(s.t_s);
            }
        }
        self.truth.push(s.truth);
        if self.last_pallet != Some(s.pallet) {
            self.last_pallet = Some(s.pallet);
            self.pallet_pose.0.push(s.t_s);
            self.pallet_pose.1.push(s.pallet);
        }
        if self.last_estimate != Some(s.pallet_estimate) {
            self.last_estimate = Some(s.pallet_estimate);
            self.estimates.0.push(s.t_s);
            self.estimates.1.push(s.pallet_estimate);
        }
        if let Some(fix) = s.fix {
            self.fixes.0.push(s.t_s);
            self.fixes.1.push(fix);
        }
        self.lookahead
            .push([s.lookahead[0] as f32, s.lookahead[1] as f32]);
        if self.steps % TRAJECTORY_POINT_EVERY == 1 {
            self.trajectory.push(xy(&s.truth));
        }
        if self.steps % TRAJECTORY_EVERY == 1 {
            self.whole_strip(s.t_s);
        }
        let from = self.sent_points.saturating_sub(1);
        let mut tail = self.trajectory[from..].to_vec();
        tail.push(xy(&s.truth));
        self.tails.push(tail);
    }

    /// Queues the whole trajectory so far, at `t_s`.
    pub fn whole_strip(&mut self, t_s: f64) {
        self.strips.0.push(t_s);
        self.strips.1.push(self.trajectory.clone());
        self.sent_points = self.trajectory.len();
    }
}

impl RerunRecorder {
    /// Outlines in the entity's own frame, sent with its first transform (which moves them).
    pub(super) fn local_outlines(
        &mut self,
        entity: &str,
        outlines: &[[[f64; 2]; 5]],
        (rgb, radius_m, order): ([u8; 3], f32, f32),
    ) {
        let strips: Vec<Vec<[f32; 2]>> = outlines.iter().map(|c| strip(c)).collect();
        self.set_once(
            entity,
            &rerun::LineStrips2D::new(strips)
                .with_colors([color(rgb)])
                .with_radii([radius_m])
                .with_draw_order(order),
        );
    }

    /// Queues `data` for the first row of `entity`'s first columns.
    pub(super) fn set_once(&mut self, entity: &str, data: &dyn rerun::AsComponents) {
        let cols = data
            .as_serialized_batches()
            .into_iter()
            .map(rerun::SerializedComponentColumn::from);
        let rows = &mut self.cols.first_rows;
        match rows.iter_mut().find(|(e, _)| e == entity) {
            Some((_, c)) => c.extend(cols),
            None => rows.push((entity.to_owned(), cols.collect())),
        }
    }

    /// One planar pose per row on `sim_time`.
    fn send_poses(&mut self, entity: &str, times: &[f64], poses: &[Pose2]) {
        if times.is_empty() {
            return;
        }
        let cols = rerun::Transform3D::update_fields()
            .with_many_translation(poses.iter().map(|p| [p.x_m as f32, p.y_m as f32, 0.0]))
            .with_many_rotation_axis_angle(poses.iter().map(|p| {
                rerun::RotationAxisAngle::new(
                    [0.0, 0.0, 1.0],
                    rerun::Angle::from_radians(p.heading_rad as f32),
                )
            }))
            .columns_of_unit_batches();
        self.send_cols(entity, times, cols);
    }

    /// Sends one entity's columns on `sim_time`, noting an error from building or sending.
    pub(super) fn send_cols<C: IntoIterator<Item = rerun::SerializedComponentColumn>>(
        &mut self,
        entity: &str,
        times: &[f64],
        cols: rerun::SerializationResult<C>,
    ) {
        let column = rerun::TimeColumn::new_duration_secs("sim_time", times.iter().copied());
        let first = match self.cols.first_rows.iter().position(|(e, _)| e == entity) {
            Some(i) => self.cols.first_rows.swap_remove(i).1,
            None => Vec::new(),
        };
        let first: Result<Vec<_>, _> = first
            .into_iter()
            .map(|c| first_row_only(c, times.len()))
            .collect();
        match (cols, first) {
            (Ok(cols), Ok(first)) => {
                let r = self
                    .rec
                    .send_columns(entity, [column], cols.into_iter().chain(first));
                self.note(r);
            }
            (Err(e), _) => self.note::<(), _>(Err(e)),
            (_, Err(e)) => self.note::<(), _>(Err(e)),
        }
    }

    /// Set-once data of entities that got no columns (a trial without steps).
    pub(super) fn send_leftover_first_rows(&mut self) {
        let left: Vec<String> = self
            .cols
            .first_rows
            .iter()
            .map(|(e, _)| e.clone())
            .collect();
        for entity in left {
            self.send_cols(&entity, &[0.0], Ok(Vec::new()));
        }
    }

    /// Sends the buffered per-step columns.
    pub(super) fn send_buffered(&mut self) {
        self.send_signal_columns();
        if self.cols.times.is_empty() {
            return;
        }
        let times = std::mem::take(&mut self.cols.times);
        let plots = std::mem::take(&mut self.cols.plots);
        let plot_times = std::mem::take(&mut self.cols.plot_times);
        for ((plot, values), t) in PLOTS.iter().zip(plots).zip(plot_times) {
            if t.is_empty() {
                continue;
            }
            let n = plot.series.len();
            let cols = rerun::Scalars::new(values).columns(std::iter::repeat_n(n, t.len()));
            self.send_cols(plot.entity, &t, cols);
        }
        let truth = std::mem::take(&mut self.cols.truth);
        match self.cols.truck_start.take() {
            Some(start) => {
                let t: Vec<f64> = std::iter::once(0.0).chain(times.iter().copied()).collect();
                let p: Vec<Pose2> = std::iter::once(start)
                    .chain(truth.iter().copied())
                    .collect();
                self.send_poses("map/truck", &t, &p);
            }
            None => self.send_poses("map/truck", &times, &truth),
        }
        let (t, p) = std::mem::take(&mut self.cols.pallet_pose);
        self.send_poses("map/world/pallet", &t, &p);
        let (t, p) = std::mem::take(&mut self.cols.estimates);
        self.send_poses("map/sensors/pallet_estimate", &t, &p);
        self.send_fixes(&times, &truth);
        self.send_trajectory(&times);
    }

    /// True and measured pose side by side at each NAV350 fix, as two arrows of one entity
    /// (one chunk); the truck outline shows the true pose at every step.
    fn send_fixes(&mut self, times: &[f64], truth: &[Pose2]) {
        let (t, measured) = std::mem::take(&mut self.cols.fixes);
        if t.is_empty() {
            return;
        }
        let (origins, vectors): (Vec<[f32; 2]>, Vec<[f32; 2]>) = t
            .iter()
            .zip(&measured)
            .flat_map(|(tf, m)| {
                [
                    truth[times.partition_point(|x| x < tf).min(truth.len() - 1)],
                    *m,
                ]
            })
            .map(|p| {
                let (s, c) = p.heading_rad.sin_cos();
                (xy(&p), [(FIX_ARROW_M * c) as f32, (FIX_ARROW_M * s) as f32])
            })
            .unzip();
        let n = t.len();
        let cols = rerun::Arrows2D::update_fields()
            .with_origins(origins)
            .with_vectors(vectors)
            .with_colors(std::iter::repeat_n([color(TRUE_RGB), color(MEASURED_RGB)], n).flatten())
            .columns(std::iter::repeat_n(2, n));
        self.send_cols("map/sensors/nav350_fix", &t, cols);
    }

    /// The whole trajectory strips, and the per-step tails with the look-ahead points.
    fn send_trajectory(&mut self, times: &[f64]) {
        let (t, strips) = std::mem::take(&mut self.cols.strips);
        if !t.is_empty() {
            let cols = rerun::LineStrips2D::update_fields()
                .with_strips(strips)
                .columns_of_unit_batches();
            self.send_cols("map/track/trajectory", &t, cols);
        }
        let tails = std::mem::take(&mut self.cols.tails);
        let lookahead = std::mem::take(&mut self.cols.lookahead);
        let tails = rerun::LineStrips2D::update_fields()
            .with_strips(tails)
            .columns_of_unit_batches();
        let points = rerun::Points2D::update_fields()
            .with_positions(lookahead)
            .columns_of_unit_batches();
        let cols = tails.and_then(|t| Ok(t.chain(points?)));
        self.send_cols("map/track/now", times, cols);
    }
}
