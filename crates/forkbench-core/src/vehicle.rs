//! The forklift specification (Hangcha A30 defaults, SPEC section 0) and its derived limits.

use serde::{Deserialize, Serialize};

use crate::actuators::{Actuators, ControlTiming, DriveActuator, SteeringActuator};
use crate::layout::TruckLayout;
use crate::mounts::SensorMounts;

/// Geometry and limits of a rear-steered counterbalance forklift.
///
/// The kinematic origin is the centre of the front (drive) axle; the path reference
/// point for picking is the fork root.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ForkliftSpec {
    /// Which wheel steers and which drives (`layout` in a truck file); left out of
    /// serialised specs at its default, the counterbalance truck.
    #[serde(skip_serializing_if = "TruckLayout::is_counterbalance")]
    pub layout: TruckLayout,
    /// Distance between the fixed (fork-side) axle and the steered wheel.
    pub wheelbase_m: f64,
    /// Largest equivalent steering angle of the rear wheel.
    pub max_steer_rad: f64,
    /// Chassis length (simulation body).
    pub body_length_m: f64,
    /// Chassis width (simulation body).
    pub body_width_m: f64,
    /// Mass of the loaded-free truck.
    pub mass_kg: f64,
    pub fork_length_m: f64,
    pub fork_width_m: f64,
    /// Centre-to-centre spacing of the two forks.
    pub fork_spacing_m: f64,
    /// Longitudinal distance from the front axle forward to the fork root.
    pub fork_root_ahead_of_front_axle_m: f64,
    /// Largest speed while picking.
    pub max_speed_mps: f64,
    /// Rate limit of the steering actuator.
    pub max_steer_rate_radps: f64,
    /// Heaviest load (pallet with its payload) the truck is rated to lift.
    #[serde(skip_serializing_if = "is_default_capacity")]
    pub rated_capacity_kg: f64,
    /// Fork blade thickness; when given, a pallet whose pockets are lower is refused.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fork_thickness_m: Option<f64>,
    /// What the fixed (fork-side) axle carries unladen, VDI 2198 line 2.3 (a
    /// counterbalance truck's front axle, a stacker's load wheels). Given with
    /// `axle_load_steered_kg`, the two place the truck's centre of mass; without them it
    /// sits at the chassis centre.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub axle_load_fixed_kg: Option<f64>,
    /// What the steered wheel carries unladen, VDI 2198 line 2.3 (a counterbalance
    /// truck's rear axle, a stacker's drive side).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub axle_load_steered_kg: Option<f64>,
    /// The steering actuator (`[steering]` in a truck file, `[truck.steering]` in a
    /// scenario); left out of serialised specs at its default.
    #[serde(skip_serializing_if = "SteeringActuator::is_default")]
    pub steering: SteeringActuator,
    /// The traction drive (`[drive]`).
    #[serde(skip_serializing_if = "DriveActuator::is_default")]
    pub drive: DriveActuator,
    /// The controller's period and transport delay (`[control]`).
    #[serde(skip_serializing_if = "ControlTiming::is_default")]
    pub control: ControlTiming,
    /// Where the truck carries its sensors (`[mount.<sensor>]` in a truck file); left
    /// out of serialised specs when it gives none.
    #[serde(skip_serializing_if = "SensorMounts::is_empty")]
    pub mounts: SensorMounts,
}

/// The A30's rating: 3 t.
const DEFAULT_RATED_CAPACITY_KG: f64 = 3000.0;

// Left out of serialised specs at its default, so settings written before it existed keep
// their hashes.
fn is_default_capacity(v: &f64) -> bool {
    *v == DEFAULT_RATED_CAPACITY_KG
}

impl Default for ForkliftSpec {
    // 1.0471 rad is the paper's printed α_max (not π/3); κ_max = 1.063 m⁻¹ follows from it.
    #[allow(clippy::approx_constant)]
    fn default() -> Self {
        Self {
            layout: TruckLayout::Counterbalance,
            wheelbase_m: 1.629,
            max_steer_rad: 1.0471,
            body_length_m: 2.45,
            body_width_m: 1.2,
            mass_kg: 4850.0,
            fork_length_m: 1.6,
            fork_width_m: 0.15,
            fork_spacing_m: 0.535,
            fork_root_ahead_of_front_axle_m: 0.45,
            max_speed_mps: 0.8,
            max_steer_rate_radps: 0.8,
            rated_capacity_kg: DEFAULT_RATED_CAPACITY_KG,
            fork_thickness_m: None,
            axle_load_fixed_kg: None,
            axle_load_steered_kg: None,
            steering: SteeringActuator::default(),
            drive: DriveActuator::default(),
            control: ControlTiming::default(),
            mounts: SensorMounts::default(),
        }
    }
}

/// A forklift spec value that cannot describe a real truck: the settings convention.
pub type SpecError = crate::SettingsError;

/// `field` refused: `reason`, with the value given.
fn refused(field: &str, value: f64, reason: &str) -> SpecError {
    SpecError::field(field, format!("{reason} (got {value})"))
}

impl ForkliftSpec {
    /// Largest path curvature the truck can follow: tan(α_max) / L, with α_max the lock
    /// planners take for its layout (`TruckLayout::planning_lock_rad`).
    pub fn max_curvature_per_m(&self) -> f64 {
        self.layout.planning_lock_rad(self.max_steer_rad).tan() / self.wheelbase_m
    }

    /// Smallest turning radius of the front-axle reference point: 1 / κ_max.
    pub fn min_turn_radius_m(&self) -> f64 {
        1.0 / self.max_curvature_per_m()
    }

    /// Closed outlines of the truck at a fork-root pose: the chassis, then the two forks,
    /// then (for a steered drive wheel) the drive wheel, so a drawing shows which end
    /// drives.
    pub fn outlines(&self, root: &crate::Pose2) -> Vec<[[f64; 2]; 5]> {
        use crate::geometry::rect_outline;
        let mut v = vec![rect_outline(
            &self.chassis_centre(root),
            self.body_length_m,
            self.body_width_m,
        )];
        for f in self.fork_points(root, self.fork_length_m / 2.0) {
            v.push(rect_outline(&f, self.fork_length_m, self.fork_width_m));
        }
        if self.layout.steered_drive_wheel() {
            // The wheel's drawn size is a choice: a drive wheel's 0.25 m by 0.1 m.
            let back = -self.fork_root_ahead_of_front_axle_m - self.wheelbase_m;
            let wheel = root.to_world(&crate::Pose2::new(back, 0.0, 0.0));
            v.push(rect_outline(&wheel, 0.25, 0.1));
        }
        v
    }

    /// Centre pose of the chassis for a fork-root pose (the chassis ends at the fork root).
    pub fn chassis_centre(&self, root: &crate::Pose2) -> crate::Pose2 {
        root.to_world(&crate::Pose2::new(-self.body_length_m / 2.0, 0.0, 0.0))
    }

    /// Lateral offsets of the left and right fork centre lines from the truck's axis.
    pub fn fork_offsets_m(&self) -> [f64; 2] {
        [self.fork_spacing_m / 2.0, -self.fork_spacing_m / 2.0]
    }

    /// Poses of the left and right forks' points `along_m` ahead of the fork root (0: the
    /// root, `fork_length_m`: the tips).
    pub fn fork_points(&self, root: &crate::Pose2, along_m: f64) -> [crate::Pose2; 2] {
        self.fork_offsets_m()
            .map(|y| root.to_world(&crate::Pose2::new(along_m, y, 0.0)))
    }

    /// Depth of the shallower fork tip past the face of a pallet `pallet_depth_m` deep
    /// whose face centre is at `pallet`, at most the fork length, for forks rooted at
    /// `root`. The fork root may reach the face (and, pressed against it, lie a contact's
    /// penetration past it): a truck whose forks are no longer than the pallet is deep
    /// inserts them whole that way. Only a root past the pallet's back (a truck that drove
    /// past or away behind it) inserted nothing: 0.
    pub fn insertion_depth_m(
        &self,
        pallet: &crate::Pose2,
        pallet_depth_m: f64,
        root: &crate::Pose2,
    ) -> f64 {
        if pallet.to_local(root).x_m > pallet_depth_m {
            return 0.0;
        }
        self.fork_points(root, self.fork_length_m)
            .iter()
            .map(|tip| pallet.to_local(tip).x_m)
            .fold(f64::INFINITY, f64::min)
            .min(self.fork_length_m)
    }

    /// The same geometry and mass as `other`, whatever either's actuators and timing.
    pub fn same_geometry(&self, other: &Self) -> bool {
        let strip = |t: &Self| Self {
            steering: SteeringActuator::default(),
            drive: DriveActuator::default(),
            control: ControlTiming::default(),
            max_steer_rate_radps: 0.0,
            ..t.clone()
        };
        strip(self) == strip(other)
    }

    /// Equivalent steering angle that yields the given path curvature: arctan(L κ).
    pub fn steer_for_curvature(&self, curvature_per_m: f64) -> f64 {
        (self.wheelbase_m * curvature_per_m).atan()
    }

    /// Rejects values no truck can have, naming the field.
    pub fn validate(&self) -> Result<(), SpecError> {
        let positive = [
            ("wheelbase_m", self.wheelbase_m),
            ("body_length_m", self.body_length_m),
            ("body_width_m", self.body_width_m),
            ("mass_kg", self.mass_kg),
            ("fork_length_m", self.fork_length_m),
            ("fork_width_m", self.fork_width_m),
            ("fork_spacing_m", self.fork_spacing_m),
            ("max_speed_mps", self.max_speed_mps),
            ("max_steer_rate_radps", self.max_steer_rate_radps),
            ("rated_capacity_kg", self.rated_capacity_kg),
        ];
        for (field, value) in positive {
            if !(value.is_finite() && value > 0.0) {
                return Err(refused(field, value, "must be a positive finite number"));
            }
        }
        self.validate_lock()?;
        if !self.fork_root_ahead_of_front_axle_m.is_finite() {
            return Err(refused(
                "fork_root_ahead_of_front_axle_m",
                self.fork_root_ahead_of_front_axle_m,
                "must be finite",
            ));
        }
        // Upper bounds: beyond them no forklift exists, and the geometry and the physics
        // would only be asked for absurd work.
        if let Some(t) = self.fork_thickness_m {
            crate::settings::in_ranges(&[("fork_thickness_m", t, 0.005, 0.3)])?;
        }
        crate::settings::in_ranges(&[
            ("wheelbase_m", self.wheelbase_m, 0.0, 10.0),
            ("body_length_m", self.body_length_m, 0.0, 20.0),
            ("body_width_m", self.body_width_m, 0.0, 10.0),
            ("mass_kg", self.mass_kg, 0.0, 100_000.0),
            ("fork_length_m", self.fork_length_m, 0.0, 5.0),
            ("fork_width_m", self.fork_width_m, 0.0, 1.0),
            ("fork_spacing_m", self.fork_spacing_m, 0.0, 5.0),
            ("max_speed_mps", self.max_speed_mps, 0.0, 10.0),
            ("max_steer_rate_radps", self.max_steer_rate_radps, 0.0, 20.0),
            ("rated_capacity_kg", self.rated_capacity_kg, 0.0, 100_000.0),
            (
                "fork_root_ahead_of_front_axle_m",
                self.fork_root_ahead_of_front_axle_m,
                -5.0,
                5.0,
            ),
        ])?;
        if self.fork_spacing_m + self.fork_width_m > self.body_width_m * 1.5 {
            return Err(refused(
                "fork_spacing_m",
                self.fork_spacing_m,
                "forks spread far wider than the truck",
            ));
        }
        self.validate_mass_centre()?;
        self.mounts.validate()?;
        self.steering.validate()?;
        self.drive.validate()?;
        self.control.validate()
    }

    /// The lock's range follows the layout: a counterbalance truck's steered rear axle
    /// turns less than 90°, a steered drive wheel up to 90°.
    fn validate_lock(&self) -> Result<(), SpecError> {
        let (right, lock) = (std::f64::consts::FRAC_PI_2, self.max_steer_rad);
        let within = if self.layout.steered_drive_wheel() {
            // 1.5708, π/2 to four places, is how a truck file writes 90°.
            lock > 0.0 && lock <= right + 5e-5
        } else {
            lock > 0.0 && lock < right
        };
        if within {
            return Ok(());
        }
        let reason = if self.layout.steered_drive_wheel() {
            format!(
                "a {}'s steered drive wheel turns at most π/2 (90°)",
                self.layout.key().replace('_', " ")
            )
        } else {
            "must lie strictly between 0 and π/2: a counterbalance truck's rear axle turns \
             less than 90° (a steered drive wheel that reaches 90° is layout = \"pallet_stacker\" \
             or \"reach_truck\")"
                .to_string()
        };
        Err(refused("max_steer_rad", lock, &reason))
    }

    /// The actuators and timing, together.
    pub fn actuators(&self) -> Actuators {
        Actuators {
            steering: self.steering.clone(),
            drive: self.drive.clone(),
            control: self.control.clone(),
        }
    }

    /// This truck with the actuators and timing of `a` (a preset), its geometry kept.
    pub fn with_actuators(self, a: Actuators) -> Self {
        Self {
            steering: a.steering,
            drive: a.drive,
            control: a.control,
            ..self
        }
    }

    /// From a steering command leaving the controller to the motor acting on it: the
    /// steering's dead time and the bus.
    pub fn steering_delay_s(&self) -> f64 {
        self.steering.dead_time_s + self.control.transport_delay_s
    }

    /// The same for a speed command and the drive.
    pub fn drive_delay_s(&self) -> f64 {
        self.drive.dead_time_s + self.control.transport_delay_s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a30_limits_match_spec_section_0() {
        let spec = ForkliftSpec::default();
        assert!((spec.max_curvature_per_m() - 1.063).abs() < 1e-3);
        assert!((spec.min_turn_radius_m() - 0.9407).abs() < 1e-3);
        assert!(spec.validate().is_ok());
    }

    /// Issue 21, defect 10: a truck that drove away behind the pallet reported an
    /// insertion depth of 106 m; depth counts only from the front and is at most the forks.
    #[test]
    fn insertion_depth_is_bounded_by_the_forks_and_counted_from_the_front() {
        let truck = ForkliftSpec::default();
        let pallet = crate::Pose2::new(0.0, 0.0, 0.0);
        let at = |x: f64| truck.insertion_depth_m(&pallet, 1.2, &crate::Pose2::new(x, 0.0, 0.0));
        assert!(
            (at(-truck.fork_length_m - 0.5) + 0.5).abs() < 1e-12,
            "short of the face"
        );
        assert!(
            (at(-truck.fork_length_m + 0.8) - 0.8).abs() < 1e-12,
            "0.8 m in"
        );
        assert!(at(-0.01) <= truck.fork_length_m);
        assert_eq!(at(105.0), 0.0, "drove away behind the pallet");
        assert_eq!(at(1.3), 0.0, "root past the pallet's back");
    }

    /// Issue 77: forks no longer than the pallet is deep go in whole with the root at the
    /// face, and a root pressed a contact's penetration past the face still counts them
    /// in (the 1.22 m forks read "0.000 m deep" there).
    #[test]
    fn a_root_at_or_just_past_the_face_counts_the_whole_forks() {
        let truck = ForkliftSpec {
            fork_length_m: 1.22,
            ..ForkliftSpec::default()
        };
        let pallet = crate::Pose2::new(0.0, 0.0, 0.0);
        let at = |x: f64| truck.insertion_depth_m(&pallet, 1.2, &crate::Pose2::new(x, 0.0, 0.0));
        assert_eq!(at(0.0), 1.22);
        assert_eq!(at(0.003), 1.22, "pressed against the face");
        assert!((at(-0.07) - 1.15).abs() < 1e-12, "the default target");
    }

    #[test]
    fn toml_overrides_and_rejects_unknown_fields() {
        let spec: ForkliftSpec = toml::from_str("wheelbase_m = 2.0").expect("valid toml");
        assert_eq!(spec.wheelbase_m, 2.0);
        assert_eq!(spec.max_speed_mps, 0.8);
        assert!(toml::from_str::<ForkliftSpec>("wheelbase = 2.0").is_err());
    }

    #[test]
    fn validate_names_the_field() {
        let spec = ForkliftSpec {
            wheelbase_m: -1.0,
            ..ForkliftSpec::default()
        };
        let err = spec.validate().expect_err("negative wheelbase");
        assert_eq!(err.field.as_deref(), Some("wheelbase_m"));
        let spec = ForkliftSpec {
            max_steer_rad: 2.0,
            ..ForkliftSpec::default()
        };
        assert_eq!(
            spec.validate()
                .expect_err("too much steer")
                .field
                .as_deref(),
            Some("max_steer_rad")
        );
    }
}
