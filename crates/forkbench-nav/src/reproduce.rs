//! Luo's sample-count and connection-distance studies: success rate, planning time and path length of PRM over seeds, RRT beside it.

use crate::grid::OccupancyGrid;
use crate::roadmap::{PrmParams, plan_prm};
use crate::rrt::{RrtParams, plan_rrt};
use crate::{NavError, Route};

/// One study row: a planner setting over `runs` seeds.
#[derive(Debug, Clone, PartialEq)]
pub struct StudyRow {
    pub planner: &'static str,
    pub nodes: Option<usize>,
    pub connect_m: Option<f64>,
    pub runs: usize,
    pub found: usize,
    pub median_time_s: f64,
    /// Median over the runs that found a path (NaN when none did).
    pub median_length_m: f64,
}

/// The paper's settings: node counts at 10 m, then {500, 100, 50} × {5 m, 30 m, ∞}.
pub const NODE_STUDY: [usize; 5] = [15, 50, 100, 150, 500];
pub const GRID_NODES: [usize; 3] = [500, 100, 50];
pub const GRID_CONNECT_M: [Option<f64>; 3] = [Some(5.0), Some(30.0), None];

fn median(v: Vec<f64>) -> f64 {
    forkbench_core::quantile::quantile(v, 0.5).unwrap_or(f64::NAN)
}

fn row(
    planner: &'static str,
    nodes: Option<usize>,
    connect_m: Option<f64>,
    routes: &[Route],
) -> StudyRow {
    StudyRow {
        planner,
        nodes,
        connect_m,
        runs: routes.len(),
        found: routes.iter().filter(|r| r.found()).count(),
        median_time_s: median(routes.iter().map(|r| r.timing.total_s()).collect()),
        median_length_m: median(routes.iter().map(|r| r.length_m).collect()),
    }
}

/// PRM with `nodes` and `connect_m` from `start` to `goal` over seeds `0..runs`.
pub fn prm_row(
    grid: &OccupancyGrid,
    (start, goal): ([f64; 2], [f64; 2]),
    nodes: usize,
    connect_m: Option<f64>,
    runs: u64,
) -> Result<StudyRow, NavError> {
    let routes = (0..runs)
        .map(|seed| {
            plan_prm(
                grid,
                start,
                goal,
                &PrmParams {
                    nodes,
                    connect_m,
                    seed,
                },
            )
            .map(|r| r.0)
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(row("PRM + A*", Some(nodes), connect_m, &routes))
}

/// Both studies and an RRT row, on an inflated grid.
pub fn studies(
    grid: &OccupancyGrid,
    ends: ([f64; 2], [f64; 2]),
    runs: u64,
) -> Result<Vec<StudyRow>, NavError> {
    let mut rows = Vec::new();
    for n in NODE_STUDY {
        rows.push(prm_row(grid, ends, n, Some(10.0), runs)?);
    }
    for n in GRID_NODES {
        for c in GRID_CONNECT_M {
            rows.push(prm_row(grid, ends, n, c, runs)?);
        }
    }
    let rrt = (0..runs)
        .map(|seed| {
            plan_rrt(
                grid,
                ends.0,
                ends.1,
                &RrtParams {
                    seed,
                    ..RrtParams::default()
                },
            )
        })
        .collect::<Result<Vec<_>, _>>()?;
    rows.push(row("RRT", None, None, &rrt));
    Ok(rows)
}
