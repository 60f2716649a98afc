//! The truck's actuators and control timing as settings: steering and drive dynamics, the controller's period and transport delay, and the named presets.

use serde::{Deserialize, Serialize};

use crate::SettingsError;
use crate::settings::in_ranges;

/// The rear-wheel steering actuator between the controller's angle command and the wheel:
/// a dead time, a first-order lag limited in rate (`max_steer_rate_radps` of the truck) and
/// acceleration, a deadband, backlash between motor and wheel, and a mounting offset.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SteeringActuator {
    /// Pure delay from a command reaching the steering controller to the motor acting on it.
    pub dead_time_s: f64,
    /// First-order time constant of the angle's response (0: the rate limit alone).
    pub time_constant_s: f64,
    /// Largest change of the steering rate; none: the rate may jump.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub accel_limit_radps2: Option<f64>,
    /// A command within this angle of where the actuator stands does not move it.
    pub deadband_rad: f64,
    /// Play between the actuator and the wheel: reversing, the wheel stays until the
    /// actuator has taken up this much.
    pub backlash_rad: f64,
    /// The wheel stands this far from the angle the actuator believes (a misaligned
    /// mounting); odometry's steering-sensor offset is separate.
    pub offset_rad: f64,
}

/// The traction drive between the controller's speed command and the wheels: a dead time,
/// a first-order speed loop, acceleration and braking limits, and a creep threshold.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DriveActuator {
    /// Pure delay from a command reaching the drive controller to the motor acting on it.
    pub dead_time_s: f64,
    /// Time constant of the speed loop; none: `1 / [sim] speed_gain_per_s`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time_constant_s: Option<f64>,
    /// Largest acceleration; none: `[sim] max_accel_mps2`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub accel_limit_mps2: Option<f64>,
    /// Largest braking deceleration; none: `[sim] max_accel_mps2`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub brake_limit_mps2: Option<f64>,
    /// Speed commands slower than this do not move the truck (the drive's creep
    /// threshold); 0: every command acts.
    pub creep_speed_mps: f64,
}

/// The truck's computer: how often the controller runs and how long its commands take
/// to reach the drives.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ControlTiming {
    /// Period of the control loop; a command is held between ticks. None: every physics
    /// step. Must be a whole number of physics steps.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub period_s: Option<f64>,
    /// Delay from the controller to both drives (the bus), on top of each drive's dead time.
    pub transport_delay_s: f64,
}

impl Default for SteeringActuator {
    /// The realistic preset's (see docs/truck.md).
    fn default() -> Self {
        Actuators::REALISTIC.steering
    }
}

impl Default for DriveActuator {
    /// The realistic preset's (see docs/truck.md).
    fn default() -> Self {
        Actuators::REALISTIC.drive
    }
}

impl Default for ControlTiming {
    /// The realistic preset's (see docs/truck.md).
    fn default() -> Self {
        Actuators::REALISTIC.control
    }
}

impl SteeringActuator {
    /// The steering as the bench had it first: a bare rate limit.
    pub const IDEAL: Self = Self {
        dead_time_s: 0.0,
        time_constant_s: 0.0,
        accel_limit_radps2: None,
        deadband_rad: 0.0,
        backlash_rad: 0.0,
        offset_rad: 0.0,
    };

    pub fn is_ideal(&self) -> bool {
        *self == Self::IDEAL
    }

    /// Whether this is the default (left out of serialised specs).
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }

    /// Each value in its range, naming the field (`steering.<name>`).
    pub fn validate(&self) -> Result<(), SettingsError> {
        in_ranges(&[
            ("steering.dead_time_s", self.dead_time_s, 0.0, 2.0),
            ("steering.time_constant_s", self.time_constant_s, 0.0, 5.0),
            ("steering.deadband_rad", self.deadband_rad, 0.0, 0.2),
            ("steering.backlash_rad", self.backlash_rad, 0.0, 0.2),
            ("steering.offset_rad", self.offset_rad, -0.2, 0.2),
        ])?;
        if let Some(a) = self.accel_limit_radps2 {
            in_ranges(&[("steering.accel_limit_radps2", a, 0.01, 1000.0)])?;
        }
        Ok(())
    }
}

impl DriveActuator {
    /// The drive as the bench had it first: the `[sim]` speed loop without delay.
    pub const IDEAL: Self = Self {
        dead_time_s: 0.0,
        time_constant_s: None,
        accel_limit_mps2: None,
        brake_limit_mps2: None,
        creep_speed_mps: 0.0,
    };

    pub fn is_ideal(&self) -> bool {
        *self == Self::IDEAL
    }

    /// Whether this is the default (left out of serialised specs).
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }

    /// Each value in its range, naming the field (`drive.<name>`).
    pub fn validate(&self) -> Result<(), SettingsError> {
        in_ranges(&[
            ("drive.dead_time_s", self.dead_time_s, 0.0, 2.0),
            ("drive.creep_speed_mps", self.creep_speed_mps, 0.0, 1.0),
        ])?;
        let optional = [
            ("drive.time_constant_s", self.time_constant_s, 0.01, 10.0),
            ("drive.accel_limit_mps2", self.accel_limit_mps2, 0.01, 50.0),
            ("drive.brake_limit_mps2", self.brake_limit_mps2, 0.01, 50.0),
        ];
        for (field, value, lo, hi) in optional {
            if let Some(v) = value {
                in_ranges(&[(field, v, lo, hi)])?;
            }
        }
        Ok(())
    }
}

impl ControlTiming {
    /// The controller as the bench had it first: every physics step, no transport delay.
    pub const IDEAL: Self = Self {
        period_s: None,
        transport_delay_s: 0.0,
    };

    pub fn is_ideal(&self) -> bool {
        *self == Self::IDEAL
    }

    /// Whether this is the default (left out of serialised specs).
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }

    /// Each value in its range, naming the field (`control.<name>`).
    pub fn validate(&self) -> Result<(), SettingsError> {
        in_ranges(&[(
            "control.transport_delay_s",
            self.transport_delay_s,
            0.0,
            1.0,
        )])?;
        if let Some(p) = self.period_s {
            in_ranges(&[("control.period_s", p, 0.001, 1.0)])?;
        }
        Ok(())
    }

    /// Physics steps per control tick for a physics step of `dt_s`: the period must be a
    /// whole number of steps (within a microsecond), so ticks never drift.
    pub fn steps_per_tick(&self, dt_s: f64) -> Result<u32, SettingsError> {
        let Some(p) = self.period_s else {
            return Ok(1);
        };
        let n = (p / dt_s).round();
        if !(n.is_finite() && (1.0..=1e6).contains(&n)) || (n * dt_s - p).abs() > 1e-6 {
            return Err(SettingsError::field(
                "control.period_s",
                format!("{p} s is not a whole number of physics steps of {dt_s} s ([sim] dt_s)"),
            ));
        }
        Ok(n as u32)
    }
}

/// The share of the way to its target a first-order lag of `time_constant_s` covers in
/// `dt_s` (the exact discrete step, so sampled responses match the analytic one); 1 for
/// no lag.
pub fn lag_fraction(dt_s: f64, time_constant_s: f64) -> f64 {
    if time_constant_s > 0.0 {
        1.0 - (-dt_s / time_constant_s).exp()
    } else {
        1.0
    }
}

/// The truck's actuators and timing together, as a preset names them.
#[derive(Debug, Clone, PartialEq)]
pub struct Actuators {
    pub steering: SteeringActuator,
    pub drive: DriveActuator,
    pub control: ControlTiming,
}

/// The presets `--truck NAME` takes, with what each stands for.
pub const PRESETS: [(&str, &str); 2] = [
    (
        "ideal",
        "the bench's first truck (before forkbench modelled actuators): steering a bare rate limit, the speed loop without delay, control every physics step",
    ),
    (
        "realistic",
        "an electric counterbalance truck's actuators and a 50 Hz controller on a CAN bus (each value a stated choice; see docs/truck.md)",
    ),
];

impl Actuators {
    pub const IDEAL: Self = Self {
        steering: SteeringActuator::IDEAL,
        drive: DriveActuator::IDEAL,
        control: ControlTiming::IDEAL,
    };

    /// Values of an electric counterbalance truck. No datasheet gives these for a
    /// forklift; each is a choice of the order such trucks show, stated in docs/truck.md.
    pub const REALISTIC: Self = Self {
        steering: SteeringActuator {
            dead_time_s: 0.06,
            time_constant_s: 0.08,
            // The steepest a first-order lag of 0.08 s climbs to the 0.8 rad/s rate: r / τ.
            accel_limit_radps2: Some(10.0),
            deadband_rad: 0.002,
            backlash_rad: 0.004,
            offset_rad: 0.0,
        },
        drive: DriveActuator {
            dead_time_s: 0.05,
            time_constant_s: Some(0.25),
            accel_limit_mps2: Some(1.0),
            brake_limit_mps2: Some(1.5),
            creep_speed_mps: 0.02,
        },
        control: ControlTiming {
            period_s: Some(0.02),
            transport_delay_s: 0.01,
        },
    };

    /// A preset by name (`PRESETS`).
    pub fn preset(name: &str) -> Option<Self> {
        match name {
            "ideal" => Some(Self::IDEAL),
            "realistic" => Some(Self::REALISTIC),
            _ => None,
        }
    }

    pub fn validate(&self) -> Result<(), SettingsError> {
        self.steering.validate()?;
        self.drive.validate()?;
        self.control.validate()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_are_valid_and_realistic_is_the_default() {
        for (name, _) in PRESETS {
            Actuators::preset(name)
                .expect("named")
                .validate()
                .expect("valid");
        }
        assert_eq!(SteeringActuator::default(), Actuators::REALISTIC.steering);
        assert_eq!(DriveActuator::default(), Actuators::REALISTIC.drive);
        assert_eq!(ControlTiming::default(), Actuators::REALISTIC.control);
        assert!(!Actuators::REALISTIC.steering.is_ideal());
    }

    #[test]
    fn out_of_range_values_are_refused_by_name() {
        let s = SteeringActuator {
            dead_time_s: 5.0,
            ..SteeringActuator::IDEAL
        };
        let e = s.validate().expect_err("5 s dead time");
        assert_eq!(e.field.as_deref(), Some("steering.dead_time_s"));
        let d = DriveActuator {
            brake_limit_mps2: Some(f64::NAN),
            ..DriveActuator::IDEAL
        };
        let e = d.validate().expect_err("NaN brake");
        assert_eq!(e.field.as_deref(), Some("drive.brake_limit_mps2"));
    }

    #[test]
    fn a_control_period_must_be_whole_physics_steps() {
        let c = ControlTiming {
            period_s: Some(0.02),
            transport_delay_s: 0.0,
        };
        assert_eq!(c.steps_per_tick(0.01).expect("two steps"), 2);
        assert_eq!(ControlTiming::IDEAL.steps_per_tick(0.01).expect("one"), 1);
        let c = ControlTiming {
            period_s: Some(0.025),
            transport_delay_s: 0.0,
        };
        let e = c.steps_per_tick(0.01).expect_err("2.5 steps");
        assert_eq!(e.field.as_deref(), Some("control.period_s"));
    }
}
