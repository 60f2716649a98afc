//! The rare-event crate's tests, one binary.

mod known_answer;
mod regions;
