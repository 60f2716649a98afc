//! A mission's legs and totals as a text table (the totals themselves are `forkbench_trial::MissionSummary`).

use forkbench_trial::text::one_line;
use forkbench_trial::{MissionSummary, TrialOutcome};

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
        "leg                              ok   reverse  planned  plan time  clearance  collisions  cross-track mean/max  time     no fix  fix gap  loc err  smoothing\n",
    );
    for l in &out.legs {
        s += &format!(
            "{:<32} {:<4} {:<8} {:<8} {:<10} {:<10} {:<11} {:<21} {:<8} {:<7} {:<8} {:<8} {}\n",
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
            l.fixes_missed,
            num(l.largest_fix_gap_s, "s"),
            num(1e3 * l.localization_error_max_m, "mm"),
            one_line(l.failure_detail.as_deref().unwrap_or(&l.smoothing)),
        );
    }
    let Some(o) = MissionSummary::of(out) else {
        return s;
    };
    let next = if o.legs_done == o.legs {
        "the pick follows"
    } else {
        "a leg failed, so the trial ends without the pick"
    };
    s += &format!(
        "legs: {} of {} done, {:.1} m driven in {:.1} s; {next}\n\n",
        o.legs_done, o.legs, o.driven_m, o.legs_time_s
    );
    s
}
