//! A row's measures gathered for the gate: pairs on the same key and seed, or the two sides' values when unpaired, each tested against its margin.

use std::collections::{BTreeMap, BTreeSet, HashMap};

use super::measure_test::{MeasureTest, Sample, median, push_side, test};
use super::measures::{MeasureSettings, gated};
use crate::{Baseline, BaselineRow, BaselineTrial, TrialKey, TrialRecord};

/// Each result trial's seed and measures, by key.
pub(super) type Measured = HashMap<TrialKey, (u64, BTreeMap<String, f64>)>;

/// What a row's measure tests need besides the row.
pub(super) struct RowContext<'a> {
    pub base: &'a Baseline,
    pub records: &'a [TrialRecord],
    pub measured: &'a Measured,
    pub paired: bool,
    pub settings: &'a MeasureSettings,
    pub manifest: Option<&'a crate::Manifest>,
    pub alpha: f64,
}

/// Whether a baseline trial belongs to `row` (its mode, or plan-once for a row without).
pub(super) fn in_row(row: &BaselineRow, t: &BaselineTrial) -> bool {
    (
        t.scenario.as_str(),
        t.planner.as_str(),
        t.tracker.as_str(),
        t.replan,
    ) == (
        row.scenario.as_str(),
        row.planner.as_str(),
        row.tracker.as_str(),
        row.replan.unwrap_or(false),
    )
}

fn record_in_row(row: &BaselineRow, r: &TrialRecord) -> bool {
    let o = &r.outcome;
    row.holds(
        &o.scenario,
        &o.planner,
        &o.tracker,
        r.replan.unwrap_or(false),
    )
}

/// Every measure's sample in this row.
fn samples(row: &BaselineRow, c: &RowContext<'_>) -> BTreeMap<String, Sample> {
    let trials = c.base.trials.iter().filter(|t| in_row(row, t));
    if c.paired {
        let mut out: BTreeMap<String, Vec<(f64, f64)>> = BTreeMap::new();
        for t in trials {
            let Some((seed, now)) = c.measured.get(&t.key()) else {
                continue;
            };
            if *seed != t.seed {
                continue;
            }
            for (k, b) in &t.measures {
                if let Some(n) = now.get(k) {
                    out.entry(k.clone()).or_default().push((*b, *n));
                }
            }
        }
        return out
            .into_iter()
            .map(|(k, v)| (k, Sample::Paired(v)))
            .collect();
    }
    let mut sides: BTreeMap<String, (Vec<f64>, Vec<f64>)> = BTreeMap::new();
    for t in trials {
        push_side(&mut sides, &t.measures, false);
    }
    for r in c.records.iter().filter(|r| record_in_row(row, r)) {
        if let Some((_, m)) = c.measured.get(&r.key()) {
            push_side(&mut sides, m, true);
        }
    }
    sides
        .into_iter()
        .map(|(k, (base, now))| (k, Sample::Unpaired { base, now }))
        .collect()
}

/// The row's measure tests (uncorrected), and the measures it saw but does not gate.
pub(super) fn row_tests(
    row: &BaselineRow,
    c: &RowContext<'_>,
) -> (Vec<MeasureTest>, BTreeSet<String>) {
    let mut tests = Vec::new();
    let mut ungated = BTreeSet::new();
    for (name, sample) in samples(row, c) {
        let base = sample.baseline_values();
        let m = median(&base);
        match gated(
            &name,
            c.settings,
            tolerances_of(c.manifest, &row.scenario),
            m,
        ) {
            Some(g) => tests.push(test(&name, &g, &sample, (&base, m), c.alpha)),
            None => {
                ungated.insert(name);
            }
        }
    }
    (tests, ungated)
}

/// A scenario's resolved tolerances in the results' manifest, which the default margins
/// take a tenth of.
fn tolerances_of<'a>(
    manifest: Option<&'a crate::Manifest>,
    scenario: &str,
) -> Option<&'a serde_json::Value> {
    manifest?
        .scenarios
        .iter()
        .find(|s| s.name == scenario)?
        .settings
        .get("tolerances")
}

/// Why a baseline without measures is gated on counts alone, and how to mend it.
pub(super) fn unmeasured_note() -> String {
    "the baseline's trials carry no measures (made by an older forkbench, or from counts \
     only), so it is gated on success counts alone; re-make it with `forkbench baseline DIR \
     --out FILE` to gate on the measures too"
        .to_owned()
}
