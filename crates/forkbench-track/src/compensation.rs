//! Delay compensation for any tracker, as a Smith predictor does it: the pose is carried forward over the truck's known actuator delay with the commands still in flight, and the tracker steers from there.

use std::collections::VecDeque;

use forkbench_core::actuators::lag_fraction;
use forkbench_core::{ForkliftSpec, Path, Pose2};

use crate::predictor::advance_pose;
use crate::{Command, Tracker, TrackerInput};

/// Step of the forward prediction.
const PREDICT_DT_S: f64 = 0.01;

/// The speed loop's time constant when the truck does not set its own: the physics'
/// default (`[sim] speed_gain_per_s` 4/s), which a tracker cannot read.
const SIM_SPEED_LOOP_S: f64 = 0.25;

/// A tracker that steers from where the truck will be once its command acts.
pub struct DelayCompensated {
    inner: Box<dyn Tracker>,
    name: String,
    /// Commands issued, with when: (t_s, speed, steer), the last second or so.
    issued: VecDeque<(f64, f64, f64)>,
}

impl std::fmt::Debug for DelayCompensated {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DelayCompensated")
            .field("name", &self.name)
            .finish_non_exhaustive()
    }
}

impl DelayCompensated {
    /// `inner` compensated, reported as `name`.
    pub fn new(inner: Box<dyn Tracker>, name: &str) -> Self {
        Self {
            inner,
            name: name.to_owned(),
            issued: VecDeque::new(),
        }
    }

    /// The command in force at `t_s` among those issued (the latest at or before it;
    /// `now` where none was issued that early is in the log).
    fn issued_at(&self, t_s: f64, now: (f64, f64)) -> (f64, f64) {
        self.issued
            .iter()
            .rev()
            .find(|(t, _, _)| *t <= t_s + 1e-9)
            .map_or(now, |&(_, v, s)| (v, s))
    }

    /// Where the truck will stand, how fast and how steered, once a command issued now
    /// reaches the wheels: the measured state carried over the steering's dead time
    /// (with the transport delay) under the commands in flight, through the truck's
    /// steering lag and rate limit and its speed loop.
    pub fn predict(&self, input: &TrackerInput) -> (Pose2, f64, f64) {
        let t = input.truck;
        let (steer_delay, drive_delay) = (t.steering_delay_s(), t.drive_delay_s());
        let horizon = steer_delay.max(drive_delay);
        let (mut pose, mut v, mut steer) = (input.pose, input.speed_mps, input.steer_rad);
        let n = (horizon / PREDICT_DT_S).round() as usize;
        let now = (v, steer);
        let tau_v = t.drive.time_constant_s.unwrap_or(SIM_SPEED_LOOP_S);
        for k in 0..n {
            let at = input.t_s + k as f64 * PREDICT_DT_S;
            let (_, steer_cmd) = self.issued_at(at - steer_delay, now);
            let (speed_cmd, _) = self.issued_at(at - drive_delay, now);
            steer = steer_step(t, steer, steer_cmd);
            v += (speed_cmd - v) * (PREDICT_DT_S / tau_v).min(1.0);
            pose = advance_pose(
                &pose,
                (v, steer),
                (t.wheelbase_m, t.fork_root_ahead_of_front_axle_m),
                PREDICT_DT_S,
            );
        }
        (pose, v, steer)
    }
}

/// One prediction step of the steering: the first-order lag within the rate limit.
fn steer_step(t: &ForkliftSpec, steer: f64, cmd: f64) -> f64 {
    let alpha = lag_fraction(PREDICT_DT_S, t.steering.time_constant_s);
    let r = t.max_steer_rate_radps * PREDICT_DT_S;
    steer + (alpha * (cmd - steer)).clamp(-r, r)
}

impl Tracker for DelayCompensated {
    fn name(&self) -> &str {
        &self.name
    }

    fn reset(&mut self, path: &Path, truck: &ForkliftSpec) {
        self.inner.reset(path, truck);
    }

    fn command(&mut self, input: &TrackerInput) -> Command {
        let (pose, speed_mps, steer_rad) = self.predict(input);
        let ahead = TrackerInput {
            pose,
            speed_mps,
            steer_rad,
            ..*input
        };
        let cmd = self.inner.command(&ahead);
        self.issued
            .push_back((input.t_s, cmd.speed_mps, cmd.steer_rad));
        while self
            .issued
            .front()
            .is_some_and(|(t0, _, _)| *t0 < input.t_s - 3.0)
        {
            self.issued.pop_front();
        }
        cmd
    }

    fn fault(&self) -> Option<String> {
        self.inner.fault()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::PurePursuit;

    /// The A30 with the first truck's actuators.
    fn ideal() -> ForkliftSpec {
        ForkliftSpec::default().with_actuators(forkbench_core::actuators::Actuators::IDEAL)
    }

    /// Without delays the prediction is the measured state: the compensation is a no-op.
    #[test]
    fn no_delay_no_prediction() {
        let truck = ideal();
        let c = DelayCompensated::new(Box::new(PurePursuit::with_config(Default::default())), "x");
        let input = TrackerInput {
            t_s: 1.0,
            pose: Pose2::new(1.0, 2.0, 0.3),
            speed_mps: 0.5,
            steer_rad: 0.1,
            fix_measured_s: None,
            truck: &truck,
        };
        assert_eq!(c.predict(&input), (input.pose, 0.5, 0.1));
    }

    /// Driving straight at 0.8 m/s with 0.2 s of dead time: the pose is predicted 0.16 m on.
    #[test]
    fn a_dead_time_carries_the_pose_forward() {
        let mut truck = ideal();
        truck.steering.dead_time_s = 0.2;
        truck.drive.dead_time_s = 0.2;
        let c = DelayCompensated::new(Box::new(PurePursuit::with_config(Default::default())), "x");
        let input = TrackerInput {
            t_s: 1.0,
            pose: Pose2::new(0.0, 0.0, 0.0),
            speed_mps: 0.8,
            steer_rad: 0.0,
            fix_measured_s: None,
            truck: &truck,
        };
        let (p, v, _) = c.predict(&input);
        assert!((p.x_m - 0.16).abs() < 1e-9 && v == 0.8, "{p:?} {v}");
    }
}
