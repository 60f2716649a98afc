//! forkbench's Python module `forkbench._forkbench`: scenarios, trials and batches as Python objects, and the Gymnasium environments' Rust core.

mod batch;
mod convert;
mod env;
mod options;
mod rare;
mod report;
mod scenario;
mod vec_env;

use pyo3::prelude::*;

/// The extension module; `forkbench` re-exports it with the Python-side helpers.
#[pymodule]
fn _forkbench(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("ScenarioError", py.get_type::<convert::ScenarioError>())?;
    m.add("BatchError", py.get_type::<convert::BatchError>())?;
    m.add("RecordingError", py.get_type::<convert::RecordingError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<scenario::Scenario>()?;
    m.add_class::<env::PickEnv>()?;
    m.add_class::<vec_env::PickVecEnv>()?;
    m.add_function(wrap_pyfunction!(scenario::default_scenarios, m)?)?;
    m.add_function(wrap_pyfunction!(batch::run_trial, m)?)?;
    m.add_function(wrap_pyfunction!(batch::run_batch, m)?)?;
    m.add_function(wrap_pyfunction!(rare::estimate, m)?)?;
    m.add_function(wrap_pyfunction!(rare::falsify, m)?)?;
    m.add_function(wrap_pyfunction!(report::report, m)?)?;
    m.add_function(wrap_pyfunction!(report::replay, m)?)?;
    m.add("OBSERVATION_FIELDS", forkbench_gym::obs::FIELDS.to_vec())?;
    m.add(
        "RUN_OPTIONS",
        forkbench_trial::trial::Overrides::field_names().to_vec(),
    )?;
    m.add("STAGE_FIELD", forkbench_gym::obs::STAGE_FIELD)?;
    m.add(
        "ENV_DEFAULTS",
        convert::serde_to_py(py, &forkbench_gym::EnvSpec::default())?,
    )?;
    Ok(())
}
