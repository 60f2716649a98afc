//! What a session and its trial share each tick: the stage being driven, the caller's control in, the observation and the truth out, and the polling that hands the caller its turn.

use std::future::Future;
use std::pin::Pin;
use std::sync::{Arc, Mutex, PoisonError};
use std::task::{Context, Poll, Waker};

use forkbench_core::Pose2;

use super::session_view::ScanKeeper;
use crate::recorder::Recorder;

/// Which part of the cycle a drive belongs to (what a caller's observation names).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    /// A mission leg before the pick.
    Leg,
    /// The drive to a staging pose and the moves between looks.
    Staging,
    /// The approach and insertion.
    Pick,
    /// A phase after the pick, by its index in the scenario's `phases` list (1 is the
    /// first after the pick).
    Phase(u16),
}

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
    /// Time left before the current drive's time limit (the pick's is the scenario's).
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
    /// The part of the cycle being driven.
    pub stage: Stage,
}

/// The truth a reward may use (a judge's view, not the controller's).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Truth {
    pub fork_root: Pose2,
    /// The fork-root pose at the target depth in the real pallet.
    pub goal: Pose2,
    /// Depth of the shallower fork tip past the real pallet face.
    pub insertion_depth_m: f64,
    /// The real pallet face pose.
    pub pallet: Pose2,
}

/// Polls `fut` once: `Some` once it has finished.
pub(crate) fn poll_once<T>(fut: Pin<&mut (dyn Future<Output = T> + Send + '_)>) -> Option<T> {
    match fut.poll(&mut Context::from_waker(Waker::noop())) {
        Poll::Ready(v) => Some(v),
        Poll::Pending => None,
    }
}

/// Runs a trial with no caller to its end (it never yields without a link).
pub(crate) fn run_to_end<T>(fut: impl Future<Output = T>) -> T {
    let mut fut = std::pin::pin!(fut);
    loop {
        if let Poll::Ready(v) = fut.as_mut().poll(&mut Context::from_waker(Waker::noop())) {
            return v;
        }
    }
}

/// Which stages a session's caller takes the ticks of.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Episode {
    /// The pick alone (the legs and staging before it run on their own; the episode ends
    /// at the pick's verdict).
    Pick,
    /// The whole cycle: every leg, the staging, the pick and each phase.
    Cycle,
}

/// What a session and its trial share: the caller's control in, the view out.
#[derive(Debug, Clone)]
pub(crate) struct Link {
    episode: Episode,
    slot: Arc<Mutex<Slot>>,
}

/// The shared state behind a [`Link`].
#[derive(Debug, Default)]
pub(crate) struct Slot {
    pub(crate) control: Option<Control>,
    pub(crate) obs: Option<Observation>,
    pub(crate) truth: Option<Truth>,
    /// The path the trial follows, when it changed since the session took it.
    pub(crate) path: Option<forkbench_core::Path>,
    pub(super) path_version: Option<u64>,
    /// The session draws its scene: the racks' outlines (once) and the last scans.
    pub(crate) viewed: bool,
    pub(crate) obstacles: Option<Vec<[[f64; 2]; 5]>>,
    pub(super) obstacles_sent: bool,
    pub(crate) scans: ScanKeeper,
    /// The last drive the caller stepped ended at its time limit.
    pub(crate) deadline_hit: bool,
}

impl Link {
    pub(crate) fn new(episode: Episode, viewed: bool) -> Self {
        let slot = Slot {
            viewed,
            ..Slot::default()
        };
        Link {
            episode,
            slot: Arc::new(Mutex::new(slot)),
        }
    }

    pub(crate) fn lock(&self) -> std::sync::MutexGuard<'_, Slot> {
        self.slot.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// The session ends at the pick's verdict.
    pub(crate) fn pick_only(&self) -> bool {
        self.episode == Episode::Pick
    }

    pub(super) fn covers(&self, stage: Stage) -> bool {
        self.episode == Episode::Cycle || stage == Stage::Pick
    }

    pub(super) fn control(&self) -> Control {
        self.lock().control.unwrap_or(Control::Tracker)
    }
}

/// A session's recorder: keeps the last scans for its view, when it is drawn.
#[derive(Debug)]
pub(crate) struct LinkRecorder(pub(crate) Link);

impl Recorder for LinkRecorder {
    fn signal(
        &mut self,
        t_s: f64,
        path: &str,
        signal: &forkbench_core::Signal<'_>,
        style: forkbench_core::Style,
    ) {
        if matches!(signal, forkbench_core::Signal::Scan(_)) {
            let mut slot = self.0.lock();
            if slot.viewed {
                slot.scans.signal(t_s, path, signal, style);
            }
        }
    }
}
