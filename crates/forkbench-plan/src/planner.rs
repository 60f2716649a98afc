//! The `Planner` trait every pick planner implements, and the two published planners behind it.

use forkbench_core::settings::{self, Settings, SettingsError};

use crate::{BsplineConfig, Plan, PlanError, PlanRequest, SpiralConfig, bspline, spiral};

/// A pose-to-pose pick planner: a forward path of the fork root from the request's start
/// to its goal. One instance serves one worker thread, trial after trial.
pub trait Planner: Send {
    /// The name results are reported under.
    fn name(&self) -> &str;

    /// Plans one path; a typed error when there is none.
    fn plan(&mut self, req: &PlanRequest) -> Result<Plan, PlanError>;
}

/// Lü et al.'s cubic B-spline, optimised for least max |κ|.
#[derive(Debug, Clone, Default)]
pub struct BsplinePlanner {
    pub cfg: BsplineConfig,
    /// Near the pallet (replans) the paper's 1.5 m handle bound cannot fit the chord:
    /// relax it to a third of the start–goal distance there.
    pub relax_handles_near_goal: bool,
}

impl BsplinePlanner {
    /// From a scenario's `[planner]` table: [`BsplineConfig`]'s fields and
    /// `relax_handles_near_goal` (default true).
    pub fn from_settings(s: &Settings) -> Result<Self, SettingsError> {
        let mut s = s.clone();
        let relax = match s.remove("relax_handles_near_goal") {
            None => true,
            Some(toml::Value::Boolean(b)) => b,
            Some(_) => {
                return Err(SettingsError::field(
                    "relax_handles_near_goal",
                    "must be true or false",
                ));
            }
        };
        let cfg: BsplineConfig = settings::parse(&s).map_err(|mut e| {
            if e.reason.contains("expected one of") {
                e.reason.push_str(", `relax_handles_near_goal`");
            }
            e
        })?;
        cfg.validate()?;
        Ok(Self {
            cfg,
            relax_handles_near_goal: relax,
        })
    }
}

impl Planner for BsplinePlanner {
    fn name(&self) -> &str {
        "bspline"
    }

    fn plan(&mut self, req: &PlanRequest) -> Result<Plan, PlanError> {
        let mut cfg = self.cfg.clone();
        if self.relax_handles_near_goal {
            let chord = req.start.distance_to(&req.goal);
            cfg.min_handle_m = cfg.min_handle_m.min(chord / 3.0).max(0.05);
        }
        bspline::plan(req, &cfg).map(bspline::BsplinePlan::into_plan)
    }
}

/// Shen et al.'s quartic polynomial spiral, optimised for least bending energy.
#[derive(Debug, Clone, Default)]
pub struct SpiralPlanner {
    pub cfg: SpiralConfig,
}

impl SpiralPlanner {
    /// From a scenario's `[planner]` table: [`SpiralConfig`]'s fields.
    pub fn from_settings(s: &Settings) -> Result<Self, SettingsError> {
        let cfg: SpiralConfig = settings::parse(s)?;
        cfg.validate()?;
        Ok(Self { cfg })
    }
}

impl Planner for SpiralPlanner {
    fn name(&self) -> &str {
        "spiral"
    }

    fn plan(&mut self, req: &PlanRequest) -> Result<Plan, PlanError> {
        spiral::plan(req, &self.cfg).map(spiral::SpiralPlan::into_plan)
    }
}
