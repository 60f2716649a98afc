//! One pick trial end to end: scenario and world files, noisy estimate → plan → tracker in rapier2d → judged outcome, with components from a registry.

pub mod components;
pub mod defaults;
pub mod footprints;
pub mod mission_summary;
pub mod outcome;
pub mod phase;
pub mod pose_deg;
pub mod recorder;
pub mod scenario;
pub mod stage_error;
pub mod step_criteria;
pub mod text;
pub mod tolerances;
pub mod trial;

pub use components::{ComponentSpec, Registry, Role};
pub use mission_summary::MissionSummary;
pub use outcome::{Failure, SafetyOutcome, TrialOutcome};
pub use recorder::{Level, NoRecorder, Recorder, SceneInfo, StepRecord, Tee};
pub use scenario::{Case, Limits, PoseDeg, Replan, Scenario, Tolerances, World};
pub use trial::{LegError, Resolved, StageError, TrialOptions, run_trial, run_trial_recorded};

/// A scenario or world file that cannot be used, with the file and field named.
#[derive(Debug, thiserror::Error)]
pub enum TrialError {
    /// The reason is in the message, not chained as a source: `{:#}` would print it twice.
    #[error("{file}: {cause}")]
    Read { file: String, cause: std::io::Error },
    /// Syntax or type error; toml's message carries line and column.
    #[error("{file}: {message}")]
    Parse { file: String, message: String },
    #[error("{file}: field `{field}`: {reason}")]
    Invalid {
        file: String,
        field: String,
        reason: String,
    },
    /// A scenario of several cases run without naming one (`--case`, or `case=`).
    #[error(
        "{file}: has {count} cases; name one (`--case` on the command line, `case=` in Python; cases: {known})"
    )]
    CaseNeeded {
        file: String,
        count: usize,
        known: String,
    },
    #[error("{file}: no case named {case:?} (cases: {known})")]
    UnknownCase {
        file: String,
        case: String,
        known: String,
    },
}
