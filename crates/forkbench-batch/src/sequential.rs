//! `batch --trials auto`: a group-sequential gate that runs trials in looks (doubling up to a cap) until the gate can decide, with α split over the planned looks so that looking often costs no false alarms.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::{
    BatchError, BatchSpec, GateOptions, GateReport, Manifest, Summary, TrialRecord, Verdict,
};

/// The fewest trials per case of a first look.
pub const FIRST_LOOK: u64 = 10;

/// The drop in success rate a passing look must be able to see with 80 % power, unless
/// told otherwise (`--min-detectable-drop`).
pub const DEFAULT_DECIDE_DROP: f64 = 0.1;

/// A measure's worsening a passing look must be able to see with 80 % power, in margins.
const DECIDE_MARGINS: f64 = 2.0;

/// The planned looks: trial counts per case, from `first` doubling up to `cap` (the last
/// look is the cap).
pub fn plan_looks(first: u64, cap: u64) -> Vec<u64> {
    let mut looks = Vec::new();
    let mut n = first.clamp(1, cap.max(1));
    while n < cap {
        looks.push(n);
        n = n.saturating_mul(2);
    }
    looks.push(cap.max(1));
    looks
}

/// What one look decided.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Decision {
    /// A row failed at the look's level: stop, the gate fails.
    Regression,
    /// Nothing failed, and every row could have seen the asked drop and every measure
    /// twice its margin: stop, the gate passes.
    Pass,
    /// Nothing failed, but the gate could not yet tell: run the next look.
    Undecided,
}

/// One look: its trials per case, level, decision and why.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Look {
    pub trials: u64,
    /// The α this look's gate ran at (the whole α over the planned looks).
    pub alpha: f64,
    pub decision: Decision,
    pub why: String,
}

/// Whether `report` (one look's gate) decides, and why.
pub fn decide(report: &GateReport, want_drop: f64) -> (Decision, String) {
    if !report.passed {
        return (Decision::Regression, report.verdict_reason());
    }
    let mut short = Vec::new();
    for r in report.rows.iter().filter(|r| r.verdict == Verdict::Ok) {
        if r.detectable_drop.is_none_or(|d| d > want_drop) {
            short.push(format!(
                "{} / {} sees a drop of {}, not {:.1} pp",
                r.scenario,
                r.tracker,
                r.detectable_text(),
                100.0 * want_drop
            ));
        }
        for m in r.measures.iter().filter(|m| m.p_value.is_some()) {
            if m.margin > 0.0 && m.detectable.is_none_or(|d| d > DECIDE_MARGINS * m.margin) {
                short.push(format!(
                    "{} / {}: {} sees {}, not twice its margin {}",
                    r.scenario,
                    r.tracker,
                    m.measure,
                    m.detectable.map_or("nothing".into(), crate::gate_num),
                    crate::gate_num(m.margin)
                ));
            }
        }
    }
    if short.is_empty() {
        (
            Decision::Pass,
            "passed, and powered for the asked drop and twice each margin".into(),
        )
    } else {
        let more = short.len().saturating_sub(3);
        short.truncate(3);
        let tail = if more > 0 {
            format!(" (and {more} more)")
        } else {
            String::new()
        };
        (Decision::Undecided, format!("{}{tail}", short.join("; ")))
    }
}

/// Raises the directory's manifest to `trials` per case, so that the batch goes on where
/// the last look ended (only ever up: its trials stay).
fn grow(dir: &Path, trials: u64) -> Result<(), BatchError> {
    let _lock = crate::DirLock::take(dir)?;
    match Manifest::read(dir)? {
        Some(mut m) if m.trials < trials => {
            m.trials = trials;
            m.write(dir)
        }
        _ => Ok(()),
    }
}

/// A sequential run's looks, and its last look's summary and gate.
#[derive(Debug, Clone)]
pub struct Sequential {
    /// The looks planned (α was split over them), and those run.
    pub planned: usize,
    pub looks: Vec<Look>,
    pub summary: Summary,
    pub report: GateReport,
}

/// How a sequential run gates.
pub struct SequentialPlan<'a> {
    pub looks: Vec<u64>,
    pub options: GateOptions,
    pub want_drop: f64,
    /// The gate over the directory as it stands, at the options given.
    pub gate: &'a dyn Fn(&GateOptions) -> Result<GateReport, BatchError>,
}

impl std::fmt::Debug for SequentialPlan<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SequentialPlan")
            .field("looks", &self.looks)
            .field("options", &self.options)
            .field("want_drop", &self.want_drop)
            .finish_non_exhaustive()
    }
}

/// Runs `spec` look by look into `dir` until a look decides or the cap is reached. A
/// directory already holding some looks' trials goes on from the first look beyond them.
pub fn run_sequential(
    spec: &BatchSpec,
    dir: &Path,
    jobs: usize,
    plan: &SequentialPlan<'_>,
    on_done: &(dyn Fn(&TrialRecord) + Sync),
) -> Result<Sequential, BatchError> {
    let have = Manifest::read(dir)?.map_or(0, |m| m.trials);
    let level = plan.options.alpha / plan.looks.len().max(1) as f64;
    let options = GateOptions {
        alpha: level,
        min_detectable_drop: None,
        ..plan.options.clone()
    };
    let mut looks = Vec::new();
    let todo: Vec<u64> = plan.looks.iter().copied().filter(|n| *n >= have).collect();
    for (k, &n) in todo.iter().enumerate() {
        if k > 0 || have > 0 {
            grow(dir, n)?;
        }
        let mut s = spec.clone();
        s.trials = n;
        let summary = crate::run_batch(&s, dir, jobs, on_done)?;
        let report = (plan.gate)(&options)?;
        let (decision, why) = decide(&report, plan.want_drop);
        looks.push(Look {
            trials: n,
            alpha: level,
            decision,
            why,
        });
        if decision != Decision::Undecided || k + 1 == todo.len() {
            return Ok(Sequential {
                planned: plan.looks.len(),
                looks,
                summary,
                report,
            });
        }
    }
    Err(BatchError::Setting(format!(
        "{}: holds {have} trials per case, more than the last planned look ({}); raise \
         --max-trials or choose another --out",
        dir.display(),
        plan.looks.last().copied().unwrap_or(0)
    )))
}

/// The trials per case the baseline holds for its smallest row (the most a look can pair).
pub fn baseline_cap(base: &crate::Baseline) -> u64 {
    let mut most: std::collections::BTreeMap<(&str, &str), u64> = Default::default();
    for t in &base.trials {
        let e = most.entry((&t.scenario, &t.case)).or_default();
        *e = (*e).max(t.trial + 1);
    }
    most.values().copied().min().unwrap_or(0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn looks_double_up_to_the_cap() {
        assert_eq!(plan_looks(10, 160), vec![10, 20, 40, 80, 160]);
        assert_eq!(plan_looks(10, 100), vec![10, 20, 40, 80, 100]);
        assert_eq!(plan_looks(10, 5), vec![5]);
        assert_eq!(plan_looks(0, 0), vec![1]);
    }
}
