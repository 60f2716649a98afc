//! rerun recording: world, truck, plans, trajectory, sensors on the `sim_time` timeline, plots and a blueprint.

use std::path::PathBuf;

use forkbench_core::{ForkliftSpec, Pose2};
use forkbench_trial::{Level, Recorder, SceneInfo, StepRecord, TrialOutcome};
use rerun::blueprint::{Blueprint, Horizontal, Spatial2DView, TimeSeriesView, Vertical};

use crate::rrd_file::{ErrorSlot, Prefix, RrdFileSink};
use crate::{LogError, pallet_outlines, truck_outlines};
use forkbench_core::geometry::rect_outline;

/// Where the recording goes.
#[derive(Debug, Clone, PartialEq)]
pub enum RerunTarget {
    /// An .rrd file.
    File(PathBuf),
    /// Spawn a local viewer (the `rerun` executable must be on PATH).
    Spawn,
    /// A running viewer at host:port (its gRPC proxy).
    Connect(String),
}

/// The driven trajectory (a growing strip) is re-logged every this many steps (2 Hz; the
/// truck outline moves at the full rate); it keeps a point every `TRAJECTORY_POINT_EVERY`
/// steps (1.6 cm apart at 0.8 m/s), since its size grows with the square of the trial's
/// length.
const TRAJECTORY_EVERY: u64 = 50;
const TRAJECTORY_POINT_EVERY: u64 = 2;
const TRAJECTORY_RGB: [u8; 3] = [30, 160, 60];
/// True (green) and measured (red) pose at a NAV350 fix.
const TRUE_RGB: [u8; 3] = [30, 160, 60];
const MEASURED_RGB: [u8; 3] = [220, 40, 40];
/// Length of a fix's arrow along its heading.
const FIX_ARROW_M: f64 = 0.3;
/// B-spline control polygon and its points.
const CONTROL_RGB: [u8; 3] = [120, 150, 230];
/// Buffered per-step data is sent as columns every this many steps and at the end: one
/// `send_columns` per entity instead of one `log` per entity and step, since rerun's cost
/// is per chunk (about 0.7 M instructions each: Arrow schema, validation, footer
/// manifest). Files take a minute of simulated time per chunk (a pick trial sends each
/// entity once); a live viewer gets 0.1 s, so it follows the truck smoothly.
const SEND_EVERY_FILE: usize = 6000;
const SEND_EVERY_LIVE: usize = 10;

/// Plot entities and their series (several series share one entity, so one chunk).
const PLOTS: [(&str, &[&str]); 5] = [
    ("plots/curvature", &["planned", "actual"]),
    ("plots/steering", &["command", "actual"]),
    ("plots/speed", &["command", "actual"]),
    ("plots/lateral_error", &["cross-track"]),
    ("plots/contact_force", &["fork contact"]),
];

/// Where a recording is in its closing.
/// How long a live viewer may take to accept the recording's last data.
const VIEWER_TIMEOUT: std::time::Duration = std::time::Duration::from_secs(5);

enum Close {
    Open,
    /// The trial's outcome is logged: this thread flushes the stream and closes it (rerun
    /// writes the file's footer on close).
    Closing(std::sync::mpsc::Receiver<Option<String>>),
    /// Joined (or closed without a thread); later calls log nothing.
    Closed,
}

/// Streams one trial to rerun.
pub struct RerunRecorder {
    rec: rerun::RecordingStream,
    send_every: usize,
    truck: Option<ForkliftSpec>,
    steps: u64,
    trajectory: Vec<[f32; 2]>,
    /// Per-step columns not yet sent.
    times: Vec<f64>,
    /// One flat vector per plot entity, its series interleaved per step.
    plots: [Vec<f64>; 5],
    truth: Vec<Pose2>,
    /// Pallet poses, only when it moved (it moves only when pushed).
    pallet_pose: (Vec<f64>, Vec<Pose2>),
    /// Growing trajectory strips not yet sent.
    strips: (Vec<f64>, Vec<Vec<[f32; 2]>>),
    lookahead: Vec<[f32; 2]>,
    /// Pallet estimates and NAV350 fixes, only when they change or arrive.
    estimates: (Vec<f64>, Vec<Pose2>),
    fixes: (Vec<f64>, Vec<Pose2>),
    last_estimate: Option<Pose2>,
    last_pallet: Option<Pose2>,
    error: Option<String>,
    close: Close,
    /// How long closing may wait for the sink: unbounded for a file, bounded for a
    /// viewer (a port that accepts TCP but is no viewer would otherwise hang the run).
    close_timeout: Option<std::time::Duration>,
    /// Write errors of the .rrd file, also those found while closing it.
    file_errors: Option<ErrorSlot>,
    /// The truck's pose before the first step, sent with the first columns.
    truck_start: Option<Pose2>,
    /// Data set once (outlines, series names), per entity: it rides as the first row of
    /// the entity's first columns instead of costing a chunk of its own.
    first_rows: Vec<(&'static str, Vec<rerun::SerializedComponentColumn>)>,
}

impl std::fmt::Debug for RerunRecorder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "RerunRecorder({} steps)", self.steps)
    }
}

fn blueprint() -> Blueprint {
    let plots = Vertical::new([
        TimeSeriesView::new("curvature (1/m)")
            .with_origin("plots/curvature")
            .into(),
        TimeSeriesView::new("steering (rad)")
            .with_origin("plots/steering")
            .into(),
        TimeSeriesView::new("speed (m/s)")
            .with_origin("plots/speed")
            .into(),
        TimeSeriesView::new("lateral error (m)")
            .with_origin("plots/lateral_error")
            .into(),
        TimeSeriesView::new("contact force (N)")
            .with_origin("plots/contact_force")
            .into(),
    ]);
    Blueprint::new(
        Horizontal::new([
            Spatial2DView::new("map")
                .with_origin("/")
                .with_contents(["world/**", "truck/**", "plan/**", "track/**", "sensors/**"])
                .into(),
            plots.into(),
        ])
        .with_column_shares([0.6, 0.4]),
    )
}

/// The blueprint's messages, built once per process: building them spins up a whole
/// in-memory recording stream, which cost as much as a trial (5 ms) when done per file.
fn blueprint_msgs() -> Result<&'static [rerun::log::LogMsg], LogError> {
    use rerun::log::LogMsg;
    static MSGS: std::sync::OnceLock<Result<Vec<LogMsg>, String>> = std::sync::OnceLock::new();
    MSGS.get_or_init(|| {
        let (rec, storage) = rerun::RecordingStreamBuilder::new("forkbench")
            .memory()
            .map_err(|e| e.to_string())?;
        blueprint()
            .send(
                &rec,
                rerun::blueprint::BlueprintActivation {
                    make_active: true,
                    make_default: true,
                },
            )
            .map_err(|e| e.to_string())?;
        rec.flush_blocking().map_err(|e| e.to_string())?;
        // Keep only the blueprint store and its activation, not the carrier recording.
        Ok(storage
            .take()
            .into_iter()
            .filter(|m| match m {
                LogMsg::BlueprintActivationCommand(_) => true,
                m => m.store_id().kind() == rerun::StoreKind::Blueprint,
            })
            .collect())
    })
    .as_deref()
    .map_err(|e| LogError::Rerun(format!("building the blueprint: {e}")))
}

/// The start of an .rrd file (stream header and blueprint), encoded once per process.
fn blueprint_prefix() -> Result<&'static Prefix, LogError> {
    static PREFIX: std::sync::OnceLock<Result<Prefix, String>> = std::sync::OnceLock::new();
    let msgs = blueprint_msgs()?;
    PREFIX
        .get_or_init(|| Prefix::encode(msgs))
        .as_ref()
        .map_err(|e| LogError::Rerun(format!("encoding the blueprint: {e}")))
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

fn color(rgb: [u8; 3]) -> rerun::Color {
    rerun::Color::from_rgb(rgb[0], rgb[1], rgb[2])
}

fn strip(points: &[[f64; 2]]) -> Vec<[f32; 2]> {
    points.iter().map(|p| [p[0] as f32, p[1] as f32]).collect()
}

impl RerunRecorder {
    pub fn new(target: &RerunTarget) -> Result<Self, LogError> {
        let builder = rerun::RecordingStreamBuilder::new("forkbench");
        let mut file_errors = None;
        let rec = match target {
            RerunTarget::File(p) => {
                let sink = RrdFileSink::create(p, blueprint_prefix()?).map_err(LogError::Rerun)?;
                file_errors = Some(sink.error_slot());
                builder.set_sinks(vec![Box::new(sink) as Box<dyn rerun::sink::LogSink>])
            }
            RerunTarget::Spawn => builder.spawn(),
            RerunTarget::Connect(addr) => {
                // Fail now, clearly, if nothing listens there (the gRPC client would
                // otherwise retry silently in the background).
                let sock: std::net::SocketAddr = addr.parse().map_err(|e| {
                    LogError::Rerun(format!("--connect {addr:?}: expected host:port ({e})"))
                })?;
                std::net::TcpStream::connect_timeout(&sock, std::time::Duration::from_secs(2))
                    .map_err(|e| {
                        LogError::Rerun(format!("no rerun viewer reachable at {addr}: {e}"))
                    })?;
                builder.connect_grpc_opts(format!("rerun+http://{addr}/proxy"))
            }
        }
        .map_err(|e| LogError::Rerun(e.to_string()))?;
        // `sim_time` is the recording's only timeline: a wall-clock `log_time` on some
        // entities would only confuse (and costs a manifest column per component).
        rec.set_log_time_enabled(false);
        if !matches!(target, RerunTarget::File(_)) {
            // A file starts with the blueprint already (its sink writes it first).
            for msg in blueprint_msgs()? {
                rec.record_msg(msg.clone());
            }
        }
        Ok(Self {
            rec,
            send_every: match target {
                RerunTarget::File(_) => SEND_EVERY_FILE,
                RerunTarget::Spawn | RerunTarget::Connect(_) => SEND_EVERY_LIVE,
            },
            truck: None,
            steps: 0,
            trajectory: Vec::new(),
            times: Vec::new(),
            plots: Default::default(),
            truth: Vec::new(),
            pallet_pose: Default::default(),
            strips: Default::default(),
            lookahead: Vec::new(),
            estimates: Default::default(),
            fixes: Default::default(),
            last_estimate: None,
            last_pallet: None,
            error: None,
            close: Close::Open,
            close_timeout: match target {
                RerunTarget::File(_) => None,
                RerunTarget::Spawn | RerunTarget::Connect(_) => Some(VIEWER_TIMEOUT),
            },
            file_errors,
            truck_start: None,
            first_rows: Vec::new(),
        })
    }

    fn at(&self, t_s: f64) {
        self.rec.set_duration_secs("sim_time", t_s);
    }

    fn note<T, E: std::fmt::Display>(&mut self, r: Result<T, E>) {
        if let Err(e) = r {
            self.error.get_or_insert(e.to_string());
        }
    }

    /// Outlines in the entity's own frame, sent with its first transform (which moves them).
    fn local_outlines(&mut self, entity: &'static str, outlines: &[[[f64; 2]; 5]], rgb: [u8; 3]) {
        let strips: Vec<Vec<[f32; 2]>> = outlines.iter().map(|c| strip(c)).collect();
        self.set_once(
            entity,
            &rerun::LineStrips2D::new(strips)
                .with_colors([color(rgb)])
                .with_radii([0.01]),
        );
    }

    /// Queues `data` for the first row of `entity`'s first columns.
    fn set_once(&mut self, entity: &'static str, data: &dyn rerun::AsComponents) {
        let cols = data
            .as_serialized_batches()
            .into_iter()
            .map(rerun::SerializedComponentColumn::from);
        match self.first_rows.iter_mut().find(|(e, _)| *e == entity) {
            Some((_, c)) => c.extend(cols),
            None => self.first_rows.push((entity, cols.collect())),
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
    fn send_cols<C: IntoIterator<Item = rerun::SerializedComponentColumn>>(
        &mut self,
        entity: &str,
        times: &[f64],
        cols: rerun::SerializationResult<C>,
    ) {
        let column = rerun::TimeColumn::new_duration_secs("sim_time", times.iter().copied());
        let first = match self.first_rows.iter().position(|(e, _)| *e == entity) {
            Some(i) => self.first_rows.swap_remove(i).1,
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

    /// Sends the buffered per-step columns.
    fn send_buffered(&mut self) {
        if self.times.is_empty() {
            return;
        }
        let times = std::mem::take(&mut self.times);
        let plots = std::mem::take(&mut self.plots);
        for ((name, series), values) in PLOTS.iter().zip(plots) {
            let cols =
                rerun::Scalars::new(values).columns(std::iter::repeat_n(series.len(), times.len()));
            self.send_cols(name, &times, cols);
        }
        let truth = std::mem::take(&mut self.truth);
        match self.truck_start.take() {
            Some(start) => {
                let t: Vec<f64> = std::iter::once(0.0).chain(times.iter().copied()).collect();
                let p: Vec<Pose2> = std::iter::once(start)
                    .chain(truth.iter().copied())
                    .collect();
                self.send_poses("truck", &t, &p);
            }
            None => self.send_poses("truck", &times, &truth),
        }
        let (t, p) = std::mem::take(&mut self.pallet_pose);
        self.send_poses("world/pallet", &t, &p);
        let (t, p) = std::mem::take(&mut self.estimates);
        self.send_poses("sensors/pallet_estimate", &t, &p);
        // True and measured pose side by side at each NAV350 fix, as two arrows of one
        // entity (one chunk); the truck outline shows the true pose at every step.
        let (t, measured) = std::mem::take(&mut self.fixes);
        if !t.is_empty() {
            let pairs: Vec<[Pose2; 2]> = t
                .iter()
                .zip(&measured)
                .map(|(tf, m)| {
                    let truth = truth[times.partition_point(|x| x < tf).min(truth.len() - 1)];
                    [truth, *m]
                })
                .collect();
            let (origins, vectors): (Vec<[f32; 2]>, Vec<[f32; 2]>) = pairs
                .iter()
                .flatten()
                .map(|p| {
                    let (s, c) = p.heading_rad.sin_cos();
                    (
                        [p.x_m as f32, p.y_m as f32],
                        [(FIX_ARROW_M * c) as f32, (FIX_ARROW_M * s) as f32],
                    )
                })
                .unzip();
            // Style rides along in every row: a static style would cost a chunk.
            let n = pairs.len();
            let cols = rerun::Arrows2D::update_fields()
                .with_origins(origins)
                .with_vectors(vectors)
                .with_colors(
                    std::iter::repeat_n([color(TRUE_RGB), color(MEASURED_RGB)], n).flatten(),
                )
                .with_labels(std::iter::repeat_n(["true", "measured"], n).flatten())
                .with_radii(std::iter::repeat_n(0.02, 2 * n))
                .columns(std::iter::repeat_n(2, n));
            self.send_cols("sensors/nav350_fix", &t, cols);
        }
        let (t, strips) = std::mem::take(&mut self.strips);
        if !t.is_empty() {
            // The strip's style rides in the same chunk (one chunk fewer than a static
            // style of its own).
            let n = strips.len();
            let cols = rerun::LineStrips2D::update_fields()
                .with_strips(strips)
                .with_colors(std::iter::repeat_n(color(TRAJECTORY_RGB), n))
                .with_radii(std::iter::repeat_n(0.01, n))
                .columns_of_unit_batches();
            self.send_cols("track/trajectory", &t, cols);
        }
        let lookahead = std::mem::take(&mut self.lookahead);
        let cols = rerun::Points2D::update_fields()
            .with_positions(lookahead)
            .columns_of_unit_batches();
        self.send_cols("track/lookahead", &times, cols);
    }

    /// Sends what is buffered, then flushes and closes the stream on a thread of its own,
    /// so that the footer is built while other sinks finish; later calls log nothing.
    fn close_async(&mut self) {
        if !matches!(self.close, Close::Open) {
            return;
        }
        self.close = Close::Closed;
        self.send_buffered();
        // Set-once data of entities that got no columns (a trial without steps).
        let left: Vec<&'static str> = self.first_rows.iter().map(|(e, _)| *e).collect();
        for entity in left {
            self.send_cols(entity, &[0.0], Ok(Vec::new()));
        }
        let rec = std::mem::replace(&mut self.rec, rerun::RecordingStream::disabled());
        let timeout = self.close_timeout.unwrap_or(std::time::Duration::MAX);
        let (tx, rx) = std::sync::mpsc::channel();
        let closing = std::thread::Builder::new()
            .name("rrd-close".into())
            .spawn(move || {
                let r = rec.flush_with_timeout(timeout).err().map(|e| e.to_string());
                // Dropping the last handle closes the sink: the footer is written and the
                // writer thread joined.
                drop(rec);
                let _ = tx.send(r);
            });
        match closing {
            Ok(_) => self.close = Close::Closing(rx),
            Err(e) => self.note::<(), _>(Err(e)),
        }
    }

    /// Sends what is buffered and closes the recording (the .rrd is complete when this
    /// returns); returns the first logging error, if any.
    pub fn finish(&mut self) -> Result<(), LogError> {
        self.close_async();
        if let Close::Closing(rx) = std::mem::replace(&mut self.close, Close::Closed) {
            use std::sync::mpsc::RecvTimeoutError;
            let got = match self.close_timeout {
                None => rx.recv().map_err(|_| RecvTimeoutError::Disconnected),
                // Twice the flush's own timeout: dropping the stream may wait too.
                Some(t) => rx.recv_timeout(2 * t),
            };
            match got {
                Ok(Some(e)) => self.note::<(), _>(Err(e)),
                Ok(None) => {}
                Err(RecvTimeoutError::Timeout) => self.note::<(), _>(Err(format!(
                    "the viewer did not take the recording within {} s (is it a rerun viewer?)",
                    2 * self.close_timeout.map_or(0, |t| t.as_secs())
                ))),
                Err(RecvTimeoutError::Disconnected) => {
                    self.note::<(), _>(Err("the rerun closing thread panicked"))
                }
            }
        }
        if let Some(e) = self
            .file_errors
            .as_ref()
            .and_then(|slot| slot.lock().ok().and_then(|e| e.clone()))
        {
            self.error.get_or_insert(e);
        }
        match self.error.take() {
            Some(e) => Err(LogError::Rerun(e)),
            None => Ok(()),
        }
    }
}

impl Drop for RerunRecorder {
    fn drop(&mut self) {
        let _ = self.finish();
    }
}

impl Recorder for RerunRecorder {
    fn scene(&mut self, s: &SceneInfo<'_>) {
        self.truck = Some(s.truck.clone());
        let info = format!(
            "scenario {} / case {} / planner {} / seed {}",
            s.scenario, s.case, s.planner, s.seed
        );
        // The trial's identity opens the event log (an entity of its own would cost a
        // chunk).
        self.at(0.0);
        let r = self.rec.log(
            "events",
            &rerun::TextLog::new(info).with_level(rerun::TextLogLevel::INFO),
        );
        self.note(r);
        let obstacles: Vec<[[f64; 2]; 5]> = s
            .obstacles
            .iter()
            .map(|o| rect_outline(&o.centre, o.length_m, o.width_m))
            .collect();
        if !obstacles.is_empty() {
            let strips: Vec<Vec<[f32; 2]>> = obstacles.iter().map(|c| strip(c)).collect();
            let r = self.rec.log_static(
                "world/racks",
                &rerun::LineStrips2D::new(strips)
                    .with_colors([rerun::Color::from_rgb(128, 128, 128)])
                    .with_radii([0.03]),
            );
            self.note(r);
        }
        for (name, series) in PLOTS {
            self.set_once(
                name,
                &rerun::SeriesLines::new().with_names(series.iter().copied()),
            );
        }
        let origin = Pose2::new(0.0, 0.0, 0.0);
        self.local_outlines(
            "world/pallet",
            &pallet_outlines(s.pallet, &origin),
            [205, 140, 50],
        );
        self.local_outlines(
            "sensors/pallet_estimate",
            &pallet_outlines(s.pallet, &origin),
            [220, 40, 40],
        );
        self.local_outlines("truck", &truck_outlines(s.truck, &origin), [230, 190, 25]);
        // The start pose goes out with the first columns.
        self.truck_start = Some(s.start);
        // The pallet's first pose goes out with the first columns.
        self.pallet_pose.0.push(0.0);
        self.pallet_pose.1.push(s.pallet_pose);
        self.last_pallet = Some(s.pallet_pose);
    }

    fn plan(
        &mut self,
        t_s: f64,
        index: u32,
        path: &forkbench_core::Path,
        control_polygon: Option<&[[f64; 2]]>,
    ) {
        self.at(t_s);
        let pts: Vec<[f32; 2]> = path
            .samples
            .iter()
            .map(|p| [p.x_m as f32, p.y_m as f32])
            .collect();
        let entity = if index == 0 {
            "plan/path".to_owned()
        } else {
            format!("plan/replan_{index}")
        };
        let r = self.rec.log(
            entity.as_str(),
            &rerun::LineStrips2D::new([pts])
                .with_colors([rerun::Color::from_rgb(40, 100, 230)])
                .with_radii([0.015]),
        );
        self.note(r);
        if let Some(c) = control_polygon {
            // Polygon and points in one row of one entity: one chunk.
            let polygon = rerun::LineStrips2D::new([strip(c)]).with_colors([color(CONTROL_RGB)]);
            let points = rerun::Points2D::new(strip(c))
                .with_radii([0.05])
                .with_colors([color(CONTROL_RGB)]);
            let r = self.rec.log(
                format!("{entity}/control_polygon"),
                &[&polygon as &dyn rerun::AsComponents, &points],
            );
            self.note(r);
        }
        // Logged rows wait in rerun's batcher until its 200 ms tick, longer than a whole
        // trial: push the shapes and the plan to the file writer now, so it encodes them
        // while the trial runs instead of after it.
        let r = self.rec.flush_async();
        self.note(r);
    }

    fn step(&mut self, s: &StepRecord) {
        self.steps += 1;
        if self.steps % TRAJECTORY_POINT_EVERY == 1 {
            self.trajectory
                .push([s.truth.x_m as f32, s.truth.y_m as f32]);
        }
        self.times.push(s.t_s);
        let actual_curvature =
            s.steer_rad.tan() / self.truck.as_ref().map_or(1.0, |t| t.wheelbase_m);
        let values: [&[f64]; 5] = [
            &[s.path_curvature_per_m, actual_curvature],
            &[s.steer_cmd_rad, s.steer_rad],
            &[s.speed_cmd_mps, s.speed_mps],
            &[s.cross_track_m],
            &[s.contact_force_n],
        ];
        for (v, series) in values.iter().zip(self.plots.iter_mut()) {
            series.extend_from_slice(v);
        }
        self.truth.push(s.truth);
        if self.last_pallet != Some(s.pallet) {
            self.last_pallet = Some(s.pallet);
            self.pallet_pose.0.push(s.t_s);
            self.pallet_pose.1.push(s.pallet);
        }
        self.lookahead
            .push([s.lookahead[0] as f32, s.lookahead[1] as f32]);
        if self.last_estimate != Some(s.pallet_estimate) {
            self.last_estimate = Some(s.pallet_estimate);
            self.estimates.0.push(s.t_s);
            self.estimates.1.push(s.pallet_estimate);
        }
        if let Some(fix) = s.fix {
            self.fixes.0.push(s.t_s);
            self.fixes.1.push(fix);
        }
        if self.steps % TRAJECTORY_EVERY == 1 {
            self.strips.0.push(s.t_s);
            self.strips.1.push(self.trajectory.clone());
        }
        if self.times.len() >= self.send_every {
            self.send_buffered();
        }
    }

    fn event(&mut self, t_s: f64, level: Level, text: &str) {
        self.at(t_s);
        let level = match level {
            Level::Info => rerun::TextLogLevel::INFO,
            Level::Warn => rerun::TextLogLevel::WARN,
            Level::Error => rerun::TextLogLevel::ERROR,
        };
        let r = self
            .rec
            .log("events", &rerun::TextLog::new(text).with_level(level));
        self.note(r);
    }

    fn outcome(&mut self, t_s: f64, outcome: &TrialOutcome) {
        self.at(t_s);
        self.strips.0.push(t_s);
        self.strips.1.push(self.trajectory.clone());
        let verdict = match (outcome.success, outcome.failure) {
            (true, _) => "SUCCESS".to_owned(),
            (false, Some(f)) => format!(
                "FAILED: {} ({})",
                f.name(),
                outcome.failure_detail.as_deref().unwrap_or("")
            ),
            (false, None) => "FAILED".to_owned(),
        };
        let level = if outcome.success {
            rerun::TextLogLevel::INFO
        } else {
            rerun::TextLogLevel::ERROR
        };
        let r = self.rec.log(
            "events",
            &rerun::TextLog::new(format!("outcome: {verdict}")).with_level(level),
        );
        self.note(r);
        let r = self.rec.log(
            "outcome",
            &rerun::TextDocument::new(serde_json::to_string_pretty(outcome).unwrap_or_default()),
        );
        self.note(r);
        // The outcome is the trial's last call: close now, in parallel with other sinks.
        self.close_async();
    }
}
