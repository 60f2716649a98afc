//! Clutter in a world file: what a warehouse leaves in a scanner's view (rack uprights, boxes, wrapped loads, a standing person's legs, a pallet at any angle, walls, another truck's forks), each a set of fixed rectangles.

use forkbench_core::{PalletSpec, Pose2};
use serde::{Deserialize, Serialize};

use super::invalid;
use crate::ScenarioError;
use crate::pose_deg::PoseDeg;

/// The kinds, and the size each takes unless the file gives `length_m` and `width_m`.
pub const CLUTTER_KINDS: [&str; 7] = [
    "upright",
    "box",
    "wrapped_load",
    "person",
    "pallet",
    "wall",
    "forks",
];

/// Most clutter items a world may hold (each adds a few rectangles to every scan's and
/// every collision check's work).
pub const MAX_CLUTTER: usize = 4096;

/// One item: a kind at a pose (its centre; for a pallet, the face centre, heading into
/// it), with an optional size.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClutterFile {
    pub kind: String,
    #[serde(default)]
    pub name: String,
    pub x_m: f64,
    pub y_m: f64,
    #[serde(default)]
    pub heading_deg: f64,
    /// Along the heading and across it; the kind's own when absent (a box 0.6 × 0.6 m, a
    /// wrapped load 1.2 × 0.8 m, an upright 0.1 × 0.1 m, a wall 3 × 0.2 m). Not for a
    /// person, a pallet or forks, whose parts are fixed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub length_m: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub width_m: Option<f64>,
}

impl ClutterFile {
    fn pose(&self) -> Pose2 {
        Pose2::new(self.x_m, self.y_m, self.heading_deg.to_radians())
    }

    /// Its rectangles: (centre, length along the heading, width).
    pub fn rects(&self) -> Vec<(Pose2, f64, f64)> {
        let p = self.pose();
        let at = |x: f64, y: f64| p.to_world(&Pose2::new(x, y, 0.0));
        let sized =
            |l: f64, w: f64| vec![(p, self.length_m.unwrap_or(l), self.width_m.unwrap_or(w))];
        match self.kind.as_str() {
            "upright" => sized(0.1, 0.1),
            "box" => sized(0.6, 0.6),
            "wrapped_load" => sized(1.2, 0.8),
            "wall" => sized(3.0, 0.2),
            // Two legs 0.25 m apart, each 0.12 m across.
            "person" => [-0.125, 0.125]
                .iter()
                .map(|y| (at(0.0, *y), 0.12, 0.12))
                .collect(),
            // Two tines 1.15 m long, 0.12 m wide, 0.6 m apart, the heading along them.
            "forks" => [-0.3, 0.3]
                .iter()
                .map(|y| (at(0.0, *y), 1.15, 0.12))
                .collect(),
            // The field pallet's parts, its face at the pose.
            _ => PalletSpec::field_1200().part_boxes(&p),
        }
    }

    /// Kind known, pose within the world, sizes positive and at most 100 m, given only
    /// where the kind takes one.
    pub fn check(&self, file: &str, field: &str) -> Result<(), ScenarioError> {
        if !CLUTTER_KINDS.contains(&self.kind.as_str()) {
            return Err(invalid(
                file,
                &format!("{field}.kind"),
                &format!(
                    "{:?} is not a clutter kind ({})",
                    self.kind,
                    CLUTTER_KINDS.join(", ")
                ),
            ));
        }
        PoseDeg {
            x_m: self.x_m,
            y_m: self.y_m,
            heading_deg: self.heading_deg,
        }
        .check(file, field)?;
        let fixed = matches!(self.kind.as_str(), "person" | "pallet" | "forks");
        for (name, v) in [("length_m", self.length_m), ("width_m", self.width_m)] {
            let Some(v) = v else { continue };
            if fixed {
                return Err(invalid(
                    file,
                    &format!("{field}.{name}"),
                    &format!("a {} has a fixed size", self.kind),
                ));
            }
            if !(v.is_finite() && v > 0.0 && v <= 100.0) {
                return Err(invalid(
                    file,
                    &format!("{field}.{name}"),
                    "must be a positive length of at most 100 m",
                ));
            }
        }
        Ok(())
    }
}
