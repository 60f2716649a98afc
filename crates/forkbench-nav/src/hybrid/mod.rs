//! Hybrid-A* over (x, y, heading), forward and reverse, with Reeds-Shepp shots to the goal (as Nav2's Smac planner): manoeuvres a point planner cannot make.

mod approach;
mod heuristic;
mod refine;
mod search;

use forkbench_core::path::{Path, PathSample};
use forkbench_core::{ForkliftSpec, Pose2};
use forkbench_geom::{Footprint, Obstacles};

use crate::{NavError, NavMap, truck_parts};

pub use search::{CORNER_STEP_M, plan_hybrid, plan_hybrid_from_here};

/// Hybrid-A* settings: the search lattice, the costs and the budget.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct HybridParams {
    /// Position bin of the closed set, and the coarse heuristic grid's cell.
    pub cell_m: f64,
    /// Heading bins over a full turn.
    pub headings: usize,
    /// Cost multiplier on distance driven backwards.
    pub reverse_penalty: f64,
    /// Cost added at each change of direction (a cusp), in metres of travel.
    pub cusp_penalty_m: f64,
    /// Cost multiplier on distance driven turning.
    pub turn_penalty: f64,
    /// Cost multiplier on distance driven with the chassis nearer an obstacle than
    /// `proximity_m` (scaled by how much nearer).
    pub proximity_penalty: f64,
    pub proximity_m: f64,
    /// Plan forwards only (reversing refused).
    pub forward_only: bool,
    /// Most nodes expanded before giving up.
    pub max_expansions: usize,
    /// Most wall time before giving up.
    pub max_time_s: f64,
    /// Least distance driven in one direction before changing direction (no shuffles).
    pub min_segment_m: f64,
    /// Share of the fork root's tightest curvature the moves use: the rest is the
    /// tracker's headroom.
    pub curvature_fraction: f64,
}

impl Default for HybridParams {
    fn default() -> Self {
        Self {
            cell_m: 0.4,
            headings: 72,
            reverse_penalty: 2.0,
            cusp_penalty_m: 3.0,
            turn_penalty: 1.2,
            proximity_penalty: 1.0,
            proximity_m: 0.5,
            forward_only: false,
            max_expansions: 200_000,
            max_time_s: 5.0,
            curvature_fraction: 0.9,
            min_segment_m: 1.0,
        }
    }
}

impl HybridParams {
    /// Every setting within its range, named when not.
    pub fn check(&self) -> Result<(), NavError> {
        let ranges: [(&str, f64, f64, f64); 10] = [
            ("min_segment_m", self.min_segment_m, 0.0, 10.0),
            ("curvature_fraction", self.curvature_fraction, 0.1, 1.0),
            ("cell_m", self.cell_m, 0.05, 2.0),
            ("headings", self.headings as f64, 8.0, 360.0),
            ("reverse_penalty", self.reverse_penalty, 1.0, 100.0),
            ("cusp_penalty_m", self.cusp_penalty_m, 0.0, 1000.0),
            ("turn_penalty", self.turn_penalty, 1.0, 100.0),
            ("proximity_penalty", self.proximity_penalty, 0.0, 100.0),
            ("proximity_m", self.proximity_m, 0.0, 10.0),
            ("max_time_s", self.max_time_s, 0.001, 600.0),
        ];
        for (name, v, lo, hi) in ranges {
            if !(v.is_finite() && (lo..=hi).contains(&v)) {
                return Err(NavError::Params(format!(
                    "hybrid-astar {name} = {v}: must lie within {lo}..{hi}"
                )));
            }
        }
        if !(1..=5_000_000).contains(&self.max_expansions) {
            return Err(NavError::Params(format!(
                "hybrid-astar max_expansions = {}: must lie within 1..5000000",
                self.max_expansions
            )));
        }
        Ok(())
    }
}

/// What the truck must clear: its chassis and forks grown by a margin, and a carried
/// pallet when loaded.
#[derive(Debug, Clone)]
pub struct Body {
    pub parts: Vec<Footprint>,
}

impl Body {
    /// The truck's chassis and forks grown by `margin_m`, with `load` (a footprint relative
    /// to the fork root, e.g. a pallet on the forks) when carrying one.
    pub fn of(truck: &ForkliftSpec, margin_m: f64, load: Option<Footprint>) -> Self {
        let mut parts: Vec<Footprint> = truck_parts(truck, margin_m).into();
        if let Some(l) = load {
            parts.push(Footprint {
                length_m: l.length_m + 2.0 * margin_m,
                width_m: l.width_m + 2.0 * margin_m,
                ..l
            });
        }
        Self { parts }
    }

    /// The farthest any corner lies from the fork root.
    pub fn reach_m(&self) -> f64 {
        let origin = Pose2::new(0.0, 0.0, 0.0);
        self.parts
            .iter()
            .flat_map(|fp| fp.corners(&origin))
            .map(|c| c[0].hypot(c[1]))
            .fold(0.0, f64::max)
    }

    pub fn free(&self, obstacles: &Obstacles, pose: &Pose2) -> bool {
        self.parts.iter().all(|fp| !obstacles.collides(fp, pose))
    }

    /// Whether the fork root lies within `lo`–`hi` (the map's extent). The floor beyond
    /// the map counts as open, as the other planners' footprint checks see it.
    pub fn on_map(&self, pose: &Pose2, (lo, hi): ([f64; 2], [f64; 2])) -> bool {
        (lo[0]..=hi[0]).contains(&pose.x_m) && (lo[1]..=hi[1]).contains(&pose.y_m)
    }
}

/// A Hybrid-A* query: poses of the fork root, the truck and what it carries.
#[derive(Debug, Clone)]
pub struct HybridQuery {
    pub start: Pose2,
    pub goal: Pose2,
    pub truck: ForkliftSpec,
    pub margin_m: f64,
    pub load: Option<Footprint>,
    pub params: HybridParams,
    /// A straight this long, driven forwards, ends the manoeuvre (0: none): the tracker
    /// settles onto the goal heading on it, as before a rack face.
    pub approach_m: f64,
}

/// A manoeuvre: paths driven in turn, each forwards or backwards, with a stop and change
/// of direction (a cusp) between them.
#[derive(Debug, Clone, PartialEq)]
pub struct Manoeuvre {
    pub segments: Vec<Path>,
    pub length_m: f64,
    /// Nodes expanded and search time.
    pub expansions: usize,
    pub time_s: f64,
}

impl Manoeuvre {
    /// Where the truck stops to change direction.
    pub fn cusps(&self) -> Vec<Pose2> {
        self.segments
            .iter()
            .skip(1)
            .filter_map(|p| p.samples.first().map(PathSample::pose))
            .collect()
    }

    /// Distance driven backwards.
    pub fn reverse_m(&self) -> f64 {
        self.segments
            .iter()
            .filter(|p| p.reverse)
            .map(Path::length_m)
            .fold(0.0, |a, b| a + b)
    }

    /// Every pose in driving order (cusps appear twice).
    pub fn poses(&self) -> impl Iterator<Item = Pose2> + '_ {
        self.segments
            .iter()
            .flat_map(|p| p.samples.iter().map(PathSample::pose))
    }

    /// The positions as one polyline.
    pub fn polyline(&self) -> Vec<[f64; 2]> {
        self.poses().map(|p| [p.x_m, p.y_m]).collect()
    }
}

/// Dense samples `(pose, curvature, backwards)` in driving order, split where the
/// direction changes into paths whose arc length restarts at 0.
fn segments_of(samples: &[(Pose2, f64, bool)]) -> Vec<Path> {
    let mut out: Vec<Path> = Vec::new();
    let mut prev: Option<(Pose2, bool)> = None;
    for &(pose, kappa, reverse) in samples {
        let start_new = prev.is_none_or(|(_, r)| r != reverse);
        if start_new {
            // The new segment starts where the last ended (the cusp).
            let from = prev.map_or(pose, |(p, _)| p);
            let mut path = Path::new(vec![PathSample {
                s_m: 0.0,
                x_m: from.x_m,
                y_m: from.y_m,
                heading_rad: from.heading_rad,
                curvature_per_m: kappa,
            }]);
            path.reverse = reverse;
            out.push(path);
            if prev.is_none() {
                prev = Some((pose, reverse));
                continue;
            }
        }
        let Some(path) = out.last_mut() else { break };
        let last = path.samples.last().copied().unwrap_or(PathSample {
            s_m: 0.0,
            x_m: pose.x_m,
            y_m: pose.y_m,
            heading_rad: pose.heading_rad,
            curvature_per_m: kappa,
        });
        let ds = (pose.x_m - last.x_m).hypot(pose.y_m - last.y_m);
        if ds < 1e-9 {
            prev = Some((pose, reverse));
            continue;
        }
        path.samples.push(PathSample {
            s_m: last.s_m + ds,
            x_m: pose.x_m,
            y_m: pose.y_m,
            heading_rad: pose.heading_rad,
            curvature_per_m: kappa,
        });
        prev = Some((pose, reverse));
    }
    out.retain(|p| p.samples.len() >= 2);
    out
}

/// The tightest curvature the fork root can drive: the truck turns about a point on its
/// fixed front axle's line, `1 / κ_max` from the axle, and the fork root sits ahead of the
/// axle, so it circles wider than the axle does.
pub fn root_max_curvature_per_m(truck: &ForkliftSpec) -> f64 {
    1.0 / truck
        .min_turn_radius_m()
        .hypot(truck.fork_root_ahead_of_front_axle_m)
}

/// The radius the truck covers around its fork root in every pose (the heuristic's
/// relaxation).
fn covered_radius_m(truck: &ForkliftSpec, margin_m: f64) -> f64 {
    let forks = truck.fork_spacing_m + truck.fork_width_m;
    (forks / 2.0)
        .min(truck.body_width_m / 2.0)
        .min(truck.fork_length_m)
        .min(truck.body_length_m)
        + margin_m
}

/// The inflated grid the heuristic relaxes to.
fn relaxed_grid(map: &NavMap, q: &HybridQuery) -> std::sync::Arc<crate::OccupancyGrid> {
    // The grid marks a cell when an obstacle overlaps any of it: a cell less keeps it a relaxation.
    map.inflated((covered_radius_m(&q.truck, q.margin_m) - map.grid.resolution_m).max(0.0))
}
