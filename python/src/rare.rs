//! `estimate` and `falsify`: rare events over a scenario's `[[uncertain]]` parameters, as the CLI's commands compute them, returned as dicts.

use forkbench_batch::rare::{Event, RareSetup, Tried};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::{BatchError, scenario_error, serde_to_py};
use crate::scenario::Scenario;

fn setup(
    py: Python<'_>,
    scenario: &Scenario,
    case: Option<&str>,
    (planner, tracker): (Option<String>, Option<String>),
    (event, seed, jobs): (&str, u64, Option<usize>),
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<RareSetup> {
    let overrides = crate::options::overrides(options)?;
    let scn = scenario.inner.as_ref().clone();
    let case = scn
        .pick_case(case)
        .map_err(|e| scenario_error(py, &e))?
        .name
        .clone();
    let event = Event::parse(event).map_err(|e| PyValueError::new_err(e.to_string()))?;
    let jobs = jobs.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, usize::from));
    Ok(RareSetup {
        scenario: scn,
        case,
        planner,
        tracker,
        overrides,
        seed,
        event,
        jobs,
    })
}

/// P(`event`) over the scenario's uncertain parameters: `method` `"ce"` (cross-entropy
/// importance sampling), `"subset"` (subset simulation, with its `level_fraction` p₀ and
/// `per_level` N) or `"mc"` (plain Monte Carlo), `budget` trials in all. A dict: `p`,
/// `ci`, `std_error`, `relative_error`, `ess`, `trials`, `adapting`, `events`, `stages`,
/// `levels`, `halt`; and `records`, every trial's record with its standard-normal point `z`.
#[pyfunction]
#[pyo3(signature = (scenario, case=None, *, event="failure", method="ce", budget=2000,
                    seed=1, jobs=None, planner=None, tracker=None, level_fraction=None,
                    per_level=None, **options))]
#[allow(clippy::too_many_arguments)]
pub fn estimate<'py>(
    py: Python<'py>,
    scenario: &Scenario,
    case: Option<&str>,
    event: &str,
    method: &str,
    budget: usize,
    seed: u64,
    jobs: Option<usize>,
    planner: Option<String>,
    tracker: Option<String>,
    level_fraction: Option<f64>,
    per_level: Option<usize>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyAny>> {
    if (level_fraction.is_some() || per_level.is_some()) && method != "subset" {
        return Err(PyValueError::new_err(
            "level_fraction and per_level are subset simulation's (method=\"subset\")",
        ));
    }
    let subset = forkbench_rare::SubsetSettings {
        level_fraction: level_fraction
            .unwrap_or(forkbench_rare::SubsetSettings::default().level_fraction),
        per_level,
    };
    let method = match method {
        "ce" => forkbench_rare::Method::Ce,
        "mc" => forkbench_rare::Method::Mc,
        "subset" => forkbench_rare::Method::Subset,
        m => {
            return Err(PyValueError::new_err(format!(
                "method {m:?}: \"ce\", \"subset\" or \"mc\""
            )));
        }
    };
    let s = setup(
        py,
        scenario,
        case,
        (planner, tracker),
        (event, seed, jobs),
        options,
    )?;
    with_records(py, &s, |s| {
        forkbench_batch::rare::estimate_with(s, (method, subset), budget, None)
    })
}

/// The most likely failure (the failing point of highest nominal density) within `budget`
/// trials, and the least robust trial; `monte_carlo=True` draws plainly instead, to
/// compare. A dict: `most_likely`, `least_robust` (each `z`, `outcome`, `ln_density`, or
/// None), `trials`, `events`, `stages`, and `records`.
#[pyfunction]
#[pyo3(signature = (scenario, case=None, *, event="failure", budget=2000, seed=1,
                    monte_carlo=false, jobs=None, planner=None, tracker=None, **options))]
#[allow(clippy::too_many_arguments)]
pub fn falsify<'py>(
    py: Python<'py>,
    scenario: &Scenario,
    case: Option<&str>,
    event: &str,
    budget: usize,
    seed: u64,
    monte_carlo: bool,
    jobs: Option<usize>,
    planner: Option<String>,
    tracker: Option<String>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyAny>> {
    let s = setup(
        py,
        scenario,
        case,
        (planner, tracker),
        (event, seed, jobs),
        options,
    )?;
    with_records(py, &s, |s| {
        forkbench_batch::rare::falsify(s, budget, monte_carlo, None)
    })
}

/// A rare-event run on `s` without the GIL, as a dict: its result and `records`, every
/// trial run with its point.
fn with_records<'py, T: serde::Serialize + Send>(
    py: Python<'py>,
    s: &RareSetup,
    run: impl FnOnce(&RareSetup) -> Result<(T, Vec<Tried>), forkbench_batch::BatchError> + Send,
) -> PyResult<Bound<'py, PyAny>> {
    let (result, tried) = py
        .detach(|| run(s))
        .map_err(|e| BatchError::new_err(e.to_string()))?;
    let d = serde_to_py(py, &result)?;
    d.set_item("records", serde_to_py(py, &tried)?)?;
    Ok(d)
}
