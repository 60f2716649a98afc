//! `forkbench plan`: one path, printed as text or JSON, optionally plotted.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

use forkbench_core::{ForkliftSpec, Pose2};
use forkbench_plan::{PlanParams, PlanRequest, PlannerConfig, PlannerKind};
use serde_json::json;

use crate::plot;

#[derive(Debug)]
pub struct PlanArgs {
    pub planner: PlannerKind,
    pub start: Pose2,
    pub goal: Pose2,
    pub start_curvature_per_m: f64,
    pub truck: ForkliftSpec,
    pub cfg: PlannerConfig,
    pub json: bool,
    pub plot: Option<PathBuf>,
}

pub fn run(a: PlanArgs) -> anyhow::Result<()> {
    let req = PlanRequest {
        start: a.start,
        goal: a.goal,
        start_curvature_per_m: a.start_curvature_per_m,
        truck: a.truck.clone(),
    };
    let t0 = Instant::now();
    let plan = forkbench_plan::plan(a.planner, &req, &a.cfg)?;
    let solve_time_us = t0.elapsed().as_secs_f64() * 1e6;
    let m = plan.path.metrics(&a.start, &a.goal, &a.truck);
    if let Some(file) = &a.plot {
        let polygon = match &plan.params {
            PlanParams::Bspline {
                control_points_m, ..
            } => Some(control_points_m.to_vec()),
            PlanParams::Spiral(_) => None,
        };
        let title = format!("{} plan", a.planner);
        plot::draw_plans(
            file,
            &title,
            &[plot::Series {
                label: a.planner.to_string(),
                path: &plan.path,
                control_polygon: polygon,
            }],
            &a.truck,
        )?;
    }
    if a.json {
        let pose = |p: &Pose2| json!({"x_m": p.x_m, "y_m": p.y_m, "heading_rad": p.heading_rad});
        let out = json!({
            "planner": a.planner.name(),
            "start": pose(&a.start),
            "goal": pose(&a.goal),
            "start_curvature_per_m": a.start_curvature_per_m,
            "params": plan.params,
            "cost": plan.cost,
            "max_curvature_per_m": m.max_abs_curvature_per_m,
            "max_steer_rad": m.max_steer_rad,
            "length_m": m.length_m,
            "endpoint_error_m": m.endpoint_position_error_m,
            "endpoint_heading_error_rad": m.endpoint_heading_error_rad,
            "max_curvature_jump_per_m": m.max_curvature_jump_per_m,
            "solve_time_us": solve_time_us,
            "samples": plan.path.samples,
        });
        return crate::emit(&format!("{out}\n"));
    }
    let mut s = String::new();
    let _ = writeln!(s, "planner              {}", a.planner);
    match &plan.params {
        PlanParams::Bspline { l1_m, l2_m, .. } => {
            let _ = writeln!(s, "handles L1, L2       {l1_m:.4} m, {l2_m:.4} m");
        }
        PlanParams::Spiral(p) => {
            let _ = writeln!(
                s,
                "spiral (normalised)  a={:.5} b={:.5} c={:.5} d={:.5} e={:.5} s_f={:.5}",
                p.a, p.b, p.c, p.d, p.e, p.sf
            );
            let _ = writeln!(s, "scale R, mirrored    {:.4} m, {}", p.scale_m, p.mirrored);
            let _ = writeln!(s, "cost ∫½κ² (norm.)    {:.6}", plan.cost);
        }
    }
    let _ = writeln!(s, "length               {:.4} m", m.length_m);
    let _ = writeln!(
        s,
        "max |κ|              {:.6} m⁻¹ (κ_max {:.4})",
        m.max_abs_curvature_per_m,
        a.truck.max_curvature_per_m()
    );
    let _ = writeln!(
        s,
        "max steering         {:.4} rad ({:.2}°; α_max {:.4} rad)",
        m.max_steer_rad,
        m.max_steer_rad.to_degrees(),
        a.truck.max_steer_rad
    );
    let _ = writeln!(
        s,
        "endpoint error       {:.3e} m, {:.3e} rad",
        m.endpoint_position_error_m, m.endpoint_heading_error_rad
    );
    let _ = writeln!(
        s,
        "samples              {} (≤ {:.3} m apart)",
        plan.path.samples.len(),
        m.max_sample_spacing_m
    );
    let _ = writeln!(s, "solve time           {solve_time_us:.0} µs");
    if let Some(file) = &a.plot {
        let _ = writeln!(s, "plot                 {}", file.display());
    }
    crate::emit(&s)
}
