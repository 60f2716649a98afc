//! Rectangles by centre pose and size: the one place their corners are computed.

use serde::{Deserialize, Serialize};

use crate::Pose2;

/// A fixed rectangle (rack upright, rack bay, wall) in the world frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Obstacle {
    pub centre: Pose2,
    pub length_m: f64,
    pub width_m: f64,
}

impl Obstacle {
    /// Its four corners, counter-clockwise from front left.
    pub fn corners(&self) -> [[f64; 2]; 4] {
        rect_corners(&self.centre, self.length_m, self.width_m)
    }

    /// How far `p` lies inside the rectangle: positive inside (the distance to the
    /// nearest side), 0 on a side, negative outside.
    pub fn depth_inside(&self, p: [f64; 2]) -> f64 {
        let l = self.centre.to_local(&Pose2::new(p[0], p[1], 0.0));
        (self.length_m / 2.0 - l.x_m.abs()).min(self.width_m / 2.0 - l.y_m.abs())
    }
}

/// Corners of a `length_m` × `width_m` rectangle centred on `centre` (length along its
/// heading), counter-clockwise from front left.
pub fn rect_corners(centre: &Pose2, length_m: f64, width_m: f64) -> [[f64; 2]; 4] {
    let (s, c) = centre.heading_rad.sin_cos();
    let (hl, hw) = (length_m / 2.0, width_m / 2.0);
    [[hl, hw], [-hl, hw], [-hl, -hw], [hl, -hw]]
        .map(|[x, y]| [centre.x_m + c * x - s * y, centre.y_m + s * x + c * y])
}

/// [`rect_corners`] with the first corner repeated at the end: a closed outline to draw.
pub fn rect_outline(centre: &Pose2, length_m: f64, width_m: f64) -> [[f64; 2]; 5] {
    let c = rect_corners(centre, length_m, width_m);
    [c[0], c[1], c[2], c[3], c[0]]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn corners_turn_with_the_heading() {
        let c = rect_corners(&Pose2::new(1.0, 2.0, std::f64::consts::FRAC_PI_2), 4.0, 2.0);
        let want = [[0.0, 4.0], [0.0, 0.0], [2.0, 0.0], [2.0, 4.0]];
        for (a, b) in c.iter().zip(want) {
            assert!(
                (a[0] - b[0]).abs() < 1e-12 && (a[1] - b[1]).abs() < 1e-12,
                "{c:?}"
            );
        }
    }

    #[test]
    fn depth_inside_is_positive_inside_zero_on_a_side_negative_outside() {
        // 4 m along y (the heading), 2 m across: x spans 0..2, y 0..4.
        let o = Obstacle {
            centre: Pose2::new(1.0, 2.0, std::f64::consts::FRAC_PI_2),
            length_m: 4.0,
            width_m: 2.0,
        };
        assert!((o.depth_inside([1.0, 2.0]) - 1.0).abs() < 1e-12);
        assert!(o.depth_inside([2.0, 2.0]).abs() < 1e-12);
        assert!((o.depth_inside([3.0, 2.0]) + 1.0).abs() < 1e-12);
        assert!((o.depth_inside([1.0, 3.5]) - 0.5).abs() < 1e-12);
    }
}
