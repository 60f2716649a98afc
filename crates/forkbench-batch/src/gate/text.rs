//! The gate's report in words: the Markdown table `regress` prints, and each row's numbers for JUnit and HTML.

use super::{GateReport, MeasureTest, Pairing, RegressRow, Verdict};
use crate::summary::mode_name;
use forkbench_trial::text::md_cell;

fn pct(v: f64) -> String {
    format!("{:.1} %", 100.0 * v)
}

/// A measure's value in its own unit, to four decimals or three significant digits.
pub fn num(v: f64) -> String {
    // −0 (a "lower is worse" measure's equal pair) reads as 0.
    let v = if v == 0.0 { 0.0 } else { v };
    if v == 0.0 || v.abs() >= 0.01 {
        format!("{v:.4}")
    } else {
        format!("{v:.2e}")
    }
}

impl MeasureTest {
    /// "+0.0351 [0.0310, 0.0392]": how much worse, with its one-sided bounds.
    pub fn shift_text(&self) -> String {
        self.shift.map_or("–".to_owned(), |s| {
            format!(
                "{:+} [{}, {}]",
                NumSigned(s.estimate),
                num(s.low),
                num(s.high)
            )
        })
    }

    /// The measure's verdict in words.
    pub fn verdict_text(&self) -> &'static str {
        match (self.p_value, self.worse_beyond_margin) {
            (None, _) => "not tested (too few values)",
            (Some(_), true) => "WORSE beyond margin",
            (Some(_), false) => "ok",
        }
    }

    /// Everything about this measure in one line, for JUnit and the console.
    pub fn numbers(&self) -> String {
        let p = match (self.p_value, self.p_adjusted) {
            (Some(p), Some(a)) => format!(", p = {p:.4}, adjusted p = {a:.4}"),
            _ => String::new(),
        };
        format!(
            "{}: worse by {} vs margin {} ({}), {} {}{p}, detectable {}: {}",
            self.measure,
            self.shift_text(),
            num(self.margin),
            self.margin_source,
            self.n,
            if self.paired { "pairs" } else { "values" },
            self.detectable.map_or("–".to_owned(), num),
            self.verdict_text()
        )
    }
}

/// A signed number in [`num`]'s form.
struct NumSigned(f64);

impl std::fmt::Display for NumSigned {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let sign = if self.0 >= 0.0 { "+" } else { "" };
        write!(f, "{sign}{}", num(self.0))
    }
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
        let mut s = format!(
            "baseline {base}, now {now}, {}{p}, detectable drop {}{need}",
            self.pairs_text(),
            self.detectable_text()
        );
        for m in &self.measures {
            s.push_str("; ");
            s.push_str(&m.numbers());
        }
        s
    }

    /// The measures worse beyond their margins, by name.
    pub fn worse_measures(&self) -> Vec<&str> {
        self.measures
            .iter()
            .filter(|m| m.worse_beyond_margin)
            .map(|m| m.measure.as_str())
            .collect()
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
        let word = if self.passed { "PASSED" } else { "REGRESSION" };
        format!("{word}: {}", self.verdict_reason())
    }

    /// Why the gate passed or failed: the verdict without its first word.
    pub fn verdict_reason(&self) -> String {
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
            let measured = if self.rows.iter().any(|r| !r.measures.is_empty()) {
                ", no measure worse beyond its margin"
            } else {
                ""
            };
            format!("no significant drop{measured}{new_text}")
        } else if failed.is_empty() {
            format!("new rows with --fail-on-new{new_text}")
        } else {
            let names: Vec<String> = failed
                .iter()
                .map(|r| {
                    let mut why = r.verdict.name().to_owned();
                    if r.verdict == Verdict::Worse {
                        why = format!("{why}: {}", r.worse_measures().join(", "));
                    }
                    format!("{} / {} / {} ({why})", r.scenario, r.planner, r.tracker)
                })
                .collect();
            format!(
                "{} rows failed: {}{new_text}",
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
            "\nα = {} over the {} tests (rows × success and measures), {} correction. broke / fixed: trials that passed \
             in the baseline and fail now, and the reverse, at the same seed. detectable drop: \
             the smallest drop this row sees with 80 % power at level α/m = {:.4} (paired: at \
             the discordance seen now, at least the drop itself). A row fails on adjusted p < α, \
             a rate below the floor, a missing row, too few trials for \
             --min-detectable-drop, or a measure worse beyond its margin.\n\n",
            (self.alpha * 1e6).round() / 1e6,
            self.tests(),
            self.correction.name(),
            self.power_level,
        ));
        s.push_str(&self.measures_markdown());
        s.push_str(&format!("{}\n", self.verdict_text()));
        s
    }

    /// Tests in the family: each row's success and each of its measures.
    pub fn tests(&self) -> usize {
        self.rows
            .iter()
            .map(|r| {
                usize::from(r.p_value.is_some())
                    + r.measures.iter().filter(|m| m.p_value.is_some()).count()
            })
            .sum()
    }

    /// The measures' table, and what was not gated and why.
    fn measures_markdown(&self) -> String {
        let mut s = String::new();
        if let Some(note) = &self.measures_note {
            s.push_str(&format!("Measures: none compared: {}.\n\n", md_cell(note)));
        }
        if self.rows.iter().any(|r| !r.measures.is_empty()) {
            s.push_str(
                "| row | measure | margin | baseline median | now median | worse by (one-sided bounds) | p (worse > margin) | p adjusted | detectable | verdict |\n|---|---|---|---|---|---|---|---|---|---|\n",
            );
            for r in &self.rows {
                for m in &r.measures {
                    let p = |v: Option<f64>| v.map_or("–".to_owned(), |p| format!("{p:.4}"));
                    let med = |v: Option<f64>| v.map_or("–".to_owned(), num);
                    s.push_str(&format!(
                        "| {} / {} / {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
                        md_cell(&r.scenario),
                        md_cell(&r.planner),
                        md_cell(&r.tracker),
                        md_cell(&m.measure),
                        num(m.margin),
                        med(m.baseline_median),
                        med(m.now_median),
                        m.shift_text(),
                        p(m.p_value),
                        p(m.p_adjusted),
                        med(m.detectable),
                        m.verdict_text()
                    ));
                }
            }
            s.push_str(
                "\nworse by: the Hodges–Lehmann shift of the results against the baseline \
                 (positive: worse; paired: on the same seeds, Wilcoxon's signed-rank test; \
                 unpaired: the rank-sum test), with one-sided bounds at α. A measure fails \
                 when it is worse than its margin with confidence (adjusted p < α), not \
                 merely different. Margins: a tenth of the scenario's tolerance for the \
                 entry errors, contact force and displacement (and the fork-tip clearance, \
                 as the lateral error), 0.1 of robustness (a tenth of a limit), 5 % of the baseline's median \
                 time; `--gate FILE` sets others.\n\n",
            );
        }
        if !self.ungated_measures.is_empty() {
            s.push_str(&format!(
                "Not gated (unknown to the gate and not in a gate file, or switched off): \
                 {}.\n\n",
                md_cell(&self.ungated_measures.join(", "))
            ));
        }
        s
    }
}
