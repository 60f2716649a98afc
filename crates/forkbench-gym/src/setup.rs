//! What every episode of an environment shares, checked once: the scenario and the run's options, the observation's and reward's settings, the ticks a step takes, the frame size.

use std::sync::Arc;

use forkbench_trial::trial::{Episode, Overrides};
use forkbench_trial::{Scenario, TrialOptions};

use crate::GymError;
use crate::obs::{ObsConfig, RewardConfig};

/// Most path points an observation carries (it is allocated per step).
pub const MAX_PATH_POINTS: usize = 1000;

/// A whole cycle's reward for each part of it judged a success, by default.
pub const DEFAULT_PHASE_REWARD: f64 = 2.0;

/// Frame sizes a drawn environment may ask for, in pixels a side.
pub const RENDER_PX: (u32, u32) = (16, 4096);

/// An environment as its constructor is given it (the Python keywords, one field each,
/// the run's options aside). Serialised, its default is the Python module's
/// `ENV_DEFAULTS`, against which a test checks the constructors' keywords and the stub.
#[derive(Debug, Clone, serde::Serialize)]
pub struct EnvSpec {
    /// The case every episode runs; `None`: drawn per episode.
    pub case: Option<String>,
    pub planner: Option<String>,
    pub tracker: Option<String>,
    pub noise: bool,
    pub replan: Option<bool>,
    /// The run's options (noise scales, sensing models, the truck's actuators).
    #[serde(skip)]
    pub overrides: Overrides,
    pub ticks_per_step: u32,
    pub path_points: usize,
    pub path_spacing_m: f64,
    /// Weights: success, failure, time per second, heading metres per radian.
    pub reward: (f64, f64, f64, f64),
    /// `"pick"` or `"cycle"`.
    pub episode: String,
    /// A whole cycle's reward per part judged a success (default 2).
    pub phase_reward: Option<f64>,
    /// Frame size (width, height) when episodes are drawn.
    pub render_size: Option<(u32, u32)>,
}

impl Default for EnvSpec {
    fn default() -> Self {
        Self {
            case: None,
            planner: None,
            tracker: None,
            noise: true,
            replan: None,
            overrides: Overrides::default(),
            ticks_per_step: 1,
            path_points: 0,
            path_spacing_m: 0.5,
            reward: (10.0, 10.0, 0.1, 1.0),
            episode: "pick".to_owned(),
            phase_reward: None,
            render_size: None,
        }
    }
}

/// What every episode of an environment shares.
#[derive(Debug, Clone)]
pub struct Setup {
    pub scn: Arc<Scenario>,
    /// The case every episode runs; `None`: drawn per episode.
    pub case: Option<String>,
    pub(crate) opts: TrialOptions,
    pub obs: ObsConfig,
    pub(crate) reward: RewardConfig,
    pub(crate) ticks_per_step: u32,
    /// Frame size (width, height) when episodes are drawn; `None`: no views kept.
    pub render: Option<[u32; 2]>,
    /// The pick alone, or the whole cycle.
    pub(crate) episode: Episode,
}

impl Setup {
    /// `spec` on `scn`, every setting checked (the run's options as a trial checks them).
    pub fn new(scn: Arc<Scenario>, spec: EnvSpec) -> Result<Self, GymError> {
        if let Some(c) = &spec.case {
            scn.case(c)?;
        }
        let opts = TrialOptions {
            planner: spec.planner,
            tracker: spec.tracker,
            no_noise: !spec.noise,
            replan: spec.replan,
            overrides: spec.overrides,
            ..TrialOptions::default()
        };
        opts.check_against(&scn)?;
        let bad = |why: String| Err(GymError::Setting(why));
        if spec.ticks_per_step == 0
            || !(spec.path_spacing_m.is_finite() && spec.path_spacing_m > 0.0)
        {
            return bad(
                "ticks_per_step must be at least 1 and path_spacing_m a positive length".into(),
            );
        }
        if spec.path_points > MAX_PATH_POINTS {
            return bad(format!(
                "path_points {}: at most {MAX_PATH_POINTS}",
                spec.path_points
            ));
        }
        let (episode, phase) = episode_of(&spec.episode, spec.phase_reward)?;
        let (success, failure, time_per_s, heading_m_per_rad) = spec.reward;
        if ![success, failure, time_per_s, heading_m_per_rad]
            .iter()
            .all(|v| v.is_finite())
        {
            return bad("the reward weights must be finite".into());
        }
        Ok(Setup {
            scn,
            case: spec.case,
            opts,
            obs: ObsConfig {
                stage: episode == Episode::Cycle,
                path_points: spec.path_points,
                path_spacing_m: spec.path_spacing_m,
            },
            reward: RewardConfig {
                success,
                failure,
                time_per_s,
                heading_m_per_rad,
                phase,
            },
            ticks_per_step: spec.ticks_per_step,
            render: render_of(spec.render_size)?,
            episode,
        })
    }
}

/// The frame size asked for, each side within [`RENDER_PX`].
fn render_of(size: Option<(u32, u32)>) -> Result<Option<[u32; 2]>, GymError> {
    let Some((w, h)) = size else {
        return Ok(None);
    };
    let (lo, hi) = RENDER_PX;
    if !((lo..=hi).contains(&w) && (lo..=hi).contains(&h)) {
        return Err(GymError::Setting(format!(
            "render_size ({w}, {h}): each side {lo}–{hi} pixels"
        )));
    }
    Ok(Some([w, h]))
}

/// The episode's extent and its phase reward: `phase_reward` only for whole cycles.
fn episode_of(episode: &str, phase_reward: Option<f64>) -> Result<(Episode, f64), GymError> {
    let bad = |why: String| Err(GymError::Setting(why));
    let episode = match episode {
        "pick" => Episode::Pick,
        "cycle" => Episode::Cycle,
        other => return bad(format!("episode {other:?}: \"pick\" or \"cycle\"")),
    };
    let phase = match (episode, phase_reward) {
        (Episode::Pick, Some(_)) => {
            return bad(
                "phase_reward rewards the parts of a whole cycle: it needs episode=\"cycle\""
                    .into(),
            );
        }
        (_, Some(p)) if !(p.is_finite() && p.abs() <= 1e6) => {
            return bad(format!("phase_reward {p}: a finite weight within ±1e6"));
        }
        (Episode::Cycle, p) => p.unwrap_or(DEFAULT_PHASE_REWARD),
        (Episode::Pick, None) => 0.0,
    };
    Ok((episode, phase))
}
