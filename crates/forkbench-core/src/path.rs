//! Dense path samples (s, x, y, heading, curvature) and the metrics every planner reports.

use serde::{Deserialize, Serialize};

use crate::pose::Pose2;
use crate::units::wrap_angle;
use crate::vehicle::ForkliftSpec;

/// One sample along a planned path.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PathSample {
    pub s_m: f64,
    pub x_m: f64,
    pub y_m: f64,
    pub heading_rad: f64,
    pub curvature_per_m: f64,
}

impl PathSample {
    pub fn pose(&self) -> Pose2 {
        Pose2::new(self.x_m, self.y_m, self.heading_rad)
    }
}

/// A path as dense samples ordered by arc length travelled. Headings are the truck's (the
/// forks' direction) and positions the fork root's.
///
/// A `reverse` path is driven backwards: the truck travels against its heading. Its
/// curvature is the steering curvature (heading change per metre of signed displacement),
/// so the same κ gives the same steering angle in either direction.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Path {
    pub samples: Vec<PathSample>,
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub reverse: bool,
}

/// Summary figures of a path against the pose it was meant to reach.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PathMetrics {
    pub length_m: f64,
    pub max_abs_curvature_per_m: f64,
    /// Equivalent steering angle arctan(L |κ|max) for the given truck.
    pub max_steer_rad: f64,
    /// Largest curvature change between neighbouring samples (continuity check).
    pub max_curvature_jump_per_m: f64,
    /// Largest spacing between neighbouring samples.
    pub max_sample_spacing_m: f64,
    pub start_position_error_m: f64,
    pub start_heading_error_rad: f64,
    pub endpoint_position_error_m: f64,
    pub endpoint_heading_error_rad: f64,
}

impl Path {
    /// A forward path.
    pub fn new(samples: Vec<PathSample>) -> Self {
        Self {
            samples,
            reverse: false,
        }
    }

    /// The same track driven the other way: a forward path from B to A becomes the
    /// reverse path from A to B (same poses, order and arc length reversed).
    pub fn driven_backwards(&self) -> Path {
        let len = self.length_m();
        let samples = self
            .samples
            .iter()
            .rev()
            .map(|p| PathSample {
                s_m: len - p.s_m,
                ..*p
            })
            .collect();
        Path {
            samples,
            reverse: !self.reverse,
        }
    }

    pub fn length_m(&self) -> f64 {
        self.samples.last().map_or(0.0, |p| p.s_m)
    }

    pub fn is_finite(&self) -> bool {
        self.samples.iter().all(|p| {
            p.s_m.is_finite()
                && p.x_m.is_finite()
                && p.y_m.is_finite()
                && p.heading_rad.is_finite()
                && p.curvature_per_m.is_finite()
        })
    }

    /// A straight path of `length_m` from `start` along its heading, samples at most
    /// `spacing_m` apart.
    pub fn straight(start: &Pose2, length_m: f64, spacing_m: f64) -> Path {
        let mut p = Path::new(vec![PathSample {
            s_m: 0.0,
            x_m: start.x_m,
            y_m: start.y_m,
            heading_rad: start.heading_rad,
            curvature_per_m: 0.0,
        }]);
        p.extend_straight(length_m, spacing_m);
        p
    }

    /// Appends a straight segment of `length_m` along the last sample's heading, with
    /// samples at most `spacing_m` apart (e.g. the fork insertion after an approach curve).
    pub fn extend_straight(&mut self, length_m: f64, spacing_m: f64) {
        let Some(last) = self.samples.last().copied() else {
            return;
        };
        if !(length_m > 0.0 && spacing_m > 0.0) {
            return;
        }
        let n = (length_m / spacing_m).ceil() as usize;
        let (s, c) = last.heading_rad.sin_cos();
        for i in 1..=n {
            let d = length_m * i as f64 / n as f64;
            self.samples.push(PathSample {
                s_m: last.s_m + d,
                x_m: last.x_m + c * d,
                y_m: last.y_m + s * d,
                heading_rad: last.heading_rad,
                curvature_per_m: 0.0,
            });
        }
    }

    /// Measures the path against the start and goal poses it was planned for.
    pub fn metrics(&self, start: &Pose2, goal: &Pose2, truck: &ForkliftSpec) -> PathMetrics {
        let first = self.samples.first().map_or(*start, PathSample::pose);
        let last = self.samples.last().map_or(*start, PathSample::pose);
        let max_k = self
            .samples
            .iter()
            .map(|p| p.curvature_per_m.abs())
            .fold(0.0, f64::max);
        let (mut jump, mut spacing) = (0.0_f64, 0.0_f64);
        for w in self.samples.windows(2) {
            jump = jump.max((w[1].curvature_per_m - w[0].curvature_per_m).abs());
            spacing = spacing.max((w[1].x_m - w[0].x_m).hypot(w[1].y_m - w[0].y_m));
        }
        PathMetrics {
            length_m: self.length_m(),
            max_abs_curvature_per_m: max_k,
            max_steer_rad: truck.steer_for_curvature(max_k),
            max_curvature_jump_per_m: jump,
            max_sample_spacing_m: spacing,
            start_position_error_m: first.distance_to(start),
            start_heading_error_rad: wrap_angle(first.heading_rad - start.heading_rad).abs(),
            endpoint_position_error_m: last.distance_to(goal),
            endpoint_heading_error_rad: wrap_angle(last.heading_rad - goal.heading_rad).abs(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extend_straight_appends_along_the_heading() {
        let mut p = Path::new(vec![PathSample {
            s_m: 0.0,
            x_m: 1.0,
            y_m: 1.0,
            heading_rad: std::f64::consts::FRAC_PI_2,
            curvature_per_m: 0.3,
        }]);
        p.extend_straight(0.5, 0.01);
        let last = p.samples.last().expect("samples");
        assert_eq!(p.samples.len(), 51);
        assert!((last.x_m - 1.0).abs() < 1e-12 && (last.y_m - 1.5).abs() < 1e-12);
        assert!((last.s_m - 0.5).abs() < 1e-12 && last.curvature_per_m == 0.0);
    }

    #[test]
    fn metrics_of_a_straight_line() {
        let samples = (0..=100)
            .map(|i| {
                let s = i as f64 * 0.01;
                PathSample {
                    s_m: s,
                    x_m: s,
                    y_m: 0.0,
                    heading_rad: 0.0,
                    curvature_per_m: 0.0,
                }
            })
            .collect();
        let path = Path::new(samples);
        let m = path.metrics(
            &Pose2::new(0.0, 0.0, 0.0),
            &Pose2::new(1.0, 0.1, 0.0),
            &ForkliftSpec::default(),
        );
        assert!((m.length_m - 1.0).abs() < 1e-12);
        assert_eq!(m.max_abs_curvature_per_m, 0.0);
        assert!((m.endpoint_position_error_m - 0.1).abs() < 1e-12);
        assert!((m.max_sample_spacing_m - 0.01).abs() < 1e-12);
    }
}
