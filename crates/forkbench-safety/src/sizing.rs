//! The protective field's length and width per speed range, term by term, from the scanner makers' formula (S_L = S_A + TZ + Z_R + Z_F + Z_G + Z_B).

use serde::Serialize;

use crate::config::SafetyConfig;

/// Z_R: a retroreflector within 6 m of the protective field can make the scanner's ranges
/// err by this much.
pub const REFLECTOR_SUPPLEMENT_M: f64 = 0.35;

/// Z_F: a foot ahead of the point where a leg is detected, for a truck this low.
pub const FLOOR_SUPPLEMENT_M: f64 = 0.15;

/// Ground clearance below which Z_F applies (the makers' flat rate; their graph may
/// reduce it, which is not modelled).
pub const FLOOR_CLEARANCE_LIMIT_M: f64 = 0.12;

/// Whether the truck is sized empty or carrying its rated load.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Load {
    Empty,
    Rated,
}

impl Load {
    pub fn name(self) -> &'static str {
        match self {
            Load::Empty => "empty",
            Load::Rated => "rated",
        }
    }
}

/// One protective field's size with every term of the formula (metres, seconds).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FieldTerms {
    /// The top of the speed range this field is active in.
    pub speed_max_mps: f64,
    pub load: Load,
    /// S_Br: the braking distance from that speed, measured in the physics.
    pub braking_m: f64,
    /// S_AnF: travelled during the vehicle control's response time.
    pub controller_m: f64,
    /// S_AnS: travelled during the scanner's response time.
    pub scanner_m: f64,
    /// S_A = S_Br + S_AnF + S_AnS: the stopping distance.
    pub stopping_m: f64,
    /// TZ: the scanner's tolerance range.
    pub tolerance_m: f64,
    /// Z_R: the reflector supplement (0 when no reflector is near).
    pub reflector_m: f64,
    /// Z_F: the floor supplement (0 at a ground clearance of 120 mm or more).
    pub floor_m: f64,
    /// Z_G: the general supplement.
    pub general_m: f64,
    /// Z_B: the supplement for decreasing braking force.
    pub braking_supplement_m: f64,
    /// S_L: the protective field's length ahead of the truck.
    pub length_m: f64,
    /// The vehicle's width with its load (the wider of body and pallet).
    pub vehicle_width_m: f64,
    /// S_B = vehicle width + 2 (TZ + Z_R + Z_F): the protective field's width.
    pub width_m: f64,
}

/// The inputs of one field besides the configuration: the range's top speed, the load,
/// the measured braking distance, whether a reflector is near, and the loaded width.
#[derive(Debug, Clone, Copy)]
pub struct FieldInputs {
    pub speed_max_mps: f64,
    pub load: Load,
    pub braking_m: f64,
    pub reflectors_near: bool,
    pub vehicle_width_m: f64,
}

/// The field's terms and size from the formula.
pub fn field_terms(cfg: &SafetyConfig, i: &FieldInputs) -> FieldTerms {
    let v = i.speed_max_mps;
    let controller_m = v * cfg.controller_response_s;
    let scanner_m = v * cfg.scanner.response_time_s;
    let stopping_m = i.braking_m + controller_m + scanner_m;
    let tolerance_m = cfg.scanner.tolerance_m;
    let reflector_m = if i.reflectors_near {
        REFLECTOR_SUPPLEMENT_M
    } else {
        0.0
    };
    let floor_m = if cfg.ground_clearance_m < FLOOR_CLEARANCE_LIMIT_M {
        FLOOR_SUPPLEMENT_M
    } else {
        0.0
    };
    let (general_m, braking_supplement_m) = (cfg.general_supplement_m, cfg.braking_supplement_m);
    FieldTerms {
        speed_max_mps: v,
        load: i.load,
        braking_m: i.braking_m,
        controller_m,
        scanner_m,
        stopping_m,
        tolerance_m,
        reflector_m,
        floor_m,
        general_m,
        braking_supplement_m,
        length_m: stopping_m
            + tolerance_m
            + reflector_m
            + floor_m
            + general_m
            + braking_supplement_m,
        vehicle_width_m: i.vehicle_width_m,
        width_m: i.vehicle_width_m + 2.0 * (tolerance_m + reflector_m + floor_m),
    }
}
