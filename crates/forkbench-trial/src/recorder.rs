//! What a trial reports as it runs, for recording sinks (rerun, MCAP) that live outside this crate: its scene, plans, steps, events and outcome, and open-ended signals.

use forkbench_core::{ForkliftSpec, Path, Pose2, Signal, Style};
use forkbench_sim::{Obstacle, PalletSpec};

use crate::outcome::TrialOutcome;

/// The fixed scene of a trial, sent once before the first step.
#[derive(Debug, Clone)]
pub struct SceneInfo<'a> {
    pub scenario: &'a str,
    pub case: &'a str,
    pub planner: &'a str,
    pub tracker: &'a str,
    pub seed: u64,
    pub truck: &'a ForkliftSpec,
    pub pallet: &'a PalletSpec,
    /// True pallet pose (front-face centre) at the start.
    pub pallet_pose: Pose2,
    pub obstacles: &'a [Obstacle],
    /// Fork-root start pose.
    pub start: Pose2,
    /// What the judge checks, for drawing the limits beside the errors.
    pub tolerances: &'a crate::tolerances::Limits,
}

/// One control step: truth, what the controller saw, what it commanded.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepRecord {
    pub t_s: f64,
    /// True fork-root pose.
    pub truth: Pose2,
    /// A NAV350 fix delivered this step, if any.
    pub fix: Option<Pose2>,
    /// The pose the controller used (last fix propagated by odometry).
    pub estimate: Pose2,
    pub pallet: Pose2,
    pub pallet_estimate: Pose2,
    pub steer_cmd_rad: f64,
    pub steer_rad: f64,
    pub speed_cmd_mps: f64,
    pub speed_mps: f64,
    pub lookahead: [f64; 2],
    pub cross_track_m: f64,
    /// Planned curvature at the tracked point.
    pub path_curvature_per_m: f64,
    pub contact_force_n: f64,
}

/// Severity of a trial event.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Level {
    Info,
    Warn,
    Error,
}

/// Receives a trial as it happens. Every method has an empty default. `Send`, so a
/// trial (and a session stepping it) can move between threads with its recorder.
pub trait Recorder: Send {
    fn scene(&mut self, _scene: &SceneInfo<'_>) {}
    /// A plan (index 0) or a replan (1, 2, …); `control_polygon` for B-splines.
    fn plan(
        &mut self,
        _t_s: f64,
        _index: u32,
        _path: &Path,
        _control_polygon: Option<&[[f64; 2]]>,
    ) {
    }
    /// Anything else, at a path: a sensor's scan, a mission's map and routes, a phase.
    /// Sinks draw each [`Signal`] kind the same way wherever it comes from, so a new
    /// component records itself without changing this trait.
    fn signal(&mut self, _t_s: f64, _path: &str, _signal: &Signal<'_>, _style: Style) {}
    fn step(&mut self, _step: &StepRecord) {}
    fn event(&mut self, _t_s: f64, _level: Level, _text: &str) {}
    fn outcome(&mut self, _t_s: f64, _outcome: &TrialOutcome) {}
}

/// Records nothing.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoRecorder;

impl Recorder for NoRecorder {}

/// Fans every call out to several borrowed recorders (e.g. a file and a viewer).
pub struct Tee<'a>(pub Vec<&'a mut dyn Recorder>);

impl std::fmt::Debug for Tee<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Tee({} recorders)", self.0.len())
    }
}

impl Recorder for Tee<'_> {
    fn scene(&mut self, s: &SceneInfo<'_>) {
        self.0.iter_mut().for_each(|r| r.scene(s));
    }
    fn plan(&mut self, t: f64, i: u32, p: &Path, c: Option<&[[f64; 2]]>) {
        self.0.iter_mut().for_each(|r| r.plan(t, i, p, c));
    }
    fn signal(&mut self, t: f64, path: &str, signal: &Signal<'_>, style: Style) {
        self.0
            .iter_mut()
            .for_each(|r| r.signal(t, path, signal, style));
    }
    fn step(&mut self, s: &StepRecord) {
        self.0.iter_mut().for_each(|r| r.step(s));
    }
    fn event(&mut self, t: f64, l: Level, text: &str) {
        self.0.iter_mut().for_each(|r| r.event(t, l, text));
    }
    fn outcome(&mut self, t: f64, o: &TrialOutcome) {
        self.0.iter_mut().for_each(|r| r.outcome(t, o));
    }
}
