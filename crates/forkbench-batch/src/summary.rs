//! Batch summaries: success rates with Wilson intervals, failure counts and entry errors per scenario × planner × tracker.

use std::collections::BTreeMap;
use std::path::Path;

use serde::{Deserialize, Serialize};

use super::{BatchError, TrialRecord};
use crate::stats::{Z95, percentile_sorted, wilson};
use forkbench_trial::outcome::Failure;
use forkbench_trial::text::md_cell;

/// Success statistics of one scenario × planner × tracker.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SummaryRow {
    pub scenario: String,
    pub planner: String,
    /// Summaries written before trackers were pluggable have none: pure pursuit.
    #[serde(default = "pure_pursuit")]
    pub tracker: String,
    /// Replanning on new pallet estimates (false: plan once, the papers' mode).
    #[serde(default)]
    pub replan: bool,
    pub trials: u64,
    pub successes: u64,
    pub success_rate: f64,
    /// Wilson 95 % interval of the success rate.
    pub ci95_low: f64,
    pub ci95_high: f64,
    /// Failed trials by first failed criterion.
    pub failures: BTreeMap<String, u64>,
    /// |lateral| and |heading| error at entry, over trials whose forks reached the face.
    pub lateral_error_mean_m: Option<f64>,
    pub lateral_error_p95_m: Option<f64>,
    pub heading_error_mean_rad: Option<f64>,
    pub heading_error_p95_rad: Option<f64>,
    /// Median |lateral error| of the estimate the truck last aimed at, over trials that
    /// had one: what a pallet-noise scale moves.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub estimate_error_median_m: Option<f64>,
    /// Median of the trials' mean localisation error: what a localisation-noise scale
    /// moves.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub localization_error_median_m: Option<f64>,
    /// Sum of trial wall times (CPU-side cost, not elapsed time).
    pub wall_time_total_s: f64,
    /// Missions: success per leg, over the trials that reached the leg.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub legs: Vec<LegSummary>,
    /// Handling cycles: success per phase (the pick, lift, …), over the trials that
    /// reached the phase.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub phases: Vec<LegSummary>,
    /// People and safety fields: stops, false trips, slowdowns, contacts (rows whose
    /// scenario has them).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub safety: Option<super::SafetySummary>,
    /// The reliability the row demonstrates, as a success-run test states it (absent in
    /// summaries written before it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub success_run: Option<crate::success_run::SuccessRun>,
    /// Where the row's profiled trials spent their time, summed (`batch --profile`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub profile: Option<forkbench_core::profile::Profile>,
}

/// Success of one mission leg (or cycle phase) across a row's trials.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LegSummary {
    pub name: String,
    /// Trials that reached this leg (earlier legs done).
    pub attempted: u64,
    pub done: u64,
    pub success_rate: f64,
    pub ci95_low: f64,
    pub ci95_high: f64,
}

/// Per-stage counts (legs or phases): (name, attempted, done) by index.
fn count_stages<'a>(
    acc: &mut Vec<(String, u64, u64)>,
    stages: impl Iterator<Item = (&'a str, bool)>,
) {
    for (i, (name, success)) in stages.enumerate() {
        if acc.len() <= i {
            acc.push((name.to_owned(), 0, 0));
        }
        acc[i].1 += 1;
        acc[i].2 += u64::from(success);
    }
}

fn leg_summaries(acc: Vec<(String, u64, u64)>) -> Vec<LegSummary> {
    acc.into_iter()
        .map(|(name, n, k)| {
            let (lo, hi) = wilson(k, n, Z95);
            LegSummary {
                name,
                attempted: n,
                done: k,
                success_rate: k as f64 / n.max(1) as f64,
                ci95_low: lo,
                ci95_high: hi,
            }
        })
        .collect()
}

/// A batch's summary.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    pub trials: u64,
    pub successes: u64,
    pub rows: Vec<SummaryRow>,
    /// Replanning against planning once, paired, for every row run in both modes.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub replanning: Vec<super::ModePairs>,
    /// Where every profiled trial's time went, summed over the rows (`batch --profile`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub profile: Option<forkbench_core::profile::Profile>,
    /// How, where and with what the batch ran (absent in summaries derived from records alone).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub provenance: Option<super::Provenance>,
}

/// One summary row's tallies while records are read.
#[derive(Default)]
struct Acc {
    n: u64,
    k: u64,
    failures: BTreeMap<String, u64>,
    lat: Vec<f64>,
    head: Vec<f64>,
    wall: Vec<f64>,
    legs: Vec<(String, u64, u64)>,
    phases: Vec<(String, u64, u64)>,
    est: Vec<f64>,
    loc: Vec<f64>,
    safety: super::safety_summary::SafetyAcc,
    profile: Option<forkbench_core::profile::Profile>,
}

impl Acc {
    fn add(&mut self, o: &forkbench_trial::TrialOutcome) {
        self.n += 1;
        if o.success {
            self.k += 1;
        } else {
            let name = o
                .failure
                .as_ref()
                .map_or("unknown", Failure::name)
                .to_owned();
            *self.failures.entry(name).or_default() += 1;
        }
        if let Some(v) = o.lateral_error_m.filter(|v| v.is_finite()) {
            self.lat.push(v.abs());
        }
        if let Some(v) = o.heading_error_rad.filter(|v| v.is_finite()) {
            self.head.push(v.abs());
        }
        if let Some(v) = o.estimate_lateral_error_m.filter(|v| v.is_finite()) {
            self.est.push(v.abs());
        }
        if o.fixes > 0 && o.localization_error_mean_m.is_finite() {
            self.loc.push(o.localization_error_mean_m);
        }
        self.wall.push(o.wall_time_ms);
        count_stages(
            &mut self.legs,
            o.legs.iter().map(|l| (l.name.as_str(), l.success)),
        );
        count_stages(
            &mut self.phases,
            o.phases.iter().map(|p| (p.name.as_str(), p.success)),
        );
        if let Some(s) = &o.safety {
            self.safety.add(s);
        }
        if let Some(p) = &o.profile {
            forkbench_core::profile::Profile::add_into(&mut self.profile, p);
        }
    }
}

/// Summarises records; order-independent (values are sorted before any sum). The
/// success runs are stated at the default confidence and target.
pub fn summarize(records: &[TrialRecord]) -> Summary {
    summarize_with(records, Default::default())
}

/// [`summarize`], the success runs stated at `target` (a batch's
/// `--success-confidence` and `--success-reliability`).
pub fn summarize_with(
    records: &[TrialRecord],
    target: crate::success_run::SuccessTarget,
) -> Summary {
    let mut groups: BTreeMap<(String, String, String, bool), Acc> = BTreeMap::new();
    for r in records {
        let o = &r.outcome;
        groups
            .entry((
                o.scenario.clone(),
                o.planner.clone(),
                o.tracker.clone(),
                r.replan.unwrap_or(false),
            ))
            .or_default()
            .add(o);
    }
    let mean = |v: &[f64]| (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64);
    let rows: Vec<SummaryRow> = groups
        .into_iter()
        .map(|((scenario, planner, tracker, replan), mut a)| {
            a.lat.sort_by(f64::total_cmp);
            a.head.sort_by(f64::total_cmp);
            a.wall.sort_by(f64::total_cmp);
            a.est.sort_by(f64::total_cmp);
            a.loc.sort_by(f64::total_cmp);
            let (lo, hi) = wilson(a.k, a.n, Z95);
            SummaryRow {
                scenario,
                planner,
                tracker,
                replan,
                trials: a.n,
                successes: a.k,
                success_rate: a.k as f64 / a.n as f64,
                ci95_low: lo,
                ci95_high: hi,
                failures: a.failures,
                lateral_error_mean_m: mean(&a.lat),
                lateral_error_p95_m: percentile_sorted(&a.lat, 0.95),
                heading_error_mean_rad: mean(&a.head),
                heading_error_p95_rad: percentile_sorted(&a.head, 0.95),
                estimate_error_median_m: percentile_sorted(&a.est, 0.5),
                localization_error_median_m: percentile_sorted(&a.loc, 0.5),
                wall_time_total_s: a.wall.iter().sum::<f64>() / 1e3,
                legs: leg_summaries(a.legs),
                phases: leg_summaries(a.phases),
                safety: a.safety.finish(),
                success_run: Some(crate::success_run::success_run(a.k, a.n, target)),
                profile: a.profile,
            }
        })
        .collect();
    Summary {
        profile: forkbench_core::profile::Profile::sum(
            rows.iter().filter_map(|r| r.profile.as_ref()),
        ),
        trials: rows.iter().map(|r| r.trials).sum(),
        successes: rows.iter().map(|r| r.successes).sum(),
        rows,
        replanning: super::mode_pairs(records),
        provenance: None,
    }
}

impl Summary {
    /// The success table as markdown.
    pub fn markdown(&self) -> String {
        let mut s = String::from(
            "| scenario | planner | tracker | mode | trials | successes | success rate | 95 % CI (Wilson) | failures | lateral mean / p95 (mm) | heading mean / p95 (°) | wall time, sum (s) |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n",
        );
        let mm = |v: Option<f64>| v.map_or("–".to_owned(), |v| format!("{:.1}", v * 1e3));
        let deg = |v: Option<f64>| v.map_or("–".to_owned(), |v| format!("{:.2}", v.to_degrees()));
        for r in &self.rows {
            let failures = if r.failures.is_empty() {
                "–".to_owned()
            } else {
                r.failures
                    .iter()
                    .map(|(k, v)| format!("{k} {v}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            };
            s.push_str(&format!(
                "| {} | {} | {} | {} | {} | {} | {:.1} % | {:.1}–{:.1} % | {} | {} / {} | {} / {} | {:.2} |\n",
                md_cell(&r.scenario),
                md_cell(&r.planner),
                md_cell(&r.tracker),
                mode_name(r.replan),
                r.trials,
                r.successes,
                100.0 * r.success_rate,
                100.0 * r.ci95_low,
                100.0 * r.ci95_high,
                failures,
                mm(r.lateral_error_mean_m),
                mm(r.lateral_error_p95_m),
                deg(r.heading_error_mean_rad),
                deg(r.heading_error_p95_rad),
                r.wall_time_total_s
            ));
        }
        s.push_str(&format!(
            "\n{} trials, {} successes ({:.1} %)\n",
            self.trials,
            self.successes,
            100.0 * self.successes as f64 / self.trials.max(1) as f64
        ));
        let modes: Vec<bool> = [false, true]
            .into_iter()
            .filter(|m| self.rows.iter().any(|r| r.replan == *m))
            .collect();
        if modes.len() > 1 {
            for m in modes {
                let (n, k) = self
                    .rows
                    .iter()
                    .filter(|r| r.replan == m)
                    .fold((0, 0), |(n, k), r| (n + r.trials, k + r.successes));
                s.push_str(&format!(
                    "{}: {k} of {n} ({:.1} %)\n",
                    mode_name(m),
                    100.0 * k as f64 / n.max(1) as f64
                ));
            }
        }
        s.push_str(&super::mode_pairs_markdown(&self.replanning));
        s.push_str(&self.legs_markdown());
        s.push_str(&self.phases_markdown());
        s.push_str(&super::safety_summary::markdown(&self.rows));
        s.push_str(&crate::success_run::markdown(&self.rows));
        s
    }
}

impl Summary {
    /// The mission legs' success table (empty without missions).
    fn legs_markdown(&self) -> String {
        self.stages_markdown(
            "Mission legs (a trial counts for a leg once the legs before it are done)",
            "leg",
            |r| &r.legs,
        )
    }

    /// The cycle phases' success table (empty without phases after the pick).
    fn phases_markdown(&self) -> String {
        self.stages_markdown(
            "Phases (a trial counts for a phase once the phases before it succeeded)",
            "phase",
            |r| &r.phases,
        )
    }

    /// A success table of stages (legs or phases) per row, under `title`.
    fn stages_markdown(
        &self,
        title: &str,
        column: &str,
        stages: fn(&SummaryRow) -> &[LegSummary],
    ) -> String {
        let rows: Vec<_> = self.rows.iter().filter(|r| !stages(r).is_empty()).collect();
        if rows.is_empty() {
            return String::new();
        }
        let mut s = format!(
            "\n{title}:\n\n| scenario | planner | tracker | mode | {column} | attempted | done | success rate | 95 % CI (Wilson) |\n|---|---|---|---|---|---|---|---|---|\n",
        );
        for r in rows {
            for l in stages(r) {
                s.push_str(&format!(
                    "| {} | {} | {} | {} | {} | {} | {} | {:.1} % | {:.1}–{:.1} % |\n",
                    md_cell(&r.scenario),
                    md_cell(&r.planner),
                    md_cell(&r.tracker),
                    mode_name(r.replan),
                    md_cell(&l.name),
                    l.attempted,
                    l.done,
                    100.0 * l.success_rate,
                    100.0 * l.ci95_low,
                    100.0 * l.ci95_high
                ));
            }
        }
        s
    }
}

/// How a row's trials handled new pallet estimates.
pub fn mode_name(replan: bool) -> &'static str {
    if replan { "replan" } else { "plan once" }
}

pub(super) fn pure_pursuit() -> String {
    "pure_pursuit".to_owned()
}

pub(super) fn write_summary(dir: &Path, s: &Summary) -> Result<(), BatchError> {
    let text =
        serde_json::to_string_pretty(s).map_err(|e| BatchError::Internal(e.to_string()))? + "\n";
    super::write_atomic(&dir.join("summary.json"), text.as_bytes())?;
    super::write_atomic(&dir.join("summary.md"), s.markdown().as_bytes())
}
