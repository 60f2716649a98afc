//! One episode: a trial `Session` stepped tick by tick under a caller's control, its shaped reward (the truth's progress, the phases passed, the verdict) and its observation.

use forkbench_trial::trial::{Control, Episode, Session, SessionEnd, Stage};
use forkbench_trial::{ScenarioError, TrialOptions, TrialOutcome};

use crate::obs;
use crate::render::Window;
use crate::{GymError, Setup};

/// One environment: the episode's session and the reward's running potential.
#[derive(Debug)]
pub struct Core {
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
pub struct StepOut {
    pub reward: f64,
    pub terminated: bool,
    pub truncated: bool,
}

impl Core {
    pub fn start(s: &Setup, seed: u64, case: &str) -> Result<Self, ScenarioError> {
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
    pub fn ended(&self) -> bool {
        self.session.ended().is_some()
    }

    /// Up to `ticks_per_step` ticks under `control`, their summed reward, and the end.
    pub fn step(&mut self, s: &Setup, control: Control) -> StepOut {
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
    pub fn frame(&self, s: &Setup) -> Option<(Vec<u8>, [u32; 2])> {
        let (size, window, view) = (s.render?, self.window?, self.session.view()?);
        let pixels = crate::render::draw(&view, &s.scn.truck, &s.scn.pallet, window, size);
        Some((pixels, size))
    }

    pub fn write_obs(&self, s: &Setup, out: &mut [f32]) {
        obs::write(self.session.observation(), self.session.path(), &s.obs, out);
    }

    /// The controller's view now.
    pub fn observation(&self) -> &forkbench_trial::trial::Observation {
        self.session.observation()
    }

    /// The episode's trial seed and case.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    pub fn case(&self) -> &str {
        &self.case
    }

    /// The judged outcome, once the episode has ended.
    pub fn outcome(&self) -> Option<&TrialOutcome> {
        self.session.ended().map(|(o, _)| o)
    }
}

/// A caller's command: finite numbers (the session clamps them to the truck's
/// limits); `residual`: a correction to the scenario's tracker's command.
pub fn command(speed_mps: f64, steer_rad: f64, residual: bool) -> Result<Control, GymError> {
    if !(speed_mps.is_finite() && steer_rad.is_finite()) {
        return Err(GymError::Setting(format!(
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
