//! `forkbench replay`: one trial re-run from its JSON line, recorded, and checked against the record.

use std::path::{Path, PathBuf};

use anyhow::{Context as _, bail};

/// `forkbench replay`'s arguments.
#[derive(Debug, clap::Args)]
pub struct ReplayArgs {
    /// File with JSON lines (e.g. DIR/trials.jsonl).
    file: PathBuf,
    /// 1-based line of the trial to replay (default: the first).
    #[arg(long, default_value_t = 1)]
    line: usize,
    /// Scenario file the trial came from (default: the embedded scenario of that name).
    #[arg(long)]
    scenario: Option<PathBuf>,
    /// The components file the batch ran with (`batch --components FILE`).
    #[arg(long, value_name = "FILE")]
    components: Option<PathBuf>,
    #[command(flatten)]
    record: crate::RecordFlags,
}

/// `forkbench replay` as the command line gives it.
pub fn replay_args(a: ReplayArgs) -> anyhow::Result<bool> {
    let from = (a.scenario.as_deref(), a.components.as_deref());
    replay(&a.file, a.line, from, &a.record.args()?)
}

/// `forkbench replay`: re-runs one trial from its JSON line, records it, and checks that
/// the outcome is the recorded one.
pub fn replay(
    file: &Path,
    line: usize,
    (scenario, components): (Option<&Path>, Option<&Path>),
    rec: &forkbench_log::RecordTargets,
) -> anyhow::Result<bool> {
    if line == 0 {
        bail!("--line 0: lines are numbered from 1");
    }
    let mut job = forkbench_batch::Replay::load(file, line, scenario)?;
    job.scenario = crate::with_components(job.scenario, components)?;
    let opts = job.options();
    let run = opts.resolve(&job.scenario)?;
    // The trials file and a components file are inputs too: no recording replaces them.
    let mut rec = rec.clone();
    rec.inputs.push(file.to_path_buf());
    rec.inputs.extend(components.map(Path::to_path_buf));
    let r = forkbench_log::run_recorded((&job.scenario, job.case()?), (&opts, &run), &rec)?;
    if let Some(e) = &r.viewer_error {
        eprintln!(
            "error: {} (the trial ran without the viewer)",
            forkbench_trial::text::visible(&e.to_string())
        );
    }
    let out = &r.outcome;
    let same = job.reproduces(out);
    crate::emit(&format!(
        "replayed {} / case {} / {} / {} / seed {}: {} ({})\n",
        out.scenario,
        out.case,
        out.planner,
        out.tracker,
        out.seed,
        out.verdict_word(),
        if same {
            "identical to the recorded outcome"
        } else {
            "DIFFERS from the recorded outcome"
        }
    ))?;
    // As for `trial`: the outcome is printed first, then a recording or viewer error
    // makes the exit status 1.
    r.written.context("writing the recording")?;
    if r.viewer_error.is_some() {
        bail!("the requested rerun viewer could not be reached");
    }
    if !same {
        bail!("the replay did not reproduce the recorded outcome");
    }
    Ok(out.success)
}
