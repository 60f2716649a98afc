//! Where the truck may go: the paper's inflated grid, or the true chassis-and-forks footprint swept along straight edges.

use forkbench_core::{ForkliftSpec, Pose2};
use forkbench_geom::{Footprint, Obstacles};

use std::sync::Arc;

use crate::NavMap;
use crate::grid::{Cell, OccupancyGrid};

/// Free space as the sampling planners see it: points (roadmap nodes, tree nodes) and
/// straight edges between them. Points and edges are those of the fork root.
pub trait FreeSpace {
    /// Lower-left and upper-right corners of the sampling area.
    fn extent(&self) -> ([f64; 2], [f64; 2]);
    /// Whether `p` lies on the map.
    fn on_map(&self, p: [f64; 2]) -> bool;
    fn point_free(&self, p: [f64; 2]) -> bool;
    fn segment_free(&self, a: [f64; 2], b: [f64; 2]) -> bool;
}

impl FreeSpace for OccupancyGrid {
    fn extent(&self) -> ([f64; 2], [f64; 2]) {
        OccupancyGrid::extent(self)
    }
    fn on_map(&self, p: [f64; 2]) -> bool {
        self.cell_of(p).is_some()
    }
    fn point_free(&self, p: [f64; 2]) -> bool {
        self.is_free(p)
    }
    fn segment_free(&self, a: [f64; 2], b: [f64; 2]) -> bool {
        OccupancyGrid::segment_free(self, a, b)
    }
}

/// The truck's two rectangles relative to the fork root: the chassis behind it and the
/// forks ahead (one block as wide as both forks), each grown by `margin_m` on every side.
pub fn truck_parts(truck: &ForkliftSpec, margin_m: f64) -> [Footprint; 2] {
    let m2 = 2.0 * margin_m;
    [
        Footprint {
            length_m: truck.body_length_m + m2,
            width_m: truck.body_width_m + m2,
            centre_ahead_m: -truck.body_length_m / 2.0,
        },
        Footprint {
            length_m: truck.fork_length_m + m2,
            width_m: truck.fork_spacing_m + truck.fork_width_m + m2,
            centre_ahead_m: truck.fork_length_m / 2.0,
        },
    ]
}

/// Which collision model plans a route.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum CollisionModel {
    /// Luo's model: obstacles inflated by half the wheelbase, the truck a point.
    Inflate,
    /// The chassis and forks swept along each edge, heading along the edge.
    Footprint,
}

impl CollisionModel {
    /// The clearance a plan keeps by default: none for the inflated grid (inflation is the
    /// clearance), 0.15 m around the swept footprint.
    pub fn default_margin_m(self) -> f64 {
        match self {
            Self::Inflate => 0.0,
            Self::Footprint => 0.15,
        }
    }
}

impl std::str::FromStr for CollisionModel {
    type Err = forkbench_core::UnknownChoice;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "inflate" => Ok(Self::Inflate),
            "footprint" => Ok(Self::Footprint),
            other => Err(forkbench_core::UnknownChoice::new(
                other,
                "expected `inflate` or `footprint`",
            )),
        }
    }
}

/// The footprint model: a node must lie half the truck's width from every obstacle, and
/// an edge is free when the chassis and forks, facing along it, clear every obstacle over
/// its whole length. A rectangle moved along its own axis sweeps a longer rectangle, so
/// one exact test per part covers the edge.
#[derive(Debug)]
pub struct FootprintSpace<'a> {
    /// The map inflated by half the truck's width, for nodes.
    nodes: Arc<OccupancyGrid>,
    obstacles: &'a Obstacles,
    parts: [Footprint; 2],
}

/// How far the node grid is inflated: half the truck's width and the margin.
fn node_inflation_m(truck: &ForkliftSpec, margin_m: f64) -> f64 {
    truck.body_width_m / 2.0 + margin_m
}

impl<'a> FootprintSpace<'a> {
    /// `margin_m`: the clearance every edge keeps from the obstacles (tracking error).
    pub fn new(
        map: &OccupancyGrid,
        obstacles: &'a Obstacles,
        truck: &ForkliftSpec,
        margin_m: f64,
    ) -> Self {
        Self {
            nodes: Arc::new(map.inflated(node_inflation_m(truck, margin_m))),
            obstacles,
            parts: truck_parts(truck, margin_m),
        }
    }

    /// The same on a [`NavMap`], whose inflated grid is made once and shared.
    pub fn on(map: &'a NavMap, truck: &ForkliftSpec, margin_m: f64) -> Self {
        Self {
            nodes: map.inflated(node_inflation_m(truck, margin_m)),
            obstacles: &map.obstacles,
            parts: truck_parts(truck, margin_m),
        }
    }

    /// Whether the truck with its fork root at `pose` touches an obstacle.
    pub fn pose_free(&self, pose: &Pose2) -> bool {
        self.parts
            .iter()
            .all(|fp| !self.obstacles.collides(fp, pose))
    }
}

impl FreeSpace for FootprintSpace<'_> {
    fn extent(&self) -> ([f64; 2], [f64; 2]) {
        self.nodes.extent()
    }
    fn on_map(&self, p: [f64; 2]) -> bool {
        self.nodes.cell_of(p).is_some()
    }
    fn point_free(&self, p: [f64; 2]) -> bool {
        self.nodes.is_free(p)
    }
    fn segment_free(&self, a: [f64; 2], b: [f64; 2]) -> bool {
        let d = (b[0] - a[0]).hypot(b[1] - a[1]);
        let from = Pose2::new(a[0], a[1], (b[1] - a[1]).atan2(b[0] - a[0]));
        self.parts.iter().all(|fp| {
            let swept = Footprint {
                length_m: fp.length_m + d,
                centre_ahead_m: fp.centre_ahead_m + d / 2.0,
                ..*fp
            };
            !self.obstacles.collides(&swept, &from)
        })
    }
}

/// Obstacles for the footprint checker from a grid's non-free cells (a map from SLAM has
/// no shapes).
pub fn grid_obstacles(grid: &OccupancyGrid) -> Obstacles {
    let mut out = Obstacles::new();
    for [lo, hi] in blocked_rects(grid) {
        let centre = Pose2::new((lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0, 0.0);
        out.add_rect(&centre, hi[0] - lo[0], hi[1] - lo[1]);
    }
    out
}

/// A grid's non-free cells as few rectangles (lower-left, upper-right).
pub fn blocked_rects(grid: &OccupancyGrid) -> Vec<[[f64; 2]; 2]> {
    forkbench_core::signal::merge_cells(
        (grid.width, grid.height),
        |ix, iy| grid.get(ix, iy) != Cell::Free,
        grid.origin_m,
        grid.resolution_m,
    )
}
