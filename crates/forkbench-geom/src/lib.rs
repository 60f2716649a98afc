//! Footprint collision checking with parry2d: a rectangular body at a pose against fixed obstacles.

use forkbench_core::{Path, Pose2};
use parry2d::math::{Pose, Vector};
use parry2d::query::{distance, intersection_test};
use parry2d::shape::{ConvexPolygon, Cuboid, Shape};

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
    buckets: std::collections::HashMap<(i64, i64), Vec<usize>>,
    /// Shapes too large to bucket, tested by every query.
    large: Vec<usize>,
}

/// Side of a bucket.
const BUCKET_M: f64 = 2.0;
/// Shapes spanning more buckets than this go to the always-tested list.
const MAX_BUCKETS_PER_SHAPE: i64 = 4096;

/// The bucket range (inclusive) that `b` overlaps.
fn bucket_range(b: &Bounds) -> ([i64; 2], [i64; 2]) {
    let cell = |v: f64| (v / BUCKET_M).floor().clamp(-1e12, 1e12) as i64;
    ([cell(b[0]), cell(b[1])], [cell(b[2]), cell(b[3])])
}

/// Axis-aligned bounds: min x, min y, max x, max y.
type Bounds = [f64; 4];

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
    let dx = (a[0] - b[2]).max(b[0] - a[2]).max(0.0);
    let dy = (a[1] - b[3]).max(b[1] - a[3]).max(0.0);
    dx.hypot(dy)
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
        let (lo, hi) = bucket_range(&b);
        let span = (hi[0] - lo[0] + 1).saturating_mul(hi[1] - lo[1] + 1);
        if !(b.iter().all(|v| v.is_finite()) && span <= MAX_BUCKETS_PER_SHAPE) {
            self.large.push(i);
            return;
        }
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                self.buckets.entry((x, y)).or_default().push(i);
            }
        }
    }

    /// Shapes whose buckets overlap `b` grown by `reach_m`, in insertion order.
    fn near(&self, b: &Bounds, reach_m: f64) -> Vec<usize> {
        let grown = [
            b[0] - reach_m,
            b[1] - reach_m,
            b[2] + reach_m,
            b[3] + reach_m,
        ];
        let (lo, hi) = bucket_range(&grown);
        let mut out = self.large.clone();
        let span = (hi[0] - lo[0] + 1).saturating_mul(hi[1] - lo[1] + 1);
        if span > self.buckets.len() as i64 {
            // A query wider than the map: every bucketed shape.
            out.extend(self.buckets.values().flatten());
        } else {
            for x in lo[0]..=hi[0] {
                for y in lo[1]..=hi[1] {
                    if let Some(v) = self.buckets.get(&(x, y)) {
                        out.extend(v);
                    }
                }
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    }

    pub fn len(&self) -> usize {
        self.shapes.len()
    }

    pub fn is_empty(&self) -> bool {
        self.shapes.is_empty()
    }

    /// The first obstacle the footprint at `reference` overlaps (touching counts), if any.
    pub fn hit(&self, fp: &Footprint, reference: &Pose2) -> Option<usize> {
        let body = fp.cuboid();
        let at = pose(&fp.centre(reference));
        let near = bounds_of(&fp.corners(reference));
        self.near(&near, 0.0).into_iter().find(|&i| {
            let (p, s) = &self.shapes[i];
            // Convex–cuboid pairs are always supported; an unsupported pair would be a bug here.
            bounds_gap(&near, &self.bounds[i]) <= 0.0
                && intersection_test(&at, &body, p, s.as_ref()).is_ok_and(|r| r.intersecting)
        })
    }

    /// Distance from the footprint at `reference` to the nearest obstacle (0 when they
    /// touch), looking no further than `cap_m`: `cap_m` when nothing is that close.
    pub fn clearance(&self, fp: &Footprint, reference: &Pose2, cap_m: f64) -> f64 {
        let body = fp.cuboid();
        let at = pose(&fp.centre(reference));
        let near = bounds_of(&fp.corners(reference));
        let mut best = cap_m;
        for i in self.near(&near, cap_m) {
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

    pub fn collides(&self, fp: &Footprint, reference: &Pose2) -> bool {
        self.hit(fp, reference).is_some()
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
