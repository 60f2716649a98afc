//! Footprint collision checking with parry2d: a rectangular body at a pose against fixed obstacles.

use forkbench_core::{Path, Pose2};
use parry2d::math::{Pose, Vector};
use parry2d::query::{distance, intersection_test};
use parry2d::shape::{ConvexPolygon, Cuboid, Shape};

mod buckets;
use buckets::{Bounds, Buckets};

/// A rectangular vehicle body, placed relative to the vehicle's reference point (the
/// point whose pose the planner or controller reports).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Footprint {
    pub length_m: f64,
    pub width_m: f64,
    /// How far the rectangle's centre lies ahead of the reference point, along the heading.
    pub centre_ahead_m: f64,
}

impl Footprint {
    /// A rectangle centred on the reference point.
    pub fn centred(length_m: f64, width_m: f64) -> Self {
        Self {
            length_m,
            width_m,
            centre_ahead_m: 0.0,
        }
    }

    /// The rectangle's centre pose for a reference pose.
    pub fn centre(&self, reference: &Pose2) -> Pose2 {
        reference.to_world(&Pose2::new(self.centre_ahead_m, 0.0, 0.0))
    }

    fn cuboid(&self) -> Cuboid {
        Cuboid::new(Vector::new(
            (self.length_m / 2.0) as f32,
            (self.width_m / 2.0) as f32,
        ))
    }

    /// The four corners (world frame) for a reference pose, counter-clockwise from front left.
    pub fn corners(&self, reference: &Pose2) -> [[f64; 2]; 4] {
        forkbench_core::geometry::rect_corners(&self.centre(reference), self.length_m, self.width_m)
    }
}

/// Fixed rectangular obstacles (racks, walls). Each keeps its axis-aligned bounds in a
/// uniform grid of buckets, so a query tests only the shapes near it (a SLAM map's cell
/// runs give tens of thousands of shapes).
#[derive(Default)]
pub struct Obstacles {
    shapes: Vec<(Pose, Box<dyn Shape>)>,
    bounds: Vec<Bounds>,
    buckets: Buckets,
}

fn bounds_of(points: &[[f64; 2]]) -> Bounds {
    points.iter().fold(
        [
            f64::INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
        ],
        |b, p| {
            [
                b[0].min(p[0]),
                b[1].min(p[1]),
                b[2].max(p[0]),
                b[3].max(p[1]),
            ]
        },
    )
}

/// Distance between two bounds (0 when they overlap): a lower bound of the shapes'.
fn bounds_gap(a: &Bounds, b: &Bounds) -> f64 {
    let [dx, dy] = bounds_gap_xy(a, b);
    dx.hypot(dy)
}

/// The gap between two bounds along x and along y (0 where they overlap).
fn bounds_gap_xy(a: &Bounds, b: &Bounds) -> [f64; 2] {
    [
        (a[0] - b[2]).max(b[0] - a[2]).max(0.0),
        (a[1] - b[3]).max(b[1] - a[3]).max(0.0),
    ]
}

/// A footprint as an oriented rectangle, for a cheap test that an obstacle's bounds lie
/// wholly beside it before the exact one.
struct Oriented {
    centre: [f64; 2],
    axes: [[f64; 2]; 2],
    half: [f64; 2],
}

/// How far apart a separation must be for [`Oriented::clear_of`] to trust it: far more
/// than the exact test's single-precision rounding, so the exact test decides every
/// near-touch.
const CLEAR_SLACK_M: f64 = 1e-3;

impl Oriented {
    fn of(fp: &Footprint, centre: &Pose2) -> Self {
        let (s, c) = centre.heading_rad.sin_cos();
        Self {
            centre: [centre.x_m, centre.y_m],
            axes: [[c, s], [-s, c]],
            half: [fp.length_m / 2.0, fp.width_m / 2.0],
        }
    }

    /// Whether `b` lies beyond one of the rectangle's own sides by more than the slack
    /// (the axis-aligned sides are the bounds test's).
    fn clear_of(&self, b: &Bounds) -> bool {
        let (cx, cy) = ((b[0] + b[2]) / 2.0, (b[1] + b[3]) / 2.0);
        let (hx, hy) = ((b[2] - b[0]) / 2.0, (b[3] - b[1]) / 2.0);
        let d = [cx - self.centre[0], cy - self.centre[1]];
        self.axes.iter().zip(self.half).any(|(a, h)| {
            let gap = (d[0] * a[0] + d[1] * a[1]).abs();
            let reach = h + hx * a[0].abs() + hy * a[1].abs();
            gap > reach + CLEAR_SLACK_M
        })
    }
}

impl std::fmt::Debug for Obstacles {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Obstacles({})", self.shapes.len())
    }
}

/// Where a path first hits an obstacle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Arc length along the path.
    pub s_m: f64,
    /// Index of the obstacle hit, in insertion order.
    pub obstacle: usize,
}

fn pose(p: &Pose2) -> Pose {
    Pose::new(
        Vector::new(p.x_m as f32, p.y_m as f32),
        p.heading_rad as f32,
    )
}

impl Obstacles {
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a rectangle given by its centre pose and full side lengths.
    pub fn add_rect(&mut self, centre: &Pose2, length_m: f64, width_m: f64) {
        let corners = forkbench_core::geometry::rect_corners(centre, length_m, width_m);
        self.register(bounds_of(&corners));
        self.shapes.push((
            pose(centre),
            Box::new(Cuboid::new(Vector::new(
                (length_m / 2.0) as f32,
                (width_m / 2.0) as f32,
            ))),
        ));
    }

    /// Adds a convex polygon given by its vertices (world frame); `false` if degenerate.
    pub fn add_convex(&mut self, points: &[[f64; 2]]) -> bool {
        let pts: Vec<Vector> = points
            .iter()
            .map(|p| Vector::new(p[0] as f32, p[1] as f32))
            .collect();
        match ConvexPolygon::from_convex_hull(&pts) {
            Some(poly) => {
                self.register(bounds_of(points));
                self.shapes
                    .push((Pose::translation(0.0, 0.0), Box::new(poly)));
                true
            }
            None => false,
        }
    }

    /// Files the next shape's bounds into the buckets it overlaps.
    fn register(&mut self, b: Bounds) {
        let i = self.bounds.len();
        self.bounds.push(b);
        self.buckets.register(i, &b);
    }

    /// Shapes near `b` whose bounds lie less than `within_m` from it (touching at 0),
    /// in insertion order, each once: the only ones a query at `b` need test exactly.
    fn candidates(&self, b: &Bounds, within_m: f64) -> Vec<usize> {
        let mut out = Vec::new();
        self.buckets.each_near(b, within_m, |i| {
            let [dx, dy] = bounds_gap_xy(b, &self.bounds[i]);
            // Touching needs no square root; only a positive reach does.
            if (dx == 0.0 && dy == 0.0) || (within_m > 0.0 && dx.hypot(dy) < within_m) {
                out.push(i);
            }
        });
        out.sort_unstable();
        out.dedup();
        out
    }

    /// The first obstacle the footprint at `reference` overlaps (touching counts), if any.
    pub fn hit(&self, fp: &Footprint, reference: &Pose2) -> Option<usize> {
        let body = fp.cuboid();
        let centre = fp.centre(reference);
        let at = pose(&centre);
        let near = bounds_of(&fp.corners(reference));
        let obb = Oriented::of(fp, &centre);
        self.candidates(&near, 0.0).into_iter().find(|&i| {
            if obb.clear_of(&self.bounds[i]) {
                return false;
            }
            let (p, s) = &self.shapes[i];
            // Convex–cuboid pairs are always supported; an unsupported pair would be a bug here.
            intersection_test(&at, &body, p, s.as_ref()).is_ok_and(|r| r.intersecting)
        })
    }

    /// Distance from the footprint at `reference` to the nearest obstacle (0 when they
    /// touch), looking no further than `cap_m`: `cap_m` when nothing is that close.
    pub fn clearance(&self, fp: &Footprint, reference: &Pose2, cap_m: f64) -> f64 {
        let body = fp.cuboid();
        let at = pose(&fp.centre(reference));
        let near = bounds_of(&fp.corners(reference));
        let mut best = cap_m;
        for i in self.candidates(&near, cap_m) {
            let ((p, s), b) = (&self.shapes[i], &self.bounds[i]);
            if bounds_gap(&near, b) >= best {
                continue;
            }
            if let Ok(d) = distance(&at, &body, p, s.as_ref()) {
                best = best.min(f64::from(d.distance));
            }
        }
        best
    }

    /// Whether the footprint at `reference` overlaps any obstacle (touching counts): the
    /// answer [`Obstacles::hit`] gives, without finding which obstacle is first.
    pub fn collides(&self, fp: &Footprint, reference: &Pose2) -> bool {
        let body = fp.cuboid();
        let centre = fp.centre(reference);
        let at = pose(&centre);
        let near = bounds_of(&fp.corners(reference));
        let obb = Oriented::of(fp, &centre);
        let mut found = false;
        self.buckets.each_near(&near, 0.0, |i| {
            if found || bounds_gap_xy(&near, &self.bounds[i]) != [0.0, 0.0] {
                return;
            }
            if obb.clear_of(&self.bounds[i]) {
                return;
            }
            let (p, s) = &self.shapes[i];
            found = intersection_test(&at, &body, p, s.as_ref()).is_ok_and(|r| r.intersecting);
        });
        found
    }

    /// Checks the footprint along a path (its poses are the reference point's) every
    /// `step_m` of arc length and at the end; returns the first hit.
    pub fn first_hit_along(&self, fp: &Footprint, path: &Path, step_m: f64) -> Option<Hit> {
        let mut next_s = f64::NEG_INFINITY;
        let last = path.samples.len().saturating_sub(1);
        for (i, p) in path.samples.iter().enumerate() {
            if p.s_m < next_s && i != last {
                continue;
            }
            next_s = p.s_m + step_m;
            let pose = Pose2::new(p.x_m, p.y_m, p.heading_rad);
            if let Some(obstacle) = self.hit(fp, &pose) {
                return Some(Hit {
                    s_m: p.s_m,
                    obstacle,
                });
            }
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotated_near_miss_and_hit() {
        let mut obs = Obstacles::new();
        obs.add_rect(&Pose2::new(0.0, 0.0, 0.0), 2.0, 1.0);
        let fp = Footprint::centred(1.0, 1.0);
        // Axis-aligned extents overlap, the rotated box's own axis separates them.
        assert!(!obs.collides(&fp, &Pose2::new(1.5, 1.0, std::f64::consts::FRAC_PI_4)));
        assert!(obs.collides(&fp, &Pose2::new(1.5, 0.0, 0.5)));
        // The body sits ahead of the reference point.
        let ahead = Footprint {
            centre_ahead_m: 2.0,
            ..fp
        };
        assert!(obs.collides(&ahead, &Pose2::new(-2.0, 0.0, 0.0)));
        assert!(!obs.collides(&ahead, &Pose2::new(-2.0, 0.0, std::f64::consts::PI)));
    }

    #[test]
    fn collides_agrees_with_the_first_hit() {
        let mut obs = Obstacles::new();
        let mut state = 12345u64;
        let mut draw = |lo: f64, hi: f64| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            lo + (hi - lo) * ((state >> 11) as f64 / (1u64 << 53) as f64)
        };
        for _ in 0..60 {
            let c = Pose2::new(draw(0.0, 40.0), draw(0.0, 40.0), draw(-3.2, 3.2));
            obs.add_rect(&c, draw(0.2, 4.0), draw(0.2, 2.0));
        }
        let (mut hits, mut misses) = (0, 0);
        for _ in 0..4000 {
            let fp = Footprint {
                length_m: draw(0.5, 12.0),
                width_m: draw(0.5, 2.0),
                centre_ahead_m: draw(-3.0, 3.0),
            };
            let at = Pose2::new(draw(-2.0, 42.0), draw(-2.0, 42.0), draw(-3.2, 3.2));
            let hit = obs.hit(&fp, &at).is_some();
            assert_eq!(obs.collides(&fp, &at), hit, "{fp:?} at {at:?}");
            if hit { hits += 1 } else { misses += 1 }
        }
        assert!(hits > 400 && misses > 400, "{hits} hits, {misses} misses");
    }

    #[test]
    fn clearance_is_the_gap_and_capped() {
        let mut obs = Obstacles::new();
        obs.add_rect(&Pose2::new(0.0, 0.0, 0.0), 2.0, 1.0);
        obs.add_convex(&[[10.0, 0.0], [11.0, 0.0], [11.0, 1.0]]);
        let fp = Footprint::centred(1.0, 1.0);
        let d = obs.clearance(&fp, &Pose2::new(2.0, 0.0, 0.0), 5.0);
        assert!((d - 0.5).abs() < 1e-5, "{d}");
        assert_eq!(obs.clearance(&fp, &Pose2::new(5.0, 20.0, 0.0), 3.0), 3.0);
        assert_eq!(obs.clearance(&fp, &Pose2::new(1.0, 0.0, 0.0), 3.0), 0.0);
        assert_eq!(obs.hit(&fp, &Pose2::new(10.6, 0.4, 0.0)), Some(1));
    }
}
