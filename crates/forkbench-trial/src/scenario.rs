//! The scenario format (the `forkbench-scenario` crate) with this crate's registry as its catalogue.

pub use forkbench_scenario::*;

/// A scenario whose components this crate's [`Registry`](crate::Registry) checks and builds.
pub type Scenario = forkbench_scenario::Scenario<crate::Registry>;
