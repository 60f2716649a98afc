//! The cost of safety per summary row: protective stops, false trips, warning slowdowns and the time they take, contacts with people, and how close the truck came to them.

use forkbench_trial::SafetyOutcome;
use serde::{Deserialize, Serialize};

use crate::stats::percentile_sorted;

/// A row's safety figures, over its trials that had people or a safety function.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SafetySummary {
    pub trials: u64,
    /// Trials in which the moving truck touched a person or vehicle.
    pub trials_with_contact: u64,
    /// Means per trial.
    pub stops_per_trial: f64,
    pub false_trips_per_trial: f64,
    pub stop_time_per_trial_s: f64,
    pub slowdowns_per_trial: f64,
    pub slowdown_time_per_trial_s: f64,
    /// The least gap to any person or vehicle per trial: the smallest, and the median.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub closest_min_m: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub closest_median_m: Option<f64>,
}

impl SafetySummary {
    /// The figures as both the markdown and the HTML tables show them, in their column
    /// order: trials, with a contact, stops, false trips, stopped, slowdowns, slowed,
    /// closest min / median.
    pub fn cells(&self) -> [String; 8] {
        let m = |v: Option<f64>| v.map_or("–".to_owned(), |v| format!("{v:.2}"));
        [
            self.trials.to_string(),
            self.trials_with_contact.to_string(),
            format!("{:.2}", self.stops_per_trial),
            format!("{:.2}", self.false_trips_per_trial),
            format!("{:.1}", self.stop_time_per_trial_s),
            format!("{:.2}", self.slowdowns_per_trial),
            format!("{:.1}", self.slowdown_time_per_trial_s),
            format!("{} / {}", m(self.closest_min_m), m(self.closest_median_m)),
        ]
    }
}

/// Tallies while records are read.
#[derive(Debug, Default)]
pub(crate) struct SafetyAcc {
    n: u64,
    contacts: u64,
    stops: u64,
    false_trips: u64,
    slowdowns: u64,
    stop_s: Vec<f64>,
    slow_s: Vec<f64>,
    closest: Vec<f64>,
}

impl SafetyAcc {
    pub(crate) fn add(&mut self, s: &SafetyOutcome) {
        self.n += 1;
        self.contacts += u64::from(s.person_contacts > 0);
        self.stops += u64::from(s.stops);
        self.false_trips += u64::from(s.false_trips);
        self.slowdowns += u64::from(s.slowdowns);
        self.stop_s.push(s.stop_time_s);
        self.slow_s.push(s.slowdown_time_s);
        self.closest.extend(s.closest_any_m());
    }

    /// The row's figures (none when no trial had people or fields).
    pub(crate) fn finish(mut self) -> Option<SafetySummary> {
        if self.n == 0 {
            return None;
        }
        let n = self.n as f64;
        // Sorted before summing, so the figures do not depend on the records' order.
        for v in [&mut self.stop_s, &mut self.slow_s, &mut self.closest] {
            v.sort_by(f64::total_cmp);
        }
        Some(SafetySummary {
            trials: self.n,
            trials_with_contact: self.contacts,
            stops_per_trial: self.stops as f64 / n,
            false_trips_per_trial: self.false_trips as f64 / n,
            stop_time_per_trial_s: self.stop_s.iter().sum::<f64>() / n,
            slowdowns_per_trial: self.slowdowns as f64 / n,
            slowdown_time_per_trial_s: self.slow_s.iter().sum::<f64>() / n,
            closest_min_m: self.closest.first().copied(),
            closest_median_m: percentile_sorted(&self.closest, 0.5),
        })
    }
}

/// The safety table as markdown (empty when no row had people or fields).
pub(crate) fn markdown(rows: &[crate::SummaryRow]) -> String {
    let with: Vec<_> = rows
        .iter()
        .filter_map(|r| r.safety.as_ref().map(|s| (r, s)))
        .collect();
    if with.is_empty() {
        return String::new();
    }
    let mut s = String::from(
        "\nSafety (people and safety fields; per trial: means)\n\n| scenario | planner | mode | trials | with a contact | stops | false trips | stopped (s) | slowdowns | slowed (s) | closest min / median (m) |\n|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for (r, x) in with {
        s.push_str(&format!(
            "| {} | {} | {} | {} |\n",
            forkbench_trial::text::md_cell(&r.scenario),
            forkbench_trial::text::md_cell(&r.planner),
            crate::mode_name(r.replan),
            x.cells().join(" | "),
        ));
    }
    s
}
