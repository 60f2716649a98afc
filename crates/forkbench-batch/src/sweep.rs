//! Noise sweeps (one batch per pallet-noise scale) and the choice of a batch's trials to record.

use std::collections::{BTreeMap, VecDeque};
use std::path::{Path, PathBuf};

use super::{BatchSpec, Summary, TrialRecord};
use forkbench_trial::scenario::{Case, Scenario};
use forkbench_trial::trial::TrialOptions;

/// One point of a finished sweep as `sweep.json` holds it.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct SweepResult {
    pub pallet_noise: f64,
    pub summary: Summary,
}

/// Largest `sweep.json` read.
const MAX_SWEEP_BYTES: u64 = 256 << 20;

/// Writes a finished sweep: `sweep.md` (the table) and `sweep.json` (every point's
/// summary), each atomically; returns the table.
pub fn write_sweep(out: &Path, points: &[(f64, Summary)]) -> Result<String, super::BatchError> {
    let text = sweep_markdown(points);
    super::write_atomic(&out.join("sweep.md"), text.as_bytes())?;
    let results: Vec<SweepResult> = points
        .iter()
        .map(|(v, s)| SweepResult {
            pallet_noise: *v,
            summary: s.clone(),
        })
        .collect();
    let json = serde_json::to_string_pretty(&results)
        .map_err(|e| super::BatchError::Invalid(format!("serialising the sweep: {e}")))?;
    super::write_atomic(&out.join("sweep.json"), (json + "\n").as_bytes())?;
    Ok(text)
}

/// Reads the points of the sweep in `dir` (its `sweep.json`).
pub fn read_sweep(dir: &Path) -> Result<Vec<(f64, Summary)>, super::BatchError> {
    let path = dir.join("sweep.json");
    let text = super::read_regular(&path, MAX_SWEEP_BYTES)?;
    let results: Vec<SweepResult> = serde_json::from_str(&text)
        .map_err(|e| super::BatchError::Invalid(format!("{}: not a sweep: {e}", path.display())))?;
    Ok(results
        .into_iter()
        .map(|r| (r.pallet_noise, r.summary))
        .collect())
}

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
    let chosen: Vec<&TrialRecord> = records
        .iter()
        .filter(|r| match choice {
            RecordChoice::None => false,
            RecordChoice::Failures => !r.outcome.success,
            RecordChoice::All => true,
        })
        .collect();
    spread(chosen, max)
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
        .collect()
}

/// At most `max` of `records`, spread over scenario, then first failed criterion, then
/// mode, then case: groups are interleaved at each level (one scenario after another, within
/// one the failures in turn, …) and one trial is taken from each group in turn, so the
/// recordings show the different ways trials fail, not the first cases of one scenario.
fn spread(records: Vec<&TrialRecord>, max: usize) -> Vec<&TrialRecord> {
    type Groups<'r> = BTreeMap<
        String,
        BTreeMap<&'static str, BTreeMap<Option<bool>, BTreeMap<String, Vec<&'r TrialRecord>>>>,
    >;
    let mut groups: Groups = BTreeMap::new();
    for r in records {
        let o = &r.outcome;
        groups
            .entry(o.scenario.clone())
            .or_default()
            .entry(o.failure.map_or("success", |f| f.name()))
            .or_default()
            .entry(r.replan)
            .or_default()
            .entry(o.case.clone())
            .or_default()
            .push(r);
    }
    let ordered: Vec<Vec<&TrialRecord>> = interleave(
        groups
            .into_values()
            .map(|fails| {
                interleave(
                    fails
                        .into_values()
                        .map(|modes| {
                            interleave(
                                modes
                                    .into_values()
                                    .map(|cases| cases.into_values().collect())
                                    .collect(),
                            )
                        })
                        .collect(),
                )
            })
            .collect(),
    );
    let mut queues: Vec<VecDeque<&TrialRecord>> = ordered
        .into_iter()
        .map(|mut g| {
            g.sort_by_key(|r| r.key());
            g.into()
        })
        .collect();
    let mut out = Vec::new();
    while out.len() < max && queues.iter().any(|q| !q.is_empty()) {
        for q in &mut queues {
            if out.len() == max {
                break;
            }
            if let Some(r) = q.pop_front() {
                out.push(r);
            }
        }
    }
    out
}

/// The lists' items taken in turn: the first of each list, then the second of each, …
fn interleave<T>(lists: Vec<Vec<T>>) -> Vec<T> {
    let mut iters: Vec<std::vec::IntoIter<T>> = lists.into_iter().map(Vec::into_iter).collect();
    let mut out = Vec::new();
    loop {
        let before = out.len();
        for it in &mut iters {
            out.extend(it.next());
        }
        if out.len() == before {
            return out;
        }
    }
}
