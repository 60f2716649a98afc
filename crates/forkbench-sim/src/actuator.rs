//! The truck's actuators between the controller's commands and the physics: delay lines, the steering's lag, limits, deadband, backlash and offset, and the drive's delayed speed loop.

use std::collections::VecDeque;

use forkbench_core::ForkliftSpec;
use forkbench_core::actuators::{DriveActuator, SteeringActuator, lag_fraction};

/// A pure delay of whole physics steps: what goes in comes out that many steps later;
/// before then, the value the truck stood with.
#[derive(Debug, Clone)]
struct DelayLine {
    buf: VecDeque<f64>,
}

impl DelayLine {
    /// A delay of `delay_s` at step `dt_s`, rounded to whole steps.
    fn new(delay_s: f64, dt_s: f64, initial: f64) -> Self {
        let n = (delay_s / dt_s).round().max(0.0) as usize;
        Self {
            buf: std::iter::repeat_n(initial, n).collect(),
        }
    }

    fn pass(&mut self, v: f64) -> f64 {
        self.buf.push_back(v);
        self.buf.pop_front().unwrap_or(v)
    }
}

/// The steering actuator's state: the motor's angle and rate, the wheel behind the
/// backlash, and the commands still on their way.
#[derive(Debug, Clone)]
pub(crate) struct Steering {
    cfg: SteeringActuator,
    max_rad: f64,
    max_rate_radps: f64,
    /// The physics step, and the share of its error the lag closes in one.
    dt_s: f64,
    lag: f64,
    delay: DelayLine,
    /// Where the actuator stands (before backlash and offset).
    motor_rad: f64,
    motor_rate_radps: f64,
    /// The wheel behind the play, before the mounting offset.
    wheel_rad: f64,
}

impl Steering {
    pub(crate) fn new(spec: &ForkliftSpec, dt_s: f64) -> Self {
        Self {
            cfg: spec.steering.clone(),
            max_rad: spec.max_steer_rad,
            max_rate_radps: spec.max_steer_rate_radps,
            dt_s,
            lag: lag_fraction(dt_s, spec.steering.time_constant_s),
            delay: DelayLine::new(spec.steering_delay_s(), dt_s, 0.0),
            motor_rad: 0.0,
            motor_rate_radps: 0.0,
            wheel_rad: 0.0,
        }
    }

    /// One physics step under the command `cmd_rad`; returns the wheel's equivalent
    /// angle. A non-finite command holds the actuator where it stands.
    pub(crate) fn step(&mut self, cmd_rad: f64) -> f64 {
        let (max, dt_s) = (self.max_rad, self.dt_s);
        let cmd = if cmd_rad.is_finite() {
            cmd_rad.clamp(-max, max)
        } else {
            self.motor_rad
        };
        let target = self.delay.pass(cmd);
        let err = target - self.motor_rad;
        let rate = self.max_rate_radps * dt_s;
        let mut delta = if self.cfg.deadband_rad > 0.0 && err.abs() <= self.cfg.deadband_rad {
            0.0
        } else {
            self.lag * err
        };
        delta = delta.clamp(-rate, rate);
        if let Some(acc) = self.cfg.accel_limit_radps2 {
            // Slow down in time to stop at the target (the discrete braking bound, so the
            // last steps land on it), and change the rate only so fast.
            let half_step = 0.5 * acc * dt_s;
            let stop = ((2.0 * acc * err.abs()) + half_step * half_step).sqrt() - half_step;
            let prev = self.motor_rate_radps;
            let w = (delta / dt_s)
                .clamp(-stop, stop)
                .clamp(prev - acc * dt_s, prev + acc * dt_s);
            delta = w * dt_s;
        }
        self.motor_rate_radps = delta / dt_s;
        self.motor_rad = (self.motor_rad + delta).clamp(-max, max);
        self.wheel_rad = take_up(self.wheel_rad, self.motor_rad, self.cfg.backlash_rad);
        if self.cfg.offset_rad == 0.0 {
            self.wheel_rad
        } else {
            (self.wheel_rad + self.cfg.offset_rad).clamp(-max, max)
        }
    }
}

/// Where a part driven through `play` of backlash stands once its driver is at
/// `driver`: it moves only when the driver pushes it at one end of the play.
fn take_up(driven: f64, driver: f64, play: f64) -> f64 {
    if play <= 0.0 {
        return driver;
    }
    let half = play / 2.0;
    driven.clamp(driver - half, driver + half)
}

/// The traction drive's state: the speed commands on their way.
#[derive(Debug, Clone)]
pub(crate) struct Drive {
    cfg: DriveActuator,
    delay: DelayLine,
}

impl Drive {
    pub(crate) fn new(spec: &ForkliftSpec, dt_s: f64) -> Self {
        Self {
            cfg: spec.drive.clone(),
            delay: DelayLine::new(spec.drive_delay_s(), dt_s, 0.0),
        }
    }

    /// The acceleration the drive asks for at speed `v_mps` under the command
    /// `cmd_mps`, given the `[sim]` speed gain and acceleration limit the actuator's own
    /// settings fall back on. A non-finite command stops the truck.
    pub(crate) fn accel(&mut self, cmd_mps: f64, v_mps: f64, gain_per_s: f64, limit: f64) -> f64 {
        let cmd = if cmd_mps.is_finite() { cmd_mps } else { 0.0 };
        let mut set = self.delay.pass(cmd);
        if set.abs() < self.cfg.creep_speed_mps {
            set = 0.0;
        }
        let gain = self.cfg.time_constant_s.map_or(gain_per_s, |tau| 1.0 / tau);
        let accel = gain * (set - v_mps);
        let up = self.cfg.accel_limit_mps2.unwrap_or(limit);
        let down = self.cfg.brake_limit_mps2.unwrap_or(limit);
        if accel * v_mps < 0.0 {
            accel.clamp(-down, down)
        } else {
            accel.clamp(-up, up)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The A30 with the first truck's actuators.
    fn ideal() -> ForkliftSpec {
        ForkliftSpec::default().with_actuators(forkbench_core::actuators::Actuators::IDEAL)
    }

    fn truck(steering: SteeringActuator) -> ForkliftSpec {
        ForkliftSpec {
            steering,
            max_steer_rate_radps: 20.0,
            ..ideal()
        }
    }

    /// A small step through dead time d and lag τ: the sampled response is
    /// A (1 − e^{−(t − d)/τ}) from t = d on, and exactly 0 before.
    #[test]
    fn a_step_arrives_after_the_dead_time_then_follows_the_first_order_lag() {
        let (dt, d, tau, a) = (0.01, 0.12, 0.15, 0.1);
        let mut s = Steering::new(
            &truck(SteeringActuator {
                dead_time_s: d,
                time_constant_s: tau,
                ..SteeringActuator::IDEAL
            }),
            dt,
        );
        for k in 1..=200 {
            let got = s.step(a);
            let t = k as f64 * dt;
            // The command of step 1 acts from step 1 + d/dt.
            let since = t - dt - d;
            let want = if since < -1e-9 {
                0.0
            } else {
                a * (1.0 - (-(since + dt) / tau).exp())
            };
            assert!((got - want).abs() < 1e-12, "t {t}: {got} vs {want}");
        }
    }

    #[test]
    fn the_ideal_actuator_is_the_bare_rate_limit() {
        let spec = ideal();
        let mut s = Steering::new(&spec, 0.01);
        let mut legacy = 0.0_f64;
        for k in 0..300 {
            let cmd = if k < 150 { 0.9 } else { -0.4 };
            let rate = spec.max_steer_rate_radps * 0.01;
            let max = spec.max_steer_rad;
            legacy = (legacy + (cmd - legacy).clamp(-rate, rate)).clamp(-max, max);
            assert_eq!(s.step(cmd).to_bits(), legacy.to_bits(), "step {k}");
        }
    }

    #[test]
    fn backlash_holds_the_wheel_on_reversal_and_deadband_ignores_small_commands() {
        let mut s = Steering::new(
            &truck(SteeringActuator {
                backlash_rad: 0.02,
                ..SteeringActuator::IDEAL
            }),
            0.01,
        );
        // Out to 0.1: the wheel trails the motor by half the play.
        let w = (0..100).map(|_| s.step(0.1)).last().expect("stepped");
        assert!((w - 0.09).abs() < 1e-12, "{w}");
        // Back by less than the play: the wheel does not move.
        let w = (0..100).map(|_| s.step(0.085)).last().expect("stepped");
        assert!((w - 0.09).abs() < 1e-12, "{w}");
        let mut s = Steering::new(
            &truck(SteeringActuator {
                deadband_rad: 0.01,
                ..SteeringActuator::IDEAL
            }),
            0.01,
        );
        assert_eq!(s.step(0.008), 0.0);
        assert!((s.step(0.05) - 0.05).abs() < 1e-12);
    }

    #[test]
    fn the_rate_never_changes_faster_than_the_acceleration_limit() {
        let acc = 2.0;
        let mut s = Steering::new(
            &truck(SteeringActuator {
                accel_limit_radps2: Some(acc),
                ..SteeringActuator::IDEAL
            }),
            0.01,
        );
        let (mut prev_angle, mut prev_rate) = (0.0, 0.0);
        for _ in 0..400 {
            let a = s.step(0.5);
            let rate = (a - prev_angle) / 0.01;
            assert!((rate - prev_rate).abs() <= acc * 0.01 + 1e-9);
            assert!(a <= 0.5 + 2e-3, "overshoot under a milliradian or two: {a}");
            (prev_angle, prev_rate) = (a, rate);
        }
        assert!((prev_angle - 0.5).abs() < 1e-3, "{prev_angle}");
    }

    #[test]
    fn the_drive_brakes_at_its_own_limit_and_creeps_not_below_its_threshold() {
        let spec = ForkliftSpec {
            drive: DriveActuator {
                brake_limit_mps2: Some(2.0),
                accel_limit_mps2: Some(0.5),
                creep_speed_mps: 0.05,
                ..DriveActuator::IDEAL
            },
            ..ideal()
        };
        let mut d = Drive::new(&spec, 0.01);
        assert_eq!(d.accel(1.0, 0.0, 4.0, 1.0), 0.5);
        assert_eq!(d.accel(0.0, 0.8, 4.0, 1.0), -2.0);
        assert_eq!(
            d.accel(0.04, 0.0, 4.0, 1.0),
            0.0,
            "below the creep threshold"
        );
    }
}
