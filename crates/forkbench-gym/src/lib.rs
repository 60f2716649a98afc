//! The Gymnasium episode as a Rust library: an environment's checked setup, its episodes stepped through a trial `Session`, the observation vector, the reward and the drawn frame. `forkbench._forkbench` binds it for Python.

mod episode;
pub mod obs;
mod render;
mod setup;

pub use episode::{Core, StepOut, command};
pub use setup::{DEFAULT_PHASE_REWARD, EnvSpec, MAX_PATH_POINTS, RENDER_PX, Setup};

/// Why an environment could not be set up or an episode started.
#[derive(Debug, thiserror::Error)]
pub enum GymError {
    /// The scenario refused the run (an unknown case, component or option out of range).
    #[error(transparent)]
    Scenario(#[from] forkbench_trial::ScenarioError),
    /// An environment setting out of its range, or an action that is not a number.
    #[error("{0}")]
    Setting(String),
}
