//! Oriented-rectangle overlap (separating axes) for rejecting impossible layouts before simulating.

use forkbench_core::Pose2;

/// A rectangle with its centre pose and full side lengths.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rect {
    pub centre: Pose2,
    pub length_m: f64,
    pub width_m: f64,
}

impl Rect {
    fn corners(&self) -> [[f64; 2]; 4] {
        let (s, c) = self.centre.heading_rad.sin_cos();
        let (hl, hw) = (self.length_m / 2.0, self.width_m / 2.0);
        [[hl, hw], [-hl, hw], [-hl, -hw], [hl, -hw]].map(|[x, y]| {
            [
                self.centre.x_m + c * x - s * y,
                self.centre.y_m + s * x + c * y,
            ]
        })
    }

    fn axes(&self) -> [[f64; 2]; 2] {
        let (s, c) = self.centre.heading_rad.sin_cos();
        [[c, s], [-s, c]]
    }

    /// True when the interiors overlap by more than `margin_m` along every axis.
    pub fn overlaps(&self, other: &Rect, margin_m: f64) -> bool {
        let (a, b) = (self.corners(), other.corners());
        for axis in self.axes().into_iter().chain(other.axes()) {
            let proj = |pts: &[[f64; 2]; 4]| {
                pts.iter()
                    .map(|p| p[0] * axis[0] + p[1] * axis[1])
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                        (lo.min(v), hi.max(v))
                    })
            };
            let (a0, a1) = proj(&a);
            let (b0, b1) = proj(&b);
            if a1 - margin_m <= b0 || b1 - margin_m <= a0 {
                return false;
            }
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overlap_of_rotated_rectangles() {
        let a = Rect {
            centre: Pose2::new(0.0, 0.0, 0.0),
            length_m: 2.0,
            width_m: 1.0,
        };
        let b = Rect {
            centre: Pose2::new(1.5, 0.0, 0.5),
            length_m: 1.0,
            width_m: 1.0,
        };
        let c = Rect {
            centre: Pose2::new(3.0, 0.0, 0.0),
            length_m: 1.0,
            width_m: 1.0,
        };
        assert!(a.overlaps(&b, 0.0));
        assert!(!a.overlaps(&c, 0.0));
        // Diagonal near miss: the axis-aligned extents overlap, but the rotated box's own
        // axis separates them (projections 1.06 vs 1.27).
        let d = Rect {
            centre: Pose2::new(1.5, 1.0, std::f64::consts::FRAC_PI_4),
            length_m: 1.0,
            width_m: 1.0,
        };
        assert!(!a.overlaps(&d, 0.0));
        let e = Rect {
            centre: Pose2::new(1.3, 0.8, std::f64::consts::FRAC_PI_4),
            length_m: 1.0,
            width_m: 1.0,
        };
        assert!(a.overlaps(&e, 0.0));
    }
}
