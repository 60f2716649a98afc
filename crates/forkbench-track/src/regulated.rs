//! Regulated pure pursuit (after Nav2's controller): speed-scaled look-ahead, slower on tight arcs and on the final approach.

use forkbench_core::settings::{self, Settings, SettingsError};
use forkbench_core::{ForkliftSpec, Path};
use serde::{Deserialize, Serialize};

use crate::pursuit::{DriveAnswer, stop_profile};
use crate::{Command, PurePursuit, Tracker, TrackerConfig, TrackerInput};

/// Settings of the regulated tracker (SI units).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RegulatedConfig {
    /// Look-ahead = this · speed, clamped to [min, max].
    pub lookahead_time_s: f64,
    pub min_lookahead_m: f64,
    pub max_lookahead_m: f64,
    pub cruise_speed_mps: f64,
    /// Below this pursuit-arc radius the speed scales with radius / this.
    pub regulated_min_radius_m: f64,
    /// Lowest speed the curvature regulation leaves.
    pub regulated_min_speed_mps: f64,
    /// Over the last this many metres the speed scales with the distance left.
    pub approach_distance_m: f64,
    /// Lowest speed of the final approach (fork entry).
    pub min_approach_speed_mps: f64,
    pub decel_mps2: f64,
}

impl Default for RegulatedConfig {
    fn default() -> Self {
        Self {
            lookahead_time_s: 0.9,
            min_lookahead_m: 0.5,
            max_lookahead_m: 0.8,
            cruise_speed_mps: 0.8,
            regulated_min_radius_m: 2.5,
            regulated_min_speed_mps: 0.25,
            approach_distance_m: 2.5,
            min_approach_speed_mps: 0.15,
            decel_mps2: 0.4,
        }
    }
}

impl RegulatedConfig {
    /// The first field that holds an impossible value, with the reason.
    pub fn validate(&self) -> Result<(), SettingsError> {
        let fields = [
            ("lookahead_time_s", self.lookahead_time_s),
            ("min_lookahead_m", self.min_lookahead_m),
            ("max_lookahead_m", self.max_lookahead_m),
            ("cruise_speed_mps", self.cruise_speed_mps),
            ("regulated_min_radius_m", self.regulated_min_radius_m),
            ("regulated_min_speed_mps", self.regulated_min_speed_mps),
            ("approach_distance_m", self.approach_distance_m),
            ("min_approach_speed_mps", self.min_approach_speed_mps),
            ("decel_mps2", self.decel_mps2),
        ];
        if let Some((f, _)) = fields.iter().find(|(_, v)| !(v.is_finite() && *v > 0.0)) {
            return Err(SettingsError::field(f, "must be a positive finite number"));
        }
        if self.max_lookahead_m < self.min_lookahead_m {
            return Err(SettingsError::field(
                "max_lookahead_m",
                "must be ≥ min_lookahead_m",
            ));
        }
        Ok(())
    }
}

/// Pure pursuit's geometry with Nav2-style speed regulation.
#[derive(Debug, Clone)]
pub struct RegulatedPurePursuit {
    cfg: RegulatedConfig,
    pursuit: PurePursuit,
}

impl RegulatedPurePursuit {
    pub fn new(cfg: RegulatedConfig) -> Self {
        Self {
            cfg,
            pursuit: PurePursuit::with_config(TrackerConfig::default()),
        }
    }

    /// From a scenario's `[tracker]` table.
    pub fn from_settings(s: &Settings) -> Result<Self, SettingsError> {
        let cfg: RegulatedConfig = settings::parse(s)?;
        cfg.validate()?;
        Ok(Self::new(cfg))
    }

    /// The regulated speed for the pursuit arc's curvature and the distance left.
    fn speed(
        &self,
        arc_curvature_per_m: f64,
        remaining_m: f64,
        (truck, measured_mps): (&ForkliftSpec, f64),
    ) -> f64 {
        let c = &self.cfg;
        let mut v = c.cruise_speed_mps.min(truck.max_speed_mps);
        let radius = 1.0 / arc_curvature_per_m.abs().max(1e-9);
        if radius < c.regulated_min_radius_m {
            v = (v * radius / c.regulated_min_radius_m).max(c.regulated_min_speed_mps.min(v));
        }
        if remaining_m < c.approach_distance_m {
            let scaled = v * remaining_m.max(0.0) / c.approach_distance_m;
            v = scaled.max(c.min_approach_speed_mps.min(v));
        }
        let drive = DriveAnswer::of(truck, measured_mps);
        stop_profile(v, c.decel_mps2, remaining_m, drive)
    }
}

impl Tracker for RegulatedPurePursuit {
    fn name(&self) -> &str {
        "regulated_pure_pursuit"
    }

    fn reset(&mut self, path: &Path, truck: &ForkliftSpec) {
        Tracker::reset(&mut self.pursuit, path, truck);
    }

    fn command(&mut self, input: &TrackerInput) -> Command {
        let c = &self.cfg;
        let ld = (c.lookahead_time_s * input.speed_mps.abs())
            .clamp(c.min_lookahead_m, c.max_lookahead_m);
        let Some(g) = self.pursuit.geometry(&input.pose, ld, input.truck) else {
            return crate::pursuit::stopped(&input.pose);
        };
        let at = (input.truck, input.speed_mps);
        g.command(self.speed(g.arc_curvature_per_m, g.remaining_m, at))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use forkbench_core::Pose2;

    fn straight(len: f64) -> Path {
        Path::straight(&Pose2::new(0.0, 0.0, 0.0), len, 0.01)
    }

    #[test]
    fn slows_on_tight_arcs_and_on_the_approach() {
        let truck = ForkliftSpec::default();
        let rpp = RegulatedPurePursuit::new(RegulatedConfig::default());
        let open = rpp.speed(0.0, 10.0, (&truck, 0.0));
        let tight = rpp.speed(1.0, 10.0, (&truck, 0.0));
        let approach = rpp.speed(0.0, 1.0, (&truck, 0.0));
        assert!((open - 0.8).abs() < 1e-12, "{open}");
        assert!((0.25..0.5).contains(&tight), "{tight}");
        assert!(approach < open && approach >= 0.15, "{approach}");
    }

    #[test]
    fn follows_a_straight_path_to_its_end() {
        let truck = ForkliftSpec::default();
        let mut rpp = RegulatedPurePursuit::new(RegulatedConfig::default());
        rpp.reset(
            &straight(5.0),
            &ForkliftSpec {
                fork_root_ahead_of_front_axle_m: 0.0,
                ..truck.clone()
            },
        );
        let input = |x: f64, y: f64, v: f64| TrackerInput {
            t_s: 0.0,
            pose: Pose2::new(x, y, 0.0),
            speed_mps: v,
            steer_rad: 0.0,
            fix_measured_s: None,
            truck: &truck,
        };
        assert!(
            rpp.command(&input(1.0, 0.2, 0.5)).steer_rad < 0.0,
            "steers back"
        );
        let end = rpp.command(&input(4.999, 0.0, 0.05));
        assert!(end.done && end.speed_mps == 0.0);
    }
}
