//! Quartic polynomial-spiral pick planner (Shen et al. 2022): exact endpoint, minimum ∫½κ² over the free length.

mod newton;
mod problem;
mod search;

pub use problem::{SpiralEvaluation, SpiralProblem};

use forkbench_core::units::wrap_angle;
use forkbench_core::{Path, PathSample, Pose2};
use serde::{Deserialize, Serialize};

use crate::numeric::sin_cos;
use crate::{Plan, PlanError, PlanParams, PlanRequest};
use search::LengthSearch;

/// Settings of the spiral planner.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SpiralConfig {
    /// Keep the paper's empirical window 1 + θ²/5 ≤ s_f ≤ 2 + θ²/5 (normalised);
    /// when false the window widens to 1 ≤ s_f ≤ 3 + θ².
    pub enforce_length_window: bool,
    /// Lengths tried across the window before the local refinement.
    pub length_grid_points: usize,
    /// Largest arc-length spacing of the output samples.
    pub sample_spacing_m: f64,
}

impl Default for SpiralConfig {
    fn default() -> Self {
        Self {
            enforce_length_window: true,
            length_grid_points: 12,
            sample_spacing_m: 0.01,
        }
    }
}

/// Coefficients of κ(s) = a + b s + c s² + d s³ + e s⁴ on the normalised problem.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SpiralParams {
    pub a: f64,
    pub b: f64,
    pub c: f64,
    pub d: f64,
    pub e: f64,
    pub sf: f64,
    /// R: the start–goal distance that normalises the problem onto the unit circle.
    pub scale_m: f64,
    /// The goal lay on the −y side of the start frame and the problem was mirrored.
    pub mirrored: bool,
}

impl SpiralParams {
    pub fn curvature(&self, s: f64) -> f64 {
        (((self.e * s + self.d) * s + self.c) * s + self.b) * s + self.a
    }

    pub fn heading(&self, s: f64) -> f64 {
        ((((self.e / 5.0 * s + self.d / 4.0) * s + self.c / 3.0) * s + self.b / 2.0) * s + self.a)
            * s
    }
}

/// Result of the spiral planner.
#[derive(Debug, Clone, PartialEq)]
pub struct SpiralPlan {
    pub params: SpiralParams,
    /// Normalised ∫½κ² ds.
    pub cost: f64,
    pub max_abs_curvature_per_m: f64,
    pub path: Path,
    /// Fixed-length Newton solves of the endpoint equations the search used.
    pub newton_solves: usize,
}

impl SpiralPlan {
    pub fn into_plan(self) -> Plan {
        Plan {
            planner: "spiral".into(),
            params: PlanParams::Spiral(self.params),
            cost: self.cost,
            path: self.path,
            control_polygon_m: None,
        }
    }
}

impl SpiralConfig {
    pub(crate) fn validate(&self) -> Result<(), forkbench_core::SettingsError> {
        if self.length_grid_points < 3 {
            return Err(forkbench_core::SettingsError::field(
                "length_grid_points",
                "must be at least 3",
            ));
        }
        if !(self.sample_spacing_m.is_finite()
            && self.sample_spacing_m >= crate::MIN_SAMPLE_SPACING_M)
        {
            return Err(forkbench_core::SettingsError::field(
                "sample_spacing_m",
                format!(
                    "must be a finite length of at least {} m",
                    crate::MIN_SAMPLE_SPACING_M
                ),
            ));
        }
        if self.length_grid_points > 10_000 {
            return Err(forkbench_core::SettingsError::field(
                "length_grid_points",
                "must be at most 10000",
            ));
        }
        forkbench_core::settings::in_ranges(&[(
            "sample_spacing_m",
            self.sample_spacing_m,
            0.0,
            1.0,
        )])
    }
}

/// Plans the spiral: for each length s_f the endpoint is met exactly by Newton on (b, c);
/// the cost ∫½κ² is minimised over s_f in the window (grid with continuation both ways,
/// then Brent's method).
pub fn plan(req: &PlanRequest, cfg: &SpiralConfig) -> Result<SpiralPlan, PlanError> {
    req.validate()?;
    cfg.validate()?;
    let prob = SpiralProblem::from_request(req, 0.0);
    let (lo, hi) = prob.length_window(cfg.enforce_length_window);
    // The paper's window is one normalised length unit wide; wider windows get as many
    // grid lengths per unit, so continuation steps stay as short.
    let per_unit = (cfg.length_grid_points - 1) as f64;
    let m = ((hi - lo) * per_unit).ceil().max(per_unit) as usize + 1;
    let mut search = LengthSearch::new(&prob, (lo, hi), m);
    let (sf, [bb, cc], cost, max_k) = search.run().map_err(|least_k| {
        if least_k.is_finite() {
            PlanError::curvature("spiral", least_k / prob.scale_m, &req.truck)
        } else {
            PlanError::Unreachable {
                planner: "spiral".into(),
                reason: format!(
                    "no quartic spiral of normalised length {lo:.3}–{hi:.3} reaches the goal"
                ),
            }
        }
    })?;
    let params = prob.params(bb, cc, sf);
    let path = sample(&params, &req.start, &req.goal, cfg.sample_spacing_m);
    Ok(SpiralPlan {
        params,
        cost,
        max_abs_curvature_per_m: max_k / prob.scale_m,
        path,
        newton_solves: search.newton_solves,
    })
}

/// Which bound of the length window `sf` sits at ("short end", "long end"), if any:
/// within the refinement's tolerance of it.
pub fn window_bound(sf: f64, (lo, hi): (f64, f64)) -> Option<&'static str> {
    let tol = 1e-4 * (hi - lo);
    if sf <= lo + tol {
        Some("short end")
    } else if sf >= hi - tol {
        Some("long end")
    } else {
        None
    }
}

/// Dense world-frame samples of a normalised spiral, ≤ `spacing_m` apart.
///
/// x and y advance by the Euler–Maclaurin-corrected trapezoid
/// ∫f ≈ h/2 (f₀ + f₁) + h²/12 (f′₀ − f′₁), with f = cos θ, f′ = −κ sin θ (and likewise
/// for sin θ): O(h⁵) per step like Simpson, but one sin_cos per sample.
pub fn sample(p: &SpiralParams, start: &Pose2, goal: &Pose2, spacing_m: f64) -> Path {
    let r = p.scale_m;
    let sign = if p.mirrored { -1.0 } else { 1.0 };
    let n = ((p.sf * r / spacing_m).ceil() as usize).max(1);
    let h = p.sf / n as f64;
    let (mut x, mut y) = (0.0, 0.0);
    let mut samples = Vec::with_capacity(n + 1);
    // The start frame's rotation, once: `Pose2::to_world` would take a sin_cos per sample.
    let (rot_s, rot_c) = start.heading_rad.sin_cos();
    // Headings and their sines and cosines first, in passes the compiler vectorises;
    // then the running sums.
    let theta: Vec<f64> = (0..=n).map(|i| p.heading(h * i as f64)).collect();
    let sc: Vec<(f64, f64)> = theta.iter().map(|&t| sin_cos(t)).collect();
    let mut prev: Option<(f64, f64, f64)> = None; // (sin θ, cos θ, κ) at the last sample
    for (i, (&theta, &(sn, cs))) in theta.iter().zip(&sc).enumerate() {
        let s = h * i as f64;
        let k = p.curvature(s);
        if let Some((s0, c0, k0)) = prev {
            x += h / 2.0 * (c0 + cs) + h * h / 12.0 * (-k0 * s0 + k * sn);
            y += h / 2.0 * (s0 + sn) + h * h / 12.0 * (k0 * c0 - k * cs);
        }
        prev = Some((sn, cs, k));
        let (lx, ly) = (r * x, sign * r * y);
        samples.push(PathSample {
            s_m: r * s,
            x_m: start.x_m + rot_c * lx - rot_s * ly,
            y_m: start.y_m + rot_s * lx + rot_c * ly,
            // Unwrapped heading: the spiral's θ(s) is continuous by construction.
            heading_rad: start.heading_rad + sign * theta,
            curvature_per_m: sign * k / r,
        });
    }
    if let Some(last) = samples.last_mut() {
        last.heading_rad += wrap_angle(goal.heading_rad - last.heading_rad);
    }
    Path::new(samples)
}
