//! Planar poses (x, y, heading) in SI units and their frame transforms.

use serde::{Deserialize, Serialize};

use crate::units::{deg_to_rad, wrap_angle};

/// A planar pose: position in metres, heading in radians (counter-clockwise from +x).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Pose2 {
    pub x_m: f64,
    pub y_m: f64,
    pub heading_rad: f64,
}

/// Why a pose given as text could not be read.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PoseParseError {
    #[error("expected three comma-separated numbers `x_m,y_m,heading_deg`, got {0:?}")]
    Shape(String),
    #[error("`{field}` is not a number: {text:?}")]
    NotANumber { field: &'static str, text: String },
    #[error("`{field}` must be finite, got {value}")]
    NotFinite { field: &'static str, value: f64 },
}

impl Pose2 {
    pub const fn new(x_m: f64, y_m: f64, heading_rad: f64) -> Self {
        Self {
            x_m,
            y_m,
            heading_rad,
        }
    }

    /// Parses the user-interface form `x_m,y_m,heading_deg` (heading in degrees).
    pub fn parse_ui(text: &str) -> Result<Self, PoseParseError> {
        let parts: Vec<&str> = text.split(',').map(str::trim).collect();
        if parts.len() != 3 {
            return Err(PoseParseError::Shape(text.to_owned()));
        }
        let names = ["x_m", "y_m", "heading_deg"];
        let mut v = [0.0; 3];
        for ((slot, part), field) in v.iter_mut().zip(&parts).zip(names) {
            let value: f64 = part.parse().map_err(|_| PoseParseError::NotANumber {
                field,
                text: (*part).to_owned(),
            })?;
            if !value.is_finite() {
                return Err(PoseParseError::NotFinite { field, value });
            }
            *slot = value;
        }
        Ok(Self::new(v[0], v[1], deg_to_rad(v[2])))
    }

    pub fn is_finite(&self) -> bool {
        self.x_m.is_finite() && self.y_m.is_finite() && self.heading_rad.is_finite()
    }

    /// Unit vector of the heading.
    pub fn direction(&self) -> [f64; 2] {
        [self.heading_rad.cos(), self.heading_rad.sin()]
    }

    /// Expresses `other` (given in the world frame) in this pose's frame.
    pub fn to_local(&self, other: &Pose2) -> Pose2 {
        let (s, c) = self.heading_rad.sin_cos();
        let dx = other.x_m - self.x_m;
        let dy = other.y_m - self.y_m;
        Pose2::new(
            c * dx + s * dy,
            -s * dx + c * dy,
            wrap_angle(other.heading_rad - self.heading_rad),
        )
    }

    /// Maps `local` (given in this pose's frame) into the world frame.
    pub fn to_world(&self, local: &Pose2) -> Pose2 {
        let (s, c) = self.heading_rad.sin_cos();
        Pose2::new(
            self.x_m + c * local.x_m - s * local.y_m,
            self.y_m + s * local.x_m + c * local.y_m,
            wrap_angle(self.heading_rad + local.heading_rad),
        )
    }

    /// Euclidean distance between the positions of two poses.
    pub fn distance_to(&self, other: &Pose2) -> f64 {
        (other.x_m - self.x_m).hypot(other.y_m - self.y_m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parse_ui_reads_degrees() {
        let p = Pose2::parse_ui("1.5, -2, 90").expect("valid pose");
        assert_eq!(p.x_m, 1.5);
        assert_eq!(p.y_m, -2.0);
        assert!((p.heading_rad - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
    }

    #[test]
    fn parse_ui_rejects_bad_text() {
        assert!(matches!(
            Pose2::parse_ui("1,2"),
            Err(PoseParseError::Shape(_))
        ));
        assert!(matches!(
            Pose2::parse_ui("1,x,3"),
            Err(PoseParseError::NotANumber { field: "y_m", .. })
        ));
        assert!(matches!(
            Pose2::parse_ui("1,2,inf"),
            Err(PoseParseError::NotFinite {
                field: "heading_deg",
                ..
            })
        ));
    }

    #[test]
    fn local_world_round_trip() {
        let a = Pose2::new(1.0, 2.0, 0.7);
        let b = Pose2::new(-3.0, 0.5, -2.9);
        let back = a.to_world(&a.to_local(&b));
        assert!((back.x_m - b.x_m).abs() < 1e-12);
        assert!((back.y_m - b.y_m).abs() < 1e-12);
        assert!((back.heading_rad - b.heading_rad).abs() < 1e-12);
    }
}
