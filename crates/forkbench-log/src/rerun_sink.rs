//! rerun recording: world, truck, plans, trajectory, sensors on the `sim_time` timeline, plots and a blueprint.

use std::path::PathBuf;

use forkbench_core::{ForkliftSpec, Pose2};
use forkbench_sim::PalletSpec;
use forkbench_trial::{Level, Recorder, SceneInfo, StepRecord, TrialOutcome};
use rerun::blueprint::{Blueprint, Horizontal, Spatial2DView, TimeSeriesView, Vertical};

use crate::{LogError, pallet_outlines, rect_corners, truck_outlines};

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

/// Geometry is re-logged every this many control steps (20 Hz at 100 Hz).
const GEOMETRY_EVERY: u64 = 5;
/// The driven trajectory is re-logged every this many steps.
const TRAJECTORY_EVERY: u64 = 25;

const PLOTS: [&str; 8] = [
    "plots/curvature/planned",
    "plots/steering/command",
    "plots/steering/actual",
    "plots/speed/command",
    "plots/speed/actual",
    "plots/lateral_error",
    "plots/contact_force",
    "plots/curvature/actual",
];

/// Streams one trial to rerun.
pub struct RerunRecorder {
    rec: rerun::RecordingStream,
    truck: Option<ForkliftSpec>,
    pallet: Option<PalletSpec>,
    steps: u64,
    trajectory: Vec<[f32; 2]>,
    times: Vec<f64>,
    plots: [Vec<f64>; 8],
    error: Option<String>,
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

fn strip(points: &[[f64; 2]]) -> Vec<[f32; 2]> {
    points.iter().map(|p| [p[0] as f32, p[1] as f32]).collect()
}

impl RerunRecorder {
    pub fn new(target: &RerunTarget) -> Result<Self, LogError> {
        let builder = rerun::RecordingStreamBuilder::new("forkbench").with_blueprint(blueprint());
        let rec = match target {
            RerunTarget::File(p) => builder.save(p),
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
        Ok(Self {
            rec,
            truck: None,
            pallet: None,
            steps: 0,
            trajectory: Vec::new(),
            times: Vec::new(),
            plots: Default::default(),
            error: None,
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

    fn outlines(&mut self, entity: &str, outlines: &[[[f64; 2]; 5]], rgb: [u8; 3]) {
        let strips: Vec<Vec<[f32; 2]>> = outlines.iter().map(|c| strip(c)).collect();
        let r = self.rec.log(
            entity,
            &rerun::LineStrips2D::new(strips)
                .with_colors([rerun::Color::from_rgb(rgb[0], rgb[1], rgb[2])])
                .with_radii([0.01]),
        );
        self.note(r);
    }

    fn pose_marker(&mut self, entity: &str, p: &Pose2, rgb: [u8; 3], radius: f32) {
        let tip = p.to_world(&Pose2::new(0.3, 0.0, 0.0));
        let r = self.rec.log(
            entity,
            &rerun::Points2D::new([[p.x_m as f32, p.y_m as f32]])
                .with_colors([rerun::Color::from_rgb(rgb[0], rgb[1], rgb[2])])
                .with_radii([radius]),
        );
        self.note(r);
        let r = self.rec.log(
            format!("{entity}/heading"),
            &rerun::LineStrips2D::new([[
                [p.x_m as f32, p.y_m as f32],
                [tip.x_m as f32, tip.y_m as f32],
            ]])
            .with_colors([rerun::Color::from_rgb(rgb[0], rgb[1], rgb[2])]),
        );
        self.note(r);
    }

    /// Sends the collected plots and flushes; returns the first logging error, if any.
    pub fn finish(&mut self) -> Result<(), LogError> {
        if !self.times.is_empty() {
            let times = std::mem::take(&mut self.times);
            let plots = std::mem::take(&mut self.plots);
            for (name, values) in PLOTS.iter().zip(plots) {
                let column =
                    rerun::TimeColumn::new_duration_secs("sim_time", times.iter().copied());
                match rerun::Scalars::new(values).columns_of_unit_batches() {
                    Ok(cols) => {
                        let r = self.rec.send_columns(*name, [column], cols);
                        self.note(r);
                    }
                    Err(e) => self.note::<(), _>(Err(e)),
                }
            }
        }
        let r = self.rec.flush_blocking();
        self.note(r);
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
        self.pallet = Some(s.pallet.clone());
        let info = format!(
            "scenario {} / case {} / planner {} / seed {}",
            s.scenario, s.case, s.planner, s.seed
        );
        let r = self.rec.log_static("info", &rerun::TextDocument::new(info));
        self.note(r);
        let obstacles: Vec<[[f64; 2]; 5]> = s
            .obstacles
            .iter()
            .map(|o| rect_corners(&o.centre, o.length_m, o.width_m))
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
        self.at(0.0);
        self.outlines(
            "world/pallet",
            &pallet_outlines(s.pallet, &s.pallet_pose),
            [205, 140, 50],
        );
        self.outlines(
            "truck/outline",
            &truck_outlines(s.truck, &s.start),
            [230, 190, 25],
        );
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
            let r = self.rec.log(
                format!("{entity}/control_polygon"),
                &rerun::LineStrips2D::new([strip(c)])
                    .with_colors([rerun::Color::from_rgb(120, 150, 230)]),
            );
            self.note(r);
            let r = self.rec.log(
                format!("{entity}/control_points"),
                &rerun::Points2D::new(strip(c))
                    .with_radii([0.05])
                    .with_colors([rerun::Color::from_rgb(120, 150, 230)]),
            );
            self.note(r);
        }
    }

    fn step(&mut self, s: &StepRecord) {
        self.steps += 1;
        self.trajectory
            .push([s.truth.x_m as f32, s.truth.y_m as f32]);
        self.times.push(s.t_s);
        let actual_curvature =
            s.steer_rad.tan() / self.truck.as_ref().map_or(1.0, |t| t.wheelbase_m);
        let values = [
            s.path_curvature_per_m,
            s.steer_cmd_rad,
            s.steer_rad,
            s.speed_cmd_mps,
            s.speed_mps,
            s.cross_track_m,
            s.contact_force_n,
            actual_curvature,
        ];
        for (v, series) in values.iter().zip(self.plots.iter_mut()) {
            series.push(*v);
        }
        if let Some(fix) = &s.fix {
            self.at(s.t_s);
            self.pose_marker("sensors/measured_pose", fix, [220, 40, 40], 0.04);
        }
        if self.steps % GEOMETRY_EVERY == 1 {
            self.at(s.t_s);
            if let (Some(truck), Some(pallet)) = (self.truck.clone(), self.pallet.clone()) {
                self.outlines(
                    "truck/outline",
                    &truck_outlines(&truck, &s.truth),
                    [230, 190, 25],
                );
                self.outlines(
                    "world/pallet",
                    &pallet_outlines(&pallet, &s.pallet),
                    [205, 140, 50],
                );
                self.outlines(
                    "sensors/pallet_estimate",
                    &pallet_outlines(&pallet, &s.pallet_estimate),
                    [220, 40, 40],
                );
            }
            self.pose_marker("sensors/true_pose", &s.truth, [30, 160, 60], 0.04);
            let r = self.rec.log(
                "track/lookahead",
                &rerun::Points2D::new([[s.lookahead[0] as f32, s.lookahead[1] as f32]])
                    .with_radii([0.05])
                    .with_colors([rerun::Color::from_rgb(150, 60, 200)]),
            );
            self.note(r);
        }
        if self.steps % TRAJECTORY_EVERY == 1 {
            self.at(s.t_s);
            let r = self.rec.log(
                "track/trajectory",
                &rerun::LineStrips2D::new([self.trajectory.clone()])
                    .with_colors([rerun::Color::from_rgb(30, 160, 60)]),
            );
            self.note(r);
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
        let r = self.rec.log(
            "track/trajectory",
            &rerun::LineStrips2D::new([self.trajectory.clone()])
                .with_colors([rerun::Color::from_rgb(30, 160, 60)]),
        );
        self.note(r);
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
    }
}
