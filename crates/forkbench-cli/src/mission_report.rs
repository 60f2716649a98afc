//! A mission's legs as a text table and its overall figures as JSON.

use forkbench_trial::TrialOutcome;
use forkbench_trial::text::one_line;
use serde_json::json;

/// One line per leg, then the totals; empty for a pick trial.
pub fn legs_text(out: &TrialOutcome) -> String {
    if out.legs.is_empty() {
        return String::new();
    }
    let num = |v: f64, unit: &str| {
        if v.is_finite() {
            format!("{v:.2} {unit}")
        } else {
            "–".to_owned()
        }
    };
    let mut s = String::from(
        "leg                              ok   reverse  planned  plan time  clearance  collisions  cross-track mean/max  time     smoothing\n",
    );
    for l in &out.legs {
        s += &format!(
            "{:<32} {:<4} {:<8} {:<8} {:<10} {:<10} {:<11} {:<21} {:<8} {}\n",
            one_line(&l.name),
            if l.success { "yes" } else { "NO" },
            num(l.reverse_length_m, "m"),
            num(l.planned_length_m, "m"),
            format!("{:.1} ms", 1e3 * l.planning_time_s),
            num(l.min_clearance_m, "m"),
            l.collisions,
            format!(
                "{} / {}",
                num(1e3 * l.cross_track_mean_m, "mm"),
                num(1e3 * l.cross_track_max_m, "mm")
            ),
            num(l.time_s, "s"),
            one_line(l.failure_detail.as_deref().unwrap_or(&l.smoothing)),
        );
    }
    let o = overall_json(out);
    let next = if o["legs_done"] == o["legs"] {
        "the pick follows"
    } else {
        "a leg failed, so the trial ends without the pick"
    };
    s += &format!(
        "legs: {} of {} done, {:.1} m driven in {:.1} s; {next}\n\n",
        o["legs_done"],
        o["legs"],
        o["driven_m"].as_f64().unwrap_or(f64::NAN),
        o["legs_time_s"].as_f64().unwrap_or(f64::NAN)
    );
    s
}

/// Totals over the legs and the mission's verdict.
pub fn overall_json(out: &TrialOutcome) -> serde_json::Value {
    let done = out.legs.iter().filter(|l| l.success).count();
    let driven: f64 = out
        .legs
        .iter()
        .map(|l| {
            l.reverse_length_m
                + if l.planned_length_m.is_finite() {
                    l.planned_length_m
                } else {
                    0.0
                }
        })
        .sum();
    let min_clearance = out
        .legs
        .iter()
        .map(|l| l.min_clearance_m)
        .filter(|v| v.is_finite())
        .fold(f64::INFINITY, f64::min);
    json!({
        "legs": out.legs.len(),
        "legs_done": done,
        "driven_m": driven,
        "legs_time_s": out.legs.iter().map(|l| l.time_s).sum::<f64>(),
        "planning_time_s": out.legs.iter().map(|l| l.planning_time_s).sum::<f64>(),
        "min_clearance_m": min_clearance.is_finite().then_some(min_clearance),
        "collisions": out.legs.iter().map(|l| l.collisions).sum::<u32>(),
        "cross_track_max_m": out.legs.iter().map(|l| l.cross_track_max_m).filter(|v| v.is_finite()).fold(0.0, f64::max),
        "pick_success": out.success,
        "success": out.success && done == out.legs.len(),
    })
}
