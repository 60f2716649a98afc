//! The Gymnasium environments' Rust core: one pick trial per episode stepped a control tick at a time, singly (`PickEnv`) or many in parallel with automatic resets (`PickVecEnv`).

use std::sync::Arc;

use forkbench_trial::trial::{Control, Episode, Overrides, Session, SessionEnd, Stage};
use forkbench_trial::{Scenario as Inner, TrialError, TrialOptions};
use numpy::{IntoPyArray, PyArray1, PyArray3};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::{scenario_error, serde_to_py};
use crate::obs::{self, ObsConfig, RewardConfig};
use crate::render::Window;
use crate::scenario::Scenario;

/// Most path points an observation carries (it is allocated per step).
const MAX_PATH_POINTS: usize = 1000;

/// What every episode of an environment shares.
#[derive(Debug, Clone)]
pub(crate) struct Setup {
    pub(crate) scn: Arc<Inner>,
    /// The case every episode runs; `None`: drawn per episode.
    pub(crate) case: Option<String>,
    opts: TrialOptions,
    pub(crate) obs: ObsConfig,
    reward: RewardConfig,
    ticks_per_step: u32,
    /// Frame size (width, height) when episodes are drawn; `None`: no views kept.
    pub(crate) render: Option<[u32; 2]>,
    /// The pick alone, or the whole cycle.
    episode: Episode,
}

/// One environment: the episode's session and the reward's running potential.
#[derive(Debug)]
pub(crate) struct Core {
    session: Session,
    potential: f64,
    /// Parts of the cycle rewarded as passed so far (the pick and the phases).
    passed: usize,
    seed: u64,
    case: String,
    /// Where the episode is drawn, when it is.
    window: Option<Window>,
}

/// One step's result.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct StepOut {
    pub(crate) reward: f64,
    pub(crate) terminated: bool,
    pub(crate) truncated: bool,
}

impl Core {
    pub(crate) fn start(s: &Setup, seed: u64, case: &str) -> Result<Self, TrialError> {
        let opts = TrialOptions {
            seed: Some(seed),
            ..s.opts.clone()
        };
        let session =
            Session::start_episode(s.scn.clone(), case, &opts, s.episode, s.render.is_some())?;
        let potential = s.reward.distance(session.truth());
        let window = session
            .view()
            .map(|v| Window::around(&session.truth().fork_root, &v.pallet));
        Ok(Core {
            session,
            potential,
            passed: 0,
            seed,
            case: case.to_owned(),
            window,
        })
    }

    /// Whether the episode has ended.
    pub(crate) fn ended(&self) -> bool {
        self.session.ended().is_some()
    }

    /// Up to `ticks_per_step` ticks under `control`, their summed reward, and the end.
    pub(crate) fn step(&mut self, s: &Setup, control: Control) -> StepOut {
        let mut out = StepOut::default();
        for _ in 0..s.ticks_per_step {
            let (t0, before) = {
                let o = self.session.observation();
                (o.t_s, o.stage)
            };
            let end = match self.session.ended() {
                Some((_, end)) => Some(end),
                None => self.session.step(control),
            };
            let o = self.session.observation();
            out.reward -= s.reward.time_per_s * (o.t_s - t0);
            out.reward += self.progress(s, before, o.stage);
            if let Some(end) = end {
                if let Some((o, _)) = self.session.ended() {
                    let passed = if o.phases.is_empty() {
                        usize::from(o.success)
                    } else {
                        o.phases.iter().filter(|p| p.success).count()
                    };
                    if s.episode == Episode::Cycle && passed > self.passed {
                        out.reward += s.reward.phase * (passed - self.passed) as f64;
                        self.passed = passed;
                    }
                    out.reward += s.reward.terminal(o, end);
                }
                out.terminated = end == SessionEnd::Judged;
                out.truncated = end == SessionEnd::TimeLimit;
                break;
            }
        }
        out
    }

    /// The shaping of one tick that went from stage `before` to `now`: during the pick,
    /// the potential's decrease; on leaving the pick or a phase (a whole cycle goes on
    /// only past a success), the phase reward.
    fn progress(&mut self, s: &Setup, before: Stage, now: Stage) -> f64 {
        let mut reward = 0.0;
        if now == Stage::Pick {
            let d = s.reward.distance(self.session.truth());
            if before == Stage::Pick {
                reward += self.potential - d;
            }
            self.potential = d;
        }
        if let (Stage::Pick | Stage::Phase(_), Stage::Phase(k)) = (before, now)
            && before != now
        {
            let passed = usize::from(k);
            reward += s.reward.phase * passed.saturating_sub(self.passed) as f64;
            self.passed = self.passed.max(passed);
        }
        reward
    }

    /// The episode drawn at the setup's frame size (RGB rows); `None` when the setup does
    /// not draw, or the episode ended before its first tick.
    pub(crate) fn frame(&self, s: &Setup) -> Option<(Vec<u8>, [u32; 2])> {
        let (size, window, view) = (s.render?, self.window?, self.session.view()?);
        let pixels = crate::render::draw(&view, &s.scn.truck, &s.scn.pallet, window, size);
        Some((pixels, size))
    }

    pub(crate) fn write_obs(&self, s: &Setup, out: &mut [f32]) {
        obs::write(self.session.observation(), self.session.path(), &s.obs, out);
    }

    /// The step's `info`: time, seed, case, fix; and the judged outcome at the end.
    pub(crate) fn info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        let o = self.session.observation();
        d.set_item("t_s", o.t_s)?;
        d.set_item("fix", o.fix)?;
        d.set_item("seed", self.seed)?;
        d.set_item("case", &self.case)?;
        if let Some((out, _)) = self.session.ended() {
            d.set_item("success", out.success)?;
            d.set_item("failure", out.failure.as_ref().map(|f| f.name()))?;
            d.set_item("outcome", serde_to_py(py, out)?)?;
        }
        Ok(d)
    }
}

#[allow(clippy::too_many_arguments)]
pub(crate) fn setup(
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
    (episode, phase_reward, overrides): (&str, Option<f64>, Overrides),
) -> PyResult<Setup> {
    let scn = scenario.inner.clone();
    if let Some(c) = &case {
        scn.case(c).map_err(|e| scenario_error(py, &e))?;
    }
    let opts = TrialOptions {
        planner,
        tracker,
        no_noise: !noise,
        replan,
        overrides,
        ..TrialOptions::default()
    };
    // The run's own check: values in range, and every option acting on this scenario.
    scn.check_options(&opts)
        .map_err(|e| scenario_error(py, &e))?;
    if ticks_per_step == 0 || !(path_spacing_m.is_finite() && path_spacing_m > 0.0) {
        return Err(PyValueError::new_err(
            "ticks_per_step must be at least 1 and path_spacing_m a positive length",
        ));
    }
    if path_points > MAX_PATH_POINTS {
        return Err(PyValueError::new_err(format!(
            "path_points {path_points}: at most {MAX_PATH_POINTS}"
        )));
    }
    let (episode, phase) = episode_of(episode, phase_reward)?;
    let (success, failure, time_per_s, heading_m_per_rad) = reward;
    if ![success, failure, time_per_s, heading_m_per_rad]
        .iter()
        .all(|v| v.is_finite())
    {
        return Err(PyValueError::new_err("the reward weights must be finite"));
    }
    Ok(Setup {
        scn,
        case,
        opts,
        obs: ObsConfig {
            stage: episode == Episode::Cycle,
            path_points,
            path_spacing_m,
        },
        reward: RewardConfig {
            success,
            failure,
            time_per_s,
            heading_m_per_rad,
            phase,
        },
        ticks_per_step,
        render: None,
        episode,
    })
}

/// The episode's extent and its phase reward: `phase_reward` only for whole cycles.
fn episode_of(episode: &str, phase_reward: Option<f64>) -> PyResult<(Episode, f64)> {
    let episode = match episode {
        "pick" => Episode::Pick,
        "cycle" => Episode::Cycle,
        other => {
            return Err(PyValueError::new_err(format!(
                "episode {other:?}: \"pick\" or \"cycle\""
            )));
        }
    };
    let phase = match (episode, phase_reward) {
        (Episode::Pick, Some(_)) => {
            return Err(PyValueError::new_err(
                "phase_reward rewards the parts of a whole cycle: it needs episode=\"cycle\"",
            ));
        }
        (_, Some(p)) if !(p.is_finite() && p.abs() <= 1e6) => {
            return Err(PyValueError::new_err(format!(
                "phase_reward {p}: a finite weight within ±1e6"
            )));
        }
        (Episode::Cycle, p) => p.unwrap_or(DEFAULT_PHASE_REWARD),
        (Episode::Pick, None) => 0.0,
    };
    Ok((episode, phase))
}

/// A command from Python: finite numbers (the session clamps them to the truck's
/// limits); `residual`: a correction to the scenario's tracker's command.
pub(crate) fn command(speed_mps: f64, steer_rad: f64, residual: bool) -> PyResult<Control> {
    if !(speed_mps.is_finite() && steer_rad.is_finite()) {
        return Err(PyValueError::new_err(format!(
            "action ({speed_mps}, {steer_rad}): speed and steering must be finite"
        )));
    }
    Ok(if residual {
        Control::Residual {
            speed_mps,
            steer_rad,
        }
    } else {
        Control::Command {
            speed_mps,
            steer_rad,
        }
    })
}

/// A whole cycle's reward for each part of it judged a success, by default.
const DEFAULT_PHASE_REWARD: f64 = 2.0;

/// Frame sizes `render_size` may ask for, in pixels a side.
const RENDER_PX: (u32, u32) = (16, 4096);

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
        let overrides = crate::options::overrides(py, options)?;
        let mut setup = setup(
            py,
            scenario,
            case,
            planner,
            tracker,
            noise,
            replan,
            ticks_per_step,
            path_points,
            path_spacing_m,
            reward,
            (episode, phase_reward, overrides),
        )?;
        if let Some((w, h)) = render_size {
            let (lo, hi) = RENDER_PX;
            if !((lo..=hi).contains(&w) && (lo..=hi).contains(&h)) {
                return Err(PyValueError::new_err(format!(
                    "render_size ({w}, {h}): each side {lo}–{hi} pixels"
                )));
            }
            setup.render = Some([w, h]);
        }
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
        Ok((observation(py, &self.setup, core), core.info(py)?))
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
            core.info(py)?,
        ))
    }
}

fn observation<'py>(py: Python<'py>, s: &Setup, core: &Core) -> Bound<'py, PyArray1<f32>> {
    let mut v = vec![0.0f32; s.obs.size()];
    core.write_obs(s, &mut v);
    PyArray1::from_vec(py, v)
}
