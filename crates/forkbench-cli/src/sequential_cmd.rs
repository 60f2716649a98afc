//! `batch --trials auto`: the batch in looks, each gated against a baseline, until the gate can decide or the cap is reached.

use std::path::PathBuf;

use anyhow::bail;
use forkbench_batch::sequential::{self, Decision, SequentialPlan};
use forkbench_batch::{self as batch, Baseline, BatchSpec, GateOptions};

/// How many trials a batch runs per case: a count, or `auto` (looks until the gate
/// decides).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TrialsArg {
    Count(u64),
    Auto,
}

impl std::str::FromStr for TrialsArg {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        if s == "auto" {
            return Ok(TrialsArg::Auto);
        }
        s.parse().map(TrialsArg::Count).map_err(|_| {
            format!("`{s}`: a trial count (a whole number) or `auto` (with --baseline)")
        })
    }
}

impl std::fmt::Display for TrialsArg {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            TrialsArg::Count(n) => write!(f, "{n}"),
            TrialsArg::Auto => f.write_str("auto"),
        }
    }
}

/// What `--trials auto` gates against, and how.
#[derive(Debug, Clone, clap::Args)]
pub struct AutoArgs {
    /// With --trials auto: the baseline each look is gated against (pair by pair when
    /// this batch has its seed).
    #[arg(long, value_name = "FILE")]
    pub baseline: Option<PathBuf>,
    /// With --trials auto: gate the results' CANDIDATE as the baseline's SHIPPED (as
    /// `regress --as`).
    #[arg(long = "as", value_name = "CANDIDATE=SHIPPED")]
    pub mappings: Vec<batch::Mapping>,
    /// With --trials auto: a gate file of measure margins (as `regress --gate`).
    #[arg(long = "gate", value_name = "FILE")]
    pub gate_file: Option<PathBuf>,
    /// With --trials auto: the most trials per case (default: as many as the baseline
    /// has for its smallest case, which is the most that pair).
    #[arg(long)]
    pub max_trials: Option<u64>,
}

/// The first look's trials, for the spec; refuses what `auto` cannot go with.
pub fn first_look(
    t: TrialsArg,
    auto: &AutoArgs,
    sweep: bool,
    sharded: bool,
) -> anyhow::Result<u64> {
    match t {
        TrialsArg::Count(n) => {
            if auto.baseline.is_some()
                || !auto.mappings.is_empty()
                || auto.gate_file.is_some()
                || auto.max_trials.is_some()
            {
                bail!(
                    "--baseline, --as, --gate and --max-trials go with --trials auto (to gate a fixed count, run `forkbench regress` after the batch)"
                );
            }
            Ok(n)
        }
        TrialsArg::Auto if auto.baseline.is_none() => {
            bail!(
                "--trials auto runs until the gate against a baseline decides: give --baseline FILE"
            )
        }
        TrialsArg::Auto if sweep => bail!("--trials auto gates one batch; a --sweep is many"),
        TrialsArg::Auto if sharded => {
            bail!("--trials auto decides look by look on one machine; it does not shard")
        }
        TrialsArg::Auto => Ok(sequential::FIRST_LOOK),
    }
}

/// Runs the looks; the last look's summary, its gate, and the looks.
pub fn run_auto(
    spec: &BatchSpec,
    out: &std::path::Path,
    jobs: usize,
    auto: &AutoArgs,
    want_drop: Option<f64>,
) -> anyhow::Result<sequential::Sequential> {
    let Some(file) = &auto.baseline else {
        bail!("--trials auto needs --baseline FILE");
    };
    let base = Baseline::load(file)?;
    let options = GateOptions {
        measures: batch::MeasureSettings::load_or_default(auto.gate_file.as_deref())?,
        ..GateOptions::default()
    };
    options.validate()?;
    if let Some(m) = auto.max_trials
        && !(1..=1_000_000).contains(&m)
    {
        bail!("--max-trials {m}: must be 1 to 1000000 trials per case");
    }
    let cap = auto
        .max_trials
        .unwrap_or_else(|| sequential::baseline_cap(&base));
    if cap == 0 {
        bail!(
            "{}: holds no per-trial results, so no look can pair with it; re-make it with `forkbench baseline`",
            file.display()
        );
    }
    let gate = |o: &GateOptions| -> Result<batch::GateReport, batch::BatchError> {
        crate::gate_cmd::gate(&base, out, &auto.mappings, o)
            .map(|(r, _)| r)
            .map_err(|e| batch::BatchError::Content(format!("{e:#}")))
    };
    let plan = SequentialPlan {
        looks: sequential::plan_looks(spec.trials, cap),
        options,
        want_drop: want_drop.unwrap_or(sequential::DEFAULT_DECIDE_DROP),
        gate: &gate,
    };
    Ok(sequential::run_sequential(spec, out, jobs, &plan, &|_| {})?)
}

/// The looks in words, and the answer.
pub fn looks_text(s: &sequential::Sequential) -> String {
    let planned = s.planned;
    let mut t = format!(
        "--trials auto: {} of {planned} planned looks, each gated at α/{planned} = {:.4} (Holm within it):\n",
        s.looks.len(),
        s.looks.first().map_or(0.0, |l| l.alpha)
    );
    for (k, l) in s.looks.iter().enumerate() {
        let d = match l.decision {
            Decision::Regression => "REGRESSION",
            Decision::Pass => "PASSED",
            Decision::Undecided => "undecided",
        };
        t.push_str(&format!(
            "  look {}: {} trials per case: {d}: {}\n",
            k + 1,
            l.trials,
            l.why
        ));
    }
    if s.looks
        .last()
        .is_some_and(|l| l.decision == Decision::Undecided)
    {
        t.push_str("undecided at the cap: no row failed, but the gate could not see all it was asked to (see above); raise --max-trials (and the baseline's trials) to decide\n");
    }
    t
}

/// Prints the batch's table, the looks and the last look's gate (or all as one JSON
/// object), and writes them to OUT/sequential.json.
pub fn show(
    s: &sequential::Sequential,
    summary: &batch::Summary,
    out: &std::path::Path,
    json: bool,
) -> anyhow::Result<()> {
    let record = serde_json::json!({ "looks": s.looks, "gate": s.report });
    batch::write_atomic(
        &out.join("sequential.json"),
        format!("{}\n", serde_json::to_string_pretty(&record)?).as_bytes(),
    )?;
    if json {
        let all = serde_json::json!({ "summary": summary, "looks": s.looks, "gate": s.report });
        return crate::emit(&format!("{}\n", serde_json::to_string(&all)?));
    }
    crate::emit(&format!(
        "{}\n{}\n{}",
        summary.markdown(),
        looks_text(s),
        s.report.markdown()
    ))
}
