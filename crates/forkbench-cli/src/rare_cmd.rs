//! `forkbench estimate` and `forkbench falsify`: rare events over a scenario's uncertain parameters, their trials kept beside the result.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context as _, bail};
use clap::{Args, ValueEnum};

use forkbench_batch::rare::{Event, OUT_FILES, RareSetup, RareStore, TRIALS_FILE, Tried};

/// What `estimate` and `falsify` share: the scenario, its components, the event, the budget.
#[derive(Debug, Args)]
pub struct RareArgs {
    /// A scenario with `[[uncertain]]` parameters.
    scenario: PathBuf,
    /// The case (needed when the scenario has several).
    #[arg(long)]
    case: Option<String>,
    #[arg(long)]
    planner: Option<String>,
    #[arg(long)]
    tracker: Option<String>,
    /// Components file (external planners and trackers by name).
    #[arg(long, value_name = "FILE")]
    components: Option<PathBuf>,
    #[command(flatten)]
    options: crate::run_options::RunOptionArgs,
    /// `failure` (any criterion), `contact` (a person or vehicle touched), or a criterion's
    /// name (`lateral_error`, `contact_force`, …).
    #[arg(long, default_value = "failure")]
    event: String,
    /// Trials in all (every trial's record is also kept in memory, for the search and the
    /// result, about 1.3 KB a pick, hence the bound; a plain batch streams larger counts
    /// to disk).
    #[arg(long, default_value_t = 2000, value_parser = clap::value_parser!(u64).range(20..=250_000))]
    budget: u64,
    /// Seed of every draw (the search's points and the trials' own noise).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Worker threads (default: the machine's cores).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=1024))]
    jobs: Option<u64>,
    /// Directory for trials.jsonl (every trial with its point) and the result's JSON.
    #[arg(long)]
    out: PathBuf,
    /// Print the result as JSON.
    #[arg(long)]
    json: bool,
    /// Start over when OUT holds the trials of a run with other settings (a run with the
    /// same settings resumes: its trials are not run again).
    #[arg(long)]
    force_new: bool,
}

/// `forkbench estimate`.
#[derive(Debug, Args)]
pub struct EstimateArgs {
    #[command(flatten)]
    common: RareArgs,
    /// `ce`: cross-entropy adaptive importance sampling; `subset`: subset simulation
    /// (failures in several regions); `mc`: plain Monte Carlo.
    #[arg(long, value_enum, default_value_t = MethodArg::Ce)]
    method: MethodArg,
    /// Subset simulation: the share of each level's trials kept below the next level's
    /// threshold, p₀ (0.05 to 0.5; Au and Beck's 0.1).
    #[arg(long)]
    level_fraction: Option<f64>,
    /// Subset simulation: trials per level (20 to the budget; default a quarter of it).
    #[arg(long)]
    per_level: Option<usize>,
}

impl EstimateArgs {
    /// Subset simulation's settings; refused for another method, which has none.
    fn subset(&self) -> anyhow::Result<forkbench_rare::SubsetSettings> {
        let set = self.level_fraction.is_some() || self.per_level.is_some();
        if set && !matches!(self.method, MethodArg::Subset) {
            bail!("--level-fraction and --per-level are subset simulation's (--method subset)");
        }
        let d = forkbench_rare::SubsetSettings::default();
        Ok(forkbench_rare::SubsetSettings {
            level_fraction: self.level_fraction.unwrap_or(d.level_fraction),
            per_level: self.per_level,
        })
    }
}

#[derive(Debug, Clone, Copy, ValueEnum)]
enum MethodArg {
    Ce,
    Subset,
    Mc,
}

/// `forkbench falsify`.
#[derive(Debug, Args)]
pub struct FalsifyArgs {
    #[command(flatten)]
    common: RareArgs,
    /// Plain Monte Carlo over the same distributions instead of the search (to compare).
    #[arg(long)]
    monte_carlo: bool,
    #[command(flatten)]
    record: crate::RecordFlags,
}

impl RareArgs {
    fn setup(&self) -> anyhow::Result<RareSetup> {
        let scn = forkbench_trial::Scenario::load(&self.scenario)?;
        let scenario = crate::with_components(scn, self.components.as_deref())?;
        let case = scenario.pick_case(self.case.as_deref())?.name.clone();
        let jobs = self.jobs.map_or_else(
            || std::thread::available_parallelism().map_or(1, usize::from),
            |j| j as usize,
        );
        Ok(RareSetup {
            scenario,
            case,
            planner: self.planner.clone(),
            tracker: self.tracker.clone(),
            overrides: self.options.overrides()?,
            seed: self.seed,
            event: Event::parse(&self.event)?,
            jobs,
        })
    }

    /// `--out`, made if missing; one that holds files forkbench did not write here is refused.
    fn out_dir(&self) -> anyhow::Result<&Path> {
        let dir = self.out.as_path();
        if dir.exists() {
            for e in std::fs::read_dir(dir).with_context(|| format!("{}", dir.display()))? {
                let name = e?.file_name();
                if !OUT_FILES.iter().any(|o| name == *o) {
                    bail!(
                        "{}: holds {:?}, which estimate and falsify do not write; give an empty or new directory",
                        dir.display(),
                        name
                    );
                }
            }
        }
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        Ok(dir)
    }

    /// OUT's store for this run: its earlier trials resumed, new ones appended.
    fn store(&self, setup: &RareSetup, what: serde_json::Value) -> anyhow::Result<RareStore> {
        let store = RareStore::open(&self.out, &setup.settings(what)?, self.force_new)?;
        if store.resumed() > 0 && !self.json {
            eprintln!(
                "resuming: {} trials of this run already in {}",
                store.resumed(),
                self.out.display()
            );
        }
        Ok(store)
    }

    /// Writes the result beside the trials the store appended as they ran.
    fn write(&self, name: &str, result: &impl serde::Serialize) -> anyhow::Result<()> {
        // Checked again: a long run leaves time for someone else's file to arrive.
        let dir = self.out_dir()?;
        forkbench_batch::write_atomic(
            &dir.join(name),
            serde_json::to_string_pretty(result)?.as_bytes(),
        )?;
        Ok(())
    }
}

/// `forkbench estimate`: prints P(event) with its interval and what it cost.
pub fn estimate(a: &EstimateArgs) -> anyhow::Result<()> {
    let c = &a.common;
    let subset = a.subset()?;
    c.out_dir()?;
    let setup = c.setup()?;
    let method = match a.method {
        MethodArg::Ce => forkbench_rare::Method::Ce,
        MethodArg::Subset => forkbench_rare::Method::Subset,
        MethodArg::Mc => forkbench_rare::Method::Mc,
    };
    let mut what = serde_json::json!({ "estimate": method, "budget": c.budget });
    if method == forkbench_rare::Method::Subset {
        what["subset"] = serde_json::to_value(subset)?;
    }
    let store = c.store(&setup, what)?;
    let (e, _) = forkbench_batch::rare::estimate_with(
        &setup,
        (method, subset),
        c.budget as usize,
        Some(store),
    )?;
    c.write("estimate.json", &e)?;
    if let Some(why) = e.thin() {
        eprintln!("warning: {why}");
    }
    if c.json {
        return crate::out::emit_json_line(&e);
    }
    let mut s = format!(
        "P({}) over {} uncertain parameters of {} / case {}: {:.3e} ({} % CI {:.3e} to {:.3e})\n",
        c.event,
        setup.scenario.uncertain.0.len(),
        setup.scenario.name,
        setup.case,
        e.p,
        e.confidence * 100.0,
        e.ci.0,
        e.ci.1
    );
    let re = e
        .relative_error
        .map_or("—".into(), |r| format!("{:.1} %", r * 100.0));
    let method = match method {
        forkbench_rare::Method::Ce => format!(
            "cross-entropy importance sampling: {} trials ({} adapting in {} stages)",
            e.trials,
            e.adapting,
            e.stages.len()
        ),
        forkbench_rare::Method::Subset => format!(
            "subset simulation: {} trials in {} levels (shares {})",
            e.trials,
            e.levels.len(),
            e.levels
                .iter()
                .map(|l| format!("{:.3}", l.share))
                .collect::<Vec<_>>()
                .join(" × ")
        ),
        forkbench_rare::Method::Mc => format!("plain Monte Carlo: {} trials", e.trials),
    };
    let _ = writeln!(
        s,
        "method {method}, {} with the event; relative error {re}, effective sample size {:.0}",
        e.events, e.ess
    );
    if let Some(share) = e.not_rare() {
        let _ = writeln!(
            s,
            "note: the first stage, drawn from the nominal distributions, already had the \
             event in {:.1} % of its trials: it is not rare, and plain Monte Carlo \
             (--method mc) is the safer estimate (importance sampling gains little here, and \
             can undercover an event with several causes)",
            100.0 * share
        );
    }
    let _ = writeln!(s, "trials in {}", c.out.join(TRIALS_FILE).display());
    crate::emit(&s)
}

/// `forkbench falsify`: prints the most likely failure, the least robust trial, and the
/// command that replays it; records it when asked. Exit 3 when a failure was found.
pub fn falsify(a: FalsifyArgs) -> anyhow::Result<bool> {
    let c = &a.common;
    // The recording is checked first: a campaign must not run to fail at its replay.
    let rec = a.record.args()?;
    c.out_dir()?;
    let setup = c.setup()?;
    let what = serde_json::json!({ "falsify": !a.monte_carlo, "budget": c.budget });
    let store = c.store(&setup, what)?;
    let (f, tried) =
        forkbench_batch::rare::falsify(&setup, c.budget as usize, a.monte_carlo, Some(store))?;
    c.write("falsify.json", &f)?;
    if c.json {
        crate::out::emit_json_line(&f)?;
    } else {
        crate::emit(&falsify_text(c, &setup, &f, &tried))?;
    }
    let Some(found) = &f.most_likely else {
        return Ok(false);
    };
    let line = line_of(&tried, &found.z);
    let asked = rec.rrd.is_some()
        || rec.mcap.is_some()
        || rec.ros2.is_some()
        || rec.actuator_csv.is_some()
        || rec.rerun
        || rec.connect.is_some();
    if asked {
        let trials = c.out.join(TRIALS_FILE);
        crate::replay_cmd::replay(
            &trials,
            line,
            (Some(&c.scenario), c.components.as_deref()),
            &rec,
        )?;
    }
    Ok(true)
}

/// The 1-based line of the trial at `z`.
fn line_of(tried: &[Tried], z: &[f64]) -> usize {
    tried.iter().position(|t| t.z == z).map_or(1, |i| i + 1)
}

fn falsify_text(
    c: &RareArgs,
    setup: &RareSetup,
    f: &forkbench_rare::Falsified,
    tried: &[Tried],
) -> String {
    let mut s = format!(
        "{} trials of {} / case {} searching for {}: {} with it\n",
        f.trials, setup.scenario.name, setup.case, c.event, f.events
    );
    let describe = |s: &mut String, head: &str, z: &[f64]| {
        let Some(t) = tried.iter().find(|t| t.z == z) else {
            return;
        };
        let o = &t.record.outcome;
        let _ = writeln!(
            s,
            "{head} (line {} of trials.jsonl, robustness {}): {}",
            line_of(tried, z),
            o.robustness.map_or("—".into(), |r| format!("{r:.3}")),
            o.failure_detail.as_deref().unwrap_or("succeeded")
        );
        for (name, v) in &o.uncertain {
            let sd = setup
                .scenario
                .uncertain
                .0
                .iter()
                .position(|u| &u.name == name)
                .map_or(0.0, |i| z[i]);
            let _ = writeln!(s, "  {name} = {v:.4} ({sd:+.2} σ)");
        }
    };
    match &f.most_likely {
        Some(m) => {
            describe(&mut s, "most likely failure found", &m.z);
            let _ = writeln!(
                s,
                "replay: forkbench replay {} --line {} --scenario {} {}",
                c.out.join(TRIALS_FILE).display(),
                line_of(tried, &m.z),
                c.scenario.display(),
                if forkbench_log::HAS_RERUN {
                    "--rrd failure.rrd"
                } else {
                    "--mcap failure.mcap"
                }
            );
        }
        None => s += "no trial had the event\n",
    }
    if let Some(l) = &f.least_robust {
        describe(&mut s, "least robust trial", &l.z);
    }
    s
}
