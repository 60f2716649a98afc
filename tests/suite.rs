//! The end-to-end tests of the `forkbench` binary as one test binary: each file a module, built and linked once (a binary per file repeats the release build of everything they share).

mod cli;
mod common;
mod components_file;
mod dataset;
mod doc_numbers;
mod external_planner;
mod external_tracker;
mod gate_candidate;
mod hostile_input;
mod hostile_round4;
mod navigation;
mod outputs;
mod papercuts;
mod profile;
mod rare;
mod ros2;
mod run_options;
mod scenario_fuzz;
mod shards;
mod success_run;
mod trials_auto;
mod truck;
