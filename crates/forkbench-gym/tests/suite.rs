//! The Gymnasium episode's tests as one binary: each file a module.

mod episodes;
