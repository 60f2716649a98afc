//! `run_trial` and `run_batch`: one trial (optionally recorded to MCAP) or a parallel batch, with the CLI's seeds and outcomes, as Python dicts.

use std::path::PathBuf;

use forkbench_batch::{BatchSpec, ReplanModes};
use forkbench_trial::TrialOptions;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::{BatchError, RecordingError, scenario_error, serde_to_py};
use crate::scenario::Scenario;

/// Runs one case of `scenario` to its judged outcome (a dict: the CLI's `trial --json`).
/// `case` may be omitted when the scenario has one case. `mcap` records the trial to
/// that file (Foxglove schemas; .rrd recordings come from the CLI). Further keywords are
/// the run's options (`RUN_OPTIONS`: noise scales, sensing models, missing reflectors,
/// `truck_preset` and `truck` settings by dotted path), as the CLI's flags.
#[pyfunction]
#[pyo3(signature = (scenario, case=None, *, seed=None, planner=None, tracker=None,
                    noise=true, replan=None, mcap=None, force=false, **options))]
#[allow(clippy::too_many_arguments)]
pub fn run_trial<'py>(
    py: Python<'py>,
    scenario: &Scenario,
    case: Option<&str>,
    seed: Option<u64>,
    planner: Option<String>,
    tracker: Option<String>,
    noise: bool,
    replan: Option<bool>,
    mcap: Option<PathBuf>,
    force: bool,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyAny>> {
    let scn = &scenario.inner;
    let case = scn.pick_case(case).map_err(|e| scenario_error(py, &e))?;
    let opts = TrialOptions {
        seed,
        planner,
        tracker,
        no_noise: !noise,
        replan,
        overrides: crate::options::overrides(options)?,
        wall_budget_s: None,
        uncertain: Default::default(),
    };
    // The CLI's own check: values in range, and every override acting on this scenario.
    let run = opts
        .check_against(scn)
        .map_err(|e| scenario_error(py, &e))?;
    let out = match mcap {
        None => py.detach(|| forkbench_trial::run_trial(scn, case, &opts)),
        Some(path) => {
            // As the CLI: an existing file is replaced only when asked (`force=True`).
            let targets = forkbench_log::RecordTargets {
                mcap: Some(path),
                force,
                ..Default::default()
            };
            let r = py
                .detach(|| forkbench_log::run_recorded((scn, case), (&opts, &run), &targets))
                .map_err(|e| RecordingError::new_err(e.to_string()))?;
            r.written
                .map_err(|e| RecordingError::new_err(e.to_string()))?;
            r.outcome
        }
    };
    serde_to_py(py, &out)
}

/// Most memory the records a batch returns to Python may take, as dicts.
const MAX_RECORDS_BYTES: u64 = 2 << 30;
/// Memory of one pick's record as a Python dict (about 40 fields; measured 5.7 KB).
const PY_RECORD_BYTES: u64 = 6_000;
/// What each mission leg or phase adds to a record (its JSON's size about four times).
const PY_PART_BYTES: u64 = 4_000;

/// The memory `spec`'s records would take in Python: rows × trials × a record's size,
/// from the legs and phases each scenario's records carry (a staging leg included).
fn records_bytes(spec: &BatchSpec) -> u64 {
    spec.scenarios
        .iter()
        .map(|s| {
            let one = BatchSpec {
                scenarios: vec![s.clone()],
                ..spec.clone()
            };
            let records: u64 = one.row_sizes().iter().map(|(_, n)| n).sum();
            let legs = s.mission.as_ref().map_or(0, |m| m.via.len() + 1);
            let parts = (legs + s.phases.len() + 1) as u64;
            records.saturating_mul(PY_RECORD_BYTES + PY_PART_BYTES * parts)
        })
        .fold(0, u64::saturating_add)
}

/// Runs a batch as the CLI's `batch` does (the same trial seeds from `seed` and each
/// trial's identity, so the same outcomes), in parallel on `jobs` threads, and returns
/// its records (dicts: the lines of `trials.jsonl`) in the batch's job order. Without
/// `scenarios`, the embedded defaults in both replanning modes (the README's main job).
/// With `out`, also writes (or resumes) the CLI's batch directory there; `force_new`
/// starts that directory over (a batch's own files only), as the CLI's `--force-new`.
#[pyfunction]
#[pyo3(signature = (scenarios=None, *, trials=20, seed=1, planners=None, trackers=None,
                    modes=None, jobs=None, out=None, force_new=false, **options))]
#[allow(clippy::too_many_arguments)]
pub fn run_batch<'py>(
    py: Python<'py>,
    scenarios: Option<Vec<Scenario>>,
    trials: u64,
    seed: u64,
    planners: Option<Vec<String>>,
    trackers: Option<Vec<String>>,
    modes: Option<&str>,
    jobs: Option<usize>,
    out: Option<PathBuf>,
    force_new: bool,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Vec<Bound<'py, PyAny>>> {
    let overrides = crate::options::overrides(options)?;
    let embedded = scenarios.is_none();
    let scenarios = match scenarios {
        Some(s) => s.iter().map(|s| (*s.inner).clone()).collect(),
        None => crate::scenario::default_scenarios(py)?
            .iter()
            .map(|s| (*s.inner).clone())
            .collect(),
    };
    let asked = modes
        .map(str::parse::<ReplanModes>)
        .transpose()
        .map_err(|e| BatchError::new_err(format!("modes {e}")))?;
    let (replan, compare_replanning) = ReplanModes::choose(false, asked, embedded).spec_fields();
    let spec = BatchSpec {
        scenarios,
        planners: planners.unwrap_or_default(),
        trackers: trackers.unwrap_or_default(),
        trials,
        seed,
        shard: (0, 1),
        overrides,
        replan,
        compare_replanning,
        force_new,
        success_run: Default::default(),
        profile: false,
    };
    let bytes = records_bytes(&spec);
    if bytes > MAX_RECORDS_BYTES {
        return Err(BatchError::new_err(format!(
            "{trials} trials per case: their records would take about {:.1} GiB in Python, \
             more than {} GiB; run the CLI's batch (sharded if need be) and read its \
             trials.jsonl",
            bytes as f64 / f64::from(1u32 << 30),
            MAX_RECORDS_BYTES >> 30
        )));
    }
    if jobs == Some(0) {
        return Err(BatchError::new_err("jobs 0: at least one worker thread"));
    }
    check_out(out.as_deref(), force_new)?;
    let jobs = jobs.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    let records = py
        .detach(|| forkbench_batch::run_records(&spec, jobs, out.as_deref()))
        .map_err(|e| BatchError::new_err(e.to_string()))?;
    records.iter().map(|r| serde_to_py(py, r)).collect()
}

/// `out` names a directory when given, and `force_new` asks for one.
fn check_out(out: Option<&std::path::Path>, force_new: bool) -> PyResult<()> {
    if out.is_some_and(|p| p.as_os_str().is_empty()) {
        return Err(BatchError::new_err(
            "out \"\": name the batch directory (None keeps the records in memory)",
        ));
    }
    if force_new && out.is_none() {
        return Err(BatchError::new_err(
            "force_new: starts the batch directory `out` over; name it (without `out` the \
             records stay in memory and nothing is written)",
        ));
    }
    Ok(())
}
