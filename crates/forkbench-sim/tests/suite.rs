//! The crate's integration tests as one test binary: each file a module, built and linked once (a binary per file repeats the release build of everything they share).

mod layouts;
mod load;
mod physics;
mod view;
