//! Pallet geometry: three stringers with two open fork pockets between them.

use serde::{Deserialize, Serialize};

use crate::Pose2;

/// A two-pocket pallet seen from above at fork height: three stringers along its depth.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PalletSpec {
    /// Extent along the fork direction.
    pub depth_m: f64,
    /// Extent across the forks.
    pub width_m: f64,
    /// Width of each fork pocket.
    pub pocket_width_m: f64,
    /// The empty pallet's own mass.
    pub mass_kg: f64,
    /// The goods stacked on it: they ride with it when it is lifted, load the truck's
    /// axles, and press it on the floor.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub payload_kg: f64,
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

impl PalletSpec {
    /// The field-test pallet: 1.2 × 1.2 m with 0.405 m pockets.
    pub fn field_1200() -> Self {
        Self {
            depth_m: 1.2,
            width_m: 1.2,
            pocket_width_m: 0.405,
            mass_kg: 25.0,
            payload_kg: 0.0,
        }
    }

    /// The simulation pallet of the papers: 1.0 × 1.0 m (pockets 0.35 m).
    pub fn sim_1000() -> Self {
        Self {
            depth_m: 1.0,
            width_m: 1.0,
            pocket_width_m: 0.35,
            mass_kg: 20.0,
            payload_kg: 0.0,
        }
    }

    /// The pallet's mass with its payload: what the floor, the forks and the truck carry.
    pub fn loaded_mass_kg(&self) -> f64 {
        self.mass_kg + self.payload_kg
    }

    /// The same pallet carrying `payload_kg` of goods.
    pub fn with_payload(mut self, payload_kg: f64) -> Self {
        self.payload_kg = payload_kg;
        self
    }

    pub fn stringer_width_m(&self) -> f64 {
        (self.width_m - 2.0 * self.pocket_width_m) / 3.0
    }

    /// Lateral offsets of the stringer centres from the pallet axis.
    pub fn stringer_offsets_m(&self) -> [f64; 3] {
        let o = (self.width_m - self.stringer_width_m()) / 2.0;
        [-o, 0.0, o]
    }

    /// Lateral offsets of the two pocket centres from the pallet axis.
    pub fn pocket_offsets_m(&self) -> [f64; 2] {
        let o = self.stringer_width_m() / 2.0 + self.pocket_width_m / 2.0;
        [o, -o]
    }

    /// Centre poses of the three stringers for a pallet whose face centre is at `face`.
    pub fn stringer_centres(&self, face: &Pose2) -> [Pose2; 3] {
        self.stringer_offsets_m()
            .map(|y| face.to_world(&Pose2::new(self.depth_m / 2.0, y, 0.0)))
    }

    pub fn validate(&self) -> Result<(), crate::SettingsError> {
        for (f, v) in [
            ("depth_m", self.depth_m),
            ("width_m", self.width_m),
            ("pocket_width_m", self.pocket_width_m),
            ("mass_kg", self.mass_kg),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(crate::SettingsError::field(
                    f,
                    format!("must be a positive finite number (got {v})"),
                ));
            }
        }
        if !(self.payload_kg.is_finite() && self.payload_kg >= 0.0) {
            return Err(crate::SettingsError::field(
                "payload_kg",
                format!("must be a finite mass ≥ 0 (got {})", self.payload_kg),
            ));
        }
        if self.stringer_width_m() <= 0.01 {
            return Err(crate::SettingsError::field(
                "pocket_width_m",
                format!(
                    "two pockets of {} m leave no room for stringers in a {} m wide pallet",
                    self.pocket_width_m, self.width_m
                ),
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn field_pallet_pockets_fit_a_015_m_fork_with_01275_m_clearance() {
        let p = PalletSpec::field_1200();
        assert!((p.stringer_width_m() - 0.13).abs() < 1e-12);
        let [a, b] = p.pocket_offsets_m();
        assert!((a - 0.2675).abs() < 1e-12 && (b + 0.2675).abs() < 1e-12);
        assert!(((p.pocket_width_m - 0.15) / 2.0 - 0.1275).abs() < 1e-12);
    }
}
