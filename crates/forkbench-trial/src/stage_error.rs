//! Why a trial stage or a mission leg stopped before its judgement, as types; the outcome's failure detail is their message.

use forkbench_nav::{GridError, NavError};
use forkbench_plan::PlanError;
use forkbench_sim::SimError;

/// A stage of a trial that could not go on.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StageError {
    #[error("non-finite state at t = {t_s:.3} s")]
    NonFinite { t_s: f64 },
    #[error(transparent)]
    World(#[from] SimError),
    #[error("{0}")]
    Plan(#[from] PlanError),
    #[error("the planned path runs the truck body into {obstacle} at s = {s_m:.2} m")]
    Clash { obstacle: String, s_m: f64 },
    #[error("rasterising the world: {0}")]
    Rasterise(#[from] GridError),
    /// The pallet detector could not answer (an external one hung, crashed or broke the
    /// protocol).
    #[error(transparent)]
    Detector(#[from] forkbench_sensors::detector::DetectorError),
    /// The tracker could not steer (an external one hung, crashed or broke the protocol).
    #[error("tracker {tracker}: {reason}")]
    Tracker { tracker: String, reason: String },
    /// The trial ran past its wall-time budget (an external component slow on every tick).
    #[error(
        "the trial took more than its wall-time budget of {budget_s} s (TrialOptions::wall_budget_s; an external component answering slowly on every tick?)"
    )]
    WallBudget { budget_s: f64 },
    /// A mission leg failed; `detail` is the leg's recorded failure.
    #[error("leg {number} {name}: {detail}")]
    Leg {
        number: usize,
        name: String,
        detail: String,
    },
}

/// Why one mission leg failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LegError {
    #[error(transparent)]
    Stage(#[from] StageError),
    #[error("no clear way to back {backout_m:.1} m out of {from}")]
    NoBackout { backout_m: f64, from: String },
    #[error(
        "planning refused: {attempts} attempts × {approaches} approaches × about {per_attempt:.3e} \
         candidate edges (mission.global nodes {nodes} and connect_m) exceed {limit:.1e}; fewer \
         nodes, attempts or a shorter connection distance"
    )]
    TooMuchWork {
        attempts: u32,
        approaches: usize,
        per_attempt: f64,
        nodes: usize,
        limit: f64,
    },
    #[error("{0}")]
    Global(#[from] NavError),
    /// Smoothing failed or its path strikes an obstacle.
    #[error("{0}")]
    Smoothing(String),
    #[error("no attempt")]
    NoAttempt,
    #[error("the truck struck a rack or wall at ({x_m:.2}, {y_m:.2}) m")]
    Struck { x_m: f64, y_m: f64 },
    #[error("not stopped at the end of the path within {timeout_s} s")]
    NotStopped { timeout_s: f64 },
    #[error("the manoeuvre still had cusps ahead after {plans} plans")]
    TooManyCusps { plans: u32 },
}
