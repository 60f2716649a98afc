//! Pallet geometry in the scan plane: solid parts (stringers or blocks) with two fork pockets.

mod library;
mod model;

use serde::{Deserialize, Serialize};

use crate::Pose2;

pub use library::{PALLET_KINDS, PalletBuild, PalletKind};
pub use model::{PalletFace, PalletModel, PalletNotch};

/// One solid part of a pallet where the scan plane cuts it (a stringer, a block, or a
/// piece of a notched stringer): a box in the face frame, x from the entry face into the
/// pallet, y across it (left positive).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PalletBlock {
    /// Centre, from the entry face into the pallet.
    pub x_m: f64,
    /// Centre, across the pallet.
    pub y_m: f64,
    /// Extent along the fork direction.
    pub length_m: f64,
    /// Extent across the forks.
    pub width_m: f64,
}

impl PalletBlock {
    /// The box's extent along the fork direction, `[front, back]`.
    pub fn x_range(&self) -> [f64; 2] {
        [
            self.x_m - self.length_m / 2.0,
            self.x_m + self.length_m / 2.0,
        ]
    }

    /// The box's extent across the forks, `[right, left]`.
    pub fn y_range(&self) -> [f64; 2] {
        [self.y_m - self.width_m / 2.0, self.y_m + self.width_m / 2.0]
    }
}

/// A pallet as the truck meets it, entered from one face: its footprint, its two fork
/// pockets and the solid parts around them.
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
    /// The solid parts in the scan plane; none: three equal stringers the full depth,
    /// spaced by the pockets.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub blocks: Vec<PalletBlock>,
    /// Height of the pocket opening the forks enter, when known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pocket_height_m: Option<f64>,
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

impl PalletSpec {
    /// The field-test pallet: 1.2 × 1.2 m with 0.405 m pockets.
    pub fn field_1200() -> Self {
        Self::stringers(1.2, 1.2, 0.405, 25.0)
    }

    /// The simulation pallet of the papers: 1.0 × 1.0 m (pockets 0.35 m).
    pub fn sim_1000() -> Self {
        Self::stringers(1.0, 1.0, 0.35, 20.0)
    }

    fn stringers(depth_m: f64, width_m: f64, pocket_width_m: f64, mass_kg: f64) -> Self {
        Self {
            depth_m,
            width_m,
            pocket_width_m,
            mass_kg,
            payload_kg: 0.0,
            blocks: Vec::new(),
            pocket_height_m: None,
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

    /// Width of a stringer of the three-stringer layout.
    fn stringer_width_m(&self) -> f64 {
        (self.width_m - 2.0 * self.pocket_width_m) / 3.0
    }

    /// Lateral offset of the pocket centres from the pallet axis (the pockets are
    /// mirror images).
    fn pocket_centre_m(&self) -> f64 {
        if self.blocks.is_empty() {
            self.stringer_width_m() / 2.0 + self.pocket_width_m / 2.0
        } else {
            // The left pocket: the gap between the centre part and the left edge part.
            channels(&self.blocks, self.width_m)
                .last()
                .map_or(0.0, |[lo, hi]| (lo + hi) / 2.0)
        }
    }

    /// Lateral offsets of the two pocket centres from the pallet axis.
    pub fn pocket_offsets_m(&self) -> [f64; 2] {
        let o = self.pocket_centre_m();
        [o, -o]
    }

    /// The solid parts in the scan plane, in the face frame.
    pub fn parts(&self) -> Vec<PalletBlock> {
        if !self.blocks.is_empty() {
            return self.blocks.clone();
        }
        let sw = self.stringer_width_m();
        let o = (self.width_m - sw) / 2.0;
        [-o, 0.0, o]
            .map(|y| PalletBlock {
                x_m: self.depth_m / 2.0,
                y_m: y,
                length_m: self.depth_m,
                width_m: sw,
            })
            .to_vec()
    }

    /// Each solid part as a box in the world: (centre pose, length along the pallet's
    /// heading, width) for a pallet whose face centre is at `face`.
    pub fn part_boxes(&self, face: &Pose2) -> Vec<(Pose2, f64, f64)> {
        self.parts()
            .iter()
            .map(|b| {
                let c = face.to_world(&Pose2::new(b.x_m, b.y_m, 0.0));
                (c, b.length_m, b.width_m)
            })
            .collect()
    }

    /// Closed outlines of the solid parts for a pallet whose face centre is at `face`.
    pub fn outlines(&self, face: &Pose2) -> Vec<[[f64; 2]; 5]> {
        self.part_boxes(face)
            .iter()
            .map(|(c, l, w)| crate::geometry::rect_outline(c, *l, *w))
            .collect()
    }

    /// The three parts across the entry face, right to left, as (centre, width) across
    /// it: a stringer pallet's stringers as built, or the material between a block
    /// pallet's pockets.
    fn face_parts(&self) -> [(f64, f64); 3] {
        if self.blocks.is_empty() {
            let sw = self.stringer_width_m();
            let o = (self.width_m - sw) / 2.0;
            return [(-o, sw), (0.0, sw), (o, sw)];
        }
        let (h, o, p) = (
            self.width_m / 2.0,
            self.pocket_centre_m(),
            self.pocket_width_m / 2.0,
        );
        [[-h, -o - p], [-(o - p), o - p], [o + p, h]].map(|[lo, hi]| ((lo + hi) / 2.0, hi - lo))
    }

    /// The material across the entry face, as lateral intervals `[right, left]`: the right
    /// edge part, the centre part and the left edge part around the two pockets.
    pub fn face_solids(&self) -> [[f64; 2]; 3] {
        self.face_parts().map(|(c, w)| [c - w / 2.0, c + w / 2.0])
    }

    /// The face's two edge parts: their width, and their centres' offset from the axis.
    pub fn edge_part_m(&self) -> (f64, f64) {
        let (c, w) = self.face_parts()[2];
        (w, c)
    }

    /// The face parts' centres across the face, right to left.
    pub fn face_part_centres_m(&self) -> [f64; 3] {
        self.face_parts().map(|(c, _)| c)
    }

    /// Width of the face's centre part.
    pub fn centre_part_width_m(&self) -> f64 {
        self.face_parts()[1].1
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
        if self.blocks.is_empty() && self.stringer_width_m() <= 0.01 {
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

/// The lateral gaps `[right, left]` that run the whole depth free of every part, from
/// right to left: where forks can go in.
pub(crate) fn channels(blocks: &[PalletBlock], width_m: f64) -> Vec<[f64; 2]> {
    let mut spans: Vec<[f64; 2]> = blocks.iter().map(PalletBlock::y_range).collect();
    spans.sort_by(|a, b| a[0].total_cmp(&b[0]));
    let mut gaps = Vec::new();
    let mut covered = -width_m / 2.0;
    for [lo, hi] in spans {
        if lo > covered + 1e-9 {
            gaps.push([covered, lo]);
        }
        covered = covered.max(hi);
    }
    if covered < width_m / 2.0 - 1e-9 {
        gaps.push([covered, width_m / 2.0]);
    }
    gaps
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

    #[test]
    fn stringer_parts_are_the_face_solids_the_full_depth() {
        let p = PalletSpec::field_1200();
        let parts = p.parts();
        assert_eq!(parts.len(), 3);
        for (b, s) in parts.iter().zip(p.face_solids()) {
            assert!((b.y_range()[0] - s[0]).abs() < 1e-12 && (b.y_range()[1] - s[1]).abs() < 1e-12);
            assert_eq!(b.x_range(), [0.0, 1.2]);
        }
        assert_eq!(channels(&parts, p.width_m).len(), 2);
    }
}
