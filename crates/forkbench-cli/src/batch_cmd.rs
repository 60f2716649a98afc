//! `forkbench batch`, `merge` and `replay`: Monte-Carlo batches, their shards and single trials from them.

use std::io::IsTerminal as _;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use anyhow::{Context as _, bail};
use forkbench_batch::{self as batch, BatchSpec, RecordChoice, Summary, TrialRecord};
use forkbench_trial::{Scenario, defaults};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// Which batch trials to record.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum RecordWhich {
    Failures,
    All,
    None,
}

impl From<RecordWhich> for RecordChoice {
    fn from(r: RecordWhich) -> Self {
        match r {
            RecordWhich::None => RecordChoice::None,
            RecordWhich::Failures => RecordChoice::Failures,
            RecordWhich::All => RecordChoice::All,
        }
    }
}

/// Which replanning modes a batch runs (`forkbench_batch::ReplanModes`, as a flag).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Modes {
    Scenario,
    Replan,
    Both,
}

impl From<Modes> for batch::ReplanModes {
    fn from(m: Modes) -> Self {
        match m {
            Modes::Scenario => Self::Scenario,
            Modes::Replan => Self::Replan,
            Modes::Both => Self::Both,
        }
    }
}

/// `forkbench batch`.
#[derive(Debug, Clone, clap::Args)]
pub struct BatchArgs {
    /// Scenario files (default: the embedded field-test, rack-pick, Table 2, warehouse mission and handling-cycle sets).
    pub scenarios: Vec<PathBuf>,
    /// Trials per scenario × case × planner × tracker, or `auto`: looks of 10, 20, 40, …
    /// trials, each gated against --baseline at α over the planned looks, until the gate
    /// decides (a failure, or a pass powered for --min-detectable-drop, default 0.1, and
    /// twice each measure's margin) or --max-trials is reached.
    #[arg(long, default_value = "20")]
    pub trials: crate::sequential_cmd::TrialsArg,
    #[command(flatten)]
    pub auto: crate::sequential_cmd::AutoArgs,
    #[command(flatten)]
    pub options: crate::run_options::RunOptionArgs,
    /// Batch seed; each trial's seed derives from it and the trial's identity.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Planners to run every case with, by name: a scenario's own or a registered kind
    /// (default: each scenario's own).
    #[arg(long = "planner", num_args = 1..)]
    pub planners: Vec<String>,
    /// Trackers to run every case with, by name (default: each scenario's own).
    #[arg(long = "tracker", num_args = 1..)]
    pub trackers: Vec<String>,
    /// Planners and trackers defined by name for --planner and --tracker on every
    /// scenario (beside those of a components.toml next to each scenario file).
    #[arg(long, value_name = "FILE")]
    pub components: Option<PathBuf>,
    /// Worker threads.
    #[arg(long, default_value_t = 2)]
    pub jobs: usize,
    /// Run only shard I of N (I/N, 0-based), or `auto`: from a Slurm job array
    /// (SLURM_ARRAY_TASK_*) or a Kubernetes Indexed Job (JOB_COMPLETION_INDEX with
    /// --shard-count). Shard I of N writes OUT/shard-I-of-N/; `forkbench merge OUT`.
    #[arg(long)]
    pub shard: Option<String>,
    /// Shard count for `--shard auto` (a Kubernetes Job's completions; with Slurm, makes
    /// the array task ID the shard index so one index can be resubmitted alone).
    #[arg(long)]
    pub shard_count: Option<u64>,
    /// Output directory (trials.jsonl, summary.json, summary.md).
    #[arg(long, default_value = "recordings/batch")]
    pub out: PathBuf,
    #[arg(long)]
    pub json: bool,
    /// Re-estimate the pallet and replan on the way in (short for --modes replan).
    #[arg(long, conflicts_with = "modes")]
    pub replan: bool,
    /// Replanning modes: each scenario's own setting, replan always, or both side by side
    /// with the same seeds (default: both for the embedded scenarios, else scenario).
    #[arg(long, value_enum)]
    pub modes: Option<Modes>,
    /// Sweep a noise knob on the same trial seeds: pallet_noise, localization_noise or
    /// odometry_noise, e.g. pallet_noise=0,1,3 (table and plot per planner).
    #[arg(long)]
    pub sweep: Option<String>,
    /// Which trials to record under OUT/recordings/: as .mcap, and as .rrd too in a CLI
    /// built with `--features rerun`.
    #[arg(long, value_enum, default_value_t = RecordWhich::Failures)]
    pub record: RecordWhich,
    /// Also write each recorded trial as a ROS 2 bag, the rosbag2 directory `<stem>.ros2`
    /// (metadata.yaml and an MCAP of the `ros2` profile: CDR messages with ros2msg
    /// schemas, for `ros2 bag play`, RViz, rosbags).
    #[arg(long)]
    pub ros2: bool,
    /// At most this many recordings, spread over scenario × case × failure × mode (one
    /// from each in turn).
    #[arg(long, default_value_t = 20)]
    pub max_recordings: usize,
    /// Discard what OUT holds from a batch with other settings and start over
    /// (without it such a directory is refused, naming the differences).
    #[arg(long)]
    pub force_new: bool,
    /// Also write the results as JUnit XML to FILE: a test case per scenario × planner ×
    /// tracker, failing below --floor.
    #[arg(long)]
    pub junit: Option<PathBuf>,
    /// Success-rate floor (0–1) for the --junit cases; a row below it exits 3.
    #[arg(long, requires = "junit")]
    pub floor: Option<f64>,
    /// Also write OUT/trials.csv: one row per trial, flat columns in SI units.
    #[arg(long)]
    pub csv: bool,
    /// Also write OUT/report.html (see `forkbench report`).
    #[arg(long)]
    pub report: bool,
    /// Time each trial's stages (physics, scans, detection, localisation, planning,
    /// tracking, criteria, safety, recording) into its record, summary.json and the
    /// report, and print where the batch's time went.
    #[arg(long)]
    pub profile: bool,
    /// The drop (0–1, e.g. 0.05) the regression gate must see with 80 % power: refuse to
    /// run when a row has fewer trials than a paired gate needs for it.
    #[arg(long)]
    pub min_detectable_drop: Option<f64>,
    /// The confidence (0.5–0.999999) the success-run figures are stated at.
    #[arg(long, default_value_t = batch::success_run::CONFIDENCE)]
    pub success_confidence: f64,
    /// The reliability (0.5–0.999999) the success-run figures ask each row to show.
    #[arg(long, default_value_t = batch::success_run::TARGET_RELIABILITY)]
    pub success_reliability: f64,
}

fn progress(total: u64) -> ProgressBar {
    let target = if std::io::stderr().is_terminal() {
        ProgressDrawTarget::stderr()
    } else {
        ProgressDrawTarget::hidden()
    };
    let bar = ProgressBar::with_draw_target(Some(total), target);
    bar.set_style(
        ProgressStyle::with_template("{bar:30} {pos}/{len} trials  {per_sec}  eta {eta}  {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar
}

fn run_one(spec: &BatchSpec, dir: &Path, jobs: usize) -> anyhow::Result<Summary> {
    let total = spec.jobs().len() as u64;
    let bar = progress(total);
    let (done, ok) = (AtomicU64::new(0), AtomicU64::new(0));
    let on_done = |r: &TrialRecord| {
        let d = done.fetch_add(1, Ordering::Relaxed) + 1;
        let k = ok.fetch_add(u64::from(r.outcome.success), Ordering::Relaxed)
            + u64::from(r.outcome.success);
        bar.inc(1);
        bar.set_message(format!("success {:.1} %", 100.0 * k as f64 / d as f64));
    };
    let summary = batch::run_batch(spec, dir, jobs, &on_done)?;
    bar.finish_and_clear();
    Ok(summary)
}

/// The batch spec the arguments describe, and the arguments with OUT resolved to this
/// shard's directory.
fn prepare(a: BatchArgs) -> anyhow::Result<(BatchSpec, BatchArgs)> {
    let scenarios: Vec<Scenario> = if a.scenarios.is_empty() {
        defaults::default_scenarios()?
    } else {
        a.scenarios
            .iter()
            .map(|p| defaults::load_scenario(p))
            .collect::<Result<_, _>>()?
    };
    let scenarios = scenarios
        .into_iter()
        .map(|s| crate::with_components(s, a.components.as_deref()))
        .collect::<anyhow::Result<Vec<_>>>()?;
    scenarios.iter().for_each(crate::warn_slips);
    let shard = match a.shard.as_deref() {
        Some(text) => {
            let arg = batch::parse_shard(text, a.shard_count)?;
            batch::resolve_shard(arg, &|k| std::env::var(k).ok())?
        }
        None if a.shard_count.is_some() => bail!("--shard-count goes with --shard auto"),
        None => (0, 1),
    };
    if a.ros2 && a.record == RecordWhich::None {
        bail!("--ros2 writes bags of the recorded trials, and --record none records none");
    }
    let out = batch::shard_dir(&a.out, shard);
    if let Some(j) = &a.junit {
        // The report must not replace what the batch reads or writes.
        let mut inputs = batch::batch_files(&out);
        inputs.extend(a.scenarios.iter().cloned());
        inputs.extend(a.components.iter().cloned());
        forkbench_core::files::check_not_input(j, &inputs)?;
    }
    let a = BatchArgs { out, ..a };
    batch::check_floor(a.floor)?;
    let modes =
        batch::ReplanModes::choose(a.replan, a.modes.map(Into::into), a.scenarios.is_empty());
    let (replan, compare_replanning) = modes.spec_fields();
    let spec = BatchSpec {
        scenarios,
        planners: a.planners.clone(),
        trackers: a.trackers.clone(),
        trials: crate::sequential_cmd::first_look(
            a.trials,
            &a.auto,
            a.sweep.is_some(),
            a.shard.is_some(),
        )?,
        seed: a.seed,
        shard,
        overrides: a.options.overrides()?,
        replan,
        compare_replanning,
        force_new: a.force_new,
        success_run: batch::success_run::SuccessTarget::new(
            a.success_confidence,
            a.success_reliability,
        )?,
        profile: a.profile,
    };
    Ok((spec, a))
}

/// The trials: the batch, or with `--trials auto` its looks (the spec then holds the
/// last look's trial count, which the recordings and the report read).
fn run_trials(
    spec: &mut BatchSpec,
    a: &BatchArgs,
    auto: bool,
) -> anyhow::Result<(Summary, Option<batch::sequential::Sequential>)> {
    if !auto {
        return Ok((run_one(spec, &a.out, a.jobs)?, None));
    }
    let s = crate::sequential_cmd::run_auto(spec, &a.out, a.jobs, &a.auto, a.min_detectable_drop)?;
    spec.trials = s.looks.last().map_or(spec.trials, |l| l.trials);
    Ok((s.summary.clone(), Some(s)))
}

/// Runs the batch; `Ok(false)` when a row fell below `--floor` (the run worked, the
/// result is a failure: exit 3).
pub fn run(a: BatchArgs) -> anyhow::Result<bool> {
    let began = std::time::Instant::now();
    let (mut spec, a) = prepare(a)?;
    // Before anything is sized by the trial count (the progress bar lists the jobs).
    spec.check(a.jobs)?;
    let auto = a.trials == crate::sequential_cmd::TrialsArg::Auto;
    if let Some(d) = a.min_detectable_drop.filter(|_| !auto) {
        spec.check_power(d)?;
    }
    if let Some(sweep) = &a.sweep {
        return run_sweep(&spec, &a, sweep).map(|()| true);
    }
    let mut clock = Clock::new(began);
    clock.lap("setup");
    let (summary, looks) = run_trials(&mut spec, &a, auto)?;
    clock.lap("trials");
    // Every output is attempted, whatever failed before it (a full disk while recording
    // must not cost the table, JUnit, CSV or report); the failures are reported together.
    // The recordings first: the report links the failed trials' recordings it finds.
    let mut failed: Vec<String> = Vec::new();
    let recorded = record_batch(&spec, &a).unwrap_or_else(|e| {
        failed.push(format!("recordings: {e:#}"));
        0
    });
    clock.lap("recordings");
    let extras = write_extras(&summary, &a, &mut failed);
    clock.lap("report, CSV and JUnit");
    let shown = if let Some(s) = &looks {
        crate::sequential_cmd::show(s, &summary, &a.out, a.json)
    } else if a.json {
        crate::emit(&format!("{}\n", serde_json::to_string(&summary)?))
    } else {
        let profile = summary.profile.as_ref().map_or(String::new(), |p| {
            format!(
                "\nwhere the trials' time went ({} profiled trials, summed over the jobs):\n{}\n",
                p.trials,
                p.lines("  ").join("\n")
            )
        });
        crate::emit(&format!(
            "{}{profile}\n{} with {} jobs; results in {}/ (trials.jsonl, summary.json, summary.md{extras}){}\n",
            summary.markdown(),
            clock.text(),
            a.jobs,
            a.out.display(),
            if recorded > 0 {
                format!("; {recorded} trials recorded in recordings/")
            } else {
                String::new()
            }
        ))
    };
    if !failed.is_empty() {
        bail!(
            "the trials are intact in {}, but {}",
            a.out.display(),
            failed.join("; ")
        );
    }
    shown?;
    for w in summary.dead_rows() {
        eprintln!("warning: {}", forkbench_trial::text::visible(&w));
    }
    let below = summary.below_floor(a.floor);
    if !below.is_empty() {
        eprintln!(
            "below the floor of {:.1} %: {}",
            100.0 * a.floor.unwrap_or(0.0),
            forkbench_trial::text::visible(&below.join(", "))
        );
    }
    Ok(below.is_empty() && looks.is_none_or(|s| s.report.passed))
}

/// The batch's wall clock from its start, by part (what the closing line prints).
struct Clock {
    began: std::time::Instant,
    last: std::time::Instant,
    laps: Vec<(&'static str, f64)>,
}

impl Clock {
    fn new(began: std::time::Instant) -> Self {
        Self {
            began,
            last: began,
            laps: Vec::new(),
        }
    }

    /// The time since the last lap (or the start) was spent on `part`.
    fn lap(&mut self, part: &'static str) {
        let now = std::time::Instant::now();
        self.laps.push((part, (now - self.last).as_secs_f64()));
        self.last = now;
    }

    /// "elapsed T s (setup S s, trials N s, …)": the whole, and the parts that took a
    /// twentieth of a second or more.
    fn text(&self) -> String {
        let total = self.began.elapsed().as_secs_f64();
        let parts: Vec<String> = self
            .laps
            .iter()
            .filter(|(_, s)| *s >= 0.05)
            .map(|(part, s)| format!("{part} {s:.1} s"))
            .collect();
        if parts.is_empty() {
            format!("elapsed {total:.1} s")
        } else {
            format!("elapsed {total:.1} s ({})", parts.join(", "))
        }
    }
}

/// The outputs asked for beside the results (CSV, JUnit, HTML report), each attempted,
/// named for the closing line; failures go to `failed`.
fn write_extras(summary: &Summary, a: &BatchArgs, failed: &mut Vec<String>) -> String {
    let mut written = String::new();
    if a.csv {
        let r = batch::read_records(&a.out.join("trials.jsonl"))
            .and_then(|records| batch::write_csv(&records, &a.out.join("trials.csv")));
        match r {
            Ok(()) => written.push_str(", trials.csv"),
            Err(e) => failed.push(format!("trials.csv: {e}")),
        }
    }
    if let Some(file) = &a.junit {
        let cases = batch::junit::batch_cases(summary, a.floor);
        let xml = batch::junit::junit_xml("forkbench batch", &cases, summary.provenance.as_ref());
        match batch::write_atomic(file, xml.as_bytes()) {
            Ok(()) => written.push_str(&format!(", JUnit {}", file.display())),
            Err(e) => failed.push(format!("JUnit: {e}")),
        }
    }
    if a.report {
        match forkbench_report::html::write(&a.out, None) {
            Ok(_) => written.push_str(", report.html"),
            Err(e) => failed.push(format!("report.html: {e:#}")),
        }
    }
    written
}

fn run_sweep(spec: &BatchSpec, a: &BatchArgs, sweep: &str) -> anyhow::Result<()> {
    let sweep = batch::Sweep::parse(sweep)?;
    if spec.overrides.scale(&sweep.knob).is_some() {
        bail!(
            "--sweep {}: the knob is also set with --{}-scale; give it one way",
            sweep.knob,
            sweep.knob.replace('_', "-")
        );
    }
    let planned = batch::sweep_points(spec, &a.out, &sweep);
    // Every point is checked before the first runs: a scale the scenarios refuse is one
    // error, not a half-finished sweep.
    for p in &planned {
        p.spec.check(a.jobs)?;
    }
    let mut points: Vec<(f64, Summary)> = Vec::new();
    for p in planned {
        points.push((p.value, run_one(&p.spec, &p.dir, a.jobs)?));
    }
    let text = batch::write_sweep(&a.out, &sweep.knob, &points)?;
    forkbench_report::sweep::draw_sweeps(&a.out, &sweep.knob, &points)?;
    if a.report {
        forkbench_report::html::write(&a.out, None)?;
    }
    if a.json {
        let results: Vec<batch::SweepResult> = points
            .into_iter()
            .map(|(value, summary)| batch::SweepResult {
                knob: sweep.knob.clone(),
                value,
                summary,
            })
            .collect();
        return crate::emit(&format!("{}\n", serde_json::to_string(&results)?));
    }
    crate::emit(&format!(
        "{text}\nwritten: {}/sweep.md, sweep.json, sweep-<planner>.png\n",
        a.out.display()
    ))
}

pub fn merge(dirs: &[PathBuf], out: &Path, json: bool) -> anyhow::Result<()> {
    let s = batch::merge(&batch::merge_inputs(dirs)?, out)?;
    if json {
        return crate::emit(&format!("{}\n", serde_json::to_string(&s)?));
    }
    crate::emit(&format!(
        "{}\nmerged into {}/\n",
        s.markdown(),
        out.display()
    ))
}

/// Records the trials the library picks (failures, or all) as .mcap, .rrd with rerun built
/// in, and ROS 2 bags with `--ros2`.
fn record_batch(spec: &BatchSpec, a: &BatchArgs) -> anyhow::Result<usize> {
    let choice = RecordChoice::from(a.record);
    if choice == RecordChoice::None {
        return Ok(0);
    }
    let records = batch::read_records(&a.out.join("trials.jsonl"))?;
    let jobs = batch::trials_to_record(spec, &records, choice, a.max_recordings);
    let dir = a.out.join("recordings");
    for j in &jobs {
        std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
        forkbench_log::record_trial(j.scenario, j.case, &j.options, &dir, a.ros2)?;
    }
    Ok(jobs.len())
}
