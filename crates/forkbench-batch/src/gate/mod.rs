//! The regression gate: each result row against its baseline row, on success and on each measure's margin, paired on common random numbers when the seeds match, with multiplicity control and stated power.

mod measure_test;
mod measures;
mod row_measures;
mod text;

pub use measure_test::MeasureTest;
pub use measures::{MeasureSetting, MeasureSettingError, MeasureSettings, Worse, trial_measures};
pub use text::num;

use std::collections::HashMap;

use serde::{Deserialize, Serialize};

use super::{Baseline, BaselineRow, Manifest, Summary, SummaryRow, TrialKey, TrialRecord};
use crate::stats::{
    Correction, drop_p_value, mcnemar_drop_p, min_detectable_drop, paired_power, trials_needed,
    unpaired_power,
};

/// The gate's significance level unless told otherwise: one α for the whole family of
/// rows, in the README, `--help` and CI alike.
pub const DEFAULT_ALPHA: f64 = 0.05;

/// Most trials a `--min-detectable-drop` answer searches.
const MAX_TRIALS_SEARCHED: u64 = 1_000_000;

/// How the gate decides.
#[derive(Debug, Clone, PartialEq)]
pub struct GateOptions {
    /// Family-wise (Holm) or false-discovery (Benjamini–Hochberg) level over all rows.
    pub alpha: f64,
    pub correction: Correction,
    /// Absolute floor on every row's success rate.
    pub floor: Option<f64>,
    /// Rows the baseline does not have fail instead of being listed as unchecked.
    pub fail_on_new: bool,
    /// The drop the gate must see with 80 % power: rows with too few trials fail.
    pub min_detectable_drop: Option<f64>,
    /// Margins and directions of the measures, beside their defaults (a gate file).
    pub measures: MeasureSettings,
}

impl GateOptions {
    /// Every option in its range: α in (0, 1), the floor a rate, the detectable drop in
    /// (0, 1].
    pub fn validate(&self) -> Result<(), crate::BatchError> {
        crate::check_alpha(self.alpha)?;
        crate::check_floor(self.floor)?;
        match self.min_detectable_drop {
            Some(d) if !(d > 0.0 && d <= 1.0) => Err(crate::BatchError::Setting(format!(
                "min_detectable_drop {d}: must be a drop in success rate in (0, 1]"
            ))),
            _ => Ok(()),
        }
    }
}

impl Default for GateOptions {
    fn default() -> Self {
        Self {
            alpha: DEFAULT_ALPHA,
            correction: Correction::Holm,
            floor: None,
            fail_on_new: false,
            min_detectable_drop: None,
            measures: MeasureSettings::default(),
        }
    }
}

/// A row's verdict.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    Ok,
    /// A significant drop after the multiplicity correction.
    Drop,
    BelowFloor,
    /// In the baseline, not in the results.
    Missing,
    /// In the results, not in the baseline: unchecked.
    New,
    /// Fewer trials than `--min-detectable-drop` needs.
    Underpowered,
    /// A measure worse than the baseline's by more than its margin, after the correction.
    Worse,
}

impl Verdict {
    pub fn name(self) -> &'static str {
        match self {
            Verdict::Ok => "ok",
            Verdict::Drop => "drop",
            Verdict::BelowFloor => "below_floor",
            Verdict::Missing => "missing",
            Verdict::New => "new, unchecked",
            Verdict::Underpowered => "underpowered",
            Verdict::Worse => "worse beyond margin",
        }
    }
}

/// Trials present in both the baseline and the results with the same seed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct PairCounts {
    pub pairs: u64,
    /// Passed in the baseline, fail now.
    pub broke: u64,
    /// Failed in the baseline, pass now.
    pub fixed: u64,
}

/// One compared row.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RegressRow {
    pub scenario: String,
    pub planner: String,
    pub tracker: String,
    pub replan: Option<bool>,
    pub baseline_trials: u64,
    pub baseline_rate: Option<f64>,
    pub now_trials: u64,
    pub now_rate: Option<f64>,
    /// Present when the row was compared pair by pair (McNemar's exact test).
    pub paired: Option<PairCounts>,
    /// One-sided p-value of a drop, and after the multiplicity correction.
    pub p_value: Option<f64>,
    pub p_adjusted: Option<f64>,
    /// Smallest drop (success-rate fraction) the gate sees with 80 % power at this n;
    /// none when even a drop to zero is not seen.
    pub detectable_drop: Option<f64>,
    /// With `--min-detectable-drop`: trials (pairs, when paired) that drop needs.
    pub trials_needed: Option<u64>,
    /// Each gated measure against its margin (none: the baseline carries no measures).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub measures: Vec<MeasureTest>,
    pub verdict: Verdict,
}

/// Whether the comparison is paired, and why not.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "mode", rename_all = "snake_case")]
pub enum Pairing {
    Paired { pairs: u64 },
    Unpaired { reason: String },
}

/// The gate's whole answer.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GateReport {
    pub passed: bool,
    pub alpha: f64,
    pub correction: Correction,
    pub floor: Option<f64>,
    /// The level each row's power is stated at (α over the tested rows: Holm's first step).
    pub power_level: f64,
    pub pairing: Pairing,
    pub setting_differences: Vec<String>,
    pub rows: Vec<RegressRow>,
    /// Measures the records carry that the gate does not gate (unknown to it and not in
    /// the gate file, or switched off there).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub ungated_measures: Vec<String>,
    /// Why no measure was compared, when none was (an old baseline: counts only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub measures_note: Option<String>,
}

/// Trials a row needs for the paired gate to see `drop` with 80 % power at level
/// α / `rows` when a change only breaks trials: the best case (a change that also flips
/// trials both ways needs more, the unpaired test far more).
pub fn paired_trials_needed(drop: f64, alpha: f64, rows: usize) -> Option<u64> {
    let level = alpha / rows.max(1) as f64;
    trials_needed(MAX_TRIALS_SEARCHED, |n| paired_power(n, drop, drop, level))
}

/// Why the results cannot be paired with the baseline trial by trial, if they cannot: a
/// trial's seed depends only on the batch seed, the seed scheme, the scenario, the case
/// and the trial, so changed settings, components or noise scales still run the same
/// trials (they are listed as what changed, not a reason to unpair).
fn unpaired_reason(base: &Baseline, now: Option<&Manifest>) -> Option<String> {
    if base.trials.is_empty() {
        return Some(
            "the baseline has no per-trial results (made by an older forkbench or from counts \
             only); re-make it with `forkbench baseline` to compare pair by pair"
                .into(),
        );
    }
    let Some(then) = base.provenance.as_ref().map(|p| &p.manifest) else {
        return Some("the baseline has no provenance, so its batch seed is unknown".into());
    };
    let Some(now) = now else {
        return Some("the results have no manifest.json, so their batch seed is unknown".into());
    };
    now.seed_difference(then, "the baseline")
}

/// Trials at the same key as a baseline trial but another seed: records edited, or made
/// by another seed scheme. Pairing would silently drop them, so none is paired.
fn seed_mismatch(base: &Baseline, now: &HashMap<TrialKey, (u64, bool)>) -> Option<String> {
    let mut differ = base
        .trials
        .iter()
        .filter(|t| now.get(&t.key()).is_some_and(|(seed, _)| *seed != t.seed));
    let first = differ.next()?;
    Some(format!(
        "{} trials share a key with the baseline but not its seed (first: {} / case {} / trial \
         {}: seed {} in the baseline); records edited, or made by another seed scheme",
        1 + differ.count(),
        first.scenario,
        first.case,
        first.trial,
        first.seed
    ))
}

/// Pair counts of one row: baseline trials matched by key and seed in the results.
fn pair_row(
    base: &Baseline,
    row: &BaselineRow,
    now: &HashMap<TrialKey, (u64, bool)>,
) -> Option<PairCounts> {
    let mut c = PairCounts {
        pairs: 0,
        broke: 0,
        fixed: 0,
    };
    for t in base.trials.iter().filter(|t| row_measures::in_row(row, t)) {
        if let Some(&(seed, ok)) = now.get(&t.key())
            && seed == t.seed
        {
            c.pairs += 1;
            c.broke += u64::from(t.success && !ok);
            c.fixed += u64::from(!t.success && ok);
        }
    }
    (c.pairs > 0).then_some(c)
}

fn blank_row(s: (&str, &str, &str, Option<bool>), verdict: Verdict) -> RegressRow {
    RegressRow {
        scenario: s.0.to_owned(),
        planner: s.1.to_owned(),
        tracker: s.2.to_owned(),
        replan: s.3,
        baseline_trials: 0,
        baseline_rate: None,
        now_trials: 0,
        now_rate: None,
        paired: None,
        p_value: None,
        p_adjusted: None,
        detectable_drop: None,
        trials_needed: None,
        measures: Vec::new(),
        verdict,
    }
}

/// One baseline row against its result row (no verdict on significance yet).
fn compare_row(b: &BaselineRow, now: Option<&SummaryRow>, pairs: Option<PairCounts>) -> RegressRow {
    let key = (
        b.scenario.as_str(),
        b.planner.as_str(),
        b.tracker.as_str(),
        b.replan,
    );
    let Some(r) = now else {
        let mut row = blank_row(key, Verdict::Missing);
        row.baseline_trials = b.trials;
        row.baseline_rate = Some(b.successes as f64 / b.trials as f64);
        return row;
    };
    let mut row = blank_row(key, Verdict::Ok);
    row.baseline_trials = b.trials;
    row.baseline_rate = Some(b.successes as f64 / b.trials as f64);
    row.now_trials = r.trials;
    row.now_rate = Some(r.success_rate);
    row.paired = pairs;
    row.p_value = Some(match pairs {
        Some(c) => mcnemar_drop_p(c.broke, c.fixed),
        None => drop_p_value(b.successes, b.trials, r.successes, r.trials),
    });
    row
}

/// The smallest drop seen with 80 % power, and the trials `want` needs, at `level`.
fn power_of(row: &RegressRow, level: f64, want: Option<f64>) -> (Option<f64>, Option<u64>) {
    let p0 = row.baseline_rate.unwrap_or(0.0);
    // A rate cannot drop below zero: a wanted drop larger than the baseline's rate is the
    // drop to zero, and a row at zero has no drop to see.
    let want = want.map(|d| d.min(p0)).filter(|d| *d > 0.0);
    match row.paired {
        Some(c) => {
            let psi = (c.broke + c.fixed) as f64 / c.pairs as f64;
            let mdd = min_detectable_drop(p0, |d| paired_power(c.pairs, d, psi, level));
            let need = want.and_then(|d| {
                trials_needed(MAX_TRIALS_SEARCHED, |n| paired_power(n, d, psi, level))
            });
            (mdd, need)
        }
        None => {
            let (n0, n1) = (row.baseline_trials, row.now_trials);
            let mdd = min_detectable_drop(p0, |d| unpaired_power(p0, n0, n1, d, level));
            let need = want.and_then(|d| {
                trials_needed(MAX_TRIALS_SEARCHED, |n| unpaired_power(p0, n0, n, d, level))
            });
            (mdd, need)
        }
    }
}

/// Result rows the baseline does not have: new, unchecked.
fn new_rows(base: &Baseline, now: &Summary) -> Vec<RegressRow> {
    now.rows
        .iter()
        .filter(|r| !base.rows.iter().any(|b| b.matches(r)))
        .map(|r| {
            let key = (
                r.scenario.as_str(),
                r.planner.as_str(),
                r.tracker.as_str(),
                Some(r.replan),
            );
            let mut row = blank_row(key, Verdict::New);
            row.now_trials = r.trials;
            row.now_rate = Some(r.success_rate);
            row
        })
        .collect()
}

/// Adjusts the tested rows' p-values together, states each row's power and gives its
/// verdict; returns the level power is stated at.
fn judge(rows: &mut [RegressRow], o: &GateOptions) -> f64 {
    let tested: Vec<usize> = (0..rows.len())
        .filter(|&i| rows[i].p_value.is_some())
        .collect();
    // One family: every row's success test and every measure's, in row order.
    let mut p: Vec<f64> = Vec::new();
    for r in rows.iter() {
        p.extend(r.p_value);
        p.extend(r.measures.iter().filter_map(|m| m.p_value));
    }
    let mut adjusted = o.correction.adjust(&p).into_iter();
    for r in rows.iter_mut() {
        if r.p_value.is_some() {
            r.p_adjusted = adjusted.next();
        }
        for m in r.measures.iter_mut().filter(|m| m.p_value.is_some()) {
            m.p_adjusted = adjusted.next();
        }
    }
    let power_level = match o.correction {
        Correction::None => o.alpha,
        _ => o.alpha / p.len().max(1) as f64,
    };
    for r in rows.iter_mut() {
        for m in &mut r.measures {
            m.judge(power_level, o.alpha);
        }
    }
    for &i in &tested {
        let (mdd, need) = power_of(&rows[i], power_level, o.min_detectable_drop);
        let r = &mut rows[i];
        r.detectable_drop = mdd;
        r.trials_needed = need;
        let have = r.paired.map_or(r.now_trials, |c| c.pairs);
        r.verdict = if r.p_adjusted.is_some_and(|p| p < o.alpha) {
            Verdict::Drop
        } else if r.measures.iter().any(|m| m.worse_beyond_margin) {
            Verdict::Worse
        } else if o.floor.is_some_and(|f| r.now_rate.is_some_and(|v| v < f)) {
            Verdict::BelowFloor
        } else if o.min_detectable_drop.is_some()
            && (mdd.is_none() || need.is_none_or(|n| n > have))
        {
            Verdict::Underpowered
        } else {
            Verdict::Ok
        };
    }
    power_level
}

/// Compares results with a baseline. `records` and `manifest` are the results' trials
/// and manifest; with the baseline's per-trial results and the same batch seed and
/// settings, rows are compared pair by pair.
pub fn regress(
    base: &Baseline,
    now: &Summary,
    records: &[TrialRecord],
    manifest: Option<&Manifest>,
    o: &GateOptions,
) -> GateReport {
    let mut differences = manifest.map_or_else(Vec::new, |m| base.setting_differences(m));
    if let (Some(then), Some(now)) = (base.provenance.as_ref().map(|p| &p.manifest), manifest)
        && then.overrides != now.overrides
    {
        differences.push(format!(
            "the run's overrides: {} → {}",
            overrides_text(&then.overrides),
            overrides_text(&now.overrides)
        ));
    }
    let index: HashMap<TrialKey, (u64, bool)> = records
        .iter()
        .map(|r| (r.key(), (r.outcome.seed, r.outcome.success)))
        .collect();
    let reason = unpaired_reason(base, manifest).or_else(|| seed_mismatch(base, &index));
    // A baseline without measures compares none: the records' are not taken.
    let measured: row_measures::Measured = records
        .iter()
        .filter(|_| base.measured)
        .map(|r| (r.key(), (r.outcome.seed, trial_measures(&r.outcome))))
        .collect();
    let ctx = row_measures::RowContext {
        base,
        records,
        measured: &measured,
        paired: reason.is_none(),
        settings: &o.measures,
        manifest,
        alpha: o.alpha,
    };
    let mut ungated = std::collections::BTreeSet::new();
    let mut rows: Vec<RegressRow> = base
        .rows
        .iter()
        .map(|b| {
            let pairs = reason
                .is_none()
                .then(|| pair_row(base, b, &index))
                .flatten();
            let found = b.find(&now.rows);
            let mut row = compare_row(b, found, pairs);
            if found.is_some() && base.measured {
                let (tests, skipped) = row_measures::row_tests(b, &ctx);
                row.measures = tests;
                ungated.extend(skipped);
            }
            row
        })
        .collect();
    rows.extend(new_rows(base, now));
    let power_level = judge(&mut rows, o);
    let passed = rows
        .iter()
        .all(|r| r.verdict == Verdict::Ok || (r.verdict == Verdict::New && !o.fail_on_new));
    let pairing = match reason {
        Some(reason) => Pairing::Unpaired { reason },
        None => Pairing::Paired {
            pairs: rows.iter().filter_map(|r| r.paired.map(|c| c.pairs)).sum(),
        },
    };
    GateReport {
        passed,
        alpha: o.alpha,
        correction: o.correction,
        floor: o.floor,
        power_level,
        pairing,
        setting_differences: differences,
        rows,
        ungated_measures: ungated.into_iter().collect(),
        measures_note: (!base.measured).then(row_measures::unmeasured_note),
    }
}

/// Overrides as compact JSON (`{}` for none), for the gate's reasons.
fn overrides_text(o: &forkbench_trial::trial::Overrides) -> String {
    serde_json::to_string(o).unwrap_or_default()
}
