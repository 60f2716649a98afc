//! Replanning against planning once, paired trial by trial: per row run in both modes, the trials only one mode passed.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::TrialRecord;
use crate::stats::mcnemar_two_sided_p;
use forkbench_trial::text::md_cell;

/// One scenario × planner × tracker run in both modes on the same trials and seeds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModePairs {
    pub scenario: String,
    pub planner: String,
    pub tracker: String,
    pub pairs: u64,
    /// Trials planning once passed and replanning failed (replanning broke them), and the
    /// reverse (replanning fixed them).
    pub broke: u64,
    pub fixed: u64,
    /// McNemar's exact two-sided test on the discordant pairs (uncorrected).
    pub p_value: f64,
}

type Key = (String, String, String, String, u64);

/// The paired counts of every row run in both modes, in row order.
pub fn mode_pairs(records: &[TrialRecord]) -> Vec<ModePairs> {
    let mut sides: [BTreeMap<Key, (u64, bool)>; 2] = Default::default();
    for r in records {
        let o = &r.outcome;
        let key = (
            o.scenario.clone(),
            o.planner.clone(),
            o.tracker.clone(),
            o.case.clone(),
            r.trial,
        );
        sides[usize::from(r.replan.unwrap_or(false))].insert(key, (o.seed, o.success));
    }
    let mut rows: BTreeMap<(String, String, String), [u64; 3]> = BTreeMap::new();
    for (k, (seed, once)) in &sides[0] {
        let Some((_, again)) = sides[1].get(k).filter(|(s, _)| s == seed) else {
            continue;
        };
        let c = rows
            .entry((k.0.clone(), k.1.clone(), k.2.clone()))
            .or_default();
        c[0] += 1;
        c[1] += u64::from(*once && !*again);
        c[2] += u64::from(*again && !*once);
    }
    rows.into_iter()
        .map(|((scenario, planner, tracker), c)| ModePairs {
            scenario,
            planner,
            tracker,
            pairs: c[0],
            broke: c[1],
            fixed: c[2],
            p_value: mcnemar_two_sided_p(c[1], c[2]),
        })
        .collect()
}

/// The paired counts as a markdown table (empty when no row ran in both modes).
pub fn mode_pairs_markdown(rows: &[ModePairs]) -> String {
    if rows.is_empty() {
        return String::new();
    }
    let mut s = String::from(
        "\nReplanning against planning once, paired (same trials and seeds; `compare DIR --a plan_once --b replan`):\n\n| scenario | planner | tracker | pairs | replanning broke | replanning fixed | p (McNemar, two-sided) |\n|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        s.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {:.4} |\n",
            md_cell(&r.scenario),
            md_cell(&r.planner),
            md_cell(&r.tracker),
            r.pairs,
            r.broke,
            r.fixed,
            r.p_value
        ));
    }
    s
}
