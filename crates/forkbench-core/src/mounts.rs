//! Where a truck carries its sensors: each sensor's pose in the fork-root frame, by the sensor's name, as a truck file's `[mount.<sensor>]` tables give them.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::{Pose2, SettingsError};

/// The fields of one mount, by the names a truck file gives them.
pub const MOUNT_FIELDS: [&str; 3] = ["x_m", "y_m", "heading_rad"];

/// Farthest a sensor may sit from the fork root: beyond it no truck carries one.
const MAX_OFFSET_M: f64 = 20.0;

/// The truck's sensor mounts (fork-root frame: x forward along the forks, y left), by
/// sensor name (a scanner model such as `tim561`, or `nav350` for the reflector
/// localiser). A sensor the truck does not mount keeps the scenario's or its model's own.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct SensorMounts(BTreeMap<String, Pose2>);

impl SensorMounts {
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// The mount of sensor `name`, if the truck gives one.
    pub fn get(&self, name: &str) -> Option<&Pose2> {
        self.0.get(name)
    }

    /// Every mount, by sensor name.
    pub fn iter(&self) -> impl Iterator<Item = (&str, &Pose2)> {
        self.0.iter().map(|(k, v)| (k.as_str(), v))
    }

    /// Sets `field` (one of [`MOUNT_FIELDS`]) of sensor `name`'s mount; a mount begins at
    /// the fork root, facing along the forks, so an unset field reads 0. False when
    /// `field` is no mount field or `name` is not a plain name (lower case, digits, `_`).
    pub fn set(&mut self, name: &str, field: &str, v: f64) -> bool {
        let plain = !name.is_empty()
            && name
                .bytes()
                .all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'_');
        if !plain || !MOUNT_FIELDS.contains(&field) {
            return false;
        }
        let m = self
            .0
            .entry(name.to_owned())
            .or_insert(Pose2::new(0.0, 0.0, 0.0));
        match field {
            "x_m" => m.x_m = v,
            "y_m" => m.y_m = v,
            _ => m.heading_rad = v,
        }
        true
    }

    /// Every mount finite and near the truck, naming the field (`mount.<sensor>.<field>`).
    pub fn validate(&self) -> Result<(), SettingsError> {
        for (name, m) in &self.0 {
            let f = |k: &str| format!("mount.{name}.{k}");
            crate::settings::in_ranges(&[
                (&f("x_m"), m.x_m, -MAX_OFFSET_M, MAX_OFFSET_M),
                (&f("y_m"), m.y_m, -MAX_OFFSET_M, MAX_OFFSET_M),
                (
                    &f("heading_rad"),
                    m.heading_rad,
                    -std::f64::consts::TAU,
                    std::f64::consts::TAU,
                ),
            ])?;
        }
        Ok(())
    }
}

/// Why a sensor's own `mount` beside the truck's mount for it is refused.
pub fn mounted_twice(name: &str) -> String {
    format!(
        "the truck mounts {name} already ([mount.{name}] in its file or [truck.mount.{name}]): \
         say where it sits in one place"
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_mount_set_field_by_field_starts_at_the_fork_root() {
        let mut m = SensorMounts::default();
        assert!(m.set("tim561", "x_m", 0.1));
        assert_eq!(m.get("tim561"), Some(&Pose2::new(0.1, 0.0, 0.0)));
        assert!(m.set("tim561", "heading_rad", 0.2));
        assert_eq!(m.get("tim561"), Some(&Pose2::new(0.1, 0.0, 0.2)));
        assert!(!m.set("tim561", "z_m", 1.0), "no such field");
        assert!(!m.set("Tim 561", "x_m", 1.0), "not a plain name");
        assert!(m.validate().is_ok());
        m.set("nav350", "y_m", f64::NAN);
        let e = m.validate().expect_err("NaN");
        assert_eq!(e.field.as_deref(), Some("mount.nav350.y_m"));
    }
}
