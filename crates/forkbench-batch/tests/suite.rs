//! The crate's integration tests as one test binary: each file a module, built and linked once (a binary per file repeats the release build of everything they share).

mod batch;
mod custom_criterion;
mod external;
mod gate;
mod gate_measures;
mod hostile_external;
mod modes;
mod noise_knobs;
mod rare;
mod rust_planner_example;
