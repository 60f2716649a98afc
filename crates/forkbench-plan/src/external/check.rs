//! The contract every returned path must meet: finite, dense, from the start to the goal, within κ_max.

use forkbench_core::Path;
use forkbench_core::units::wrap_angle;

use crate::PlanRequest;

/// How far a path's first sample may lie from the start pose, and its last from the goal.
pub const ENDPOINT_TOLERANCE_M: f64 = 0.01;
/// The same for heading.
pub const ENDPOINT_TOLERANCE_RAD: f64 = 0.0175;
/// Largest spacing between samples: the tracker and the footprint check read the path
/// between samples as straight.
pub const MAX_SPACING_M: f64 = 0.05;
/// Relative slack on the curvature limit (rounding in the planner's own arithmetic).
const CURVATURE_SLACK: f64 = 1e-3;

/// Why `path` breaks the contract for `req`, if it does.
pub fn path_violation(path: &Path, req: &PlanRequest) -> Option<String> {
    let n = path.samples.len();
    if n < 2 {
        return Some(format!("the path has {n} samples; at least 2 are needed"));
    }
    if let Some(i) = path.samples.iter().position(|p| {
        ![p.s_m, p.x_m, p.y_m, p.heading_rad, p.curvature_per_m]
            .iter()
            .all(|v| v.is_finite())
    }) {
        return Some(format!(
            "sample {i} has a non-finite value (NaN or infinity)"
        ));
    }
    spacing_violation(path)
        .or_else(|| endpoint_violation(path, req))
        .or_else(|| curvature_violation(path, req))
}

fn spacing_violation(path: &Path) -> Option<String> {
    let first = path.samples[0].s_m;
    if first.abs() > 1e-6 {
        return Some(format!("the first sample's s is {first} m; it must be 0"));
    }
    path.samples.windows(2).enumerate().find_map(|(i, w)| {
        let ds = w[1].s_m - w[0].s_m;
        let step = (w[1].x_m - w[0].x_m).hypot(w[1].y_m - w[0].y_m);
        if ds <= 0.0 {
            Some(format!("s does not increase at sample {}", i + 1))
        } else if step > MAX_SPACING_M {
            Some(format!(
                "samples {i} and {} are {step:.3} m apart (at most {MAX_SPACING_M} m)",
                i + 1
            ))
        } else {
            None
        }
    })
}

fn endpoint_violation(path: &Path, req: &PlanRequest) -> Option<String> {
    let ends = [
        ("start", path.samples[0].pose(), req.start),
        (
            "goal",
            path.samples[path.samples.len() - 1].pose(),
            req.goal,
        ),
    ];
    ends.iter().find_map(|(what, got, want)| {
        let off = got.distance_to(want);
        let turn = wrap_angle(got.heading_rad - want.heading_rad).abs();
        (off > ENDPOINT_TOLERANCE_M || turn > ENDPOINT_TOLERANCE_RAD).then(|| {
            format!(
                "the path does not {} the {what}: {off:.3} m and {:.2}° off (tolerance \
                 {ENDPOINT_TOLERANCE_M} m, {:.1}°)",
                if *what == "start" {
                    "start at"
                } else {
                    "end at"
                },
                turn.to_degrees(),
                ENDPOINT_TOLERANCE_RAD.to_degrees()
            )
        })
    })
}

fn curvature_violation(path: &Path, req: &PlanRequest) -> Option<String> {
    let limit = req.truck.max_curvature_per_m();
    let worst = path
        .samples
        .iter()
        .map(|p| p.curvature_per_m.abs())
        .fold(0.0, f64::max);
    if worst > limit * (1.0 + CURVATURE_SLACK) {
        return Some(format!(
            "the path needs |κ| {worst:.4} m⁻¹ > κ_max {limit:.4} m⁻¹"
        ));
    }
    crate::find_cusp(path, limit).map(|s| {
        format!("the path turns back on itself (a cusp {s:.2} m along it), or its headings do not follow its points")
    })
}
