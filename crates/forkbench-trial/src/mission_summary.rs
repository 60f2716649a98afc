//! A mission's totals over its legs and its verdict, typed, for every front end (the CLI's table and JSON, reports).

use serde::Serialize;

use crate::outcome::TrialOutcome;

/// What a mission did as a whole.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MissionSummary {
    pub legs: usize,
    pub legs_done: usize,
    /// Planned length driven, backing out included.
    pub driven_m: f64,
    pub legs_time_s: f64,
    pub planning_time_s: f64,
    /// Smallest clearance of any leg; `None` when no leg got a path.
    pub min_clearance_m: Option<f64>,
    pub collisions: u32,
    pub cross_track_max_m: f64,
    pub pick_success: bool,
    /// Every leg done and the pick entered.
    pub success: bool,
}

impl MissionSummary {
    /// The totals of `out`'s legs; `None` for a pick trial.
    pub fn of(out: &TrialOutcome) -> Option<Self> {
        if out.legs.is_empty() {
            return None;
        }
        let legs = &out.legs;
        let finite_or_0 = |v: f64| if v.is_finite() { v } else { 0.0 };
        let min_clearance = legs
            .iter()
            .map(|l| l.min_clearance_m)
            .filter(|v| v.is_finite())
            .fold(f64::INFINITY, f64::min);
        let legs_done = legs.iter().filter(|l| l.success).count();
        Some(Self {
            legs: legs.len(),
            legs_done,
            driven_m: legs
                .iter()
                .map(|l| l.reverse_length_m + finite_or_0(l.planned_length_m))
                .sum(),
            legs_time_s: legs.iter().map(|l| l.time_s).sum(),
            planning_time_s: legs.iter().map(|l| l.planning_time_s).sum(),
            min_clearance_m: min_clearance.is_finite().then_some(min_clearance),
            collisions: legs.iter().map(|l| l.collisions).sum(),
            cross_track_max_m: legs
                .iter()
                .map(|l| l.cross_track_max_m)
                .filter(|v| v.is_finite())
                .fold(0.0, f64::max),
            pick_success: out.success,
            success: out.success && legs_done == legs.len(),
        })
    }
}
