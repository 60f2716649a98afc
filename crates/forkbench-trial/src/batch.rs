//! Monte-Carlo batches: scenario × case × planner × trial, in parallel, streamed to JSON lines, summarised, compared.

use std::collections::{BTreeMap, HashSet};
use std::fs::{File, OpenOptions};
use std::io::{BufRead as _, BufReader, BufWriter, Write as _};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use forkbench_plan::PlannerKind;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::outcome::{Failure, TrialOutcome};
use crate::scenario::Scenario;
use crate::stats::{Z95, drop_p_value, percentile_sorted, wilson};
use crate::trial::{TrialOptions, run_trial};

/// What a batch runs.
#[derive(Debug, Clone)]
pub struct BatchSpec {
    pub scenarios: Vec<Scenario>,
    /// Planners to run every case with; empty = each scenario's own planner.
    pub planners: Vec<PlannerKind>,
    /// Trials per scenario × case × planner.
    pub trials: u64,
    pub seed: u64,
    /// This shard's index and the shard count (0/1 = everything).
    pub shard: (u64, u64),
    pub pallet_noise_scale: Option<f64>,
    pub replan: Option<bool>,
}

/// Why a batch could not run or be read.
#[derive(Debug, thiserror::Error)]
pub enum BatchError {
    #[error("{path}: {source}")]
    Io {
        path: String,
        #[source]
        source: std::io::Error,
    },
    #[error("{path}:{line}: {message}")]
    Record {
        path: String,
        line: usize,
        message: String,
    },
    #[error("{0}")]
    Invalid(String),
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> BatchError + '_ {
    move |source| BatchError::Io {
        path: path.display().to_string(),
        source,
    }
}

/// One line of `trials.jsonl`: the trial index and its outcome.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrialRecord {
    pub trial: u64,
    /// Batch-wide overrides this trial ran with, so `forkbench replay` can repeat it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pallet_noise_scale: Option<f64>,
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
            planner: self.outcome.planner.parse().ok(),
            no_noise: !self.outcome.noise,
            pallet_noise_scale: self.pallet_noise_scale,
            replan: self.replan,
        }
    }
}

impl TrialRecord {
    pub fn key(&self) -> (String, String, String, u64) {
        (
            self.outcome.scenario.clone(),
            self.outcome.case.clone(),
            self.outcome.planner.clone(),
            self.trial,
        )
    }
}

/// Seed of one trial from its identity alone, so results do not depend on `--jobs`,
/// sharding or order (FNV-1a over the key, finished with SplitMix64).
pub fn trial_seed(batch_seed: u64, scenario: &str, case: &str, planner: &str, trial: u64) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |bytes: &[u8]| {
        for b in bytes {
            h ^= u64::from(*b);
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
        h ^= 0xff;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    };
    eat(&batch_seed.to_le_bytes());
    eat(scenario.as_bytes());
    eat(case.as_bytes());
    eat(planner.as_bytes());
    eat(&trial.to_le_bytes());
    let mut z = h.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// One unit of work.
#[derive(Debug, Clone)]
pub struct Job {
    pub scenario: usize,
    pub case: usize,
    pub planner: PlannerKind,
    pub trial: u64,
}

impl BatchSpec {
    /// Every job of this shard, in a fixed global order.
    pub fn jobs(&self) -> Vec<Job> {
        let mut out = Vec::new();
        let mut k: u64 = 0;
        for (si, s) in self.scenarios.iter().enumerate() {
            let planners = if self.planners.is_empty() {
                vec![s.planner]
            } else {
                self.planners.clone()
            };
            for ci in 0..s.cases.len() {
                for &p in &planners {
                    for t in 0..self.trials {
                        if k % self.shard.1 == self.shard.0 {
                            out.push(Job {
                                scenario: si,
                                case: ci,
                                planner: p,
                                trial: t,
                            });
                        }
                        k += 1;
                    }
                }
            }
        }
        out
    }

    fn key(&self, j: &Job) -> (String, String, String, u64) {
        let s = &self.scenarios[j.scenario];
        (
            s.name.clone(),
            s.cases[j.case].name.clone(),
            j.planner.name().to_owned(),
            j.trial,
        )
    }

    /// Runs one job; a panic inside the trial becomes that trial's `error` outcome.
    pub fn run_job(&self, j: &Job) -> TrialRecord {
        let s = &self.scenarios[j.scenario];
        let case = &s.cases[j.case];
        let seed = trial_seed(self.seed, &s.name, &case.name, j.planner.name(), j.trial);
        let opts = TrialOptions {
            seed: Some(seed),
            planner: Some(j.planner),
            no_noise: false,
            pallet_noise_scale: self.pallet_noise_scale,
            replan: self.replan,
        };
        let outcome = guarded(s, &case.name, j.planner, seed, || run_trial(s, case, &opts));
        TrialRecord {
            trial: j.trial,
            pallet_noise_scale: self.pallet_noise_scale,
            replan: self.replan,
            outcome,
        }
    }
}

/// Runs `f`, turning a panic into an `error` outcome that carries the message and seed.
pub fn guarded(
    s: &Scenario,
    case: &str,
    planner: PlannerKind,
    seed: u64,
    f: impl FnOnce() -> TrialOutcome,
) -> TrialOutcome {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).unwrap_or_else(|panic| {
        let message = panic
            .downcast_ref::<&str>()
            .map(|s| (*s).to_owned())
            .or_else(|| panic.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "panic with a non-text payload".to_owned());
        error_outcome(
            s,
            case,
            planner,
            seed,
            format!("trial panicked (seed {seed}): {message}"),
        )
    })
}

fn error_outcome(
    s: &Scenario,
    case: &str,
    planner: PlannerKind,
    seed: u64,
    detail: String,
) -> TrialOutcome {
    let mut out = TrialOutcome::blank(&s.name, case, planner.name(), seed, s.noise.enabled);
    out.failure = Some(Failure::Error);
    out.failure_detail = Some(detail);
    out
}

/// Reads `trials.jsonl`. A torn last line (a crash mid-write) is skipped; any other bad
/// line is an error naming the file and line.
pub fn read_records(path: &Path) -> Result<Vec<TrialRecord>, BatchError> {
    let file = match File::open(path) {
        Ok(f) => f,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(io(path)(e)),
    };
    let lines: Vec<String> = BufReader::new(file)
        .lines()
        .collect::<Result<_, _>>()
        .map_err(io(path))?;
    let mut out = Vec::with_capacity(lines.len());
    let last = lines.len();
    for (i, line) in lines.iter().enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        match serde_json::from_str::<TrialRecord>(line) {
            Ok(r) => out.push(r),
            Err(_) if i + 1 == last => {} // torn final write
            Err(e) => {
                return Err(BatchError::Record {
                    path: path.display().to_string(),
                    line: i + 1,
                    message: e.to_string(),
                });
            }
        }
    }
    Ok(out)
}

/// Runs (or resumes) a batch into `dir`: one JSON line per finished trial in
/// `trials.jsonl`, then `summary.json` and `summary.md`. `on_done` sees each finished trial.
pub fn run_batch(
    spec: &BatchSpec,
    dir: &Path,
    jobs: usize,
    on_done: &(dyn Fn(&TrialRecord) + Sync),
) -> Result<Summary, BatchError> {
    if spec.trials == 0 {
        return Err(BatchError::Invalid("--trials must be at least 1".into()));
    }
    if spec.shard.1 == 0 || spec.shard.0 >= spec.shard.1 {
        return Err(BatchError::Invalid(format!(
            "shard {}/{}: the index must be below the shard count",
            spec.shard.0, spec.shard.1
        )));
    }
    std::fs::create_dir_all(dir).map_err(io(dir))?;
    let path = dir.join("trials.jsonl");
    let existing = read_records(&path)?;
    let done: HashSet<_> = existing.iter().map(TrialRecord::key).collect();
    let todo: Vec<Job> = spec
        .jobs()
        .into_iter()
        .filter(|j| !done.contains(&spec.key(j)))
        .collect();

    // Rewrite the kept records if the file ended in a torn line, then append.
    let raw = std::fs::read_to_string(&path).unwrap_or_default();
    if !raw.is_empty() && !raw.ends_with('\n') {
        let mut w = BufWriter::new(File::create(&path).map_err(io(&path))?);
        for r in &existing {
            let line = serde_json::to_string(r).map_err(|e| BatchError::Invalid(e.to_string()))?;
            writeln!(w, "{line}").map_err(io(&path))?;
        }
        w.flush().map_err(io(&path))?;
    }
    let file = OpenOptions::new()
        .create(true)
        .append(true)
        .open(&path)
        .map_err(io(&path))?;
    let writer = Mutex::new(BufWriter::new(file));
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs.max(1))
        .build()
        .map_err(|e| BatchError::Invalid(format!("thread pool: {e}")))?;
    let write_error: Mutex<Option<std::io::Error>> = Mutex::new(None);
    pool.install(|| {
        todo.par_iter().for_each(|j| {
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
    if let Some(e) = write_error
        .into_inner()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
    {
        return Err(io(&path)(e));
    }
    let wanted: HashSet<_> = spec.jobs().iter().map(|j| spec.key(j)).collect();
    let records: Vec<TrialRecord> = read_records(&path)?
        .into_iter()
        .filter(|r| wanted.contains(&r.key()))
        .collect();
    let summary = summarize(&records);
    write_summary(dir, &summary)?;
    Ok(summary)
}

/// Merges the `trials.jsonl` of several (shard) directories into `out` and summarises.
pub fn merge(dirs: &[PathBuf], out: &Path) -> Result<Summary, BatchError> {
    let mut seen = HashSet::new();
    let mut all = Vec::new();
    for d in dirs {
        let path = d.join("trials.jsonl");
        if !path.exists() {
            return Err(BatchError::Invalid(format!(
                "{}: no trials.jsonl here",
                d.display()
            )));
        }
        for r in read_records(&path)? {
            if seen.insert(r.key()) {
                all.push(r);
            }
        }
    }
    all.sort_by_key(TrialRecord::key);
    std::fs::create_dir_all(out).map_err(io(out))?;
    let path = out.join("trials.jsonl");
    let mut w = BufWriter::new(File::create(&path).map_err(io(&path))?);
    for r in &all {
        let line = serde_json::to_string(r).map_err(|e| BatchError::Invalid(e.to_string()))?;
        writeln!(w, "{line}").map_err(io(&path))?;
    }
    w.flush().map_err(io(&path))?;
    let summary = summarize(&all);
    write_summary(out, &summary)?;
    Ok(summary)
}

/// Success statistics of one scenario × planner.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SummaryRow {
    pub scenario: String,
    pub planner: String,
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
    /// Sum of trial wall times (CPU-side cost, not elapsed time).
    pub wall_time_total_s: f64,
}

/// A batch's summary.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    pub trials: u64,
    pub successes: u64,
    pub rows: Vec<SummaryRow>,
}

/// Summarises records; order-independent (values are sorted before any sum).
pub fn summarize(records: &[TrialRecord]) -> Summary {
    #[derive(Default)]
    struct Acc {
        n: u64,
        k: u64,
        failures: BTreeMap<String, u64>,
        lat: Vec<f64>,
        head: Vec<f64>,
        wall: Vec<f64>,
    }
    let mut groups: BTreeMap<(String, String), Acc> = BTreeMap::new();
    for r in records {
        let o = &r.outcome;
        let a = groups
            .entry((o.scenario.clone(), o.planner.clone()))
            .or_default();
        a.n += 1;
        if o.success {
            a.k += 1;
        } else {
            let name = o.failure.map_or("unknown", Failure::name).to_owned();
            *a.failures.entry(name).or_default() += 1;
        }
        if let Some(v) = o.lateral_error_m.filter(|v| v.is_finite()) {
            a.lat.push(v.abs());
        }
        if let Some(v) = o.heading_error_rad.filter(|v| v.is_finite()) {
            a.head.push(v.abs());
        }
        a.wall.push(o.wall_time_ms);
    }
    let mean = |v: &[f64]| (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64);
    let rows: Vec<SummaryRow> = groups
        .into_iter()
        .map(|((scenario, planner), mut a)| {
            a.lat.sort_by(f64::total_cmp);
            a.head.sort_by(f64::total_cmp);
            a.wall.sort_by(f64::total_cmp);
            let (lo, hi) = wilson(a.k, a.n, Z95);
            SummaryRow {
                scenario,
                planner,
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
                wall_time_total_s: a.wall.iter().sum::<f64>() / 1e3,
            }
        })
        .collect();
    Summary {
        trials: rows.iter().map(|r| r.trials).sum(),
        successes: rows.iter().map(|r| r.successes).sum(),
        rows,
    }
}

impl Summary {
    /// The success table as markdown.
    pub fn markdown(&self) -> String {
        let mut s = String::from(
            "| scenario | planner | trials | successes | success rate | 95 % CI (Wilson) | failures | lateral mean / p95 (mm) | heading mean / p95 (°) | trial CPU (s) |\n|---|---|---|---|---|---|---|---|---|---|\n",
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
                "| {} | {} | {} | {} | {:.1} % | {:.1}–{:.1} % | {} | {} / {} | {} / {} | {:.2} |\n",
                r.scenario,
                r.planner,
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
        s
    }
}

fn write_summary(dir: &Path, s: &Summary) -> Result<(), BatchError> {
    let json = dir.join("summary.json");
    std::fs::write(
        &json,
        serde_json::to_string_pretty(s).map_err(|e| BatchError::Invalid(e.to_string()))? + "\n",
    )
    .map_err(io(&json))?;
    let md = dir.join("summary.md");
    std::fs::write(&md, s.markdown()).map_err(io(&md))
}

/// Committed success counts to compare new results against.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Baseline {
    pub description: String,
    pub rows: Vec<BaselineRow>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BaselineRow {
    pub scenario: String,
    pub planner: String,
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
                    trials: r.trials,
                    successes: r.successes,
                })
                .collect(),
        }
    }

    pub fn load(path: &Path) -> Result<Self, BatchError> {
        let text = std::fs::read_to_string(path).map_err(io(path))?;
        let b: Baseline = serde_json::from_str(&text).map_err(|e| BatchError::Record {
            path: path.display().to_string(),
            line: e.line(),
            message: e.to_string(),
        })?;
        for (i, r) in b.rows.iter().enumerate() {
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

/// One compared row.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RegressRow {
    pub scenario: String,
    pub planner: String,
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
            let r = now
                .rows
                .iter()
                .find(|r| r.scenario == b.scenario && r.planner == b.planner);
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
        "| scenario | planner | baseline | now | difference | p (one-sided drop) | verdict |\n|---|---|---|---|---|---|---|\n",
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
            "| {} | {} | {:.1} % | {} | {} | {} | {} |\n",
            r.scenario,
            r.planner,
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
