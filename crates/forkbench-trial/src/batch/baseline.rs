//! Committed baselines and the regression gate: a one-sided two-proportion test per row.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::{BatchError, Summary, io};
use crate::stats::drop_p_value;

/// Committed success counts to compare new results against.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Baseline {
    pub description: String,
    pub rows: Vec<BaselineRow>,
    /// The provenance of the results it was made from.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub provenance: Option<super::Provenance>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BaselineRow {
    pub scenario: String,
    pub planner: String,
    /// Baselines made before trackers were pluggable have none: pure pursuit.
    #[serde(default = "super::summary::pure_pursuit")]
    pub tracker: String,
    /// Replanning mode of the row; baselines made before modes were rows have none and
    /// match the one result row of their scenario × planner × tracker.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub replan: Option<bool>,
    pub trials: u64,
    pub successes: u64,
}

impl Baseline {
    pub fn from_summary(s: &Summary, description: String) -> Self {
        Self {
            description,
            rows: s
                .rows
                .iter()
                .map(|r| BaselineRow {
                    scenario: r.scenario.clone(),
                    planner: r.planner.clone(),
                    tracker: r.tracker.clone(),
                    replan: Some(r.replan),
                    trials: r.trials,
                    successes: r.successes,
                })
                .collect(),
            provenance: s.provenance.clone(),
        }
    }

    /// Scenarios whose resolved settings (tolerances, truck, sensors, cases) differ between
    /// this baseline's batch and `now`'s: their rows do not compare like for like.
    pub fn setting_differences(&self, now: &super::Manifest) -> Vec<String> {
        self.provenance
            .as_ref()
            .map_or_else(Vec::new, |p| super::scenario_differences(&p.manifest, now))
    }

    pub fn load(path: &Path) -> Result<Self, BatchError> {
        let text = std::fs::read_to_string(path).map_err(io(path))?;
        let b: Baseline = serde_json::from_str(&text).map_err(|e| BatchError::Record {
            path: path.display().to_string(),
            line: e.line(),
            message: e.to_string(),
        })?;
        if b.rows.is_empty() {
            return Err(BatchError::Invalid(format!(
                "{}: rows is empty; a baseline without rows would pass every result",
                path.display()
            )));
        }
        for (i, r) in b.rows.iter().enumerate() {
            if let Some(j) = b.rows[..i].iter().position(|o| o.key() == r.key()) {
                return Err(BatchError::Invalid(format!(
                    "{}: rows[{i}] repeats rows[{j}] ({} / {} / {}); each scenario × planner × \
                     tracker once",
                    path.display(),
                    r.scenario,
                    r.planner,
                    r.tracker
                )));
            }
            if r.trials == 0 || r.successes > r.trials {
                return Err(BatchError::Invalid(format!(
                    "{}: rows[{i}] ({} / {}): successes {} of {} trials is impossible",
                    path.display(),
                    r.scenario,
                    r.planner,
                    r.successes,
                    r.trials
                )));
            }
        }
        Ok(b)
    }
}

impl BaselineRow {
    fn key(&self) -> (&str, &str, &str, Option<bool>) {
        (&self.scenario, &self.planner, &self.tracker, self.replan)
    }

    /// The result row this baseline row compares with: same scenario × planner × tracker
    /// and mode; without a mode, the only row of that triple (none when there are several).
    fn find<'a>(&self, rows: &'a [super::SummaryRow]) -> Option<&'a super::SummaryRow> {
        let mut same = rows.iter().filter(|r| {
            (r.scenario.as_str(), r.planner.as_str(), r.tracker.as_str())
                == (
                    self.scenario.as_str(),
                    self.planner.as_str(),
                    self.tracker.as_str(),
                )
        });
        match self.replan {
            Some(m) => same.find(|r| r.replan == m),
            None => same.next().filter(|_| same.next().is_none()),
        }
    }
}

/// One compared row.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RegressRow {
    pub scenario: String,
    pub planner: String,
    pub tracker: String,
    pub replan: Option<bool>,
    pub baseline_rate: f64,
    pub now_rate: Option<f64>,
    pub now_trials: u64,
    pub p_value: Option<f64>,
    /// `ok`, `drop` (significant), `below_floor`, or `missing` (not in the results).
    pub verdict: String,
}

/// Compares results with a baseline: a row fails on a significant one-sided drop
/// (p < alpha) or a rate below the absolute floor, or when it is missing.
pub fn regress(
    base: &Baseline,
    now: &Summary,
    alpha: f64,
    floor: Option<f64>,
) -> (Vec<RegressRow>, bool) {
    let mut failed = false;
    let rows = base
        .rows
        .iter()
        .map(|b| {
            let r = b.find(&now.rows);
            let base_rate = b.successes as f64 / b.trials as f64;
            let (now_rate, n, p, verdict) = match r {
                None => (None, 0, None, "missing"),
                Some(r) => {
                    let p = drop_p_value(b.successes, b.trials, r.successes, r.trials);
                    let v = if p < alpha {
                        "drop"
                    } else if floor.is_some_and(|f| r.success_rate < f) {
                        "below_floor"
                    } else {
                        "ok"
                    };
                    (Some(r.success_rate), r.trials, Some(p), v)
                }
            };
            failed |= verdict != "ok";
            RegressRow {
                scenario: b.scenario.clone(),
                planner: b.planner.clone(),
                tracker: b.tracker.clone(),
                replan: b.replan,
                baseline_rate: base_rate,
                now_rate,
                now_trials: n,
                p_value: p,
                verdict: verdict.to_owned(),
            }
        })
        .collect();
    (rows, failed)
}

/// The regression report as markdown.
pub fn regress_markdown(rows: &[RegressRow], alpha: f64) -> String {
    let mut s = String::from(
        "| scenario | planner | tracker | mode | baseline | now | difference | p (one-sided drop) | verdict |\n|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let now = r.now_rate.map_or("–".to_owned(), |v| {
            format!("{:.1} % (n={})", 100.0 * v, r.now_trials)
        });
        let diff = r.now_rate.map_or("–".to_owned(), |v| {
            format!("{:+.1} pp", 100.0 * (v - r.baseline_rate))
        });
        let p = r.p_value.map_or("–".to_owned(), |p| format!("{p:.4}"));
        s.push_str(&format!(
            "| {} | {} | {} | {} | {:.1} % | {} | {} | {} | {} |\n",
            r.scenario,
            r.planner,
            r.tracker,
            r.replan.map_or("any", super::summary::mode_name),
            100.0 * r.baseline_rate,
            now,
            diff,
            p,
            r.verdict
        ));
    }
    s.push_str(&format!(
        "\nα = {alpha}; a row fails on p < α, a rate below the floor, or a missing row.\n"
    ));
    s
}
