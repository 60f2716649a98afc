//! The SI forms of a scenario's tolerances and replanning thresholds, converted once at load; they serialise back to the file's form (degrees) for manifests.

use serde::{Deserialize, Serialize};

use super::file::{ReplanFile, Tolerances};

/// A degree value for output: the value as written when `rad` still is its conversion
/// (degrees do not survive a round trip through radians exactly), else `rad` converted.
fn deg_of(rad: f64, written_deg: f64) -> f64 {
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

/// Replanning on a new pallet estimate, in SI units.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(from = "ReplanFile", into = "ReplanFile")]
pub struct Replan {
    /// Off reproduces the papers: plan once from the first estimate.
    pub enabled: bool,
    pub position_threshold_m: f64,
    pub heading_threshold_rad: f64,
    written_heading_deg: f64,
    /// Ranges at which a new estimate is taken (the trial's schedule, not the sensor's);
    /// `None`: the pallet-estimate settings' own list.
    pub reestimate_at_m: Option<Vec<f64>>,
    pub method: super::file::ReplanMethod,
}

impl Default for Replan {
    fn default() -> Self {
        ReplanFile::default().into()
    }
}

impl From<ReplanFile> for Replan {
    fn from(r: ReplanFile) -> Self {
        Self {
            enabled: r.enabled,
            position_threshold_m: r.position_threshold_m,
            heading_threshold_rad: r.heading_threshold_deg.to_radians(),
            written_heading_deg: r.heading_threshold_deg,
            reestimate_at_m: r.reestimate_at_m,
            method: r.method,
        }
    }
}

impl From<Replan> for ReplanFile {
    fn from(r: Replan) -> Self {
        ReplanFile {
            enabled: r.enabled,
            position_threshold_m: r.position_threshold_m,
            heading_threshold_deg: deg_of(r.heading_threshold_rad, r.written_heading_deg),
            reestimate_at_m: r.reestimate_at_m,
            method: r.method,
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
