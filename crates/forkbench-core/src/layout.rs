//! A truck's axle layout: which wheel steers, which drives, and which way its forks face in travel.

use serde::{Deserialize, Serialize};

/// The largest equivalent lock a planner takes for a steered drive wheel. At 90° such a
/// truck turns on the spot about its load axle, where a path's curvature is infinite;
/// 85° keeps every planner's turning radius finite (L / 11.4) while the tracker may still
/// steer to the full lock. A choice.
pub const STEERED_DRIVE_PLANNING_LOCK_RAD: f64 = 85.0 * std::f64::consts::PI / 180.0;

/// How a truck's wheels steer and drive. In every layout the fixed axle is on the forks'
/// side and the steered wheel at the far end, so the kinematics (a single-track model about
/// the fixed axle) are one; what differs is where the traction acts, how far the steered
/// wheel turns, and which way the truck faces when it travels.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TruckLayout {
    /// A counterbalance truck: the fixed front axle drives, the rear wheels steer (less than
    /// 90°), the forks lead. The Hangcha A30's layout.
    #[default]
    Counterbalance,
    /// A pallet stacker: one steered drive wheel under the drive unit, fixed load wheels in
    /// the fork arms or straddle legs, the forks trailing in travel; it enters a pallet in
    /// reverse. Its drive wheel may turn to 90°.
    PalletStacker,
    /// A reach truck: one steered drive wheel, fixed load wheels in the outriggers, the mast
    /// reached out ahead of them, the forks trailing in travel; it enters a pallet in
    /// reverse. Its drive wheel may turn to 90°.
    ReachTruck,
}

impl TruckLayout {
    /// Whether this is the default layout (left out of serialised specs, so settings
    /// written before layouts existed keep their hashes).
    pub fn is_counterbalance(&self) -> bool {
        *self == Self::Counterbalance
    }

    /// Whether the truck has one steered drive wheel: its traction acts at that wheel,
    /// along its heading (not at the fixed axle along the truck's axis), and its lock may
    /// reach 90°.
    pub fn steered_drive_wheel(&self) -> bool {
        !self.is_counterbalance()
    }

    /// The lock planners take for a truck of this layout with lock `lock_rad`.
    pub fn planning_lock_rad(&self, lock_rad: f64) -> f64 {
        if self.steered_drive_wheel() {
            lock_rad.min(STEERED_DRIVE_PLANNING_LOCK_RAD)
        } else {
            lock_rad
        }
    }

    /// Every layout, in the order of their codes.
    pub const ALL: [Self; 3] = [Self::Counterbalance, Self::PalletStacker, Self::ReachTruck];

    /// The layout a truck file names (`layout = "reach_truck"`).
    pub fn from_key(key: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|l| l.key() == key)
    }

    /// Its place in [`Self::ALL`]: how a layout rides among a run's numeric truck settings.
    pub fn code(&self) -> f64 {
        Self::ALL.iter().position(|l| l == self).unwrap_or(0) as f64
    }

    /// The layout of a code ([`Self::code`]); `None` for any other number.
    pub fn from_code(code: f64) -> Option<Self> {
        Self::ALL.into_iter().find(|l| l.code() == code)
    }

    /// The names truck files may give, for messages.
    pub fn keys() -> String {
        Self::ALL.map(|l| l.key()).join(", ")
    }

    /// Its name in truck files.
    pub fn key(&self) -> &'static str {
        match self {
            Self::Counterbalance => "counterbalance",
            Self::PalletStacker => "pallet_stacker",
            Self::ReachTruck => "reach_truck",
        }
    }

    /// One line for people: what steers, what drives, which way the forks face.
    pub fn describe(&self) -> &'static str {
        match self {
            Self::Counterbalance => {
                "counterbalance: fixed front axle drives, rear wheels steer, forks leading"
            }
            Self::PalletStacker => {
                "pallet stacker: one steered drive wheel, load wheels under the forks, forks trailing (enters the pallet in reverse)"
            }
            Self::ReachTruck => {
                "reach truck: one steered drive wheel, load wheels in the outriggers, mast reached out, forks trailing (enters the pallet in reverse)"
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn planners_take_a_finite_lock_only_where_the_wheel_reaches_90_degrees() {
        let right = std::f64::consts::FRAC_PI_2;
        assert_eq!(TruckLayout::Counterbalance.planning_lock_rad(1.2), 1.2);
        assert_eq!(
            TruckLayout::PalletStacker.planning_lock_rad(right),
            STEERED_DRIVE_PLANNING_LOCK_RAD
        );
        assert_eq!(TruckLayout::ReachTruck.planning_lock_rad(1.0), 1.0);
        let t: TruckLayout = toml::from_str::<std::collections::BTreeMap<String, TruckLayout>>(
            "l = \"reach_truck\"",
        )
        .expect("parses")["l"];
        assert_eq!(t, TruckLayout::ReachTruck);
        for l in TruckLayout::ALL {
            assert_eq!(TruckLayout::from_code(l.code()), Some(l));
            assert_eq!(TruckLayout::from_key(l.key()), Some(l));
        }
        assert_eq!(TruckLayout::from_code(0.5), None);
    }
}
