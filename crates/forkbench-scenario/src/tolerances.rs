//! A pick's success tolerances as files write them (degrees) and in SI units, converted once at load; the SI form serialises back to the file's.

use serde::{Deserialize, Serialize};

/// Success tolerances of a pick.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Tolerances {
    /// Fork-root offset from the pocket centre line at entry.
    pub lateral_m: f64,
    pub heading_deg: f64,
    /// Required fork insertion (tips past the pallet face).
    pub insertion_depth_m: f64,
    /// Fork–pallet contact force allowed before full depth.
    pub contact_force_n: f64,
    pub pallet_displacement_m: f64,
    pub pallet_rotation_deg: f64,
}

impl Default for Tolerances {
    fn default() -> Self {
        Self {
            // 0.15 m forks in 0.405 m pockets leave ±0.1275 m; keep a margin for the
            // heading error's contribution along the fork.
            lateral_m: 0.10,
            heading_deg: 3.0,
            insertion_depth_m: 1.0,
            contact_force_n: 200.0,
            pallet_displacement_m: 0.02,
            pallet_rotation_deg: 1.0,
        }
    }
}

/// A degree value for output: the value as written when `rad` still is its conversion
/// (degrees do not survive a round trip through radians exactly), else `rad` converted.
pub(crate) fn deg_of(rad: f64, written_deg: f64) -> f64 {
    if written_deg.to_radians() == rad {
        written_deg
    } else {
        rad.to_degrees()
    }
}

/// What a pick is judged by, in SI units.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(from = "Tolerances", into = "Tolerances")]
pub struct Limits {
    /// Fork-root offset from the pocket centre line at entry.
    pub lateral_m: f64,
    /// Heading off the pallet axis at entry.
    pub heading_rad: f64,
    /// Required fork insertion (tips past the pallet face).
    pub insertion_depth_m: f64,
    /// Fork–pallet contact force allowed before full depth.
    pub contact_force_n: f64,
    pub pallet_displacement_m: f64,
    pub pallet_rotation_rad: f64,
    written: Tolerances,
}

impl Limits {
    /// The heading limit in degrees, for messages.
    pub fn heading_deg(&self) -> f64 {
        deg_of(self.heading_rad, self.written.heading_deg)
    }

    /// The pallet-rotation limit in degrees, for messages.
    pub fn pallet_rotation_deg(&self) -> f64 {
        deg_of(self.pallet_rotation_rad, self.written.pallet_rotation_deg)
    }
}

impl Default for Limits {
    fn default() -> Self {
        Tolerances::default().into()
    }
}

impl From<Tolerances> for Limits {
    fn from(t: Tolerances) -> Self {
        Self {
            lateral_m: t.lateral_m,
            heading_rad: t.heading_deg.to_radians(),
            insertion_depth_m: t.insertion_depth_m,
            contact_force_n: t.contact_force_n,
            pallet_displacement_m: t.pallet_displacement_m,
            pallet_rotation_rad: t.pallet_rotation_deg.to_radians(),
            written: t,
        }
    }
}

impl From<Limits> for Tolerances {
    fn from(l: Limits) -> Self {
        Tolerances {
            lateral_m: l.lateral_m,
            heading_deg: l.heading_deg(),
            insertion_depth_m: l.insertion_depth_m,
            contact_force_n: l.contact_force_n,
            pallet_displacement_m: l.pallet_displacement_m,
            pallet_rotation_deg: l.pallet_rotation_deg(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_serialise_as_written_and_follow_changes() {
        let t = Tolerances {
            heading_deg: 3.0,
            ..Tolerances::default()
        };
        let l = Limits::from(t.clone());
        assert_eq!(l.heading_rad, 3.0f64.to_radians());
        // 3° does not survive degrees → radians → degrees exactly; the file's form does.
        assert_eq!(Tolerances::from(l.clone()), t);
        let mut changed = l;
        changed.heading_rad = 0.1;
        assert_eq!(Tolerances::from(changed).heading_deg, 0.1f64.to_degrees());
        let json = serde_json::to_value(Limits::from(t.clone())).expect("serialises");
        assert_eq!(json["heading_deg"], 3.0);
        let back: Limits = serde_json::from_value(json).expect("reads");
        assert_eq!(Tolerances::from(back), t);
    }
}
