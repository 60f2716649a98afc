//! Rectangular vehicles in corridor bends (Quan & Wang 2021): minimum widths and movable ranges per turning mode.

pub mod analysis;
pub mod bend;
pub mod reproduce;
pub mod search;

pub use analysis::{Comparison, CorridorError, Validation, check_inputs, compare, validate};
pub use bend::{Bend, Junction, MARGIN_M, Vehicle, oblique_min_width_m};
pub use reproduce::{CorridorQuery, CorridorRun, WidthRow, amv, analyse, check_regions};
pub use search::{GRegion, Mode, Resolution, Space, min_width_m, passes};
