//! The NAV350 as a localiser that measures reflectors: each 8 Hz sweep ranges the reflectors the world lets it see from its mount, matches them to its map from the controller's predicted pose, and solves a pose when enough match.

use forkbench_core::units::wrap_angle;
use forkbench_core::{Pose2, SettingsError};
use rand::Rng;
use serde::{Deserialize, Serialize};

use crate::localizer::{Cadence, Localizer, LocalizerInput, Reading};
use crate::reflectors::{self, Reflector, ReflectorNavConfig};
use crate::scan::{Seen, Surface};

/// The `nav350` localiser's settings (`[sensors.localizer]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ReflectorNavSettings {
    /// The scanner's pose in the fork-root frame (x forward, y left). The default sits
    /// on the mast above the fork root, in the reflectors' plane.
    pub mount: Pose2,
    /// Reflectors in the device's map that are not in the world (fallen off, covered):
    /// the "what if these go" question of a layout review.
    pub missing_reflectors: Vec<String>,
    /// The reflector measurement and the pose solve.
    pub measurement: ReflectorNavConfig,
}

impl Default for ReflectorNavSettings {
    fn default() -> Self {
        Self {
            mount: Pose2::new(-0.2, 0.0, 0.0),
            missing_reflectors: Vec::new(),
            measurement: ReflectorNavConfig::default(),
        }
    }
}

impl ReflectorNavSettings {
    /// Values in range, and every missing reflector named in `map`.
    pub fn validate(&self, map: &[Reflector]) -> Result<(), SettingsError> {
        self.measurement.validate().map_err(|e| SettingsError {
            field: e.field.map(|f| format!("measurement.{f}")),
            reason: e.reason,
        })?;
        if !self.mount.is_finite() {
            return Err(SettingsError::field("mount", "must be finite"));
        }
        for name in &self.missing_reflectors {
            if !map.iter().any(|r| &r.name == name) {
                return Err(SettingsError::field(
                    "missing_reflectors",
                    format!("{name:?} is not a reflector of the world"),
                ));
            }
        }
        Ok(())
    }
}

/// The NAV350 measuring reflectors in a world.
#[derive(Debug, Clone)]
pub struct ReflectorNav {
    settings: ReflectorNavSettings,
    /// The measurement with its noise (zero when noise is off).
    measured: ReflectorNavConfig,
    /// The device's map: every reflector it was commissioned with.
    map: Vec<Reflector>,
    /// The reflectors the world holds (the map less the missing ones).
    present: Vec<Reflector>,
    /// Racks and walls: the surfaces that hide a reflector.
    blocking: Vec<Surface>,
    cadence: Cadence,
}

impl ReflectorNav {
    /// A device with `map`, in a world whose surfaces are `surfaces`, sampling at
    /// `rate_hz` and delivering `latency_s` later.
    pub fn new(
        settings: ReflectorNavSettings,
        map: &[Reflector],
        surfaces: &[Surface],
        (rate_hz, latency_s): (f64, f64),
        noise: bool,
    ) -> Self {
        let mut measured = settings.measurement.clone();
        if !noise {
            measured.range_sigma_m = 0.0;
            measured.bearing_sigma_rad = 0.0;
        }
        let present = map
            .iter()
            .filter(|r| !settings.missing_reflectors.contains(&r.name))
            .cloned()
            .collect();
        Self {
            settings,
            measured,
            map: map.to_vec(),
            present,
            blocking: surfaces
                .iter()
                .filter(|s| s.seen == Seen::Fixed)
                .copied()
                .collect(),
            cadence: Cadence::new(rate_hz, latency_s),
        }
    }

    /// One sweep from the true fork-root pose, matched from the prior (the controller's
    /// prediction, or the truth before any: the integrator's set-pose at commissioning).
    pub fn sweep<R: Rng + ?Sized>(&self, truth: &Pose2, prior: &Pose2, rng: &mut R) -> Reading {
        let m = &self.settings.mount;
        let sensor = truth.to_world(m);
        let cfg = &self.settings.measurement;
        let seen =
            reflectors::visible([sensor.x_m, sensor.y_m], &self.present, &self.blocking, cfg);
        let obs = reflectors::measure(&sensor, &self.present, &seen, &self.measured, rng);
        let predicted = prior.to_world(m);
        let pairs = reflectors::associate(&obs, &predicted, &self.map, cfg);
        let fix = reflectors::solve(&obs, &pairs, &self.map, &predicted, cfg);
        Reading {
            pose: fix.as_ref().map(|f| root_of(&f.pose, m)),
            fix,
            detected: obs.len(),
        }
    }
}

/// The fork-root pose of a scanner at `sensor` mounted at `mount`.
fn root_of(sensor: &Pose2, mount: &Pose2) -> Pose2 {
    let h = wrap_angle(sensor.heading_rad - mount.heading_rad);
    let (s, c) = h.sin_cos();
    Pose2::new(
        sensor.x_m - c * mount.x_m + s * mount.y_m,
        sensor.y_m - s * mount.x_m - c * mount.y_m,
        h,
    )
}

impl Localizer for ReflectorNav {
    fn name(&self) -> &str {
        "nav350"
    }

    fn update(&mut self, input: &LocalizerInput, rng: &mut dyn Rng) -> Option<Reading> {
        if self.cadence.due(input.t_s) {
            let prior = input.predicted.unwrap_or(input.truth);
            let reading = self.sweep(&input.truth, &prior, rng);
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

    #[test]
    fn the_root_is_recovered_from_the_mounted_scanner() {
        let mount = Pose2::new(-0.4, 0.15, 0.3);
        let root = Pose2::new(3.0, -2.0, 2.5);
        let back = root_of(&root.to_world(&mount), &mount);
        assert!(back.distance_to(&root) < 1e-12, "{back:?}");
        assert!(wrap_angle(back.heading_rad - root.heading_rad).abs() < 1e-12);
    }
}
