//! `forkbench.Scenario`: a scenario file (or an embedded default) loaded and checked once, shared by trials, batches and environments.

use std::path::PathBuf;
use std::sync::Arc;

use forkbench_trial::defaults;
use forkbench_trial::scenario::Scenario as Inner;
use pyo3::prelude::*;

use crate::convert::scenario_error;

/// A loaded scenario: its world, truck, pallet, components, tolerances and cases.
#[pyclass(frozen, from_py_object, module = "forkbench")]
#[derive(Debug, Clone)]
pub struct Scenario {
    pub inner: Arc<Inner>,
}

#[pymethods]
impl Scenario {
    /// Loads and checks a scenario file (its world file and components too).
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        let loaded = py.detach(|| Inner::load(&path));
        loaded
            .map(|s| Scenario { inner: Arc::new(s) })
            .map_err(|e| scenario_error(py, &e))
    }

    /// One of the embedded default scenarios by name (see `default_scenarios()`).
    #[staticmethod]
    fn embedded(py: Python<'_>, name: &str) -> PyResult<Self> {
        let all = defaults::default_scenarios().map_err(|e| scenario_error(py, &e))?;
        let names: Vec<String> = all.iter().map(|s| s.name.clone()).collect();
        all.into_iter()
            .find(|s| s.name == name)
            .map(|s| Scenario { inner: Arc::new(s) })
            .ok_or_else(|| {
                let e = forkbench_trial::ScenarioError::Invalid {
                    file: "(embedded scenarios)".into(),
                    field: "name".into(),
                    reason: format!(
                        "no embedded scenario {name:?} (embedded: {})",
                        names.join(", ")
                    ),
                };
                scenario_error(py, &e)
            })
    }

    /// This scenario with every pallet estimate made by `kind` at its default settings
    /// (gaussian, tim561, kinect2, tim561+kinect2).
    fn with_pallet_sensing(&self, py: Python<'_>, kind: &str) -> PyResult<Self> {
        let s = (*self.inner).clone().with_pallet_sensing(kind);
        s.map(|s| Scenario { inner: Arc::new(s) })
            .map_err(|e| scenario_error(py, &e))
    }

    /// This scenario with the planners and trackers a components file defines usable by
    /// name (`planner=` / `tracker=` of trials, batches and environments), as the CLI's
    /// `--components FILE`.
    fn with_components(&self, py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        let s = (*self.inner).clone().with_components_file(&path);
        s.map(|s| Scenario { inner: Arc::new(s) })
            .map_err(|e| scenario_error(py, &e))
    }

    /// This scenario localised by `kind` at its default settings (gaussian, nav350).
    fn with_localizer(&self, py: Python<'_>, kind: &str) -> PyResult<Self> {
        let s = (*self.inner).clone().with_localizer(kind);
        s.map(|s| Scenario { inner: Arc::new(s) })
            .map_err(|e| scenario_error(py, &e))
    }

    #[getter]
    fn name(&self) -> String {
        self.inner.name.clone()
    }

    /// The file it was loaded from.
    #[getter]
    fn file(&self) -> String {
        self.inner.file.clone()
    }

    /// The case names, in file order.
    #[getter]
    fn cases(&self) -> Vec<String> {
        self.inner.cases.iter().map(|c| c.name.clone()).collect()
    }

    #[getter]
    fn planner(&self) -> String {
        self.inner.planner.name.clone()
    }

    #[getter]
    fn tracker(&self) -> String {
        self.inner.tracker.name.clone()
    }

    #[getter]
    fn seed(&self) -> u64 {
        self.inner.seed
    }

    #[getter]
    fn timeout_s(&self) -> f64 {
        self.inner.timeout_s
    }

    /// The truck's speed (m/s) and steering (rad) limits: the bounds of a command.
    #[getter]
    fn command_limits(&self) -> (f64, f64) {
        (
            self.inner.truck.max_speed_mps,
            self.inner.truck.max_steer_rad,
        )
    }

    /// How long one control tick (an environment's step) lasts: the truck's control
    /// period, or the physics step when control runs every step (s).
    #[getter]
    fn control_period_s(&self) -> f64 {
        self.inner
            .truck
            .control
            .period_s
            .unwrap_or(self.inner.sim.dt_s)
    }

    #[getter]
    fn has_mission(&self) -> bool {
        self.inner.mission.is_some()
    }

    fn __repr__(&self) -> String {
        format!(
            "Scenario({:?}, {} cases, planner {:?}, tracker {:?})",
            self.inner.name,
            self.inner.cases.len(),
            self.inner.planner.name,
            self.inner.tracker.name
        )
    }
}

/// The embedded default scenarios: what the CLI's `batch` runs without scenario files.
#[pyfunction]
pub fn default_scenarios(py: Python<'_>) -> PyResult<Vec<Scenario>> {
    let all = defaults::default_scenarios().map_err(|e| scenario_error(py, &e))?;
    Ok(all
        .into_iter()
        .map(|s| Scenario { inner: Arc::new(s) })
        .collect())
}
