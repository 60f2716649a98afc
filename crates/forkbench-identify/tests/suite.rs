//! The identification's integration tests, one binary.

mod hostile;
mod round_trip;
