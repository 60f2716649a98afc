//! Safety laser scanner fields for people detection (ISO 3691-4): protective fields sized per speed range with the scanner makers' formula, the braking distance measured in the physics.

mod braking;
mod config;
mod custom;
mod detect;
mod fields;
mod function;
mod geometry;
mod people;
mod sizing;
mod table;

use forkbench_core::{ForkliftSpec, PalletSpec, SettingsError};
use forkbench_sim::SimConfig;
use std::sync::Mutex;

use serde::Serialize;

pub use braking::{Braking, STOPPED_MPS, braking_distance};
pub use config::{MAX_SPEED_RANGES, RangeError, ReflectorsNear, SafetyConfig, SafetyScannerSpec};
pub use custom::{Direction, FieldSetSpec, Footprint, MAX_FIELD_POINTS, MAX_FIELD_REACH_M};
pub use detect::{Eye, Seen as FieldsSeen, detect};
pub use fields::{
    FIELD_STEER_STEP_RAD, FieldCache, FieldSet, FieldSets, Fields, Outline, STANDING_MPS, contains,
};
pub use function::{Reading, SafetyFunction, SafetyStats};
pub use geometry::{Rect, rect_gap_lower_bound_m, rect_gap_m};
pub use people::{
    Behaviour, LEG_M, MAX_ROUTE_POINTS, Mover, MoverKind, MoverSpec, PERSON_BODY_M, WAIT_GAP_M,
    WALKING_MPS, YIELD_GAP_M,
};
pub use sizing::{
    FLOOR_CLEARANCE_LIMIT_M, FLOOR_SUPPLEMENT_M, FieldInputs, FieldTerms, Load,
    REFLECTOR_SUPPLEMENT_M, field_terms,
};
pub use table::{drawn_text, text};

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

impl FieldSizing {
    /// How much further than true the scanner reads a range under its `range_error`.
    pub fn range_bias_m(&self) -> f64 {
        match self.config.scanner.range_error {
            RangeError::None => 0.0,
            RangeError::WorstCase => {
                let z_r = if self.reflectors_near {
                    REFLECTOR_SUPPLEMENT_M
                } else {
                    0.0
                };
                self.config.scanner.tolerance_m + z_r
            }
        }
    }
}

/// Sizings kept for the process, by their inputs: a batch sizes each scenario's fields
/// once, not at every trial's start.
const SIZINGS_KEPT: usize = 64;
static SIZINGS: Mutex<Vec<(String, FieldSizing)>> = Mutex::new(Vec::new());

/// Sizes each speed range's protective field, empty and with the rated load, braking in
/// the physics on the floor `sim_cfg` describes. `reflectors_in_world`: whether the world
/// has retroreflectors (`ReflectorsNear::Auto` follows it). The same inputs give the
/// sizing found before (up to the process's last few dozen distinct ones).
pub fn size_fields(
    cfg: &SafetyConfig,
    truck: &ForkliftSpec,
    sim_cfg: &SimConfig,
    pallet: &PalletSpec,
    reflectors_in_world: bool,
) -> Result<FieldSizing, SafetyError> {
    // Debug prints every float exactly, so equal keys are equal inputs.
    let key = format!("{cfg:?}|{truck:?}|{sim_cfg:?}|{pallet:?}|{reflectors_in_world}");
    let kept = SIZINGS.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((_, s)) = kept.iter().find(|(k, _)| *k == key) {
        return Ok(s.clone());
    }
    drop(kept);
    let sizing = measure_fields(cfg, truck, sim_cfg, pallet, reflectors_in_world)?;
    let mut kept = SIZINGS.lock().unwrap_or_else(|e| e.into_inner());
    if kept.len() < SIZINGS_KEPT && !kept.iter().any(|(k, _)| *k == key) {
        kept.push((key, sizing.clone()));
    }
    Ok(sizing)
}

fn measure_fields(
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
