//! What a finished batch says beyond its table: rows below a floor, and rows that look like a broken setup.

use crate::{Summary, SummaryRow, mode_name};

impl SummaryRow {
    /// `scenario / planner / tracker / mode`, on one line.
    pub fn name(&self) -> String {
        forkbench_trial::text::one_line(&format!(
            "{} / {} / {} / {}",
            self.scenario,
            self.planner,
            self.tracker,
            mode_name(self.replan)
        ))
    }
}

impl Summary {
    /// The rows whose success rate is below `floor`, named with their rate.
    pub fn below_floor(&self, floor: Option<f64>) -> Vec<String> {
        let Some(f) = floor else {
            return Vec::new();
        };
        self.rows
            .iter()
            .filter(|r| r.success_rate < f)
            .map(|r| format!("{} ({:.1} %)", r.name(), 100.0 * r.success_rate))
            .collect()
    }

    /// A warning per row none of whose trials succeeded, all for one reason: more often a
    /// broken setup (an external planner's traceback, a missing interpreter) than a result.
    pub fn dead_rows(&self) -> Vec<String> {
        self.rows
            .iter()
            .filter(|r| r.successes == 0 && r.failures.len() == 1)
            .map(|r| {
                let (failure, n) = r
                    .failures
                    .iter()
                    .next()
                    .map_or(("?", 0), |(f, n)| (f.as_str(), *n));
                format!(
                    "every trial of {} failed with {failure} ({n} of {}); see a trial's \
                     failure_detail in trials.jsonl or replay one",
                    r.name(),
                    r.trials
                )
            })
            .collect()
    }
}
