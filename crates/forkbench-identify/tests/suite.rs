//! The identification's integration tests, one binary.

mod round_trip;
