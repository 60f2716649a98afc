//! One pick trial end to end on a scenario (the format is `forkbench-scenario`'s): noisy estimate → plan → tracker in rapier2d → judged outcome, with components from a registry.

pub mod components;
pub mod defaults;
pub mod mission_summary;
pub mod outcome;
pub mod phase;
pub mod recorder;
pub mod scenario;
pub mod stage_error;
pub mod step_criteria;
pub mod trial;

pub use forkbench_scenario::{ScenarioError, footprints, pose_deg, text, tolerances};

pub use components::{ComponentSpec, Registry, Role};
pub use mission_summary::MissionSummary;
pub use outcome::{Failure, SafetyOutcome, TrialOutcome};
pub use recorder::{Level, NoRecorder, Recorder, SceneInfo, StepRecord, Tee};
pub use scenario::{Case, Limits, PoseDeg, Replan, Scenario, Tolerances, World};
pub use trial::{
    LegError, Resolved, StageError, TrialOptions, attach_profile, profiled, run_trial,
    run_trial_recorded,
};
