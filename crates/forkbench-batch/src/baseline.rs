//! Committed baselines: success counts per row and, for paired comparisons, every trial's key, seed, outcome and measures.

use std::collections::{BTreeMap, HashSet};
use std::path::Path;

use serde::{Deserialize, Serialize};

use super::{BatchError, Summary, TrialRecord};

/// Largest baseline file read (a baseline of 100,000 trials is about 17 MB).
pub const MAX_BASELINE_BYTES: u64 = 256 << 20;

/// Committed success counts to compare new results against.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Baseline {
    pub description: String,
    pub rows: Vec<BaselineRow>,
    /// The provenance of the results it was made from.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub provenance: Option<super::Provenance>,
    /// Every trial of the rows, so a batch run with the same seed is compared pair by
    /// pair; baselines made before pairing have none and compare unpaired.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub trials: Vec<BaselineTrial>,
    /// Whether its trials carry the gate's measures; baselines made before the gate
    /// compared measures have none and are gated on counts, with a warning.
    #[serde(default)]
    pub measured: bool,
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

/// One trial of a baseline: its identity, seed, outcome and measures.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BaselineTrial {
    pub scenario: String,
    pub case: String,
    pub planner: String,
    pub tracker: String,
    pub replan: bool,
    pub trial: u64,
    pub seed: u64,
    pub success: bool,
    /// First failed criterion (none on success).
    pub failure: Option<String>,
    /// What the gate compares pair by pair ([`crate::gate::trial_measures`]).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub measures: BTreeMap<String, f64>,
}

impl BaselineTrial {
    pub fn of(r: &TrialRecord) -> Self {
        let o = &r.outcome;
        Self {
            scenario: o.scenario.clone(),
            case: o.case.clone(),
            planner: o.planner.clone(),
            tracker: o.tracker.clone(),
            replan: r.replan.unwrap_or(false),
            trial: r.trial,
            seed: o.seed,
            success: o.success,
            failure: o.failure.as_ref().map(|f| f.name().to_owned()),
            measures: super::gate::trial_measures(o),
        }
    }

    /// The trial's identity, as [`TrialRecord::key`].
    pub fn key(&self) -> super::TrialKey {
        (
            self.scenario.clone(),
            self.case.clone(),
            self.planner.clone(),
            self.tracker.clone(),
            self.replan,
            self.trial,
        )
    }
}

impl Baseline {
    /// A baseline of a batch's summary and its trial records.
    pub fn from_results(s: &Summary, records: &[TrialRecord], description: String) -> Self {
        let mut trials: Vec<BaselineTrial> = records.iter().map(BaselineTrial::of).collect();
        trials.sort_by_key(BaselineTrial::key);
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
            measured: !trials.is_empty(),
            trials,
        }
    }

    /// Success counts only (no per-trial results: compared unpaired).
    pub fn from_summary(s: &Summary, description: String) -> Self {
        Self::from_results(s, &[], description)
    }

    /// Scenarios whose resolved settings (tolerances, truck, sensors, cases) differ between
    /// this baseline's batch and `now`'s: their rows do not compare like for like.
    pub fn setting_differences(&self, now: &super::Manifest) -> Vec<String> {
        self.provenance
            .as_ref()
            .map_or_else(Vec::new, |p| super::scenario_differences(&p.manifest, now))
    }

    /// The file's text: pretty JSON with one line per trial, so a diff of two baselines
    /// shows which trials changed.
    pub fn to_text(&self) -> Result<String, BatchError> {
        let head = Baseline {
            trials: Vec::new(),
            ..self.clone()
        };
        let mut text =
            serde_json::to_string_pretty(&head).map_err(|e| BatchError::Internal(e.to_string()))?;
        if !self.trials.is_empty() {
            text.truncate(text.trim_end().len() - 1);
            text.truncate(text.trim_end().len());
            text.push_str(",\n  \"trials\": [\n");
            for (i, t) in self.trials.iter().enumerate() {
                let line =
                    serde_json::to_string(t).map_err(|e| BatchError::Internal(e.to_string()))?;
                let sep = if i + 1 < self.trials.len() { "," } else { "" };
                text.push_str(&format!("    {line}{sep}\n"));
            }
            text.push_str("  ]\n}");
        }
        Ok(text + "\n")
    }

    /// Writes the baseline atomically; refuses one larger than [`Baseline::load`] reads.
    pub fn write(&self, path: &Path) -> Result<(), BatchError> {
        self.write_capped(path, MAX_BASELINE_BYTES)
    }

    fn write_capped(&self, path: &Path, max_bytes: u64) -> Result<(), BatchError> {
        let text = self.to_text()?;
        if text.len() as u64 > max_bytes {
            return Err(BatchError::Content(format!(
                "{}: the baseline would be {} bytes, more than the {max_bytes} that regress \
                 reads; make it from fewer trials (or shards, one baseline each)",
                path.display(),
                text.len()
            )));
        }
        super::write_atomic(path, text.as_bytes())
    }

    pub fn load(path: &Path) -> Result<Self, BatchError> {
        let text = super::read_regular(path, MAX_BASELINE_BYTES)?;
        let b: Baseline = serde_json::from_str(&text).map_err(|e| BatchError::Record {
            path: path.display().to_string(),
            line: e.line(),
            message: e.to_string(),
        })?;
        b.check()
            .map_err(|reason| BatchError::Content(format!("{}: {reason}", path.display())))?;
        Ok(b)
    }

    fn check(&self) -> Result<(), String> {
        if self.rows.is_empty() {
            return Err("rows is empty; a baseline without rows would pass every result".into());
        }
        for (i, r) in self.rows.iter().enumerate() {
            if let Some(j) = self.rows[..i].iter().position(|o| o.key() == r.key()) {
                return Err(format!(
                    "rows[{i}] repeats rows[{j}] ({} / {} / {}); each scenario × planner × \
                     tracker × mode once",
                    r.scenario, r.planner, r.tracker
                ));
            }
            if r.trials == 0 || r.successes > r.trials {
                return Err(format!(
                    "rows[{i}] ({} / {}): successes {} of {} trials is impossible",
                    r.scenario, r.planner, r.successes, r.trials
                ));
            }
        }
        self.check_trials()
    }

    /// Per-trial results must add up to the rows' counts, once per trial.
    fn check_trials(&self) -> Result<(), String> {
        if self.trials.is_empty() {
            return Ok(());
        }
        let mut seen = HashSet::new();
        let mut counts: BTreeMap<(&str, &str, &str, bool), (u64, u64)> = BTreeMap::new();
        for (i, t) in self.trials.iter().enumerate() {
            if !seen.insert(t.key()) {
                return Err(format!("trials[{i}] repeats a trial ({:?})", t.key()));
            }
            if t.success != t.failure.is_none() {
                return Err(format!(
                    "trials[{i}]: success {} with failure {:?} is contradictory",
                    t.success, t.failure
                ));
            }
            if let Some((k, v)) = t.measures.iter().find(|(_, v)| !v.is_finite()) {
                return Err(format!(
                    "trials[{i}].measures.{k} = {v}: not a finite number"
                ));
            }
            let c = counts
                .entry((&t.scenario, &t.planner, &t.tracker, t.replan))
                .or_default();
            c.0 += 1;
            c.1 += u64::from(t.success);
        }
        for (i, r) in self.rows.iter().enumerate() {
            let key = (
                r.scenario.as_str(),
                r.planner.as_str(),
                r.tracker.as_str(),
                r.replan.unwrap_or(false),
            );
            let (n, k) = counts.remove(&key).unwrap_or_default();
            if (n, k) != (r.trials, r.successes) {
                return Err(format!(
                    "rows[{i}] ({} / {} / {}) counts {} of {} but its trials hold {k} of {n}: \
                     the file was edited or truncated",
                    r.scenario, r.planner, r.tracker, r.successes, r.trials
                ));
            }
        }
        if let Some((k, _)) = counts.into_iter().next() {
            return Err(format!("trials of {k:?} belong to no row"));
        }
        Ok(())
    }
}

impl BaselineRow {
    pub(super) fn key(&self) -> (&str, &str, &str, Option<bool>) {
        (&self.scenario, &self.planner, &self.tracker, self.replan)
    }

    /// Whether a result row is this row: same scenario × planner × tracker, and the same
    /// mode when the baseline row has one.
    pub(super) fn matches(&self, r: &super::SummaryRow) -> bool {
        self.holds(&r.scenario, &r.planner, &r.tracker, r.replan)
    }

    /// Whether results of this scenario × planner × tracker in mode `replan` belong to
    /// this row (any mode when the row has none).
    pub(super) fn holds(&self, scenario: &str, planner: &str, tracker: &str, replan: bool) -> bool {
        (scenario, planner, tracker)
            == (
                self.scenario.as_str(),
                self.planner.as_str(),
                self.tracker.as_str(),
            )
            && self.replan.is_none_or(|m| replan == m)
    }

    /// The result row this baseline row compares with; without a mode, the only row of
    /// that triple (none when there are several).
    pub(super) fn find<'a>(&self, rows: &'a [super::SummaryRow]) -> Option<&'a super::SummaryRow> {
        let mut same = rows.iter().filter(|r| self.matches(r));
        let first = same.next()?;
        (self.replan.is_some() || same.next().is_none()).then_some(first)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_baseline_regress_could_not_read_is_not_written() {
        let dir = std::env::temp_dir().join(format!("forkbench-base-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("dir");
        let path = dir.join("b.json");
        let b: Baseline =
            serde_json::from_str(r#"{"description": "x", "rows": []}"#).expect("a baseline");
        let err = b
            .write_capped(&path, 10)
            .expect_err("too large")
            .to_string();
        assert!(
            err.contains("more than the 10") && err.contains("b.json"),
            "{err}"
        );
        assert!(!path.exists(), "nothing written");
        b.write_capped(&path, MAX_BASELINE_BYTES).expect("fits");
        assert!(path.exists());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
