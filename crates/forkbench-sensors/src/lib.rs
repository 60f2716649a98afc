//! Sensor models: NAV350 laser localisation, the pallet-pose estimate, world-seeing scanners and pallet detectors, drawing only from a passed-in RNG.

pub mod detect;
pub mod detector;
pub mod external;
pub mod reflectors;
pub mod scan;

use std::collections::VecDeque;

use forkbench_core::Pose2;
use forkbench_core::SettingsError;
use forkbench_core::units::wrap_angle;
use rand::{Rng, RngExt as _};
use rand_distr::StandardNormal;
use serde::{Deserialize, Serialize};

fn normal<R: Rng + ?Sized>(rng: &mut R, sigma: f64) -> f64 {
    let z: f64 = rng.sample(StandardNormal);
    sigma * z
}

/// A localisation sensor: pose fixes of the fork root as the controller receives them.
pub trait Localizer: Send {
    fn name(&self) -> &str;

    /// Advances to time `t_s` with the true pose; returns the newest fix delivered by
    /// then, if any. Draws only from `rng`.
    fn update(&mut self, t_s: f64, truth: &Pose2, rng: &mut dyn Rng) -> Option<Pose2>;
}

/// A pallet-pose estimator (camera, laser): a noisy pallet face pose at a range.
pub trait PalletEstimator: Send {
    fn name(&self) -> &str;

    /// One estimate of the pallet face pose seen from `range_m`. Draws only from `rng`.
    fn estimate(&self, truth: &Pose2, range_m: f64, rng: &mut dyn Rng) -> Pose2;

    /// Ranges (fork root to the estimated face) at which the trial asks for a new estimate.
    fn reestimate_at_m(&self) -> Vec<f64>;
}

impl Localizer for Nav350 {
    fn name(&self) -> &str {
        "nav350"
    }

    fn update(&mut self, t_s: f64, truth: &Pose2, rng: &mut dyn Rng) -> Option<Pose2> {
        Nav350::update(self, t_s, truth, rng)
    }
}

impl PalletEstimator for PalletEstimateConfig {
    fn name(&self) -> &str {
        "range_scaled_gaussian"
    }

    fn estimate(&self, truth: &Pose2, range_m: f64, rng: &mut dyn Rng) -> Pose2 {
        PalletEstimateConfig::estimate(self, truth, range_m, rng)
    }

    fn reestimate_at_m(&self) -> Vec<f64> {
        self.reestimate_at_m.clone()
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
    /// Time from measurement to delivery.
    pub latency_s: f64,
}

impl Default for Nav350Config {
    fn default() -> Self {
        Self {
            rate_hz: 8.0,
            position_sigma_m: 0.002,
            heading_sigma_rad: 0.075_f64.to_radians(),
            latency_s: 0.0,
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
        Ok(())
    }
}

/// The NAV350 as the controller sees it.
#[derive(Debug, Clone)]
pub struct Nav350 {
    cfg: Nav350Config,
    noise: bool,
    next_sample_s: f64,
    in_flight: VecDeque<(f64, Pose2)>,
}

impl Nav350 {
    pub fn new(cfg: Nav350Config, noise: bool) -> Self {
        Self {
            cfg,
            noise,
            next_sample_s: 0.0,
            in_flight: VecDeque::new(),
        }
    }

    /// Advances to time `t_s`; returns the newest fix delivered by then, if any.
    pub fn update<R: Rng + ?Sized>(
        &mut self,
        t_s: f64,
        truth: &Pose2,
        rng: &mut R,
    ) -> Option<Pose2> {
        // Sample at the rate (at most one sample per call: callers step far faster than 8 Hz).
        if t_s + 1e-12 >= self.next_sample_s {
            let fix = if self.noise {
                Pose2::new(
                    truth.x_m + normal(rng, self.cfg.position_sigma_m),
                    truth.y_m + normal(rng, self.cfg.position_sigma_m),
                    wrap_angle(truth.heading_rad + normal(rng, self.cfg.heading_sigma_rad)),
                )
            } else {
                *truth
            };
            self.in_flight.push_back((t_s + self.cfg.latency_s, fix));
            self.next_sample_s += 1.0 / self.cfg.rate_hz;
        }
        let mut out = None;
        while let Some(&(due, fix)) = self.in_flight.front() {
            if due > t_s + 1e-12 {
                break;
            }
            out = Some(fix);
            self.in_flight.pop_front();
        }
        out
    }
}

/// Pallet-pose estimate (Kinect2 near, TiM561 far): error that shrinks as the truck approaches.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PalletEstimateConfig {
    /// Range at which the reference accuracy holds (the paper: 6.5 m).
    pub reference_range_m: f64,
    /// Position σ per axis at the reference range (±60 mm read as 2σ).
    pub position_sigma_at_reference_m: f64,
    /// Heading σ at the reference range (±6° read as 2σ).
    pub heading_sigma_at_reference_rad: f64,
    /// Range at and below which the near-range (RGB-D) accuracy holds.
    pub near_range_m: f64,
    /// σ at near range as a fraction of the reference σ; linear in range in between.
    pub near_sigma_fraction: f64,
    /// Ranges (fork root to the estimated pallet face) at which a new estimate is taken.
    pub reestimate_at_m: Vec<f64>,
    /// Scales every σ (a Monte-Carlo sweep knob; 0 = perfect estimate).
    pub scale: f64,
}

impl Default for PalletEstimateConfig {
    fn default() -> Self {
        Self {
            reference_range_m: 6.5,
            position_sigma_at_reference_m: 0.030,
            heading_sigma_at_reference_rad: 3.0_f64.to_radians(),
            near_range_m: 2.5,
            near_sigma_fraction: 0.25,
            reestimate_at_m: vec![5.0, 3.5],
            scale: 1.0,
        }
    }
}

impl PalletEstimateConfig {
    pub fn validate(&self) -> Result<(), SettingsError> {
        for (f, v) in [
            ("reference_range_m", self.reference_range_m),
            ("near_range_m", self.near_range_m),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(SettingsError::field(f, "must be a positive finite number"));
            }
        }
        for (f, v) in [
            (
                "position_sigma_at_reference_m",
                self.position_sigma_at_reference_m,
            ),
            (
                "heading_sigma_at_reference_rad",
                self.heading_sigma_at_reference_rad,
            ),
            ("near_sigma_fraction", self.near_sigma_fraction),
            ("scale", self.scale),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(SettingsError::field(f, "must be a finite number ≥ 0"));
            }
        }
        if self.near_range_m > self.reference_range_m {
            return Err(SettingsError::field(
                "near_range_m",
                "must not exceed reference_range_m",
            ));
        }
        if self
            .reestimate_at_m
            .iter()
            .any(|r| !(r.is_finite() && *r > 0.0))
        {
            return Err(SettingsError::field(
                "reestimate_at_m",
                "ranges must be positive finite numbers",
            ));
        }
        Ok(())
    }

    /// σ multiplier at a range: near fraction up to near range, linear to 1 at the
    /// reference range, and growing linearly beyond it.
    pub fn sigma_factor(&self, range_m: f64) -> f64 {
        let f = if range_m <= self.near_range_m {
            self.near_sigma_fraction
        } else if range_m <= self.reference_range_m {
            let t = (range_m - self.near_range_m) / (self.reference_range_m - self.near_range_m);
            self.near_sigma_fraction + t * (1.0 - self.near_sigma_fraction)
        } else {
            range_m / self.reference_range_m
        };
        f * self.scale
    }

    /// One estimate of the pallet pose (face centre), noise drawn in the pallet's frame.
    pub fn estimate<R: Rng + ?Sized>(&self, truth: &Pose2, range_m: f64, rng: &mut R) -> Pose2 {
        let k = self.sigma_factor(range_m);
        let along = normal(rng, k * self.position_sigma_at_reference_m);
        let lateral = normal(rng, k * self.position_sigma_at_reference_m);
        let dh = normal(rng, k * self.heading_sigma_at_reference_rad);
        truth.to_world(&Pose2::new(along, lateral, dh))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn nav350_fixes_at_8_hz_with_the_configured_noise() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let mut nav = Nav350::new(Nav350Config::default(), true);
        let truth = Pose2::new(1.0, 2.0, 0.3);
        let (mut n, mut sx, mut sxx) = (0, 0.0, 0.0);
        let dt = 0.005;
        for k in 0..(200 * 400) {
            if let Some(f) = nav.update(k as f64 * dt, &truth, &mut rng) {
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
        assert!(nav.update(0.0, &truth, &mut rng).is_none());
        assert!(nav.update(0.04, &truth, &mut rng).is_none());
        assert!(nav.update(0.05, &truth, &mut rng).is_some());
    }

    #[test]
    fn pallet_estimate_shrinks_with_range_and_is_seeded() {
        let cfg = PalletEstimateConfig::default();
        assert!((cfg.sigma_factor(6.5) - 1.0).abs() < 1e-12);
        assert!(cfg.sigma_factor(1.0) < cfg.sigma_factor(4.0));
        let truth = Pose2::new(5.0, 1.0, 0.2);
        let a = cfg.estimate(&truth, 6.5, &mut ChaCha8Rng::seed_from_u64(3));
        let b = cfg.estimate(&truth, 6.5, &mut ChaCha8Rng::seed_from_u64(3));
        assert_eq!(a, b);
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let sd = |range: f64, rng: &mut ChaCha8Rng| {
            let v: Vec<f64> = (0..4000)
                .map(|_| cfg.estimate(&truth, range, rng).heading_rad - truth.heading_rad)
                .collect();
            (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
        };
        let far = sd(6.5, &mut rng);
        let near = sd(2.0, &mut rng);
        assert!(
            (far - 3.0_f64.to_radians()).abs() < 0.1_f64.to_radians(),
            "{}",
            far.to_degrees()
        );
        assert!(
            (near - 0.75_f64.to_radians()).abs() < 0.05_f64.to_radians(),
            "{}",
            near.to_degrees()
        );
    }
}
