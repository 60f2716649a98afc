//! A pick planner written in Rust against forkbench's `Planner` trait, registered by name
//! and run in a batch beside the built-in planners.
//!
//! `cargo run --release -p forkbench-batch --example rust_planner` (results in
//! recordings/rust-planner/). A scenario then names it like any other planner:
//! `[planner] kind = "bezier"` with `handle_fraction = 0.4`.

use std::path::Path;
use std::sync::Arc;

use forkbench_batch::{BatchSpec, run_batch};
use forkbench_core::settings::{self, Settings, SettingsError};
use forkbench_core::{Path as PlanPath, PathSample};
use forkbench_plan::{Plan, PlanError, PlanParams, PlanRequest, Planner};
use forkbench_trial::{Registry, Scenario};
use serde::Deserialize;

/// A cubic Bézier from the start pose to the goal pose, handles a fixed fraction of the
/// start–goal distance long.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BezierPlanner {
    pub handle_fraction: f64,
}

impl Default for BezierPlanner {
    fn default() -> Self {
        Self {
            handle_fraction: 0.4,
        }
    }
}

impl BezierPlanner {
    pub fn from_settings(s: &Settings) -> Result<Self, SettingsError> {
        let p: BezierPlanner = settings::parse(s)?;
        if !(p.handle_fraction > 0.0 && p.handle_fraction < 1.0) {
            return Err(SettingsError::field(
                "handle_fraction",
                "must lie in (0, 1)",
            ));
        }
        Ok(p)
    }
}

impl Planner for BezierPlanner {
    fn name(&self) -> &str {
        "bezier"
    }

    fn plan(&mut self, req: &PlanRequest) -> Result<Plan, PlanError> {
        req.validate()?;
        let (a, b) = (req.start, req.goal);
        let h = self.handle_fraction * a.distance_to(&b);
        let p = [
            [a.x_m, a.y_m],
            [
                a.x_m + h * a.heading_rad.cos(),
                a.y_m + h * a.heading_rad.sin(),
            ],
            [
                b.x_m - h * b.heading_rad.cos(),
                b.y_m - h * b.heading_rad.sin(),
            ],
            [b.x_m, b.y_m],
        ];
        let path = sample(&p, 0.01);
        let worst = path
            .samples
            .iter()
            .map(|s| s.curvature_per_m.abs())
            .fold(0.0, f64::max);
        if worst > req.truck.max_curvature_per_m() {
            return Err(PlanError::Unreachable {
                planner: "bezier".into(),
                reason: format!("needs |κ| {worst:.3} m⁻¹ > κ_max"),
            });
        }
        Ok(Plan {
            planner: "bezier".into(),
            params: PlanParams::Other(serde_json::json!({ "handle_m": h })),
            cost: worst,
            control_polygon_m: Some(p.to_vec()),
            path,
        })
    }
}

/// Samples the Bézier at about `spacing_m` of arc length, with heading and curvature.
fn sample(p: &[[f64; 2]; 4], spacing_m: f64) -> PlanPath {
    let at = |u: f64| {
        let v = 1.0 - u;
        let w = [v * v * v, 3.0 * v * v * u, 3.0 * v * u * u, u * u * u];
        let d1 = [
            -3.0 * v * v,
            3.0 * v * v - 6.0 * u * v,
            6.0 * u * v - 3.0 * u * u,
            3.0 * u * u,
        ];
        let d2 = [6.0 * v, 6.0 * u - 12.0 * v, 6.0 * v - 12.0 * u, 6.0 * u];
        let comb = |c: [f64; 4], k: usize| (0..4).map(|i| c[i] * p[i][k]).sum::<f64>();
        let (x1, y1, x2, y2) = (comb(d1, 0), comb(d1, 1), comb(d2, 0), comb(d2, 1));
        let kappa = (x1 * y2 - y1 * x2) / (x1 * x1 + y1 * y1).powf(1.5);
        (comb(w, 0), comb(w, 1), y1.atan2(x1), kappa)
    };
    let n = 20_000;
    let mut samples: Vec<PathSample> = Vec::new();
    let (mut s, mut last) = (0.0, at(0.0));
    for i in 0..=n {
        let q = at(i as f64 / n as f64);
        s += (q.0 - last.0).hypot(q.1 - last.1);
        last = q;
        if i == 0 || i == n || s - samples.last().map_or(0.0, |p| p.s_m) >= spacing_m {
            samples.push(PathSample {
                s_m: s,
                x_m: q.0,
                y_m: q.1,
                heading_rad: q.2,
                curvature_per_m: q.3,
            });
        }
    }
    // Headings unwrapped, as every forkbench path has them.
    for i in 1..samples.len() {
        let d =
            forkbench_core::units::wrap_angle(samples[i].heading_rad - samples[i - 1].heading_rad);
        samples[i].heading_rad = samples[i - 1].heading_rad + d;
    }
    PlanPath::new(samples)
}

/// The built-in components plus this planner: the one line that adds it.
pub fn registry() -> Registry {
    Registry::builtin().with_planner("bezier", |s, _| {
        Ok(Box::new(BezierPlanner::from_settings(s)?))
    })
}

#[allow(dead_code)]
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let scn = Scenario::load_with(
        &root.join("scenarios/field-test.toml"),
        Arc::new(registry()),
    )?;
    let spec = BatchSpec {
        scenarios: vec![scn],
        planners: vec!["bezier".into(), "bspline".into()],
        trackers: vec![],
        trials: 50,
        seed: 1,
        shard: (0, 1),
        overrides: Default::default(),
        replan: None,
        compare_replanning: false,
        force_new: true,
        success_run: Default::default(),
        profile: false,
    };
    let summary = run_batch(&spec, &root.join("recordings/rust-planner"), 2, &|_| {})?;
    print!("{}", summary.markdown());
    Ok(())
}
