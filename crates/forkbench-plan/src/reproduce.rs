//! Reproduces the papers' Table 2 (B-spline and spiral) from the data files under `scenarios/reference/`.

use std::time::Instant;

use forkbench_core::{ForkliftSpec, Pose2};
use serde::{Deserialize, Serialize};

use crate::bspline::{self, BsplineConfig};
use crate::spiral::{self, SpiralConfig, SpiralProblem};
use crate::{Plan, PlanError, PlanRequest};

/// The B-spline reference table as shipped in `scenarios/reference/bspline-table2.toml`.
pub const BSPLINE_TABLE2_TOML: &str = include_str!("../data/reference/bspline-table2.toml");
/// The spiral reference table as shipped in `scenarios/reference/spiral-table2.toml`.
pub const SPIRAL_TABLE2_TOML: &str = include_str!("../data/reference/spiral-table2.toml");

/// A reference table file that could not be read.
#[derive(Debug, thiserror::Error)]
pub enum TableError {
    /// The reason is in the message, not chained as a source: `{:#}` would print it twice.
    #[error("{file}: {cause}")]
    Parse {
        file: String,
        cause: toml::de::Error,
    },
    #[error("{file}: case {case:?}: field `{field}`: {reason}")]
    Invalid {
        file: String,
        case: String,
        field: &'static str,
        reason: String,
    },
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BsplineTable {
    pub paper: String,
    #[serde(deserialize_with = "forkbench_core::exact::array")]
    pub start_mm_deg: [f64; 3],
    pub pick_distance_mm: f64,
    pub case: Vec<BsplineCase>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BsplineCase {
    pub name: String,
    pub lateral_offset_mm: f64,
    pub pallet_angle_deg: f64,
    pub paper_l1_mm: f64,
    pub paper_l2_mm: f64,
    pub paper_max_steer_rad: Option<f64>,
    pub paper_max_abs_curvature_per_mm: Option<f64>,
}

impl BsplineTable {
    pub fn parse(text: &str, file: &str) -> Result<Self, TableError> {
        let t: Self = toml::from_str(text).map_err(|cause| TableError::Parse {
            file: file.to_owned(),
            cause,
        })?;
        for c in &t.case {
            for (field, v) in [
                ("lateral_offset_mm", c.lateral_offset_mm),
                ("pallet_angle_deg", c.pallet_angle_deg),
                ("paper_l1_mm", c.paper_l1_mm),
                ("paper_l2_mm", c.paper_l2_mm),
            ] {
                if !v.is_finite() {
                    return Err(TableError::Invalid {
                        file: file.to_owned(),
                        case: c.name.clone(),
                        field,
                        reason: "must be finite".into(),
                    });
                }
            }
        }
        Ok(t)
    }

    pub fn embedded() -> Self {
        Self::parse(
            BSPLINE_TABLE2_TOML,
            "scenarios/reference/bspline-table2.toml",
        )
        .unwrap_or_else(|e| panic!("embedded table is valid (tested): {e}"))
    }

    pub fn start(&self) -> Pose2 {
        let s = self.start_mm_deg;
        Pose2::new(s[0] / 1000.0, s[1] / 1000.0, s[2].to_radians())
    }

    /// Goal (D, L3, ψ_start + θ) relative to the start pose, as in the paper's frame.
    pub fn goal(&self, c: &BsplineCase) -> Pose2 {
        let start = self.start();
        // "Lateral offset to the right of the truck": with the truck looking along +y,
        // right is +x; expressed in the start frame that is −y.
        let local = Pose2::new(
            self.pick_distance_mm / 1000.0,
            -c.lateral_offset_mm / 1000.0,
            c.pallet_angle_deg.to_radians(),
        );
        start.to_world(&local)
    }
}

/// One row of the B-spline reproduction.
#[derive(Debug, Clone, Serialize)]
pub struct BsplineRow {
    pub name: String,
    pub lateral_offset_m: f64,
    pub pallet_angle_deg: f64,
    pub paper_l1_m: f64,
    pub paper_l2_m: f64,
    /// max |κ| of the paper's (L1, L2), evaluated with this project's code.
    pub paper_max_curvature_per_m: f64,
    pub paper_max_steer_rad: f64,
    /// Figures the paper printed for this row, if any.
    pub reported_max_steer_rad: Option<f64>,
    pub reported_max_curvature_per_m: Option<f64>,
    pub l1_m: f64,
    pub l2_m: f64,
    pub max_curvature_per_m: f64,
    pub max_steer_rad: f64,
    pub start_curvature_per_m: f64,
    pub end_curvature_per_m: f64,
    pub endpoint_error_m: f64,
    pub endpoint_heading_error_rad: f64,
    pub solve_time_us: f64,
}

/// Runs the B-spline planner on every case; returns rows with their plans (for plots).
pub fn reproduce_bspline(
    table: &BsplineTable,
    cfg: &BsplineConfig,
    truck: &ForkliftSpec,
) -> Result<Vec<(BsplineRow, Plan)>, PlanError> {
    let start = table.start();
    table
        .case
        .iter()
        .map(|c| {
            let goal = table.goal(c);
            let mut req = PlanRequest::new(start, goal);
            req.truck = truck.clone();
            let t0 = Instant::now();
            let p = bspline::plan(&req, cfg)?;
            let solve_time_us = t0.elapsed().as_secs_f64() * 1e6;
            let m = p.path.metrics(&start, &goal, truck);
            let (pl1, pl2) = (c.paper_l1_mm / 1000.0, c.paper_l2_mm / 1000.0);
            let paper_k = bspline::max_abs_curvature_for(&start, &goal, pl1, pl2);
            let row = BsplineRow {
                name: c.name.clone(),
                lateral_offset_m: c.lateral_offset_mm / 1000.0,
                pallet_angle_deg: c.pallet_angle_deg,
                paper_l1_m: pl1,
                paper_l2_m: pl2,
                paper_max_curvature_per_m: paper_k,
                paper_max_steer_rad: truck.steer_for_curvature(paper_k),
                reported_max_steer_rad: c.paper_max_steer_rad,
                reported_max_curvature_per_m: c.paper_max_abs_curvature_per_mm.map(|k| k * 1000.0),
                l1_m: p.l1_m,
                l2_m: p.l2_m,
                max_curvature_per_m: p.max_abs_curvature_per_m,
                max_steer_rad: truck.steer_for_curvature(p.max_abs_curvature_per_m),
                start_curvature_per_m: p.path.samples.first().map_or(0.0, |s| s.curvature_per_m),
                end_curvature_per_m: p.path.samples.last().map_or(0.0, |s| s.curvature_per_m),
                endpoint_error_m: m.endpoint_position_error_m,
                endpoint_heading_error_rad: m.endpoint_heading_error_rad,
                solve_time_us,
            };
            Ok((row, p.into_plan()))
        })
        .collect()
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpiralTable {
    pub paper: String,
    pub goal_ahead_m: f64,
    pub case: Vec<SpiralCase>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpiralCase {
    pub name: String,
    pub start_curvature_per_m: f64,
    pub goal_lateral_m: f64,
    pub goal_heading_deg: f64,
    pub paper_b: f64,
    pub paper_c: f64,
    pub paper_sf: f64,
    pub paper_endpoint_error_cm: Option<f64>,
    pub paper_max_curvature_per_m: Option<f64>,
    pub paper_max_steer_rad: Option<f64>,
}

impl SpiralTable {
    pub fn parse(text: &str, file: &str) -> Result<Self, TableError> {
        let t: Self = toml::from_str(text).map_err(|cause| TableError::Parse {
            file: file.to_owned(),
            cause,
        })?;
        for c in &t.case {
            for (field, v) in [
                ("start_curvature_per_m", c.start_curvature_per_m),
                ("goal_lateral_m", c.goal_lateral_m),
                ("goal_heading_deg", c.goal_heading_deg),
                ("paper_b", c.paper_b),
                ("paper_c", c.paper_c),
                ("paper_sf", c.paper_sf),
            ] {
                if !v.is_finite() {
                    return Err(TableError::Invalid {
                        file: file.to_owned(),
                        case: c.name.clone(),
                        field,
                        reason: "must be finite".into(),
                    });
                }
            }
            if c.paper_sf <= 0.0 {
                return Err(TableError::Invalid {
                    file: file.to_owned(),
                    case: c.name.clone(),
                    field: "paper_sf",
                    reason: "must be positive".into(),
                });
            }
        }
        Ok(t)
    }

    pub fn embedded() -> Self {
        Self::parse(SPIRAL_TABLE2_TOML, "scenarios/reference/spiral-table2.toml")
            .unwrap_or_else(|e| panic!("embedded table is valid (tested): {e}"))
    }

    pub fn request(&self, c: &SpiralCase, truck: &ForkliftSpec) -> PlanRequest {
        let mut req = PlanRequest::new(
            Pose2::new(0.0, 0.0, 0.0),
            Pose2::new(
                self.goal_ahead_m,
                c.goal_lateral_m,
                c.goal_heading_deg.to_radians(),
            ),
        );
        req.start_curvature_per_m = c.start_curvature_per_m;
        req.truck = truck.clone();
        req
    }
}

/// One row of the spiral reproduction.
#[derive(Debug, Clone, Serialize)]
pub struct SpiralRow {
    pub name: String,
    pub start_curvature_per_m: f64,
    pub goal_lateral_m: f64,
    pub goal_heading_rad: f64,
    pub paper_b: f64,
    pub paper_c: f64,
    pub paper_sf: f64,
    /// Normalised ∫½κ² of the paper's (b, c, s_f), evaluated with this project's code.
    pub paper_cost: f64,
    pub paper_endpoint_error_m: f64,
    pub paper_max_curvature_per_m: f64,
    pub reported_endpoint_error_m: Option<f64>,
    pub a: f64,
    pub b: f64,
    pub c: f64,
    pub d: f64,
    pub e: f64,
    pub sf: f64,
    /// The length window searched (normalised).
    pub window_lo: f64,
    pub window_hi: f64,
    /// "short end" or "long end" when the optimum sits at a window bound.
    pub sf_at_bound: Option<&'static str>,
    pub cost: f64,
    pub max_curvature_per_m: f64,
    pub max_steer_rad: f64,
    pub endpoint_error_m: f64,
    pub endpoint_heading_error_rad: f64,
    pub solve_time_us: f64,
}

/// Runs the spiral planner on every case; returns rows with their plans (for plots).
pub fn reproduce_spiral(
    table: &SpiralTable,
    cfg: &SpiralConfig,
    truck: &ForkliftSpec,
) -> Result<Vec<(SpiralRow, Plan)>, PlanError> {
    table
        .case
        .iter()
        .map(|c| {
            let req = table.request(c, truck);
            let t0 = Instant::now();
            let p = spiral::plan(&req, cfg)?;
            let solve_time_us = t0.elapsed().as_secs_f64() * 1e6;
            let m = p.path.metrics(&req.start, &req.goal, truck);
            let prob = SpiralProblem::from_request(&req, 0.0);
            let paper = prob.evaluate(c.paper_b, c.paper_c, c.paper_sf);
            let (window_lo, window_hi) = prob.length_window(cfg.enforce_length_window);
            let row = SpiralRow {
                name: c.name.clone(),
                start_curvature_per_m: c.start_curvature_per_m,
                goal_lateral_m: c.goal_lateral_m,
                goal_heading_rad: c.goal_heading_deg.to_radians(),
                paper_b: c.paper_b,
                paper_c: c.paper_c,
                paper_sf: c.paper_sf,
                paper_cost: paper.cost,
                paper_endpoint_error_m: paper.endpoint_error_m,
                paper_max_curvature_per_m: paper.max_abs_curvature_per_m,
                reported_endpoint_error_m: c.paper_endpoint_error_cm.map(|v| v / 100.0),
                a: p.params.a,
                b: p.params.b,
                c: p.params.c,
                d: p.params.d,
                e: p.params.e,
                sf: p.params.sf,
                window_lo,
                window_hi,
                sf_at_bound: spiral::window_bound(p.params.sf, (window_lo, window_hi)),
                cost: p.cost,
                max_curvature_per_m: p.max_abs_curvature_per_m,
                max_steer_rad: truck.steer_for_curvature(p.max_abs_curvature_per_m),
                endpoint_error_m: m.endpoint_position_error_m,
                endpoint_heading_error_rad: m.endpoint_heading_error_rad,
                solve_time_us,
            };
            Ok((row, p.into_plan()))
        })
        .collect()
}
