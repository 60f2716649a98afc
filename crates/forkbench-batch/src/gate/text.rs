//! The gate's report in words: the Markdown table `regress` prints, and each row's numbers for JUnit and HTML.

use super::{GateReport, Pairing, RegressRow, Verdict};
use crate::summary::mode_name;
use forkbench_trial::text::md_cell;

fn pct(v: f64) -> String {
    format!("{:.1} %", 100.0 * v)
}

impl RegressRow {
    /// "7 broke / 2 fixed of 360 pairs", or "unpaired".
    pub fn pairs_text(&self) -> String {
        self.paired.map_or_else(
            || "unpaired".to_owned(),
            |c| format!("{} broke / {} fixed of {} pairs", c.broke, c.fixed, c.pairs),
        )
    }

    /// The drop this row sees with 80 % power, in percentage points.
    pub fn detectable_text(&self) -> String {
        match (self.p_value, self.detectable_drop) {
            (None, _) => "–".to_owned(),
            (Some(_), Some(d)) => format!("{:.1} pp", 100.0 * d),
            (Some(_), None) => "none (too few trials)".to_owned(),
        }
    }

    /// Everything a reviewer needs about this row, in one line.
    pub fn numbers(&self, report: &GateReport) -> String {
        let base = self.baseline_rate.map_or("–".to_owned(), |v| {
            format!("{} (n={})", pct(v), self.baseline_trials)
        });
        let now = self.now_rate.map_or("missing".to_owned(), |v| {
            format!("{} (n={})", pct(v), self.now_trials)
        });
        let p = match (self.p_value, self.p_adjusted) {
            (Some(p), Some(a)) => format!(
                ", p = {p:.4}, adjusted p = {a:.4} ({}), α = {}",
                report.correction.name(),
                report.alpha
            ),
            _ => String::new(),
        };
        let need = self.trials_needed.map_or(String::new(), |n| {
            format!(", needs {n} trials for the asked drop")
        });
        format!(
            "baseline {base}, now {now}, {}{p}, detectable drop {}{need}",
            self.pairs_text(),
            self.detectable_text()
        )
    }
}

impl GateReport {
    /// The pairing in one sentence.
    pub fn pairing_text(&self) -> String {
        match &self.pairing {
            Pairing::Paired { pairs } => format!(
                "Paired on common random numbers: {pairs} trials matched by key and seed; each \
                 row is McNemar's exact test on the trials that changed outcome."
            ),
            Pairing::Unpaired { reason } => format!(
                "UNPAIRED: {reason}. Each row is compared as two independent samples \
                 (one-sided two-proportion z-test), which needs many more trials to see the \
                 same drop."
            ),
        }
    }

    /// The verdict in one line.
    pub fn verdict_text(&self) -> String {
        let failed: Vec<&RegressRow> = self
            .rows
            .iter()
            .filter(|r| !matches!(r.verdict, Verdict::Ok | Verdict::New))
            .collect();
        let new = self
            .rows
            .iter()
            .filter(|r| r.verdict == Verdict::New)
            .count();
        let new_text = if new > 0 {
            format!("; {new} new rows unchecked (not in the baseline)")
        } else {
            String::new()
        };
        if self.passed {
            format!("PASSED: no significant drop{new_text}")
        } else if failed.is_empty() {
            format!("REGRESSION: new rows with --fail-on-new{new_text}")
        } else {
            let names: Vec<String> = failed
                .iter()
                .map(|r| format!("{} / {} ({})", r.scenario, r.planner, r.verdict.name()))
                .collect();
            format!(
                "REGRESSION: {} rows failed: {}{new_text}",
                failed.len(),
                names.join(", ")
            )
        }
    }

    /// The report as Markdown: pairing, the table, how to read it, the verdict.
    pub fn markdown(&self) -> String {
        let mut s = format!("{}\n\n", self.pairing_text());
        for d in &self.setting_differences {
            s.push_str(&format!(
                "Settings differ from the baseline's batch: {}\n\n",
                md_cell(d)
            ));
        }
        s.push_str(
            "| scenario | planner | tracker | mode | baseline | now | broke / fixed | p (drop) | p adjusted | detectable drop | verdict |\n|---|---|---|---|---|---|---|---|---|---|---|\n",
        );
        for r in &self.rows {
            let rate = |v: Option<f64>, n: u64| {
                v.map_or("–".to_owned(), |v| format!("{} (n={n})", pct(v)))
            };
            let pairs = r.paired.map_or("unpaired".to_owned(), |c| {
                format!("{} / {} of {}", c.broke, c.fixed, c.pairs)
            });
            let p = |v: Option<f64>| v.map_or("–".to_owned(), |p| format!("{p:.4}"));
            let mut verdict = r.verdict.name().to_owned();
            if r.verdict == Verdict::Underpowered {
                verdict.push_str(&r.trials_needed.map_or_else(
                    || " (no trial count is enough against this baseline)".to_owned(),
                    |n| format!(" (needs {n})"),
                ));
            }
            s.push_str(&format!(
                "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
                md_cell(&r.scenario),
                md_cell(&r.planner),
                md_cell(&r.tracker),
                r.replan.map_or("any", mode_name),
                rate(r.baseline_rate, r.baseline_trials),
                rate(r.now_rate, r.now_trials),
                pairs,
                p(r.p_value),
                p(r.p_adjusted),
                r.detectable_text(),
                verdict
            ));
        }
        s.push_str(&format!(
            "\nα = {} over the {} tested rows, {} correction. broke / fixed: trials that passed \
             in the baseline and fail now, and the reverse, at the same seed. detectable drop: \
             the smallest drop this row sees with 80 % power at level α/m = {:.4} (paired: at \
             the discordance seen now, at least the drop itself). A row fails on adjusted p < α, \
             a rate below the floor, a missing row, or too few trials for \
             --min-detectable-drop.\n\n{}\n",
            self.alpha,
            self.rows.iter().filter(|r| r.p_value.is_some()).count(),
            self.correction.name(),
            self.power_level,
            self.verdict_text()
        ));
        s
    }
}
