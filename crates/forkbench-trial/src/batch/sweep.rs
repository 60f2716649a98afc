//! Noise sweeps (one batch per pallet-noise scale) and the choice of a batch's trials to record.

use std::path::{Path, PathBuf};

use super::{BatchSpec, Summary, TrialRecord};
use crate::scenario::{Case, Scenario};
use crate::trial::TrialOptions;

/// One point of a pallet-noise sweep: the batch to run and where its results go.
#[derive(Debug, Clone)]
pub struct SweepPoint {
    pub pallet_noise: f64,
    pub spec: BatchSpec,
    pub dir: PathBuf,
}

/// The batches of a sweep over pallet-estimate σ scales: `spec` at each scale, each in
/// `out/pallet_noise-<scale>/`.
pub fn sweep_points(spec: &BatchSpec, out: &Path, scales: &[f64]) -> Vec<SweepPoint> {
    scales
        .iter()
        .map(|&v| {
            let mut s = spec.clone();
            s.pallet_noise_scale = Some(v);
            SweepPoint {
                pallet_noise: v,
                spec: s,
                dir: out.join(format!("pallet_noise-{v}")),
            }
        })
        .collect()
}

/// A sweep's success rates as markdown: one line per scenario × planner × tracker × scale.
pub fn sweep_markdown(points: &[(f64, Summary)]) -> String {
    let mut s = String::from(
        "| scenario | planner | tracker | pallet noise scale | trials | success rate | 95 % CI |\n|---|---|---|---|---|---|---|\n",
    );
    let mut rows: Vec<(&str, &str, &str, f64, &super::SummaryRow)> = points
        .iter()
        .flat_map(|(v, sum)| {
            sum.rows.iter().map(move |r| {
                (
                    r.scenario.as_str(),
                    r.planner.as_str(),
                    r.tracker.as_str(),
                    *v,
                    r,
                )
            })
        })
        .collect();
    rows.sort_by(|a, b| {
        (a.0, a.1, a.2)
            .cmp(&(b.0, b.1, b.2))
            .then(a.3.total_cmp(&b.3))
    });
    for (sc, p, t, v, r) in rows {
        s.push_str(&format!(
            "| {sc} | {p} | {t} | {v} | {} | {:.1} % | {:.1}–{:.1} % |\n",
            r.trials,
            100.0 * r.success_rate,
            100.0 * r.ci95_low,
            100.0 * r.ci95_high
        ));
    }
    s
}

/// Which of a batch's trials to record.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RecordChoice {
    None,
    Failures,
    All,
}

/// A trial to re-run with recording: trials are deterministic, so the recording is the
/// trial that ran.
#[derive(Debug, Clone)]
pub struct RecordJob<'a> {
    pub scenario: &'a Scenario,
    pub case: &'a Case,
    pub options: TrialOptions,
}

/// The trials to record, at most `max`, the first in key order (scenario, case,
/// planner, tracker, trial).
pub fn trials_to_record<'a>(
    spec: &'a BatchSpec,
    records: &[TrialRecord],
    choice: RecordChoice,
    max: usize,
) -> Vec<RecordJob<'a>> {
    let mut sorted: Vec<&TrialRecord> = records
        .iter()
        .filter(|r| match choice {
            RecordChoice::None => false,
            RecordChoice::Failures => !r.outcome.success,
            RecordChoice::All => true,
        })
        .collect();
    sorted.sort_by_key(|r| r.key());
    sorted
        .into_iter()
        .filter_map(|r| {
            let scenario = spec
                .scenarios
                .iter()
                .find(|s| s.name == r.outcome.scenario)?;
            let case = scenario.case(&r.outcome.case).ok()?;
            Some(RecordJob {
                scenario,
                case,
                options: r.options(),
            })
        })
        .take(max)
        .collect()
}
