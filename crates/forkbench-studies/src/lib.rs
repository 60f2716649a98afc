//! Studies the CLI runs beside the trials, on the scenario format's public types only (no engine internals): the pallet detector's accuracy over range, angle and offset, a world's reflector coverage, and Luo's PRM study on the embedded warehouse.

pub mod accuracy;
pub mod coverage;
pub mod prm_study;
