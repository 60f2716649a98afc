//! A manoeuvre that ends in a straight forward approach: planned to the approach's start, the straight checked and appended (or, from inside the approach, the straight alone).

use forkbench_core::units::wrap_angle;
use forkbench_core::{Path, Pose2};

use super::{Body, HybridQuery, Manoeuvre, search::plan_hybrid};
use crate::{NavError, NavMap};

/// Longest straight approach.
pub const MAX_APPROACH_M: f64 = 50.0;
/// Spacing of the straight's samples and checks.
const STEP_M: f64 = 0.05;
/// Within this of the approach line (and heading), the truck is already on it.
const ON_LINE_M: f64 = 0.05;
const ON_LINE_RAD: f64 = 0.05;

pub(super) fn plan_with_approach(map: &NavMap, q: &HybridQuery) -> Result<Manoeuvre, NavError> {
    if !(q.approach_m.is_finite() && (0.0..=MAX_APPROACH_M).contains(&q.approach_m)) {
        return Err(NavError::Params(format!(
            "approach {} m: must lie within 0..{} m",
            q.approach_m, MAX_APPROACH_M
        )));
    }
    let pre = q.goal.to_world(&Pose2::new(-q.approach_m, 0.0, 0.0));
    let body = Body::of(&q.truck, q.margin_m, q.load);
    let straight = Path::straight(&pre, q.approach_m, STEP_M);
    if let Some(p) = straight
        .samples
        .iter()
        .find(|s| !body.free(&map.obstacles, &s.pose()))
    {
        return Err(NavError::Params(format!(
            "no room for the {:.2} m straight approach into the goal: the truck would touch \
             an obstacle at ({:.2}, {:.2}) m",
            q.approach_m, p.x_m, p.y_m
        )));
    }
    // Already on the approach line: the rest of the straight alone.
    let local = q.goal.to_local(&q.start);
    if local.x_m <= 0.0
        && local.x_m >= -q.approach_m - ON_LINE_M
        && local.y_m.abs() <= ON_LINE_M
        && wrap_angle(local.heading_rad).abs() <= ON_LINE_RAD
    {
        let rest = Path::straight(&q.start, -local.x_m, STEP_M);
        return Ok(Manoeuvre {
            length_m: rest.length_m(),
            segments: vec![rest]
                .into_iter()
                .filter(|p| p.samples.len() > 1)
                .collect(),
            expansions: 0,
            time_s: 0.0,
        });
    }
    let mut m = plan_hybrid(
        map,
        &HybridQuery {
            goal: pre,
            approach_m: 0.0,
            ..q.clone()
        },
    )?;
    match m.segments.last_mut() {
        Some(last) if !last.reverse => last.extend_straight(q.approach_m, STEP_M),
        _ => m.segments.push(straight),
    }
    m.length_m = m.segments.iter().map(Path::length_m).sum();
    Ok(m)
}
