//! The localisation sensor as the controller sees it: the trait, what one measurement delivers, the shared rate-and-latency cadence, and the Gaussian NAV350 (σ around the truth).

use std::collections::VecDeque;

use forkbench_core::units::wrap_angle;
use forkbench_core::{Pose2, SettingsError};
use rand::Rng;
use serde::{Deserialize, Serialize};

use crate::normal;
use crate::reflectors::Fix;

/// What a localiser is given each control step.
#[derive(Debug, Clone)]
pub struct LocalizerInput {
    pub t_s: f64,
    /// The true fork-root pose: what the world answers from (never copied into a fix by
    /// a model that measures).
    pub truth: Pose2,
    /// The controller's own fork-root pose (last fix carried on by odometry): the
    /// device's speed-input prior for matching what it measures to its map. `None`
    /// before the first fix.
    pub predicted: Option<Pose2>,
    /// The fork-root pose by the truck's odometry alone, never reset by a fix (its frame
    /// is arbitrary): how the truck moved between two moments, as a NAV350's speed input
    /// tells it. `None` where the controller has no odometry.
    pub odometry: Option<Pose2>,
    /// What stands in the scan plane for now and blocks sight (people, other trucks), as
    /// map segments: a model that looks through the world does not see past them.
    pub occluders: Vec<[[f64; 2]; 2]>,
}

/// One measurement as delivered to the controller.
#[derive(Debug, Clone, PartialEq)]
pub struct Reading {
    /// The fork-root pose, or `None` when the device measured but could not compute a
    /// pose (too few reflectors matched).
    pub pose: Option<Pose2>,
    /// The device's report for a reflector fix (its own pose, reflectors used, mean
    /// deviation); `None` for models without one.
    pub fix: Option<Fix>,
    /// Reflectors the device detected this sweep, matched or not (0 for models without
    /// reflectors).
    pub detected: usize,
    /// When the pose was measured (the sweep's end), on the trial's clock: a reading
    /// delivered a latency later says how old it is, so the controller can carry it to now.
    pub measured_s: f64,
}

/// A localisation sensor: pose fixes of the fork root as the controller receives them.
pub trait Localizer: Send {
    fn name(&self) -> &str;

    /// Advances to `input.t_s`; returns the newest measurement delivered by then, if
    /// any. Draws only from `rng`.
    fn update(&mut self, input: &LocalizerInput, rng: &mut dyn Rng) -> Option<Reading>;

    /// Seconds between measurements (the gap a controller expects between fixes).
    fn period_s(&self) -> f64;
}

/// Sampling at a fixed rate and delivering each sample a latency later.
#[derive(Debug, Clone)]
pub struct Cadence {
    rate_hz: f64,
    latency_s: f64,
    next_sample_s: f64,
    in_flight: VecDeque<(f64, Reading)>,
}

impl Cadence {
    pub fn new(rate_hz: f64, latency_s: f64) -> Self {
        Self {
            rate_hz,
            latency_s,
            next_sample_s: 0.0,
            in_flight: VecDeque::new(),
        }
    }

    /// Whether a sample is due at `t_s` (at most one per call: callers step far faster
    /// than the rate); when it is, the next one is scheduled.
    pub fn due(&mut self, t_s: f64) -> bool {
        if t_s + 1e-12 >= self.next_sample_s {
            self.next_sample_s += 1.0 / self.rate_hz;
            true
        } else {
            false
        }
    }

    /// Queues a reading sampled at `t_s` for delivery after the latency.
    pub fn send(&mut self, t_s: f64, reading: Reading) {
        self.in_flight.push_back((t_s + self.latency_s, reading));
    }

    /// The newest reading delivered by `t_s` (older ones due at the same call are
    /// superseded).
    pub fn deliver(&mut self, t_s: f64) -> Option<Reading> {
        let mut out = None;
        while let Some((due, _)) = self.in_flight.front() {
            if *due > t_s + 1e-12 {
                break;
            }
            out = self.in_flight.pop_front().map(|(_, r)| r);
        }
        out
    }

    pub fn period_s(&self) -> f64 {
        1.0 / self.rate_hz
    }
}

/// SICK NAV350: pose fixes at a fixed rate with zero-mean Gaussian noise and a latency.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Nav350Config {
    pub rate_hz: f64,
    /// Per-axis position σ (the datasheet's ±4 mm read as 2σ).
    pub position_sigma_m: f64,
    /// Heading σ (the datasheet's ±0.15° read as 2σ).
    pub heading_sigma_rad: f64,
    /// Time from measurement (the sweep's end) to delivery. The datasheet gives none; the
    /// default is a choice: the pose computed from the finished sweep, then sent over Ethernet.
    pub latency_s: f64,
}

impl Default for Nav350Config {
    fn default() -> Self {
        Self {
            rate_hz: 8.0,
            position_sigma_m: 0.002,
            heading_sigma_rad: 0.075_f64.to_radians(),
            latency_s: 0.05,
        }
    }
}

impl Nav350Config {
    pub fn validate(&self) -> Result<(), SettingsError> {
        if !(self.rate_hz.is_finite() && self.rate_hz > 0.0) {
            return Err(SettingsError::field(
                "rate_hz",
                "must be a positive finite number",
            ));
        }
        for (f, v) in [
            ("position_sigma_m", self.position_sigma_m),
            ("heading_sigma_rad", self.heading_sigma_rad),
            ("latency_s", self.latency_s),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(SettingsError::field(f, "must be a finite number ≥ 0"));
            }
        }
        forkbench_core::settings::in_ranges(&[
            ("rate_hz", self.rate_hz, 0.01, 1000.0),
            ("position_sigma_m", self.position_sigma_m, 0.0, 10.0),
            (
                "heading_sigma_rad",
                self.heading_sigma_rad,
                0.0,
                std::f64::consts::PI,
            ),
            ("latency_s", self.latency_s, 0.0, 10.0),
        ])
    }
}

/// The Gaussian NAV350: the true pose with noise, wherever the truck is.
#[derive(Debug, Clone)]
pub struct Nav350 {
    cfg: Nav350Config,
    noise: bool,
    cadence: Cadence,
}

impl Nav350 {
    pub fn new(cfg: Nav350Config, noise: bool) -> Self {
        let cadence = Cadence::new(cfg.rate_hz, cfg.latency_s);
        Self {
            cfg,
            noise,
            cadence,
        }
    }
}

/// The truck's odometry errors (wheel encoder scale, steering-angle offset): what makes
/// dead reckoning drift between fixes and through gaps. Not from a datasheet: σ 1 % and
/// 0.3° are typical of a calibrated counterbalance truck.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct OdometryConfig {
    /// σ of the speed scale error, drawn once per trial.
    pub speed_scale_sigma: f64,
    /// σ of the steering-angle offset, drawn once per trial.
    pub steer_offset_sigma_rad: f64,
}

impl Default for OdometryConfig {
    fn default() -> Self {
        Self {
            speed_scale_sigma: 0.01,
            steer_offset_sigma_rad: 0.3_f64.to_radians(),
        }
    }
}

impl OdometryConfig {
    pub fn validate(&self) -> Result<(), SettingsError> {
        for (f, v) in [
            ("speed_scale_sigma", self.speed_scale_sigma),
            ("steer_offset_sigma_rad", self.steer_offset_sigma_rad),
        ] {
            if !(v.is_finite() && (0.0..0.5).contains(&v)) {
                return Err(SettingsError::field(
                    f,
                    "must be a finite number in [0, 0.5)",
                ));
            }
        }
        Ok(())
    }

    /// One trial's errors: (speed scale − 1, steering offset in rad).
    pub fn draw<R: Rng + ?Sized>(&self, rng: &mut R) -> (f64, f64) {
        (
            normal(rng, self.speed_scale_sigma),
            normal(rng, self.steer_offset_sigma_rad),
        )
    }
}

impl Localizer for Nav350 {
    fn name(&self) -> &str {
        "gaussian"
    }

    fn update(&mut self, input: &LocalizerInput, rng: &mut dyn Rng) -> Option<Reading> {
        if self.cadence.due(input.t_s) {
            let truth = &input.truth;
            let fix = if self.noise {
                Pose2::new(
                    truth.x_m + normal(rng, self.cfg.position_sigma_m),
                    truth.y_m + normal(rng, self.cfg.position_sigma_m),
                    wrap_angle(truth.heading_rad + normal(rng, self.cfg.heading_sigma_rad)),
                )
            } else {
                *truth
            };
            let reading = Reading {
                pose: Some(fix),
                fix: None,
                detected: 0,
                measured_s: input.t_s,
            };
            self.cadence.send(input.t_s, reading);
        }
        self.cadence.deliver(input.t_s)
    }

    fn period_s(&self) -> f64 {
        self.cadence.period_s()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    /// The pose the Gaussian NAV350 delivers at `t_s`, if any.
    fn fix_at(nav: &mut Nav350, t_s: f64, truth: &Pose2, rng: &mut ChaCha8Rng) -> Option<Pose2> {
        let input = LocalizerInput {
            t_s,
            truth: *truth,
            predicted: None,
            odometry: None,
            occluders: Vec::new(),
        };
        nav.update(&input, rng).and_then(|r| r.pose)
    }

    #[test]
    fn nav350_fixes_at_8_hz_with_the_configured_noise() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let mut nav = Nav350::new(Nav350Config::default(), true);
        let truth = Pose2::new(1.0, 2.0, 0.3);
        let (mut n, mut sx, mut sxx) = (0, 0.0, 0.0);
        let dt = 0.005;
        for k in 0..(200 * 400) {
            if let Some(f) = fix_at(&mut nav, k as f64 * dt, &truth, &mut rng) {
                n += 1;
                sx += f.x_m - truth.x_m;
                sxx += (f.x_m - truth.x_m).powi(2);
            }
        }
        // 400 s at 8 Hz.
        assert!((n as i64 - 3200).abs() <= 1, "{n} fixes");
        let mean = sx / n as f64;
        let sd = (sxx / n as f64 - mean * mean).sqrt();
        assert!(mean.abs() < 2e-4, "mean {mean}");
        assert!((sd - 0.002).abs() < 1e-4, "sd {sd}");
    }

    #[test]
    fn nav350_latency_delays_delivery() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let cfg = Nav350Config {
            latency_s: 0.05,
            ..Nav350Config::default()
        };
        let mut nav = Nav350::new(cfg, false);
        let truth = Pose2::new(0.0, 0.0, 0.0);
        assert!(fix_at(&mut nav, 0.0, &truth, &mut rng).is_none());
        assert!(fix_at(&mut nav, 0.04, &truth, &mut rng).is_none());
        assert!(fix_at(&mut nav, 0.05, &truth, &mut rng).is_some());
    }
}
