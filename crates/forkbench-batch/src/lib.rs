//! Monte-Carlo batches of pick trials: scenario × case × planner × tracker × trial in parallel, streamed to JSON lines, sharded, merged, summarised, gated against baselines, exported.

use std::collections::HashSet;
use std::fs::OpenOptions;
use std::io::{BufWriter, Write as _};
use std::path::Path;
use std::sync::Mutex;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

mod baseline;
mod candidate;
mod case_grid;
mod checks;
mod compare;
pub mod detect_curve;
pub mod detect_eval;
pub mod detect_wrong;
mod export;
mod gate;
mod guard;
pub mod junit;
mod manifest;
mod mode_pairs;
mod modes;
mod order;
mod outdir;
pub mod prints;
mod provenance;
pub mod rank_tests;
pub mod rare;
mod rare_store;
mod records_run;
mod replay;
mod safety_summary;
mod seed;
pub mod sequential;
mod shard;
pub mod stats;
mod store;
pub mod success_run;
mod summary;
mod sweep;
mod verdicts;

pub use baseline::{Baseline, BaselineRow, BaselineTrial, MAX_BASELINE_BYTES};
pub use candidate::{Mapping, map_components};
pub use case_grid::{CaseCells, ErrorGroup, case_grids, error_groups};
pub use compare::{CompareOptions, CompareReport, CompareRow, Discordant, compare, compare_apart};
pub use export::write_csv;
pub use gate::num as gate_num;
pub use gate::{
    DEFAULT_ALPHA, GateOptions, GateReport, MeasureSetting, MeasureSettingError, MeasureSettings,
    MeasureTest, PairCounts, Pairing, RegressRow, Verdict, Worse, paired_trials_needed, regress,
    trial_measures,
};
pub use guard::guarded;
pub use manifest::{DirLock, Manifest, build_commit};
pub use mode_pairs::{ModePairs, mode_pairs, mode_pairs_markdown};
pub use modes::ReplanModes;
pub use outdir::batch_files;
pub use provenance::{Provenance, RunEntry, rfc3339, scenario_differences};
pub use records_run::run_records;
pub use replay::Replay;
pub use safety_summary::SafetySummary;
pub use seed::{SEED_SCHEME, trial_seed};
pub use shard::{ShardArg, merge_inputs, parse_shard, resolve_shard, shard_dir};
pub use store::{load_batch, load_results, merge, read_numbered, read_records};
pub use summary::{LegSummary, Summary, SummaryRow, mode_name, summarize, summarize_with};
pub use sweep::{
    RecordChoice, RecordJob, Sweep, SweepPoint, SweepResult, read_sweep, sweep_markdown,
    sweep_points, trials_to_record, write_sweep,
};

use store::{check_unique, read_records_torn, rewrite_records};
use summary::write_summary;

use forkbench_trial::outcome::TrialOutcome;
use forkbench_trial::scenario::Scenario;
use forkbench_trial::trial::{Overrides, TrialOptions, run_trial};

/// Largest `trials.jsonl` read (by `replay`, `regress`, `baseline`, `merge`, a resume).
pub const MAX_RECORDS_BYTES: u64 = 1 << 30;

/// Most worker threads a batch starts.
pub const MAX_JOBS: usize = 256;

/// What a batch runs.
#[derive(Debug, Clone)]
pub struct BatchSpec {
    pub scenarios: Vec<Scenario>,
    /// Planners to run every case with, by name; empty = each scenario's own planner.
    pub planners: Vec<String>,
    /// Trackers to run every case with, by name; empty = each scenario's own tracker.
    pub trackers: Vec<String>,
    /// Trials per scenario × case × planner × tracker.
    pub trials: u64,
    pub seed: u64,
    /// This shard's index and the shard count (0/1 = everything).
    pub shard: (u64, u64),
    /// Noise scales and sensing models every trial runs with (recorded with each trial).
    pub overrides: Overrides,
    pub replan: Option<bool>,
    /// Run every trial both planning once (the papers' mode) and replanning on new
    /// estimates, with the same seeds; `replan` is then ignored.
    pub compare_replanning: bool,
    /// Discard the output directory's trials when they were run with other settings,
    /// instead of refusing to resume.
    pub force_new: bool,
    /// The confidence and reliability the summary states success runs at.
    pub success_run: success_run::SuccessTarget,
    /// Gather each trial's profile (where its time went) into its record and the
    /// summary; outcomes are the same either way.
    pub profile: bool,
}

/// Why a batch could not run or be read.
#[derive(Debug, thiserror::Error)]
pub enum BatchError {
    /// The reason is in the message, not chained as a source: `{:#}` would print it twice.
    #[error("{path}: {cause}")]
    Io { path: String, cause: std::io::Error },
    #[error("{path}:{line}: {message}")]
    Record {
        path: String,
        line: usize,
        message: String,
    },
    /// A setting, flag or argument out of its range or malformed (trials, shard, jobs,
    /// a gate's drop, a sweep, an event, a replay's line).
    #[error("{0}")]
    Setting(String),
    /// A batch directory not in a state the command can use: not empty and not a batch's,
    /// another batch's results, locked by another process, a merge's inputs that do not
    /// belong together.
    #[error("{0}")]
    Directory(String),
    /// A file whose content is not what it should be: records that contradict their
    /// manifest, over a size cap, a file of another kind.
    #[error("{0}")]
    Content(String),
    /// The rare-event estimator stopped (see `forkbench_rare::RareError`).
    #[error("{0}")]
    Rare(String),
    /// Something that should not fail did, before any output was written (serialising a
    /// result, starting the thread pool).
    #[error("{0}")]
    Internal(String),
    #[error(transparent)]
    File(#[from] forkbench_core::files::FileError),
    /// A scenario the batch names could not be loaded or has no such case.
    #[error(transparent)]
    Trial(#[from] forkbench_trial::ScenarioError),
}

/// Writes an output file atomically (see [`forkbench_core::files::write_atomic`]).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), BatchError> {
    Ok(forkbench_core::files::write_atomic(path, bytes)?)
}

/// A success rate given as a floor must lie in [0, 1].
pub fn check_floor(floor: Option<f64>) -> Result<(), BatchError> {
    match floor {
        Some(f) if !(0.0..=1.0).contains(&f) => Err(BatchError::Setting(format!(
            "floor {f}: must be a success rate between 0 and 1"
        ))),
        _ => Ok(()),
    }
}

/// A significance level must lie strictly between 0 and 1.
pub fn check_alpha(alpha: f64) -> Result<(), BatchError> {
    if alpha > 0.0 && alpha < 1.0 {
        Ok(())
    } else {
        Err(BatchError::Setting(format!(
            "alpha {alpha}: must lie strictly between 0 and 1"
        )))
    }
}

/// Reads an input file that must be a regular file of at most `max` bytes.
pub fn read_regular(path: &Path, max: u64) -> Result<String, BatchError> {
    Ok(forkbench_core::files::read_text(path, max)?)
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> BatchError + '_ {
    move |cause| BatchError::Io {
        path: path.display().to_string(),
        cause,
    }
}

/// One line of `trials.jsonl`: the trial index and its outcome.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrialRecord {
    pub trial: u64,
    /// Batch-wide overrides this trial ran with, so `forkbench replay` can repeat it.
    #[serde(flatten)]
    pub overrides: Overrides,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub replan: Option<bool>,
    #[serde(flatten)]
    pub outcome: TrialOutcome,
}

impl TrialRecord {
    /// Options that repeat this trial exactly.
    pub fn options(&self) -> TrialOptions {
        TrialOptions {
            seed: Some(self.outcome.seed),
            planner: Some(self.outcome.planner.clone()),
            tracker: Some(self.outcome.tracker.clone()),
            no_noise: !self.outcome.noise,
            replan: self.replan,
            overrides: self.overrides.clone(),
            wall_budget_s: None,
            // A search's trial had its values given; a batch's drew them, and pinning
            // what it drew gives the same.
            uncertain: self.outcome.uncertain.clone(),
        }
    }
}

/// Identity of one trial in a batch: scenario, case, planner, tracker, replanning, trial
/// index.
pub type TrialKey = (String, String, String, String, bool, u64);

impl TrialRecord {
    pub fn key(&self) -> TrialKey {
        (
            self.outcome.scenario.clone(),
            self.outcome.case.clone(),
            self.outcome.planner.clone(),
            self.outcome.tracker.clone(),
            self.replan.unwrap_or(false),
            self.trial,
        )
    }
}

/// One unit of work.
#[derive(Debug, Clone)]
pub struct Job {
    pub scenario: usize,
    pub case: usize,
    pub planner: String,
    pub tracker: String,
    /// Replanning forced on or off for this job (`None`: the scenario's setting).
    pub replan: Option<bool>,
    pub trial: u64,
}

impl BatchSpec {
    /// Every job of this shard, in a fixed global order (`order::for_each_job`).
    pub fn jobs(&self) -> Vec<Job> {
        let scenarios: Vec<order::ScenarioJobs> = self
            .scenarios
            .iter()
            .map(|s| {
                let (planners, trackers) = self.components_of(s);
                order::ScenarioJobs {
                    cases: s.cases.len(),
                    planners,
                    trackers,
                }
            })
            .collect();
        let mut out = Vec::new();
        order::for_each_job(
            &scenarios,
            &self.replan_modes(),
            self.trials,
            self.shard,
            |j| {
                out.push(Job {
                    scenario: j.scenario,
                    case: j.case,
                    planner: j.planner.to_owned(),
                    tracker: j.tracker.to_owned(),
                    replan: j.mode,
                    trial: j.trial,
                });
            },
        );
        out
    }

    /// The replanning modes every case runs with: both, or the batch's override (or none).
    pub fn replan_modes(&self) -> Vec<Option<bool>> {
        order::modes(self.compare_replanning, self.replan)
    }

    /// Every result row this batch makes (scenario / planner / tracker / mode) and its
    /// trial count.
    pub fn row_sizes(&self) -> Vec<(String, u64)> {
        let mut out = Vec::new();
        for s in &self.scenarios {
            let (planners, trackers) = self.components_of(s);
            for p in &planners {
                for t in &trackers {
                    for m in self.replan_modes() {
                        let mode = mode_name(m.unwrap_or(s.replan.enabled));
                        out.push((
                            format!("{} / {p} / {t} / {mode}", s.name),
                            s.cases.len() as u64 * self.trials,
                        ));
                    }
                }
            }
        }
        out
    }

    /// The planner and tracker names a scenario runs with in this batch.
    fn components_of(&self, s: &Scenario) -> (Vec<String>, Vec<String>) {
        let or_own = |list: &Vec<String>, own: &str| {
            if list.is_empty() {
                vec![own.to_owned()]
            } else {
                list.clone()
            }
        };
        (
            or_own(&self.planners, &s.planner.name),
            or_own(&self.trackers, &s.tracker.name),
        )
    }

    /// The identity of the trial a job runs.
    pub fn key(&self, j: &Job) -> TrialKey {
        let s = &self.scenarios[j.scenario];
        (
            s.name.clone(),
            s.cases[j.case].name.clone(),
            j.planner.clone(),
            j.tracker.clone(),
            j.replan.unwrap_or(s.replan.enabled),
            j.trial,
        )
    }

    /// Runs one job; a panic inside the trial becomes that trial's `error` outcome.
    pub fn run_job(&self, j: &Job) -> TrialRecord {
        let s = &self.scenarios[j.scenario];
        let case = &s.cases[j.case];
        let seed = trial_seed(self.seed, &s.name, &case.name, j.trial);
        let opts = TrialOptions {
            seed: Some(seed),
            planner: Some(j.planner.clone()),
            tracker: Some(j.tracker.clone()),
            no_noise: false,
            replan: j.replan,
            overrides: self.overrides.clone(),
            wall_budget_s: None,
            uncertain: Default::default(),
        };
        let names = (j.planner.as_str(), j.tracker.as_str());
        let run = || run_trial(s, case, &opts);
        let outcome = guarded(s, &case.name, names, seed, || {
            if self.profile {
                forkbench_trial::profiled(run)
            } else {
                run()
            }
        });
        TrialRecord {
            trial: j.trial,
            overrides: self.overrides.clone(),
            // The mode the trial ran in, always written: rows are keyed by it.
            replan: Some(j.replan.unwrap_or(s.replan.enabled)),
            outcome,
        }
    }
}

/// Runs (or resumes) a batch into `dir`: one JSON line per finished trial in
/// `trials.jsonl`, then `summary.json` and `summary.md`. `on_done` sees each finished trial.
pub fn run_batch(
    spec: &BatchSpec,
    dir: &Path,
    jobs: usize,
    on_done: &(dyn Fn(&TrialRecord) + Sync),
) -> Result<Summary, BatchError> {
    spec.check(jobs)?;
    let started = std::time::SystemTime::now();
    if dir.exists() && !dir.is_dir() {
        return Err(BatchError::Directory(format!(
            "{}: exists and is not a directory (the output is a directory)",
            dir.display()
        )));
    }
    std::fs::create_dir_all(dir).map_err(io(dir))?;
    let _lock = DirLock::take(dir)?;
    spec.prepare_dir(dir)?;
    let path = dir.join("trials.jsonl");
    let (existing, torn) = read_records_torn(&path)?;
    check_unique(&existing, &path)?;
    let done: HashSet<_> = existing.iter().map(TrialRecord::key).collect();
    let todo: Vec<Job> = spec
        .jobs()
        .into_iter()
        .filter(|j| !done.contains(&spec.key(j)))
        .collect();
    // Drop a torn or corrupt last line before appending after it.
    let raw_ends_clean = std::fs::read(&path).map_or(true, |b| b.is_empty() || b.ends_with(b"\n"));
    if torn || !raw_ends_clean {
        rewrite_records(&path, &existing)?;
    }
    provenance::log_run(dir, jobs, todo.len() as u64, started)?;
    let file = OpenOptions::new()
        .create(true)
        .append(true)
        .open(&path)
        .map_err(io(&path))?;
    let writer = Mutex::new(BufWriter::new(file));
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs.max(1))
        .build()
        .map_err(|e| BatchError::Internal(format!("thread pool: {e}")))?;
    let write_error: Mutex<Option<std::io::Error>> = Mutex::new(None);
    pool.install(|| {
        // One job per task: rayon's default leaves are long runs of jobs that a thread
        // finishing early cannot steal from, which idles it through a batch's tail.
        todo.par_iter().with_max_len(1).for_each(|j| {
            let rec = spec.run_job(j);
            let line = serde_json::to_string(&rec)
                .unwrap_or_else(|e| format!("{{\"serialisation_error\":\"{e}\"}}"));
            // Flush per line: a crash or Ctrl-C loses nothing already finished.
            let mut w = writer
                .lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner);
            if let Err(e) = writeln!(w, "{line}").and_then(|()| w.flush()) {
                write_error
                    .lock()
                    .unwrap_or_else(std::sync::PoisonError::into_inner)
                    .get_or_insert(e);
            }
            drop(w);
            on_done(&rec);
        });
    });
    // Pooled external planners live in the workers' thread-locals: end them with the batch.
    pool.broadcast(|_| forkbench_plan::external::release_pooled());
    if let Some(e) = write_error
        .into_inner()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
    {
        return Err(io(&path)(e));
    }
    summarize_dir(spec, dir, jobs, started)
}

/// The summary of this batch's records in `dir`, with its provenance, written beside them.
fn summarize_dir(
    spec: &BatchSpec,
    dir: &Path,
    jobs: usize,
    started: std::time::SystemTime,
) -> Result<Summary, BatchError> {
    let wanted: HashSet<_> = spec.jobs().iter().map(|j| spec.key(j)).collect();
    let records: Vec<TrialRecord> = read_records(&dir.join("trials.jsonl"))?
        .into_iter()
        .filter(|r| wanted.contains(&r.key()))
        .collect();
    let mut summary = summarize_with(&records, spec.success_run);
    let provenance = Provenance::collect(Manifest::of(spec)?, jobs, started);
    summary.provenance = Some(provenance.with_runs(provenance::finish_runs(dir)));
    write_summary(dir, &summary)?;
    Ok(summary)
}
