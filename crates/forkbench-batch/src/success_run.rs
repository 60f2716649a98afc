//! What a row's trials demonstrate as a test method states it (ASTM F3499-style success-run figures): the reliability shown at a confidence (the exact Clopper–Pearson lower bound), the run of clean trials that shows a target reliability, and how many more clean trials this row would need.

use serde::{Deserialize, Serialize};

use crate::BatchError;
use crate::stats::binom_tail;

/// The confidence the figures are stated at, and the reliability a row is asked to show,
/// by default (a choice: F3499's worked example, 299 clean runs for R 0.99 at C 0.95).
pub const CONFIDENCE: f64 = 0.95;
pub const TARGET_RELIABILITY: f64 = 0.99;

/// The confidence and target reliability a batch states its success runs at
/// (`batch --success-confidence`, `--success-reliability`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SuccessTarget {
    pub confidence: f64,
    pub reliability: f64,
}

impl Default for SuccessTarget {
    fn default() -> Self {
        SuccessTarget {
            confidence: CONFIDENCE,
            reliability: TARGET_RELIABILITY,
        }
    }
}

impl SuccessTarget {
    /// Both within [0.5, 0.999999]: below a half a figure says nothing a coin would not,
    /// and nearer 1 the clean runs asked for exceed what any batch holds.
    pub fn new(confidence: f64, reliability: f64) -> Result<Self, BatchError> {
        for (flag, v) in [
            ("--success-confidence", confidence),
            ("--success-reliability", reliability),
        ] {
            if !(0.5..=0.999_999).contains(&v) {
                return Err(BatchError::Setting(format!(
                    "{flag} {v}: a probability from 0.5 to 0.999999"
                )));
            }
        }
        Ok(SuccessTarget {
            confidence,
            reliability,
        })
    }
}

/// Most further trials searched for (beyond, a row cannot show the target soon).
const MAX_MORE: u64 = 1_000_000;

/// A row's success-run figures.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SuccessRun {
    pub confidence: f64,
    /// The reliability the row's successes demonstrate at `confidence`: the one-sided
    /// Clopper–Pearson lower bound of the success probability.
    pub demonstrated: f64,
    pub target: f64,
    /// Consecutive successes with no failure that show `target` at `confidence`:
    /// n = ln(1 − C) / ln R, rounded up.
    pub success_run_for_target: u64,
    /// Further trials, all successes, after which this row would show `target`; `None`
    /// beyond a million (its failures are too many for the target).
    pub more_clean_trials: Option<u64>,
}

/// The lower bound p of a one-sided Clopper–Pearson interval for `k` successes in `n` at
/// `confidence`: P(X ≥ k | p) = 1 − confidence (0 without a success).
pub fn clopper_pearson_lower(k: u64, n: u64, confidence: f64) -> f64 {
    if k == 0 || n == 0 {
        return 0.0;
    }
    if k == n {
        // Closed form of the same bound with no failure.
        return (1.0 - confidence).powf(1.0 / n as f64);
    }
    let alpha = 1.0 - confidence;
    let (mut lo, mut hi) = (0.0f64, k as f64 / n as f64);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if binom_tail(k, n, mid) < alpha {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Clean runs that show reliability `r` at `confidence`.
pub fn success_run_length(r: f64, confidence: f64) -> u64 {
    ((1.0 - confidence).ln() / r.ln()).ceil() as u64
}

/// The figures for `k` successes in `n` trials.
pub fn success_run(k: u64, n: u64, t: SuccessTarget) -> SuccessRun {
    let shows = |m: u64| clopper_pearson_lower(k + m, n + m, t.confidence) >= t.reliability;
    let more = if shows(0) {
        Some(0)
    } else if !shows(MAX_MORE) {
        None
    } else {
        // The bound grows with each clean trial: the least m by bisection.
        let (mut lo, mut hi) = (0u64, MAX_MORE);
        while hi - lo > 1 {
            let mid = lo + (hi - lo) / 2;
            if shows(mid) {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        Some(hi)
    };
    SuccessRun {
        confidence: t.confidence,
        demonstrated: clopper_pearson_lower(k, n, t.confidence),
        target: t.reliability,
        success_run_for_target: success_run_length(t.reliability, t.confidence),
        more_clean_trials: more,
    }
}

/// The rows' success-run figures as a markdown table.
pub fn markdown(rows: &[crate::SummaryRow]) -> String {
    let Some(first) = rows.iter().find_map(|r| r.success_run) else {
        return String::new();
    };
    let mut s = format!(
        "\nSuccess run (ASTM F3499 style): the reliability each row demonstrates at {:.0} % \
         confidence (Clopper–Pearson), and the clean trials that would show R {}; {} in a \
         row with no failure show it\n\n| scenario | planner | tracker | mode | successes | R demonstrated | more clean trials for R {} |\n|---|---|---|---|---|---|---|\n",
        100.0 * first.confidence,
        first.target,
        first.success_run_for_target,
        first.target,
    );
    for r in rows {
        let Some(run) = r.success_run else { continue };
        s.push_str(&format!(
            "| {} | {} | {} | {} | {} of {} | {:.4} | {} |\n",
            forkbench_trial::text::md_cell(&r.scenario),
            forkbench_trial::text::md_cell(&r.planner),
            forkbench_trial::text::md_cell(&r.tracker),
            crate::mode_name(r.replan),
            r.successes,
            r.trials,
            run.demonstrated,
            run.more_clean_trials
                .map_or("over a million".to_owned(), |m| m.to_string()),
        ));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn figures_match_the_closed_forms_and_hand_values() {
        // F3499's example: 299 clean runs show R 0.99 at C 0.95.
        assert_eq!(success_run_length(0.99, 0.95), 299);
        let clean = clopper_pearson_lower(299, 299, 0.95);
        assert!(clean >= 0.99 && clopper_pearson_lower(298, 298, 0.95) < 0.99);
        // With failures the bisection meets the tail it inverts: P(X ≥ 18 | p) = 0.05.
        let p = clopper_pearson_lower(18, 20, 0.95);
        assert!((binom_tail(18, 20, p) - 0.05).abs() < 1e-9, "{p}");
        // R's binom.test(18, 20, alternative = "greater") gives 0.7174.
        assert!((p - 0.7174).abs() < 5e-4, "{p}");
        assert_eq!(clopper_pearson_lower(0, 20, 0.95), 0.0);
        // 20 clean trials need 279 more; one failure in 20 needs more than that.
        let t = SuccessTarget::default();
        let s = success_run(20, 20, t);
        assert_eq!(s.more_clean_trials, Some(279));
        let f = success_run(19, 20, t).more_clean_trials.expect("reachable");
        assert!(f > 279, "{f}");
        assert!(clopper_pearson_lower(19 + f, 20 + f, 0.95) >= 0.99);
        assert!(clopper_pearson_lower(19 + f - 1, 20 + f - 1, 0.95) < 0.99);
        // Another confidence and target: 90 % and 0.95 take 45 clean runs
        // (ln 0.1 / ln 0.95 = 44.9), and 20 clean trials show 0.891 at 90 %.
        let t = SuccessTarget::new(0.9, 0.95).expect("in range");
        let s = success_run(20, 20, t);
        assert_eq!(s.success_run_for_target, 45);
        assert_eq!(s.more_clean_trials, Some(25));
        assert!((s.demonstrated - 0.1f64.powf(1.0 / 20.0)).abs() < 1e-12);
        for (c, r) in [(0.4, 0.99), (0.95, 1.0), (f64::NAN, 0.9), (0.95, 0.9999999)] {
            let e = SuccessTarget::new(c, r).expect_err("out of range");
            assert!(e.to_string().contains("from 0.5 to 0.999999"), "{e}");
        }
    }
}
