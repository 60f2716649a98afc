//! A trial driven one control tick at a time, by its own controllers or by a caller's commands (a learning agent, an outside loop), owning its scenario: the pick alone, or the whole cycle.

use std::future::Future;
use std::pin::Pin;
use std::sync::Arc;

use forkbench_core::Path;

use super::link::{Control, Episode, Link, LinkRecorder, Observation, Stage, Truth, poll_once};
use super::session_view::SceneView;
use super::{Resolved, TrialOptions, run_stages};
use crate::ScenarioError;
use crate::outcome::TrialOutcome;
use crate::scenario::{Case, Scenario};

/// What a session owns for its trial to borrow.
#[derive(Debug)]
struct Owned {
    scn: Arc<Scenario>,
    run: Resolved,
    case: Case,
}

/// The trial, suspended between ticks.
struct Live<'a>(Pin<Box<dyn Future<Output = TrialOutcome> + Send + 'a>>);

impl std::fmt::Debug for Live<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Live(..)")
    }
}

self_cell::self_cell!(
    struct Cell {
        owner: Owned,
        #[covariant]
        dependent: Live,
    }
    impl {Debug}
);

/// How a session's episode ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SessionEnd {
    /// Judged before the time limit: a success, or a failure that no later tick can undo.
    Judged,
    /// A time limit: the scenario's (the pick's), or a leg's or phase's.
    TimeLimit,
}

/// A trial that its caller steps: [`Session::start`] runs it up to the first tick its
/// caller takes (for the pick: after the mission's legs, the first fix, estimate and plan),
/// [`Session::step`] advances one control tick. The trial is the very engine
/// [`super::run_trial`] runs; stepped with [`Control::Tracker`] throughout it gives the
/// same outcome.
#[derive(Debug)]
pub struct Session {
    inner: Inner,
    link: Link,
    last: Observation,
    truth: Truth,
    /// The path the trial follows, as of the observation.
    path: Option<Path>,
    /// For a viewed session: the racks' outlines, copied at its first tick (none before:
    /// a trial that ended before it has no scene to show).
    obstacles: Option<Vec<[[f64; 2]; 5]>>,
}

#[derive(Debug)]
enum Inner {
    Live(Box<Cell>),
    Ended(Box<TrialOutcome>, SessionEnd),
}

impl Session {
    /// Starts case `case` of `scn` under `opts`, for the pick alone. Err: the options or
    /// the case name are not usable. A trial that ends before driving (no plan, no pallet
    /// found) starts already ended.
    pub fn start(
        scn: Arc<Scenario>,
        case: &str,
        opts: &TrialOptions,
    ) -> Result<Self, ScenarioError> {
        Self::start_episode(scn, case, opts, Episode::Pick, false)
    }

    /// As [`Session::start`], keeping what [`Session::view`] draws (the last scans).
    pub fn start_viewed(
        scn: Arc<Scenario>,
        case: &str,
        opts: &TrialOptions,
    ) -> Result<Self, ScenarioError> {
        Self::start_episode(scn, case, opts, Episode::Pick, true)
    }

    /// Starts an episode of `episode`'s extent (the pick, or the whole cycle: legs,
    /// staging, pick and every phase), viewed or not.
    pub fn start_episode(
        scn: Arc<Scenario>,
        case: &str,
        opts: &TrialOptions,
        episode: Episode,
        viewed: bool,
    ) -> Result<Self, ScenarioError> {
        let run = opts.resolve(&scn)?;
        let scn = match super::scenario_for(&scn, &run)? {
            std::borrow::Cow::Borrowed(_) => scn,
            std::borrow::Cow::Owned(s) => Arc::new(s),
        };
        let case = scn.case(case)?.clone();
        let (start, pallet) = (case.start, case.pallet);
        let link = Link::new(episode, viewed);
        let owner = Owned { scn, run, case };
        let for_trial = link.clone();
        let cell = Cell::new(owner, |o| {
            Live(Box::pin(async move {
                let mut rec = LinkRecorder(for_trial.clone());
                run_stages(&o.scn, &o.case, &o.run, Some(for_trial), &mut rec).await
            }))
        });
        let mut session = Session {
            inner: Inner::Live(Box::new(cell)),
            link,
            last: Observation {
                t_s: 0.0,
                time_left_s: 0.0,
                pose: start,
                fix: false,
                pallet_estimate: pallet,
                goal: pallet,
                speed_mps: 0.0,
                steer_rad: 0.0,
                stage: Stage::Pick,
            },
            truth: Truth {
                fork_root: start,
                goal: pallet,
                insertion_depth_m: 0.0,
                pallet,
            },
            path: None,
            obstacles: None,
        };
        session.advance(Control::Tracker);
        Ok(session)
    }

    /// The scene as of the observation (the last one at the end), for a session started
    /// viewed that reached its first tick.
    pub fn view(&self) -> Option<SceneView> {
        let obstacles = self.obstacles.clone()?;
        let slot = self.link.lock();
        Some(SceneView {
            fork_root: self.truth.fork_root,
            pallet: self.truth.pallet,
            pallet_estimate: self.last.pallet_estimate,
            path: self
                .path
                .as_ref()
                .map(|p| p.samples.iter().map(|s| [s.x_m, s.y_m]).collect())
                .unwrap_or_default(),
            obstacles,
            scan: slot.scans.points(),
        })
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
            Inner::Live(_) => self.path.as_ref(),
            Inner::Ended(..) => None,
        }
    }

    /// One control tick under `control`: the command, a physics step, the judging, the
    /// next tick's sensing and observation. Returns how the episode ended when it did (an
    /// ended session stays as it is; its observation is of the last step, with the pose
    /// the controller had for it).
    pub fn step(&mut self, control: Control) -> Option<SessionEnd> {
        if let Inner::Ended(_, end) = &self.inner {
            return Some(*end);
        }
        self.advance(control);
        self.ended().map(|(_, end)| end)
    }

    /// Runs the trial with `control` up to the next tick its caller takes, or its end.
    fn advance(&mut self, control: Control) {
        let Inner::Live(cell) = &mut self.inner else {
            return;
        };
        self.link.lock().control = Some(control);
        let done = cell.with_dependent_mut(|_, live| poll_once(live.0.as_mut()));
        let mut slot = self.link.lock();
        if let Some(obs) = slot.obs.take() {
            self.last = obs;
        }
        if let Some(truth) = slot.truth.take() {
            self.truth = truth;
        }
        if let Some(path) = slot.path.take() {
            self.path = Some(path);
        }
        if let Some(obstacles) = slot.obstacles.take() {
            self.obstacles = Some(obstacles);
        }
        let deadline_hit = slot.deadline_hit;
        drop(slot);
        if let Some(out) = done {
            let end = if deadline_hit {
                SessionEnd::TimeLimit
            } else {
                SessionEnd::Judged
            };
            self.inner = Inner::Ended(Box::new(out), end);
        }
    }
}
