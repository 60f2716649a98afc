//! `forkbench replay`: one trial re-run from its JSON line, recorded, and checked against the record.

use std::path::Path;

use anyhow::{Context as _, bail};
use forkbench_batch::{self as batch, TrialRecord};
use forkbench_trial::{Scenario, defaults};

/// The scenarios a record may come from: the file the batch's manifest (beside the
/// records) names for it, else the embedded defaults.
fn replay_scenarios(records: &Path, name: &str) -> anyhow::Result<Vec<Scenario>> {
    let dir = records.parent().unwrap_or(Path::new("."));
    let embedded = defaults::default_scenarios()?;
    let entry = batch::Manifest::read(dir)
        .ok()
        .flatten()
        .and_then(|m| m.scenarios.into_iter().find(|s| s.name == name));
    let Some(entry) = entry else {
        return Ok(embedded);
    };
    if embedded
        .iter()
        .any(|s| s.name == name && s.file == entry.file)
    {
        return Ok(embedded);
    }
    let scn = Scenario::load(Path::new(&entry.file)).with_context(|| {
        format!(
            "{}'s manifest names {} for scenario {name:?}; pass its file with --scenario",
            dir.display(),
            entry.file
        )
    })?;
    Ok(vec![scn])
}

/// `forkbench replay`: re-runs one trial from its JSON line, records it, and checks that
/// the outcome is the recorded one.
pub fn replay(
    file: &Path,
    line: usize,
    scenario: Option<&Path>,
    rec: &crate::record::RecordArgs,
) -> anyhow::Result<bool> {
    let text = batch::read_regular(file, batch::MAX_RECORDS_BYTES)?;
    if line == 0 {
        bail!("--line 0: lines are numbered from 1");
    }
    let Some(raw) = text.lines().nth(line - 1) else {
        bail!("{}: has no line {line}", file.display());
    };
    let record: TrialRecord = serde_json::from_str(raw)
        .map_err(|e| anyhow::anyhow!("{}:{line}: not a trial record: {e}", file.display()))?;
    let scenarios = match scenario {
        Some(p) => vec![Scenario::load(p)?],
        None => replay_scenarios(file, &record.outcome.scenario)?,
    };
    let scn = scenarios
        .iter()
        .find(|s| s.name == record.outcome.scenario)
        .with_context(|| {
            format!(
                "no scenario named {:?} among the embedded ones or in a manifest.json beside                  {}; pass its file with --scenario",
                record.outcome.scenario,
                file.display()
            )
        })?;
    let case = scn.case(&record.outcome.case)?;
    let opts = record.options();
    let run = scn.resolve(&opts)?;
    let mut sinks =
        crate::record::Sinks::open(rec, crate::record::metadata(&scn.name, &case.name, &run))?;
    let (out, written) = sinks.record(|r| forkbench_trial::run_trial_recorded(scn, case, &opts, r));
    let viewer_error = sinks.viewer_error.take();
    if let Some(e) = &viewer_error {
        eprintln!("error: {e} (the trial ran without the viewer)");
    }
    // Wall-clock times (the trial's and each leg's planning) are all a rerun may change.
    let same = serde_json::to_value(out.without_wall_times())?
        == serde_json::to_value(record.outcome.without_wall_times())?;
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
    written.context("writing the recording")?;
    if viewer_error.is_some() {
        bail!("the requested rerun viewer could not be reached");
    }
    if !same {
        bail!("the replay did not reproduce the recorded outcome");
    }
    Ok(out.success)
}
