//! Warehouse navigation for forkbench (Luo's PRM + A* paper): occupancy grids, ROS map_server maps, PRM, RRT and RRT-Connect.

pub mod global;
pub mod grid;
pub mod hybrid;
pub mod incremental;
mod inflate;
pub mod map_server;
pub mod reeds_shepp;
pub mod reproduce;
pub mod roadmap;
pub mod rrt;
pub mod simplify;
pub mod smooth;
pub mod space;

pub use global::{Algorithm, GlobalPlan, GlobalPlannerKind, GlobalQuery, NavMap, plan_global};
pub use grid::{Cell, GridError, OccupancyGrid};
pub use incremental::plan_prm_first;
pub use inflate::{MAX_INFLATION_M, luo_inflation_m};
pub use map_server::{MapError, read_map, write_map};
pub use roadmap::{MAX_CANDIDATE_EDGES, PrmParams, Roadmap, astar, candidate_edges, plan_prm};
pub use rrt::{RrtParams, plan_rrt, plan_rrt_connect};
pub use smooth::{SmoothError, SmoothParams, Smoothed, SweptHit};
pub use space::{
    CollisionModel, FootprintSpace, FreeSpace, blocked_rects, grid_obstacles, truck_parts,
};

/// A query the planners refuse.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NavError {
    #[error("the {which} ({x:.2}, {y:.2}) m is off the map")]
    OffMap { which: &'static str, x: f64, y: f64 },
    #[error(
        "the {which} ({x:.2}, {y:.2}) m is inside an obstacle (after inflation, or too close for the truck)"
    )]
    Blocked { which: &'static str, x: f64, y: f64 },
    #[error("{0}")]
    Params(String),
    #[error("the goal cannot be reached: {0}")]
    Unreachable(String),
    #[error(
        "no path within the search budget ({expansions} nodes expanded in {time_s:.2} s; raise max_expansions or max_time_s)"
    )]
    Budget { expansions: usize, time_s: f64 },
}

/// Wall time of a plan's stages.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Timing {
    pub sampling_s: f64,
    pub connection_s: f64,
    pub search_s: f64,
}

impl Timing {
    pub fn total_s(&self) -> f64 {
        self.sampling_s + self.connection_s + self.search_s
    }
}

/// A global plan: the polyline from start to goal (`None`: no path found), its length,
/// the timing and how many nodes the roadmap or trees held.
#[derive(Debug, Clone, PartialEq)]
pub struct Route {
    pub points: Option<Vec<[f64; 2]>>,
    pub length_m: f64,
    pub timing: Timing,
    pub nodes: usize,
}

impl Route {
    pub fn new(points: Option<Vec<[f64; 2]>>, timing: Timing, nodes: usize) -> Self {
        let length_m = points.as_deref().map_or(f64::NAN, polyline_length_m);
        Self {
            points,
            length_m,
            timing,
            nodes,
        }
    }

    pub fn found(&self) -> bool {
        self.points.is_some()
    }
}

/// Length of a polyline: its legs summed.
pub fn polyline_length_m(points: &[[f64; 2]]) -> f64 {
    points
        .windows(2)
        .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]))
        .sum()
}

/// Start and goal must lie on the map in free cells.
pub(crate) fn check_endpoints<S: space::FreeSpace + ?Sized>(
    grid: &S,
    start: [f64; 2],
    goal: [f64; 2],
) -> Result<(), NavError> {
    for (which, [x, y]) in [("start", start), ("goal", goal)] {
        if !grid.on_map([x, y]) {
            return Err(NavError::OffMap { which, x, y });
        }
        if !grid.point_free([x, y]) {
            return Err(NavError::Blocked { which, x, y });
        }
    }
    Ok(())
}
