//! The studies' tests as one binary: each file a module.

mod accuracy;
mod coverage;
