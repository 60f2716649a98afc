//! A planar scanner's settings and the named models, every figure cited.
//!
//! SICK TiM561-2050101 (TiM55x/TiM56x operating instructions 8015886, technical data):
//! aperture 270°, angular resolution 0.33°, 15 Hz, working range 0.05–10 m, measurement
//! error typically 20 mm statistical (1σ) and ±60 mm systematic. Its light spot (SICK's
//! TiM3xx/TiM8xx instructions, same HDDM+ family at 0.33°): 8.6 mrad divergence + 5.8 mrad
//! HDDM+ supplement, 7 mm at the cover.
//!
//! Microsoft Kinect v2 depth camera, one image row at fork-pocket height: 512 columns
//! over a 70.6° horizontal field of view, 30 Hz, 0.5–4.5 m (Microsoft's Kinect for
//! Windows v2 specifications); axial noise σ_z = 1.5 − 0.5 z + 0.3 z² + 0.1 z^1.5 θ²/(π/2 − θ)²
//! mm with z in m and θ the surface's angle to the line of sight (Fankhauser et al.,
//! "Kinect v2 for Mobile Robot Navigation: Evaluation and Modeling", ICAR 2015). A pixel
//! integrates its own footprint, so its "spot" is one column's angle: where a pixel
//! straddles a depth edge it returns a mixed depth (the camera's flying pixels).
//!
//! Modelling choices without a datasheet figure: the grazing-incidence cut-off (80°), and
//! the TiM561 telling apart echoes more than 0.3 m apart within one spot (a pulsed
//! single-echo scanner reports the strongest; nearer echoes merge).

use forkbench_core::{Pose2, SettingsError};
use rand::{Rng, RngExt as _};
use serde::{Deserialize, Serialize};

/// A planar scanner's settings (SI); defaults are the TiM561.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ScannerConfig {
    /// Mount in the fork-root frame (x forward along the forks, y left).
    pub mount: Pose2,
    pub fov_rad: f64,
    pub step_rad: f64,
    pub rate_hz: f64,
    pub range_min_m: f64,
    pub range_max_m: f64,
    /// Random range error, 1σ: `range_sigma_m + range_sigma_per_m · r +
    /// range_sigma_per_m2 · r² + incidence_sigma · r^1.5 · θ²/(π/2 − θ)²` at range `r`
    /// and incidence `θ` (a constant for a laser; growing with range for a camera).
    pub range_sigma_m: f64,
    pub range_sigma_per_m: f64,
    pub range_sigma_per_m2: f64,
    pub incidence_sigma: f64,
    /// Systematic range error: drawn once per trial, uniform within ±this.
    pub range_bias_max_m: f64,
    /// Full angle the spot widens by (divergence and HDDM+ supplement), and its width at
    /// the cover: a beam whose spot straddles a depth edge returns a mixed range.
    pub spot_divergence_rad: f64,
    pub spot_at_cover_m: f64,
    /// Beyond this angle between beam and surface normal nothing comes back.
    pub max_incidence_rad: f64,
    /// Echoes within one spot further apart than this are told apart and the strongest
    /// (the surface holding most of the spot) is reported, as a pulsed single-echo scanner
    /// does; nearer ones merge into a mixed range. 0: always merged (a phase-based
    /// time-of-flight camera's flying pixels).
    pub echo_separation_m: f64,
    /// Time from a frame's first beam to its last: a rotating mirror sweeps its field of
    /// view in this share of a turn, so beams of a moving truck leave from different
    /// places (motion distortion); 0: every beam at once (a camera's global shutter).
    pub sweep_s: f64,
}

impl Default for ScannerConfig {
    fn default() -> Self {
        Self::tim561()
    }
}

/// How far past its range a scanner is still asked for a target (the pallet's extent).
pub const REACH_MARGIN_M: f64 = 0.5;

/// Longest sweep a scanner may take: a trial keeps the truck's poses this far back.
pub const MAX_SWEEP_S: f64 = 1.0;

/// The scanner models known by name.
pub const SCANNER_PRESETS: [&str; 2] = ["tim561", "kinect2"];

impl ScannerConfig {
    /// A scanner model by name ([`SCANNER_PRESETS`]), with its settings.
    pub fn preset(name: &str) -> Option<Self> {
        match name {
            "tim561" => Some(Self::tim561()),
            "kinect2" => Some(Self::kinect2()),
            _ => None,
        }
    }

    /// SICK TiM561 (see the module's sources), mounted at the fork root facing forward.
    pub fn tim561() -> Self {
        Self {
            mount: Pose2::new(0.0, 0.0, 0.0),
            fov_rad: 270f64.to_radians(),
            step_rad: 0.33f64.to_radians(),
            rate_hz: 15.0,
            range_min_m: 0.05,
            range_max_m: 10.0,
            range_sigma_m: 0.020,
            range_sigma_per_m: 0.0,
            range_sigma_per_m2: 0.0,
            incidence_sigma: 0.0,
            range_bias_max_m: 0.060,
            spot_divergence_rad: 0.0086 + 0.0058,
            spot_at_cover_m: 0.007,
            max_incidence_rad: 80f64.to_radians(),
            echo_separation_m: 0.3,
            // The TiM561's mirror turns once per frame with 270° of it carrying beams:
            // 0.75 / 15 s.
            sweep_s: 0.05,
        }
    }

    /// Kinect v2's depth row at pocket height (see the module's sources), mounted at the
    /// fork root facing forward. No systematic error: the noise model's source measured a
    /// calibrated camera, and no per-unit depth offset is published.
    pub fn kinect2() -> Self {
        let fov_rad = 70.6f64.to_radians();
        let step_rad = fov_rad / 511.0;
        Self {
            mount: Pose2::new(0.0, 0.0, 0.0),
            fov_rad,
            step_rad,
            rate_hz: 30.0,
            range_min_m: 0.5,
            range_max_m: 4.5,
            range_sigma_m: 0.0015,
            range_sigma_per_m: -0.0005,
            range_sigma_per_m2: 0.0003,
            incidence_sigma: 0.0001,
            range_bias_max_m: 0.0,
            spot_divergence_rad: step_rad,
            spot_at_cover_m: 0.0,
            max_incidence_rad: 80f64.to_radians(),
            echo_separation_m: 0.0,
            sweep_s: 0.0,
        }
    }

    /// The random range error's σ at range `r_m` and incidence `theta_rad` (0 = head-on).
    pub fn range_sigma_at(&self, r_m: f64, theta_rad: f64) -> f64 {
        // A laser's σ is one constant: skip the power per beam.
        let incidence = if self.incidence_sigma == 0.0 {
            0.0
        } else {
            let edge = (std::f64::consts::FRAC_PI_2 - theta_rad).max(1e-3);
            self.incidence_sigma * r_m * r_m.sqrt() * (theta_rad / edge).powi(2)
        };
        (self.range_sigma_m
            + self.range_sigma_per_m * r_m
            + self.range_sigma_per_m2 * r_m * r_m
            + incidence)
            .max(0.0)
    }

    /// Whether this scanner has any range error a noise scale could act on.
    pub fn has_noise(&self) -> bool {
        [
            self.range_sigma_m,
            self.range_sigma_per_m,
            self.range_sigma_per_m2,
            self.incidence_sigma,
            self.range_bias_max_m,
        ]
        .iter()
        .any(|v| *v != 0.0)
    }

    /// The same scanner with its random range error and systematic bias scaled by `s`
    /// (≥ 0): the spot and echo geometry are the device's optics, not noise, and stay.
    pub fn scaled_errors(&self, s: f64) -> Self {
        Self {
            range_sigma_m: self.range_sigma_m * s,
            range_sigma_per_m: self.range_sigma_per_m * s,
            range_sigma_per_m2: self.range_sigma_per_m2 * s,
            incidence_sigma: self.incidence_sigma * s,
            range_bias_max_m: self.range_bias_max_m * s,
            ..self.clone()
        }
    }

    /// Every value in its range, naming the field.
    pub fn validate(&self) -> Result<(), SettingsError> {
        let bad = |f: &str, why: &str| Err(SettingsError::field(f, why));
        if !(self.fov_rad > 0.0 && self.fov_rad <= std::f64::consts::TAU) {
            return bad("fov_rad", "must lie in (0, 2π]");
        }
        if !(self.step_rad > 0.0 && self.step_rad <= self.fov_rad) {
            return bad("step_rad", "must be positive and at most fov_rad");
        }
        if self.fov_rad / self.step_rad > 100_000.0 {
            return bad("step_rad", "gives more than 100,000 beams");
        }
        for (f, v) in [("rate_hz", self.rate_hz), ("range_max_m", self.range_max_m)] {
            if !(v.is_finite() && v > 0.0) {
                return bad(f, "must be a positive finite number");
            }
        }
        for (f, v) in [
            ("range_min_m", self.range_min_m),
            ("range_sigma_m", self.range_sigma_m),
            ("range_sigma_per_m2", self.range_sigma_per_m2),
            ("incidence_sigma", self.incidence_sigma),
            ("range_bias_max_m", self.range_bias_max_m),
            ("spot_divergence_rad", self.spot_divergence_rad),
            ("spot_at_cover_m", self.spot_at_cover_m),
            ("echo_separation_m", self.echo_separation_m),
            ("sweep_s", self.sweep_s),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return bad(f, "must be a finite number ≥ 0");
            }
        }
        if self.sweep_s > (1.0 / self.rate_hz).min(MAX_SWEEP_S) {
            return bad(
                "sweep_s",
                "must be at most one frame period (1 / rate_hz) and at most 1 s",
            );
        }
        if self.range_min_m >= self.range_max_m {
            return bad("range_min_m", "must be below range_max_m");
        }
        if !self.range_sigma_per_m.is_finite() || self.min_sigma_m() < 0.0 {
            return bad(
                "range_sigma_per_m",
                "makes the range σ negative within the working range",
            );
        }
        if !(self.max_incidence_rad > 0.0 && self.max_incidence_rad <= std::f64::consts::FRAC_PI_2)
        {
            return bad("max_incidence_rad", "must lie in (0, π/2]");
        }
        if !self.mount.is_finite() {
            return bad("mount", "must be finite");
        }
        // A scanner sits on the truck, reaches a warehouse, and measures to a metre.
        forkbench_core::settings::in_ranges(&[
            ("rate_hz", self.rate_hz, 0.01, 1000.0),
            ("range_max_m", self.range_max_m, 0.0, 1000.0),
            ("range_sigma_m", self.range_sigma_m, 0.0, 1.0),
            ("range_sigma_per_m", self.range_sigma_per_m, -1.0, 1.0),
            ("range_sigma_per_m2", self.range_sigma_per_m2, 0.0, 1.0),
            ("incidence_sigma", self.incidence_sigma, 0.0, 10.0),
            ("range_bias_max_m", self.range_bias_max_m, 0.0, 1.0),
            ("spot_divergence_rad", self.spot_divergence_rad, 0.0, 1.0),
            ("spot_at_cover_m", self.spot_at_cover_m, 0.0, 1.0),
            ("echo_separation_m", self.echo_separation_m, 0.0, 10.0),
            ("mount.x_m", self.mount.x_m, -20.0, 20.0),
            ("mount.y_m", self.mount.y_m, -20.0, 20.0),
            ("mount.heading_rad", self.mount.heading_rad, -10.0, 10.0),
        ])
    }

    /// The head-on σ's least value over the working range (a quadratic in range).
    fn min_sigma_m(&self) -> f64 {
        let s = |r: f64| {
            self.range_sigma_m + self.range_sigma_per_m * r + self.range_sigma_per_m2 * r * r
        };
        let mut lo = s(self.range_min_m).min(s(self.range_max_m));
        if self.range_sigma_per_m2 > 0.0 {
            let vertex = -self.range_sigma_per_m / (2.0 * self.range_sigma_per_m2);
            if (self.range_min_m..=self.range_max_m).contains(&vertex) {
                lo = lo.min(s(vertex));
            }
        }
        lo
    }

    /// Beam count: the aperture in whole steps, both ends included.
    pub fn beams(&self) -> usize {
        (self.fov_rad / self.step_rad + 1e-9).floor() as usize + 1
    }

    /// Whether a target (where the pallet should be) lies within this scanner's range
    /// from `sensor`, with a margin for the pallet's extent: a scanner is asked only then
    /// (a camera cannot see 8 m, and a scan costs time).
    pub fn reaches(&self, sensor: &Pose2, target: &Pose2) -> bool {
        sensor.distance_to(target) <= self.range_max_m + REACH_MARGIN_M
    }

    /// The sensor's pose in the map for a fork-root pose.
    pub fn sensor_pose(&self, fork_root: &Pose2) -> Pose2 {
        fork_root.to_world(&self.mount)
    }

    /// The systematic error of one trial: uniform within ±`range_bias_max_m`.
    pub fn draw_bias<R: Rng + ?Sized>(&self, rng: &mut R) -> f64 {
        self.range_bias_max_m * (2.0 * rng.random::<f64>() - 1.0)
    }
}
