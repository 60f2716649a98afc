//! The Gymnasium environment's Python binding: `PickEnv` over the `forkbench-gym` library's setup and episode, and the conversions both environments share (the setup from keywords, a command, a step's `info`).

use forkbench_gym::{Core, EnvSpec, GymError, Setup};
use forkbench_trial::trial::Control;
use numpy::{IntoPyArray, PyArray1, PyArray3};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::{scenario_error, serde_to_py};
use crate::scenario::Scenario;

/// An environment's setup from its keywords; a refused setting raises `ScenarioError`
/// (the scenario refused the run) or `ValueError`.
pub(crate) fn setup(py: Python<'_>, scenario: &Scenario, spec: EnvSpec) -> PyResult<Setup> {
    Setup::new(scenario.inner.clone(), spec).map_err(|e| gym_error(py, e))
}

/// A library error as the Python exception it stands for.
pub(crate) fn gym_error(py: Python<'_>, e: GymError) -> PyErr {
    match e {
        GymError::Scenario(e) => scenario_error(py, &e),
        GymError::Setting(why) => PyValueError::new_err(why),
    }
}

/// A command from Python (finite numbers; the session clamps them to the truck's limits).
pub(crate) fn command(speed_mps: f64, steer_rad: f64, residual: bool) -> PyResult<Control> {
    forkbench_gym::command(speed_mps, steer_rad, residual)
        .map_err(|e| PyValueError::new_err(e.to_string()))
}

/// The step's `info`: time, seed, case, fix; and the judged outcome at the end.
pub(crate) fn info<'py>(py: Python<'py>, core: &Core) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let o = core.observation();
    d.set_item("t_s", o.t_s)?;
    d.set_item("fix", o.fix)?;
    d.set_item("seed", core.seed())?;
    d.set_item("case", core.case())?;
    if let Some(out) = core.outcome() {
        d.set_item("success", out.success)?;
        d.set_item("failure", out.failure.as_ref().map(|f| f.name()))?;
        d.set_item("outcome", serde_to_py(py, out)?)?;
    }
    Ok(d)
}

/// One pick trial per episode, stepped from Python (see `forkbench.gym.PalletPickEnv`).
#[pyclass(module = "forkbench")]
#[derive(Debug)]
pub struct PickEnv {
    setup: Setup,
    /// Behind a mutex only so the class may be shared with other Python threads; the
    /// methods take it exclusively and never lock.
    core: std::sync::Mutex<Option<Core>>,
}

type StepTuple<'py> = (
    Bound<'py, PyArray1<f32>>,
    f64,
    bool,
    bool,
    Bound<'py, PyDict>,
);

#[pymethods]
impl PickEnv {
    #[new]
    #[pyo3(signature = (scenario, *, case=None, planner=None, tracker=None, noise=true,
                        replan=None, ticks_per_step=1, path_points=0, path_spacing_m=0.5,
                        reward=(10.0, 10.0, 0.1, 1.0), render_size=None, episode="pick",
                        phase_reward=None, **options))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        scenario: &Scenario,
        case: Option<String>,
        planner: Option<String>,
        tracker: Option<String>,
        noise: bool,
        replan: Option<bool>,
        ticks_per_step: u32,
        path_points: usize,
        path_spacing_m: f64,
        reward: (f64, f64, f64, f64),
        render_size: Option<(u32, u32)>,
        episode: &str,
        phase_reward: Option<f64>,
        options: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let spec = EnvSpec {
            case,
            planner,
            tracker,
            noise,
            replan,
            overrides: crate::options::overrides(options)?,
            ticks_per_step,
            path_points,
            path_spacing_m,
            reward,
            episode: episode.to_owned(),
            phase_reward,
            render_size,
        };
        let setup = setup(py, scenario, spec)?;
        Ok(PickEnv {
            setup,
            core: std::sync::Mutex::new(None),
        })
    }

    /// Length of an observation vector.
    #[getter]
    fn observation_size(&self) -> usize {
        self.setup.obs.size()
    }

    /// Starts an episode: case `case` (or the environment's) with trial seed `seed`.
    #[pyo3(signature = (seed, case=None))]
    fn reset<'py>(
        &mut self,
        py: Python<'py>,
        seed: u64,
        case: Option<String>,
    ) -> PyResult<(Bound<'py, PyArray1<f32>>, Bound<'py, PyDict>)> {
        let case = case
            .or_else(|| self.setup.case.clone())
            .ok_or_else(|| PyValueError::new_err("no case given and none fixed"))?;
        let setup = &self.setup;
        let core = py
            .detach(|| Core::start(setup, seed, &case))
            .map_err(|e| scenario_error(py, &e))?;
        let slot = self
            .core
            .get_mut()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        let core = slot.insert(core);
        Ok((observation(py, &self.setup, core), info(py, core)?))
    }

    /// One step under the caller's command (speed m/s, steering rad).
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        speed_mps: f64,
        steer_rad: f64,
    ) -> PyResult<StepTuple<'py>> {
        self.advance(py, command(speed_mps, steer_rad, false)?)
    }

    /// One step under the scenario's tracker's command corrected by (speed m/s, steering
    /// rad); a zero correction is the tracker's own step.
    fn residual_step<'py>(
        &mut self,
        py: Python<'py>,
        speed_mps: f64,
        steer_rad: f64,
    ) -> PyResult<StepTuple<'py>> {
        self.advance(py, command(speed_mps, steer_rad, true)?)
    }

    /// The episode as an RGB image (height × width × 3, uint8); `None` without a
    /// `render_size` or before the first reset.
    fn render<'py>(&mut self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyArray3<u8>>>> {
        let setup = &self.setup;
        let core = self
            .core
            .get_mut()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        let Some((pixels, [w, h])) = core.as_ref().and_then(|c| c.frame(setup)) else {
            return Ok(None);
        };
        let a = numpy::ndarray::Array3::from_shape_vec((h as usize, w as usize, 3), pixels)
            .map_err(|e| PyRuntimeError::new_err(format!("frame: {e}")))?;
        Ok(Some(a.into_pyarray(py)))
    }

    /// One step under the scenario's own tracker (the bench's reference controller).
    fn expert_step<'py>(&mut self, py: Python<'py>) -> PyResult<StepTuple<'py>> {
        self.advance(py, Control::Tracker)
    }
}

impl PickEnv {
    fn advance<'py>(&mut self, py: Python<'py>, control: Control) -> PyResult<StepTuple<'py>> {
        let setup = &self.setup;
        let core = self
            .core
            .get_mut()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .as_mut()
            .ok_or_else(|| PyRuntimeError::new_err("step before reset"))?;
        let out = core.step(setup, control);
        Ok((
            observation(py, setup, core),
            out.reward,
            out.terminated,
            out.truncated,
            info(py, core)?,
        ))
    }
}

fn observation<'py>(py: Python<'py>, s: &Setup, core: &Core) -> Bound<'py, PyArray1<f32>> {
    let mut v = vec![0.0f32; s.obs.size()];
    core.write_obs(s, &mut v);
    PyArray1::from_vec(py, v)
}
