//! Safety laser scanner fields for people detection (ISO 3691-4): protective fields sized per speed range with the scanner makers' formula, the braking distance measured in the physics.

mod braking;
mod config;
mod detect;
mod fields;
mod function;
mod geometry;
mod people;
mod sizing;
mod table;

use forkbench_core::{ForkliftSpec, PalletSpec, SettingsError};
use forkbench_sim::SimConfig;
use serde::Serialize;

pub use braking::{Braking, STOPPED_MPS, braking_distance};
pub use config::{MAX_SPEED_RANGES, ReflectorsNear, SafetyConfig, SafetyScannerSpec};
pub use detect::{Eye, Seen as FieldsSeen, detect};
pub use fields::{FieldSet, FieldSets, Fields, Outline, STANDING_MPS, contains};
pub use function::{Reading, SafetyFunction, SafetyStats};
pub use geometry::{Rect, rect_gap_lower_bound_m, rect_gap_m};
pub use people::{
    LEG_M, MAX_ROUTE_POINTS, Mover, MoverKind, MoverSpec, PERSON_BODY_M, WALKING_MPS, YIELD_GAP_M,
};
pub use sizing::{
    FLOOR_CLEARANCE_LIMIT_M, FLOOR_SUPPLEMENT_M, FieldInputs, FieldTerms, Load,
    REFLECTOR_SUPPLEMENT_M, field_terms,
};
pub use table::text;

/// Why fields could not be sized.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SafetyError {
    #[error("safety setting {0}")]
    Settings(#[from] SettingsError),
    #[error("the braking world: {0}")]
    Sim(#[from] forkbench_sim::SimError),
    #[error("carrying the rated load: {0}")]
    Lift(#[from] forkbench_sim::LiftError),
    #[error(
        "a braking speed must be positive and at most twice the truck's top speed (got {speed_mps} m/s)"
    )]
    Speed { speed_mps: f64 },
    #[error("the truck did not reach {speed_mps} m/s within {limit_s} s (too little grip?)")]
    NotReached { speed_mps: f64, limit_s: f64 },
    #[error("the truck did not stop from {speed_mps} m/s within {limit_s} s")]
    NotStopped { speed_mps: f64, limit_s: f64 },
}

/// Every field set's protective field, empty and at rated load, in the order of the speed
/// ranges.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FieldSizing {
    pub config: SafetyConfig,
    /// Whether Z_R was applied.
    pub reflectors_near: bool,
    /// The floor's tyre friction the braking was measured on.
    pub tyre_friction: f64,
    pub fields: Vec<FieldTerms>,
}

/// Sizes each speed range's protective field, empty and with the rated load, braking in
/// the physics on the floor `sim_cfg` describes. `reflectors_in_world`: whether the world
/// has retroreflectors (`ReflectorsNear::Auto` follows it).
pub fn size_fields(
    cfg: &SafetyConfig,
    truck: &ForkliftSpec,
    sim_cfg: &SimConfig,
    pallet: &PalletSpec,
    reflectors_in_world: bool,
) -> Result<FieldSizing, SafetyError> {
    cfg.validate(truck.max_speed_mps)?;
    let reflectors_near = match cfg.reflectors_near {
        ReflectorsNear::Auto => reflectors_in_world,
        ReflectorsNear::Yes => true,
        ReflectorsNear::No => false,
    };
    let mut fields = Vec::with_capacity(2 * cfg.speed_ranges_mps.len());
    for &v in &cfg.speed_ranges_mps {
        for load in [Load::Empty, Load::Rated] {
            let braking = braking_distance(truck, sim_cfg, pallet, v, load)?;
            let vehicle_width_m = match load {
                Load::Empty => truck.body_width_m,
                Load::Rated => truck.body_width_m.max(pallet.width_m),
            };
            let inputs = FieldInputs {
                speed_max_mps: v,
                load,
                braking_m: braking.distance_m,
                reflectors_near,
                vehicle_width_m,
            };
            fields.push(field_terms(cfg, &inputs));
        }
    }
    Ok(FieldSizing {
        config: cfg.clone(),
        reflectors_near,
        tyre_friction: sim_cfg.tyre_friction,
        fields,
    })
}
