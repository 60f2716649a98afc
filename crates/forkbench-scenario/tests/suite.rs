//! The crate's integration tests as one test binary: each file a module.

mod catalogue;
