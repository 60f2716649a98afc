//! `report` and `replay`: the CLI's HTML report of a batch directory, and one recorded trial re-run and checked, through the same library calls.

use std::path::PathBuf;

use forkbench_batch::{Replay, TrialRecord};
use pyo3::prelude::*;

use crate::convert::{BatchError, RecordingError, scenario_error, serde_to_py};
use crate::scenario::Scenario;

/// Writes the HTML report of a batch (or sweep) directory as `forkbench report DIR` does:
/// `dir/report.html`, or `out`; with `baseline`, the gate's verdict per row. Returns the
/// page's path.
#[pyfunction]
#[pyo3(signature = (dir, *, baseline=None, out=None))]
pub fn report(
    py: Python<'_>,
    dir: PathBuf,
    baseline: Option<PathBuf>,
    out: Option<PathBuf>,
) -> PyResult<PathBuf> {
    let out = out.unwrap_or_else(|| dir.join("report.html"));
    py.detach(|| forkbench_report::html::write_to(&dir, baseline.as_deref(), &out))
        .map_err(|e| BatchError::new_err(e.to_string()))
}

/// Re-runs one recorded trial as `forkbench replay` does and says whether it reproduced
/// the record (wall-clock times aside). `record` is a batch's records file (its line
/// `line`, 1-based) or one record as a dict (a `run_batch` record, or a parsed line of
/// `trials.jsonl`). The scenario is `scenario`, else the one the batch's manifest names,
/// else the embedded one of the record's name. `mcap` records the re-run. Returns
/// `{"outcome": dict, "identical": bool}`.
#[pyfunction]
#[pyo3(signature = (record, line=1, *, scenario=None, mcap=None, force=false))]
pub fn replay<'py>(
    py: Python<'py>,
    record: &Bound<'py, PyAny>,
    line: usize,
    scenario: Option<&Scenario>,
    mcap: Option<PathBuf>,
    force: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let given = scenario.map(|s| (*s.inner).clone());
    let fail = |e: forkbench_batch::BatchError| match e {
        forkbench_batch::BatchError::Trial(t) => scenario_error(py, &t),
        e => BatchError::new_err(e.to_string()),
    };
    let job = if let Ok(file) = record.extract::<PathBuf>() {
        py.detach(|| {
            let rec = Replay::read_record(&file, line)?;
            Replay::find(rec, given, Some(&file))
        })
        .map_err(fail)?
    } else {
        let text = crate::convert::json_text(record)?;
        let rec: TrialRecord = serde_json::from_str(&text)
            .map_err(|e| BatchError::new_err(format!("not a trial record: {e}")))?;
        Replay::find(rec, given, None).map_err(fail)?
    };
    let case = job.case().map_err(fail)?;
    let opts = job.options();
    let run = opts
        .resolve(&job.scenario)
        .map_err(|e| scenario_error(py, &e))?;
    let targets = forkbench_log::RecordTargets {
        mcap,
        force,
        ..Default::default()
    };
    let recorded = py
        .detach(|| forkbench_log::run_recorded((&job.scenario, case), (&opts, &run), &targets))
        .map_err(|e| RecordingError::new_err(e.to_string()))?;
    recorded
        .written
        .map_err(|e| RecordingError::new_err(e.to_string()))?;
    let identical = job.reproduces(&recorded.outcome);
    let out = pyo3::types::PyDict::new(py);
    out.set_item("outcome", serde_to_py(py, &recorded.outcome)?)?;
    out.set_item("identical", identical)?;
    Ok(out.into_any())
}
