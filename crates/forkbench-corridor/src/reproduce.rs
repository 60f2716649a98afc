//! Quan & Wang 2021's corridor analysis as runs: W_min per angle and mode, G regions, and the reproduction's sections.

use forkbench_core::ForkliftSpec;
use serde::Serialize;

use crate::{
    CorridorError, GRegion, Junction, Mode, Resolution, Vehicle, check_inputs, min_width_m,
    oblique_min_width_m,
};

/// The paper's AMV (Lc 0.56 m, Wc 0.40 m).
pub fn amv() -> Vehicle {
    Vehicle {
        length_m: 0.56,
        width_m: 0.40,
        kinematic_ahead_m: 0.0,
        min_radius_m: 0.0,
    }
}

/// One angle × turning mode.
#[derive(Debug, Clone, Serialize)]
pub struct WidthRow {
    pub angle_deg: f64,
    pub mode: Mode,
    /// Narrowest passable corridor; `None` when no width up to the search bound passes.
    pub min_width_m: Option<f64>,
    /// Area of the G region at the run's width, when one was given.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub g_area_m2: Option<f64>,
    /// Oblique translation's closed form Lc·sin θ + Wc·cos θ.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub closed_form_m: Option<f64>,
}

/// What one corridor run asks for.
#[derive(Debug, Clone)]
pub struct CorridorQuery {
    pub vehicle: Vehicle,
    pub junction: Junction,
    /// Corridor width for the G regions (none: W_min only).
    pub width_m: Option<f64>,
    pub angles_deg: Vec<f64>,
    pub cell_m: f64,
}

/// A run's results: a row per angle × mode, and the G regions at the width.
#[derive(Debug)]
pub struct CorridorRun {
    pub rows: Vec<WidthRow>,
    pub regions: Vec<(f64, GRegion)>,
}

/// The turning modes a vehicle has: the truck mode only with a turning radius.
pub fn modes_for(v: &Vehicle) -> Vec<Mode> {
    if v.min_radius_m > 0.0 {
        Mode::ALL.to_vec()
    } else {
        Mode::ALL[..4].to_vec()
    }
}

/// W_min (and G regions at the query's width) for every angle and mode.
pub fn analyse(q: &CorridorQuery) -> Result<CorridorRun, CorridorError> {
    check_inputs(&q.vehicle, q.junction, q.width_m, &q.angles_deg, q.cell_m)?;
    let res = Resolution {
        cell_m: q.cell_m,
        heading_rad: 1f64.to_radians(),
    };
    let mut rows = Vec::new();
    let mut regions = Vec::new();
    for &deg in &q.angles_deg {
        let th = deg.to_radians();
        for mode in modes_for(&q.vehicle) {
            let bound = crate::analysis::widest_searchable_m(
                &q.vehicle,
                q.junction,
                deg,
                q.cell_m,
                20.0 * q.vehicle.circumscribed_m(),
            );
            let w = min_width_m(&q.vehicle, mode, q.junction, th, res, bound);
            let g = q
                .width_m
                .map(|w| GRegion::compute(q.junction.bend(w, th), q.vehicle, mode, res));
            rows.push(WidthRow {
                angle_deg: deg,
                mode,
                min_width_m: w,
                g_area_m2: g.as_ref().map(GRegion::area_m2),
                closed_form_m: (mode == Mode::Oblique).then(|| oblique_min_width_m(&q.vehicle, th)),
            });
            if let Some(g) = g {
                regions.push((deg, g));
            }
        }
    }
    Ok(CorridorRun { rows, regions })
}

/// Positions [`crate::validate`] sweeps per G region when a run is checked.
pub const VALIDATION_SAMPLES: usize = 100;

/// Each G region against circle inflation ([`crate::compare`]) and its positions swept
/// with parry2d ([`crate::validate`], [`VALIDATION_SAMPLES`] of them), with its angle.
pub fn check_regions(
    regions: &[(f64, GRegion)],
) -> Vec<(f64, crate::Comparison, crate::Validation)> {
    regions
        .iter()
        .map(|(deg, g)| {
            (
                *deg,
                crate::compare(g),
                crate::validate(g, VALIDATION_SAMPLES),
            )
        })
        .collect()
}

/// Oblique translation's worst bend angle: arctan(Lc / Wc).
pub fn worst_oblique_angle_deg(v: &Vehicle) -> f64 {
    (v.length_m / v.width_m).atan().to_degrees()
}

/// The reproduction's sections, in order: the AMV over bend angles (with the worst
/// oblique angle), its G regions, a T junction, the A30 body, and its G regions.
pub fn reproduction() -> Vec<(&'static str, CorridorQuery)> {
    let v = amv();
    let mut angles = vec![
        15.0,
        30.0,
        45.0,
        worst_oblique_angle_deg(&v),
        60.0,
        75.0,
        90.0,
    ];
    angles.sort_by(f64::total_cmp);
    let truck = Vehicle::forklift(&ForkliftSpec::default());
    let q = |vehicle, junction, width_m, angles_deg: &[f64], cell_m| CorridorQuery {
        vehicle,
        junction,
        width_m,
        angles_deg: angles_deg.to_vec(),
        cell_m,
    };
    vec![
        ("AMV 0.56 × 0.40 m", q(v, Junction::L, None, &angles, 0.01)),
        (
            "AMV G regions at W = 0.60 m, θ = 90°",
            q(v, Junction::L, Some(0.60), &[90.0], 0.01),
        ),
        (
            "AMV turning from the stem of a T junction, W = 0.60 m",
            q(v, Junction::T, Some(0.60), &[90.0], 0.01),
        ),
        (
            "A30 truck body 2.45 × 1.2 m (r_min 0.94 m about the front axle)",
            q(truck, Junction::L, None, &[30.0, 60.0, 90.0], 0.03),
        ),
        (
            "A30 G regions at W = 2.6 m, θ = 90° (5 cm cells)",
            q(truck, Junction::L, Some(2.6), &[90.0], 0.05),
        ),
    ]
}
