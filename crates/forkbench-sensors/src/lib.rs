//! Sensor models: NAV350 laser localisation, the pallet-pose estimate, world-seeing scanners and pallet detectors, drawing only from a passed-in RNG.

pub mod dataset;
pub mod detect;
pub mod detector;
pub mod evidence;
pub mod external;
pub mod face_fit;
pub mod localizer;
pub mod reflector_nav;
pub mod reflectors;
pub mod scan;
pub mod sight;

use forkbench_core::Pose2;
use forkbench_core::SettingsError;
use rand::{Rng, RngExt as _};
use rand_distr::StandardNormal;
use serde::{Deserialize, Serialize};

pub use localizer::{Localizer, LocalizerInput, Nav350, Nav350Config, OdometryConfig, Reading};
pub use reflector_nav::{ReflectorNav, ReflectorNavSettings};

pub(crate) fn normal<R: Rng + ?Sized>(rng: &mut R, sigma: f64) -> f64 {
    let z: f64 = rng.sample(StandardNormal);
    sigma * z
}

/// A pallet-pose estimator (camera, laser): a noisy pallet face pose at a range.
pub trait PalletEstimator: Send {
    fn name(&self) -> &str;

    /// One estimate of the pallet face pose seen from `range_m`. Draws only from `rng`.
    fn estimate(&self, truth: &Pose2, range_m: f64, rng: &mut dyn Rng) -> Pose2;

    /// Ranges (fork root to the estimated face) at which the trial asks for a new estimate.
    fn reestimate_at_m(&self) -> Vec<f64>;
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
        if self.reestimate_at_m.len() > 100 {
            return Err(SettingsError::field(
                "reestimate_at_m",
                "at most 100 ranges",
            ));
        }
        if self
            .reestimate_at_m
            .iter()
            .any(|r| !(r.is_finite() && *r > 0.0 && *r <= 100.0))
        {
            return Err(SettingsError::field(
                "reestimate_at_m",
                "ranges must lie in (0, 100] m",
            ));
        }
        forkbench_core::settings::in_ranges(&[
            ("reference_range_m", self.reference_range_m, 0.0, 100.0),
            (
                "position_sigma_at_reference_m",
                self.position_sigma_at_reference_m,
                0.0,
                10.0,
            ),
            (
                "heading_sigma_at_reference_rad",
                self.heading_sigma_at_reference_rad,
                0.0,
                std::f64::consts::PI,
            ),
            ("near_sigma_fraction", self.near_sigma_fraction, 0.0, 10.0),
            ("scale", self.scale, 0.0, 100.0),
        ])
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
