//! The NAV350 as a localiser that measures reflectors: each 8 Hz sweep ranges the reflectors the world lets it see from its mount, each at its own moment of the rotating sweep, compensates the truck's motion with its speed input, matches them to its map from the controller's predicted pose, and solves a pose when enough match.

use std::collections::VecDeque;

use forkbench_core::units::wrap_angle;
use forkbench_core::{Pose2, SettingsError};
use rand::Rng;
use serde::{Deserialize, Serialize};

use crate::localizer::{Cadence, Localizer, LocalizerInput, Reading};
use crate::reflectors::{self, Observation, Reflector, ReflectorNavConfig};
use crate::scan::Surface;
use crate::sight::Sight;

/// The name a truck's `[mount.<sensor>]` table gives the reflector localiser's scanner.
pub const MOUNT_NAME: &str = "nav350";

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
    /// The device's speed input: the vehicle's odometry tells it how the truck moved
    /// during the sweep, so each reflector, measured at its own moment of the rotation,
    /// is carried to the sweep's end. Off, a moving truck's fix is smeared by its motion
    /// (the operating instructions require the input for a moving vehicle).
    pub speed_input: bool,
}

impl Default for ReflectorNavSettings {
    fn default() -> Self {
        Self {
            mount: Pose2::new(-0.2, 0.0, 0.0),
            missing_reflectors: Vec::new(),
            measurement: ReflectorNavConfig::default(),
            speed_input: true,
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
        forkbench_core::settings::in_ranges(&[
            ("mount.x_m", self.mount.x_m, -20.0, 20.0),
            ("mount.y_m", self.mount.y_m, -20.0, 20.0),
            ("mount.heading_rad", self.mount.heading_rad, -10.0, 10.0),
        ])?;
        // A world that cannot give one fix would run every trial on dead reckoning (a
        // study that takes reflectors away may leave fewer: that is its question).
        let have = map.len();
        if have < self.measurement.min_reflectors {
            return Err(SettingsError::field(
                "kind",
                format!(
                    "nav350 needs at least {} reflectors in the world ([[reflector]]) for a \
                     fix; it has {have} (use kind = \"gaussian\" on a world without them)",
                    self.measurement.min_reflectors
                ),
            ));
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
    blocking: Sight,
    cadence: Cadence,
    /// The poses over the last sweep: each reflector is measured from where the scanner
    /// was when its beam passed it.
    trail: Trail,
}

/// One control step's poses: the time, the true fork root, and the odometry's (what the
/// device's speed input integrates to).
type Mark = (f64, Pose2, Option<Pose2>);

/// The fork-root poses over the last sweep.
#[derive(Debug, Clone, Default)]
struct Trail(VecDeque<Mark>);

impl Trail {
    fn push(&mut self, mark: Mark, keep_s: f64) {
        self.0.push_back(mark);
        while self.0.len() > 2 && self.0.front().is_some_and(|f| f.0 < mark.0 - keep_s) {
            self.0.pop_front();
        }
    }

    /// The pose `pick` takes from a mark, at `t_s` (linear between marks, held at the
    /// ends); `None` when a mark in between lacks it.
    fn at(&self, t_s: f64, pick: impl Fn(&Mark) -> Option<Pose2>) -> Option<Pose2> {
        let after = self.0.iter().position(|m| m.0 >= t_s);
        let (a, b) = match after {
            Some(0) => (&self.0[0], &self.0[0]),
            Some(k) => (&self.0[k - 1], &self.0[k]),
            None => {
                let last = self.0.back()?;
                (last, last)
            }
        };
        let (pa, pb) = (pick(a)?, pick(b)?);
        let u = if b.0 > a.0 {
            (t_s - a.0) / (b.0 - a.0)
        } else {
            0.0
        };
        Some(Pose2::new(
            pa.x_m + u * (pb.x_m - pa.x_m),
            pa.y_m + u * (pb.y_m - pa.y_m),
            wrap_angle(pa.heading_rad + u * wrap_angle(pb.heading_rad - pa.heading_rad)),
        ))
    }
}

impl ReflectorNav {
    /// A device with `map`, in a world whose surfaces are `surfaces`, sampling at
    /// `rate_hz` and delivering `latency_s` later, its measurement σ scaled by
    /// `noise_scale` (0: exact).
    pub fn new(
        settings: ReflectorNavSettings,
        map: &[Reflector],
        surfaces: &[Surface],
        (rate_hz, latency_s): (f64, f64),
        noise_scale: f64,
    ) -> Self {
        let mut measured = settings.measurement.clone();
        measured.range_sigma_m *= noise_scale;
        measured.bearing_sigma_rad *= noise_scale;
        // One order whatever the world file's: noise is drawn, and reflectors matched,
        // in this order, so a reordered list must not change a sweep.
        let mut map = map.to_vec();
        map.sort_by(|a, b| {
            (a.x_m.total_cmp(&b.x_m))
                .then(a.y_m.total_cmp(&b.y_m))
                .then(a.name.cmp(&b.name))
        });
        let present = map
            .iter()
            .filter(|r| !settings.missing_reflectors.contains(&r.name))
            .cloned()
            .collect();
        Self {
            settings,
            measured,
            map,
            present,
            blocking: Sight::new(surfaces),
            cadence: Cadence::new(rate_hz, latency_s),
            trail: Trail::default(),
        }
    }

    /// One sweep ending at `t_s`, from the trail of true poses, matched from the prior
    /// (the controller's prediction, or the truth before any: the integrator's set-pose).
    /// `occluders`: map segments that hide a reflector behind them this sweep.
    fn sweep<R: Rng + ?Sized>(
        &self,
        t_s: f64,
        (prior, occluders): (Option<Pose2>, &[[[f64; 2]; 2]]),
        rng: &mut R,
    ) -> Reading {
        let m = &self.settings.mount;
        let Some(&(_, truth, _)) = self.trail.0.back() else {
            return Reading {
                pose: None,
                fix: None,
                detected: 0,
                measured_s: t_s,
            };
        };
        let prior = prior.unwrap_or(truth);
        let sensor = truth.to_world(m);
        let cfg = &self.settings.measurement;
        let at = [sensor.x_m, sensor.y_m];
        let mut seen = reflectors::visible(at, &self.present, &self.blocking, cfg);
        // People and other trucks in the way hide a reflector for this sweep.
        seen.retain(|&i| {
            let r = [self.present[i].x_m, self.present[i].y_m];
            !occluders
                .iter()
                .any(|&[a, b]| crate::sight::segments_cross(at, r, a, b))
        });
        let obs: Vec<Observation> = seen
            .iter()
            .map(|&i| self.measure_one(i, (t_s, &sensor), rng))
            .collect();
        let predicted = prior.to_world(m);
        let pairs = reflectors::associate(&obs, &predicted, &self.map, cfg);
        let fix = reflectors::solve(&obs, &pairs, &self.map, &predicted, cfg);
        Reading {
            pose: fix.as_ref().map(|f| root_of(&f.pose, m)),
            fix,
            detected: obs.len(),
            measured_s: t_s,
        }
    }

    /// Reflector `i` as measured when the rotating beam passed it (the head turns once
    /// per period, from bearing 0 counter-clockwise, ending at `t_s`), carried to the
    /// sweep's end with the speed input when the device has it.
    fn measure_one<R: Rng + ?Sized>(
        &self,
        i: usize,
        (t_s, sensor_end): (f64, &Pose2),
        rng: &mut R,
    ) -> Observation {
        let m = &self.settings.mount;
        let r = &self.present[i];
        let bearing =
            (r.y_m - sensor_end.y_m).atan2(r.x_m - sensor_end.x_m) - sensor_end.heading_rad;
        let frac = bearing.rem_euclid(std::f64::consts::TAU) / std::f64::consts::TAU;
        let t_i = t_s - self.cadence.period_s() * (1.0 - frac);
        let truth = |k: &Mark| Some(k.1);
        let sensor_i = self
            .trail
            .at(t_i, truth)
            .map_or(*sensor_end, |p| p.to_world(m));
        let o = reflectors::measure_one(&sensor_i, r, &self.measured, rng);
        if !self.settings.speed_input {
            return o;
        }
        // How the device believes it moved since: its odometry, or none without one.
        let own = |k: &Mark| k.2;
        let (from, to) = match (self.trail.at(t_i, own), self.trail.at(t_s, own)) {
            (Some(a), Some(b)) => (a.to_world(m), b.to_world(m)),
            _ => (sensor_i, *sensor_end),
        };
        let p = from.to_world(&Pose2::new(
            o.range_m * o.bearing_rad.cos(),
            o.range_m * o.bearing_rad.sin(),
            0.0,
        ));
        let local = to.to_local(&p);
        Observation {
            range_m: local.x_m.hypot(local.y_m),
            bearing_rad: local.y_m.atan2(local.x_m),
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
        let mark = (input.t_s, input.truth, input.odometry);
        self.trail.push(mark, 1.5 * self.cadence.period_s());
        if self.cadence.due(input.t_s) {
            let reading = self.sweep(input.t_s, (input.predicted, &input.occluders), rng);
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
