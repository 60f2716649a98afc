//! The crate's integration tests as one test binary: each file a module, built and linked once (a binary per file repeats the release build of everything they share).

mod common;

mod builtin_outcomes;
mod components;
mod custom_phase;
mod default_outcomes;
mod external_detector;
mod external_tracker;
mod file_layout;
mod format_doc;
mod layering;
mod localization;
mod missions;
mod order_free;
mod pallet_kinds;
mod people;
mod phases;
mod replanning;
mod sensing;
mod session;
mod settings_ranges;
mod staging;
mod state_owners;
mod trial;
mod trucks;
mod uncertain;
