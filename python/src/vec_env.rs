//! `PickVecEnv`: many pick environments stepped in parallel in Rust (rayon, the GIL released), each resetting itself on the step after its episode ends (Gymnasium's next-step autoreset).

use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray2};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use crate::env::{command, info, setup};
use crate::scenario::Scenario;
use forkbench_gym::{Core, EnvSpec, Setup, StepOut};
use forkbench_trial::trial::Control;

/// One environment of the vector: its episode, and the stream its episodes' seeds and
/// cases come from (its own, so results do not depend on the thread count).
#[derive(Debug)]
struct Slot {
    core: Option<Core>,
    rng: ChaCha8Rng,
    /// The episode ended on the last step: this step resets it.
    pending_reset: bool,
    error: Option<String>,
}

impl Slot {
    /// A new episode from this slot's stream.
    fn restart(&mut self, s: &Setup) {
        let seed = self.rng.random::<u64>() >> 1;
        let case = match &s.case {
            Some(c) => c.clone(),
            None => s.scn.cases[self.rng.random_range(0..s.scn.cases.len())]
                .name
                .clone(),
        };
        match Core::start(s, seed, &case) {
            Ok(core) => self.core = Some(core),
            Err(e) => self.error = Some(e.to_string()),
        }
        self.pending_reset = false;
    }

    fn step(&mut self, s: &Setup, control: Control, obs: &mut [f32]) -> StepOut {
        // An episode that ended before driving (no plan) terminates on the step after its
        // reset, as in the single environment.
        let out = if self.pending_reset {
            self.restart(s);
            StepOut::default()
        } else if let Some(core) = self.core.as_mut() {
            let out = core.step(s, control);
            self.pending_reset = core.ended();
            out
        } else {
            StepOut::default()
        };
        if let Some(core) = &self.core {
            core.write_obs(s, obs);
        }
        out
    }
}

/// Many pick environments stepped together (see `forkbench.gym.PalletPickVectorEnv`).
#[pyclass(module = "forkbench")]
#[derive(Debug)]
pub struct PickVecEnv {
    setup: Setup,
    n: usize,
    /// Behind a mutex only so the class may be shared with other Python threads; the
    /// methods take it exclusively and never lock.
    slots: std::sync::Mutex<Vec<Slot>>,
    pool: rayon::ThreadPool,
    /// Time spent stepping in Rust (the GIL released) since the last reset: what the
    /// Python side's overhead is measured against.
    stepping: std::time::Duration,
    /// Whether `reset` has run: a step before it has no episodes to step.
    was_reset: bool,
}

type VecReset<'py> = (Bound<'py, PyArray2<f32>>, Vec<Bound<'py, PyDict>>);

type VecStep<'py> = (
    Bound<'py, PyArray2<f32>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<bool>>,
    Bound<'py, PyArray1<bool>>,
    Vec<(usize, Bound<'py, PyDict>)>,
);

/// Most memory the environments of one vector environment may take.
const MAX_ENVS_BYTES: u64 = 4 << 30;

/// One environment's memory: its physics world, components and buffers (about 110–170 KB
/// measured on the field test), and a little more per rack, wall and reflector.
fn env_bytes(scn: &forkbench_trial::Scenario) -> u64 {
    let items = scn.world.obstacles().len() + scn.world.reflector.len();
    200_000 + 1_000 * items as u64
}

#[pymethods]
impl PickVecEnv {
    #[new]
    #[pyo3(signature = (scenario, num_envs, *, case=None, planner=None, tracker=None,
                        noise=true, replan=None, ticks_per_step=1, path_points=0,
                        path_spacing_m=0.5, reward=(10.0, 10.0, 0.1, 1.0), threads=None,
                        episode="pick", phase_reward=None, **options))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        scenario: &Scenario,
        num_envs: usize,
        case: Option<String>,
        planner: Option<String>,
        tracker: Option<String>,
        noise: bool,
        replan: Option<bool>,
        ticks_per_step: u32,
        path_points: usize,
        path_spacing_m: f64,
        reward: (f64, f64, f64, f64),
        threads: Option<usize>,
        episode: &str,
        phase_reward: Option<f64>,
        options: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let overrides = crate::options::overrides(options)?;
        let bytes = (num_envs as u64).saturating_mul(env_bytes(&scenario.inner));
        if num_envs == 0 || bytes > MAX_ENVS_BYTES {
            return Err(PyValueError::new_err(format!(
                "num_envs {num_envs}: at least 1, and at most what {} GiB holds (about {:.1} \
                 GiB asked: each environment of this scenario takes about {} KB)",
                MAX_ENVS_BYTES >> 30,
                bytes as f64 / f64::from(1u32 << 30),
                env_bytes(&scenario.inner) / 1000
            )));
        }
        let spec = EnvSpec {
            case,
            planner,
            tracker,
            noise,
            replan,
            overrides,
            ticks_per_step,
            path_points,
            path_spacing_m,
            reward,
            episode: episode.to_owned(),
            phase_reward,
            render_size: None,
        };
        let setup = setup(py, scenario, spec)?;
        let threads =
            threads.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads.clamp(1, 256))
            .build()
            .map_err(|e| PyRuntimeError::new_err(format!("thread pool: {e}")))?;
        let slots = (0..num_envs)
            .map(|_| Slot {
                core: None,
                rng: ChaCha8Rng::seed_from_u64(0),
                pending_reset: false,
                error: None,
            })
            .collect();
        Ok(PickVecEnv {
            setup,
            n: num_envs,
            slots: std::sync::Mutex::new(slots),
            pool,
            stepping: std::time::Duration::ZERO,
            was_reset: false,
        })
    }

    #[getter]
    fn num_envs(&self) -> usize {
        self.n
    }

    #[getter]
    fn observation_size(&self) -> usize {
        self.setup.obs.size()
    }

    /// Starts every environment: environment i draws its episodes from a stream seeded
    /// by `seed` and i.
    fn reset<'py>(&mut self, py: Python<'py>, seed: u64) -> PyResult<VecReset<'py>> {
        for (i, slot) in self.slots().iter_mut().enumerate() {
            slot.rng =
                ChaCha8Rng::seed_from_u64(seed ^ (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
            slot.pending_reset = true;
            slot.error = None;
        }
        let controls = vec![Control::Tracker; self.n];
        let (obs, _) = self.run(py, &controls)?;
        self.stepping = std::time::Duration::ZERO;
        self.was_reset = true;
        let infos = self
            .slots()
            .iter()
            .map(|s| match &s.core {
                Some(core) => info(py, core),
                None => Ok(PyDict::new(py)),
            })
            .collect::<PyResult<_>>()?;
        Ok((obs.into_pyarray(py), infos))
    }

    /// Seconds spent stepping the environments in Rust since the last reset.
    #[getter]
    fn stepping_s(&self) -> f64 {
        self.stepping.as_secs_f64()
    }

    /// One step of every environment under `actions` (num_envs × 2: speed m/s, steering
    /// rad; with `residual`, corrections to the tracker's command). Returns
    /// observations, rewards, terminated, truncated, and (index, info with the judged
    /// outcome) of each environment whose episode ended on this step.
    #[pyo3(signature = (actions, residual=false))]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        actions: PyReadonlyArray2<'py, f64>,
        residual: bool,
    ) -> PyResult<VecStep<'py>> {
        if !self.was_reset {
            return Err(PyRuntimeError::new_err(
                "step before reset: call reset() first (it starts every environment's episode)",
            ));
        }
        let a = actions.as_array();
        if a.shape() != [self.n, 2] {
            return Err(PyValueError::new_err(format!(
                "actions of shape {:?}: expected ({}, 2)",
                a.shape(),
                self.n
            )));
        }
        let controls = a
            .rows()
            .into_iter()
            .map(|r| command(r[0], r[1], residual))
            .collect::<PyResult<Vec<_>>>()?;
        let (obs, outs) = self.run(py, &controls)?;
        let outcomes = self
            .slots()
            .iter()
            .enumerate()
            .filter_map(|(i, s)| match &s.core {
                Some(core) if s.pending_reset => Some(info(py, core).map(|d| (i, d))),
                _ => None,
            })
            .collect::<PyResult<_>>()?;
        let col = |f: fn(&StepOut) -> bool| outs.iter().map(f).collect::<Vec<_>>().into_pyarray(py);
        Ok((
            obs.into_pyarray(py),
            outs.iter()
                .map(|o| o.reward)
                .collect::<Vec<_>>()
                .into_pyarray(py),
            col(|o| o.terminated),
            col(|o| o.truncated),
            outcomes,
        ))
    }
}

impl PickVecEnv {
    fn slots(&mut self) -> &mut Vec<Slot> {
        self.slots
            .get_mut()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    /// Every slot's step in parallel, without the GIL.
    fn run(
        &mut self,
        py: Python<'_>,
        controls: &[Control],
    ) -> PyResult<(Array2<f32>, Vec<StepOut>)> {
        let n = self.setup.obs.size();
        let mut obs = Array2::<f32>::zeros((self.n, n));
        let (setup, pool) = (&self.setup, &self.pool);
        let slots = self
            .slots
            .get_mut()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        let flat = obs
            .as_slice_mut()
            .ok_or_else(|| PyRuntimeError::new_err("observation buffer not contiguous"))?;
        let started = std::time::Instant::now();
        let outs = py.detach(|| {
            // One thread: no hand-over to the pool (it costs more than a tick).
            if pool.current_num_threads() == 1 {
                return slots
                    .iter_mut()
                    .zip(flat.chunks_mut(n.max(1)))
                    .zip(controls)
                    .map(|((slot, row), c)| slot.step(setup, *c, row))
                    .collect::<Vec<_>>();
            }
            pool.install(|| {
                slots
                    .par_iter_mut()
                    .zip(flat.par_chunks_mut(n.max(1)))
                    .zip(controls.par_iter())
                    .map(|((slot, row), c)| slot.step(setup, *c, row))
                    .collect::<Vec<_>>()
            })
        });
        self.stepping += started.elapsed();
        if let Some(e) = self.slots().iter_mut().find_map(|s| s.error.take()) {
            return Err(PyRuntimeError::new_err(format!(
                "an episode could not start: {e}"
            )));
        }
        Ok((obs, outs))
    }
}
