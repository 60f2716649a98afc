//! A pick trial driven one control tick at a time, by its own tracker or by a caller's commands (a learning agent, an outside loop), owning its scenario.

use std::sync::Arc;

use forkbench_core::units::wrap_angle;
use forkbench_core::{Path, Pose2};
use forkbench_track::Command;

use super::drive::DriveState;
use super::error::StageError;
use super::session_view::{ScanKeeper, SceneView};
use super::setup::Trial;
use super::{Resolved, TrialOptions, goal_for, prepare};
use crate::TrialError;
use crate::outcome::{Failure, TrialOutcome};
use crate::recorder::{NoRecorder, Recorder};
use crate::scenario::Scenario;

/// What a session owns for its trial to borrow.
#[derive(Debug)]
struct Owned {
    scn: Arc<Scenario>,
    run: Resolved,
}

/// A trial between control ticks.
#[derive(Debug)]
struct Live<'a> {
    trial: Trial<'a>,
    at: DriveState,
    /// For a session started viewed: the scans its views draw.
    keeper: Option<ScanKeeper>,
}

self_cell::self_cell!(
    struct Cell {
        owner: Owned,
        #[covariant]
        dependent: Live,
    }
    impl {Debug}
);

/// Where each tick's command comes from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Control {
    /// The scenario's tracker, as in a batch: the episode ends when it reports the goal
    /// reached and the truck stands.
    Tracker,
    /// The caller's speed and steering commands, clamped to the truck's limits. The
    /// episode ends when the truck stands with the forks at the required depth, or as
    /// soon as a criterion has failed for good (a collision, contact force, pallet moved,
    /// entry outside the limits).
    Command { speed_mps: f64, steer_rad: f64 },
    /// The scenario's tracker's command plus the caller's correction (speed m/s,
    /// steering rad), clamped to the truck's limits; the episode ends as under
    /// [`Control::Tracker`], so a zero correction is the tracker's own trial.
    Residual { speed_mps: f64, steer_rad: f64 },
}

/// What the truck's controller knows at a tick (never the truth).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Observation {
    pub t_s: f64,
    /// Time left before the scenario's time limit.
    pub time_left_s: f64,
    /// The controller's fork-root pose: the localiser's fix, or odometry between fixes.
    pub pose: Pose2,
    /// This tick brought a localiser fix.
    pub fix: bool,
    /// The pallet face pose the current plan aims at.
    pub pallet_estimate: Pose2,
    /// The fork-root pose that puts the forks at their target depth in the estimate.
    pub goal: Pose2,
    /// Measured speed (forward positive) and equivalent steering angle.
    pub speed_mps: f64,
    pub steer_rad: f64,
}

/// The truth a reward may use (a judge's view, not the controller's).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Truth {
    pub fork_root: Pose2,
    /// The fork-root pose at the target depth in the real pallet.
    pub goal: Pose2,
    /// Depth of the shallower fork tip past the real pallet face.
    pub insertion_depth_m: f64,
}

/// How a session's episode ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SessionEnd {
    /// Judged before the time limit: a success, or a failure that no later tick can undo.
    Judged,
    /// The scenario's time limit (the outcome's failure is `timeout`).
    TimeLimit,
}

/// A trial that its caller steps: [`Session::start`] runs it up to the drive (the
/// mission's legs, the first fix, estimate and plan), [`Session::step`] advances one
/// control tick. Stepped with [`Control::Tracker`] throughout it reproduces
/// [`super::run_trial`]'s outcome exactly.
#[derive(Debug)]
pub struct Session {
    inner: Inner,
    last: Observation,
    truth: Truth,
    /// The scene at the end, for a session started viewed (while live it is drawn from
    /// the trial when asked for).
    final_view: Option<Box<SceneView>>,
}

#[derive(Debug)]
enum Inner {
    Live(Box<Cell>),
    Ended(Box<TrialOutcome>, SessionEnd),
}

impl Session {
    /// Starts case `case` of `scn` under `opts`. Err: the options or the case name are
    /// not usable. A trial that ends before driving (no plan, no pallet found) starts
    /// already ended.
    pub fn start(scn: Arc<Scenario>, case: &str, opts: &TrialOptions) -> Result<Self, TrialError> {
        Self::start_with(scn, case, opts, false)
    }

    /// As [`Session::start`], keeping a [`SceneView`] of every tick from the first scan
    /// on (for drawing an episode; a snapshot per tick).
    pub fn start_viewed(
        scn: Arc<Scenario>,
        case: &str,
        opts: &TrialOptions,
    ) -> Result<Self, TrialError> {
        Self::start_with(scn, case, opts, true)
    }

    fn start_with(
        scn: Arc<Scenario>,
        case: &str,
        opts: &TrialOptions,
        viewed: bool,
    ) -> Result<Self, TrialError> {
        let run = scn.resolve(opts)?;
        let case = scn.case(case)?.clone();
        let owner = Owned { scn, run };
        let built = Cell::try_new(owner, |o| -> Result<Live<'_>, Box<TrialOutcome>> {
            // Starting is not the hot path: one recorder, the keeper or none.
            let (mut keeper, mut none) = (ScanKeeper::default(), NoRecorder);
            let rec: &mut dyn Recorder = if viewed { &mut keeper } else { &mut none };
            let mut trial = prepare(&o.scn, &case, &o.run, rec)?;
            let mut at = trial.begin_drive();
            if let Err(e) = trial.sense_tick(&mut at, rec) {
                return Err(Box::new(trial.stopped_by(e)));
            }
            Ok(Live {
                trial,
                at,
                keeper: viewed.then_some(keeper),
            })
        });
        let last = Observation {
            t_s: 0.0,
            time_left_s: 0.0,
            pose: case.start,
            fix: false,
            pallet_estimate: case.pallet,
            goal: case.pallet,
            speed_mps: 0.0,
            steer_rad: 0.0,
        };
        let truth = Truth {
            fork_root: case.start,
            goal: case.pallet,
            insertion_depth_m: 0.0,
        };
        let mut session = Session {
            inner: match built {
                Ok(cell) => Inner::Live(Box::new(cell)),
                Err(out) => Inner::Ended(out, SessionEnd::Judged),
            },
            last,
            truth,
            final_view: None,
        };
        session.observe();
        Ok(session)
    }

    /// The scene as of the observation (the last one at the end), for a session started
    /// with [`Session::start_viewed`].
    pub fn view(&self) -> Option<SceneView> {
        match &self.inner {
            Inner::Live(cell) => {
                let live = cell.borrow_dependent();
                live.keeper.as_ref().map(|k| SceneView::of(&live.trial, k))
            }
            Inner::Ended(..) => self.final_view.as_deref().cloned(),
        }
    }

    /// The controller's view now (at the end: the last one).
    pub fn observation(&self) -> &Observation {
        &self.last
    }

    /// The judged outcome and how the episode ended, once it has.
    pub fn ended(&self) -> Option<(&TrialOutcome, SessionEnd)> {
        match &self.inner {
            Inner::Ended(out, end) => Some((out, *end)),
            Inner::Live(_) => None,
        }
    }

    /// The true fork root, goal and insertion depth, as of the observation.
    pub fn truth(&self) -> &Truth {
        &self.truth
    }

    /// The path the truck is meant to follow now (planned for the fork root).
    pub fn path(&self) -> Option<&Path> {
        match &self.inner {
            Inner::Live(cell) => Some(&cell.borrow_dependent().trial.path),
            Inner::Ended(..) => None,
        }
    }

    /// One control tick under `control`: the command, a physics step, the judging, the
    /// next tick's sensing and observation. Returns how the episode ended when it did (an
    /// ended session stays as it is; its observation is of the last step, with the pose
    /// the controller had for it).
    pub fn step(&mut self, control: Control) -> Option<SessionEnd> {
        let Inner::Live(cell) = &mut self.inner else {
            return self.ended().map(|(_, end)| end);
        };
        let end = cell.with_dependent_mut(|_, live| live.tick(control));
        self.observe();
        let (out, end) = end?;
        self.final_view = self.view().map(Box::new);
        self.inner = Inner::Ended(Box::new(out), end);
        Some(end)
    }

    fn observe(&mut self) {
        let Inner::Live(cell) = &self.inner else {
            return;
        };
        let Live { trial: t, at, .. } = cell.borrow_dependent();
        self.last = Observation {
            t_s: t.sim.time_s(),
            time_left_s: (at.deadline_s - t.sim.time_s()).max(0.0),
            pose: at.pose,
            fix: at.fix.is_some(),
            pallet_estimate: t.pallet_est,
            goal: goal_for(&t.pallet_est, &t.scn.truck, t.insertion_m),
            speed_mps: t.sim.speed_mps(),
            steer_rad: t.sim.steer_rad(),
        };
        let truck = &t.scn.truck;
        let (root, pallet) = (t.sim.fork_root_pose(), t.sim.pallet_pose());
        self.truth = Truth {
            fork_root: root,
            goal: goal_for(&pallet, truck, t.insertion_m),
            insertion_depth_m: truck.insertion_depth_m(&pallet, &root),
        };
    }
}

impl Live<'_> {
    fn tick(&mut self, control: Control) -> Option<(TrialOutcome, SessionEnd)> {
        let t = &mut self.trial;
        let cmd = match control {
            Control::Tracker => match t.tracker_command(self.at.pose) {
                Ok(cmd) if t.docked(&cmd) => {
                    t.timed_out = false;
                    return Some((t.judged(), SessionEnd::Judged));
                }
                Ok(cmd) => cmd,
                Err(e) => return Some((t.stopped_by(e), SessionEnd::Judged)),
            },
            Control::Command {
                speed_mps,
                steer_rad,
            } => clamped(t, speed_mps, steer_rad),
            Control::Residual {
                speed_mps,
                steer_rad,
            } => match t.tracker_command(self.at.pose) {
                Ok(cmd) if t.docked(&cmd) => {
                    t.timed_out = false;
                    return Some((t.judged(), SessionEnd::Judged));
                }
                Ok(cmd) => {
                    let c = clamped(t, cmd.speed_mps + speed_mps, cmd.steer_rad + steer_rad);
                    Command {
                        speed_mps: c.speed_mps,
                        steer_rad: c.steer_rad,
                        ..cmd
                    }
                }
                Err(e) => return Some((t.stopped_by(e), SessionEnd::Judged)),
            },
        };
        t.step(&cmd, self.at.fix, self.at.pose, &mut NoRecorder);
        if matches!(control, Control::Command { .. }) && t.settled() {
            t.timed_out = false;
            return Some((t.judged(), SessionEnd::Judged));
        }
        if t.sim.time_s() >= self.at.deadline_s {
            return Some((t.judged(), SessionEnd::TimeLimit));
        }
        let sensed = match &mut self.keeper {
            Some(k) => t.sense_tick(&mut self.at, k),
            None => t.sense_tick(&mut self.at, &mut NoRecorder),
        };
        match sensed {
            Ok(()) => None,
            Err(e) => Some((t.stopped_by(e), SessionEnd::Judged)),
        }
    }
}

/// A caller's command within the truck's limits (a non-finite one stops the truck).
fn clamped(t: &Trial<'_>, speed_mps: f64, steer_rad: f64) -> Command {
    let truck = &t.scn.truck;
    let finite = |v: f64| if v.is_finite() { v } else { 0.0 };
    Command {
        speed_mps: finite(speed_mps).clamp(-truck.max_speed_mps, truck.max_speed_mps),
        steer_rad: finite(steer_rad).clamp(-truck.max_steer_rad, truck.max_steer_rad),
        lookahead_point: [f64::NAN; 2],
        cross_track_m: f64::NAN,
        remaining_m: f64::NAN,
        path_curvature_per_m: f64::NAN,
        done: false,
    }
}

impl Trial<'_> {
    /// The verdict now, as the end of a drive would give it.
    fn judged(&mut self) -> TrialOutcome {
        self.conclude();
        self.out.clone()
    }

    /// The outcome of a trial a stage error stopped, as a batch reports it.
    pub(super) fn stopped_by(&mut self, e: StageError) -> TrialOutcome {
        self.measure();
        self.out.fail(Failure::Error, e.to_string());
        self.out.clone()
    }

    /// A caller-driven episode is over: the truck stands with the forks at the required
    /// depth, or a criterion has failed in a way later ticks cannot undo.
    fn settled(&self) -> bool {
        let (tol, out) = (&self.scn.tolerances, &self.out);
        let pallet = self.sim.pallet_pose();
        let moved = pallet.distance_to(&self.pallet0) > tol.pallet_displacement_m
            || wrap_angle(pallet.heading_rad - self.pallet0.heading_rad).abs()
                > tol.pallet_rotation_rad;
        let entry_off = out.lateral_error_m.is_some_and(|e| e.abs() > tol.lateral_m)
            || out
                .heading_error_rad
                .is_some_and(|e| e.abs() > tol.heading_rad);
        let depth = self
            .scn
            .truck
            .insertion_depth_m(&pallet, &self.sim.fork_root_pose());
        let step_broken = self
            .step_criteria
            .iter()
            .any(|c| c.irreversible() && c.broken().is_some());
        self.collision
            || step_broken
            || out.max_contact_force_n > tol.contact_force_n
            || moved
            || entry_off
            || (self.stands() && depth >= tol.insertion_depth_m)
    }
}
