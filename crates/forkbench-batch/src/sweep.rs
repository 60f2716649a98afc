//! Noise sweeps (one batch per scale of a noise knob) and the choice of a batch's trials to record.

use std::collections::{BTreeMap, VecDeque};
use std::path::{Path, PathBuf};

use super::{BatchSpec, Summary, TrialRecord};
use forkbench_trial::scenario::{Case, Scenario};
use forkbench_trial::text::md_cell;
use forkbench_trial::trial::{NOISE_KNOBS, Overrides, TRUCK_KNOBS, TrialOptions, truck_path};

/// One point of a finished sweep as `sweep.json` holds it.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct SweepResult {
    /// The knob swept ([`forkbench_trial::trial::NOISE_KNOBS`]); sweeps written before
    /// there were several swept the pallet noise.
    #[serde(default = "pallet_noise")]
    pub knob: String,
    /// Its scale at this point.
    #[serde(alias = "pallet_noise")]
    pub value: f64,
    pub summary: Summary,
}

fn pallet_noise() -> String {
    "pallet_noise".into()
}

/// Largest `sweep.json` read.
const MAX_SWEEP_BYTES: u64 = 256 << 20;

/// A sweep: the knob (a noise scale of [`NOISE_KNOBS`], or a truck setting of
/// [`TRUCK_KNOBS`]) and the values it takes, in order.
#[derive(Debug, Clone, PartialEq)]
pub struct Sweep {
    pub knob: String,
    pub values: Vec<f64>,
}

impl Sweep {
    /// `knob=v1,v2,…` as `--sweep` takes it, every value in the knob's range.
    pub fn parse(text: &str) -> Result<Self, super::BatchError> {
        let bad = |why: String| super::BatchError::Setting(format!("--sweep {text:?}: {why}"));
        let (knob, values) = text
            .split_once('=')
            .ok_or_else(|| bad("expected KNOB=V1,V2,…".into()))?;
        let knob = knob.trim();
        if !NOISE_KNOBS.contains(&knob) && truck_path(knob).is_none() {
            let truck: Vec<&str> = TRUCK_KNOBS.iter().map(|(k, _)| *k).collect();
            return Err(bad(format!(
                "unknown knob {knob:?} (noise scales: {}; truck settings: {})",
                NOISE_KNOBS.join(", "),
                truck.join(", ")
            )));
        }
        let values = values
            .split(',')
            .map(|v| {
                let x: f64 = v
                    .trim()
                    .parse()
                    .map_err(|_| bad(format!("{v:?} is not a number")))?;
                // The same range check as every run's overrides.
                let mut point = Overrides::default();
                point.set_scale(knob, x);
                point.validate().map_err(|e| bad(e.to_string()))?;
                Ok(x)
            })
            .collect::<Result<Vec<f64>, super::BatchError>>()?;
        Ok(Self {
            knob: knob.to_owned(),
            values,
        })
    }
}

/// Writes a finished sweep: `sweep.md` (the table) and `sweep.json` (every point's
/// summary), each atomically; returns the table.
pub fn write_sweep(
    out: &Path,
    knob: &str,
    points: &[(f64, Summary)],
) -> Result<String, super::BatchError> {
    let text = sweep_markdown(knob, points);
    super::write_atomic(&out.join("sweep.md"), text.as_bytes())?;
    let results: Vec<SweepResult> = points
        .iter()
        .map(|(v, s)| SweepResult {
            knob: knob.to_owned(),
            value: *v,
            summary: s.clone(),
        })
        .collect();
    let json = serde_json::to_string_pretty(&results)
        .map_err(|e| super::BatchError::Internal(format!("serialising the sweep: {e}")))?;
    super::write_atomic(&out.join("sweep.json"), (json + "\n").as_bytes())?;
    Ok(text)
}

/// Reads the knob and points of the sweep in `dir` (its `sweep.json`).
pub fn read_sweep(dir: &Path) -> Result<(String, Vec<(f64, Summary)>), super::BatchError> {
    let path = dir.join("sweep.json");
    let text = super::read_regular(&path, MAX_SWEEP_BYTES)?;
    let results: Vec<SweepResult> = serde_json::from_str(&text)
        .map_err(|e| super::BatchError::Content(format!("{}: not a sweep: {e}", path.display())))?;
    let knob = results
        .first()
        .map_or_else(pallet_noise, |r| r.knob.clone());
    Ok((
        knob,
        results.into_iter().map(|r| (r.value, r.summary)).collect(),
    ))
}

/// One point of a noise sweep: the batch to run and where its results go.
#[derive(Debug, Clone)]
pub struct SweepPoint {
    pub value: f64,
    pub spec: BatchSpec,
    pub dir: PathBuf,
}

/// The batches of a sweep: `spec` with the knob at each scale, each in
/// `out/<knob>-<scale>/`. The trial seeds do not depend on the scale, so the points are
/// paired trial by trial.
pub fn sweep_points(spec: &BatchSpec, out: &Path, sweep: &Sweep) -> Vec<SweepPoint> {
    sweep
        .values
        .iter()
        .map(|&v| {
            let mut s = spec.clone();
            s.overrides.set_scale(&sweep.knob, v);
            SweepPoint {
                value: v,
                spec: s,
                dir: out.join(format!("{}-{v}", sweep.knob)),
            }
        })
        .collect()
}

/// A sweep's success rates and the errors the knob moves, as markdown: one line per
/// scenario × planner × tracker × mode × scale.
pub fn sweep_markdown(knob: &str, points: &[(f64, Summary)]) -> String {
    let column = if NOISE_KNOBS.contains(&knob) {
        format!("{} scale", knob.replace('_', " "))
    } else {
        knob.to_owned()
    };
    let mut s = format!(
        "| scenario | planner | tracker | mode | {column} | trials | success rate | 95 % CI | estimate error, median (mm) | localisation error, median (mm) |\n|---|---|---|---|---|---|---|---|---|---|\n"
    );
    let mut rows: Vec<(f64, &super::SummaryRow)> = points
        .iter()
        .flat_map(|(v, sum)| sum.rows.iter().map(move |r| (*v, r)))
        .collect();
    rows.sort_by(|a, b| {
        let key = |r: &super::SummaryRow| {
            (
                r.scenario.clone(),
                r.planner.clone(),
                r.tracker.clone(),
                r.replan,
            )
        };
        key(a.1).cmp(&key(b.1)).then(a.0.total_cmp(&b.0))
    });
    let mm = |v: Option<f64>| v.map_or("–".to_owned(), |v| format!("{:.1}", v * 1e3));
    for (v, r) in rows {
        s.push_str(&format!(
            "| {} | {} | {} | {} | {v} | {} | {:.1} % | {:.1}–{:.1} % | {} | {} |\n",
            md_cell(&r.scenario),
            md_cell(&r.planner),
            md_cell(&r.tracker),
            super::mode_name(r.replan),
            r.trials,
            100.0 * r.success_rate,
            100.0 * r.ci95_low,
            100.0 * r.ci95_high,
            mm(r.estimate_error_median_m),
            mm(r.localization_error_median_m),
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
        BTreeMap<&'r str, BTreeMap<Option<bool>, BTreeMap<String, Vec<&'r TrialRecord>>>>,
    >;
    let mut groups: Groups = BTreeMap::new();
    for r in records {
        let o = &r.outcome;
        groups
            .entry(o.scenario.clone())
            .or_default()
            .entry(o.failure.as_ref().map_or("success", |f| f.name()))
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
