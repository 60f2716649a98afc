//! Hybrid-A*'s obstacle-aware heuristic: shortest 8-connected distances to the goal on a coarse grid that relaxes the truck to a disc it always covers.

use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::time::Instant;

use crate::grid::{Cell, OccupancyGrid};

/// Distances (metres) from every coarse cell to the goal's cell; `INFINITY` where no
/// free path exists. A coarse cell is free when any fine cell inside it is free in the
/// inflated grid, so the search is a relaxation: a cell it calls unreachable is.
#[derive(Debug)]
pub(crate) struct Distances {
    origin_m: [f64; 2],
    cell_m: f64,
    nx: usize,
    ny: usize,
    dist: Vec<f64>,
}

/// Most coarse cells the heuristic holds: its memory and its Dijkstra's work, whatever the
/// map's extent.
pub(crate) const MAX_COARSE_CELLS: f64 = (1u64 << 22) as f64;

/// The coarse cell: the setting's, never finer than the map's own cells (each fine cell
/// must fall in one coarse cell for the relaxation to hold), and coarser where the map's
/// area would otherwise take more than [`MAX_COARSE_CELLS`]; a coarser cell only weakens
/// the bound, which stays a lower bound.
fn coarse_cell_m(cell_m: f64, resolution_m: f64, area_m2: f64) -> f64 {
    let floor = cell_m.max(resolution_m);
    floor.max((area_m2 / MAX_COARSE_CELLS).sqrt() * 1.001)
}

impl Distances {
    /// `inflated`: the map grown by a radius the truck covers in every pose; `start` and
    /// `goal` cells count as free whatever the map says. `None` when `deadline` passes
    /// first: the search's time budget covers this too.
    pub fn to_goal(
        inflated: &OccupancyGrid,
        cell_m: f64,
        (start, goal): ([f64; 2], [f64; 2]),
        deadline: Instant,
    ) -> Option<Self> {
        let (lo, hi) = inflated.extent();
        let cell_m = coarse_cell_m(
            cell_m,
            inflated.resolution_m,
            (hi[0] - lo[0]) * (hi[1] - lo[1]),
        );
        let nx = (((hi[0] - lo[0]) / cell_m).ceil() as usize).max(1);
        let ny = (((hi[1] - lo[1]) / cell_m).ceil() as usize).max(1);
        let mut free = vec![false; nx * ny];
        let ratio = inflated.resolution_m / cell_m;
        for iy in 0..inflated.height {
            for ix in 0..inflated.width {
                if inflated.get(ix, iy) == Cell::Free {
                    let cx = ((ix as f64 + 0.5) * ratio) as usize;
                    let cy = ((iy as f64 + 0.5) * ratio) as usize;
                    free[cy.min(ny - 1) * nx + cx.min(nx - 1)] = true;
                }
            }
        }
        let mut d = Self {
            origin_m: lo,
            cell_m,
            nx,
            ny,
            dist: vec![f64::INFINITY; nx * ny],
        };
        for p in [start, goal] {
            if let Some(i) = d.index(p) {
                free[i] = true;
            }
        }
        if let Some(g) = d.index(goal) {
            d.dijkstra(g, &free, deadline)?;
        }
        Some(d)
    }

    fn index(&self, p: [f64; 2]) -> Option<usize> {
        let fx = (p[0] - self.origin_m[0]) / self.cell_m;
        let fy = (p[1] - self.origin_m[1]) / self.cell_m;
        (fx >= 0.0 && fy >= 0.0 && (fx as usize) < self.nx && (fy as usize) < self.ny)
            .then(|| fy as usize * self.nx + fx as usize)
    }

    fn dijkstra(&mut self, goal: usize, free: &[bool], deadline: Instant) -> Option<()> {
        let (nx, ny) = (self.nx as i64, self.ny as i64);
        let diag = self.cell_m * std::f64::consts::SQRT_2;
        let mut heap = BinaryHeap::new();
        self.dist[goal] = 0.0;
        heap.push(Reverse((0u64, goal)));
        let mut popped = 0u32;
        while let Some(Reverse((d_bits, i))) = heap.pop() {
            popped = popped.wrapping_add(1);
            if popped.is_multiple_of(4096) && Instant::now() > deadline {
                return None;
            }
            let d = f64::from_bits(d_bits);
            if d > self.dist[i] {
                continue;
            }
            let (x, y) = ((i % self.nx) as i64, (i / self.nx) as i64);
            for (dx, dy) in [
                (1, 0),
                (-1, 0),
                (0, 1),
                (0, -1),
                (1, 1),
                (1, -1),
                (-1, 1),
                (-1, -1),
            ] {
                let (x2, y2) = (x + dx, y + dy);
                if x2 < 0 || y2 < 0 || x2 >= nx || y2 >= ny {
                    continue;
                }
                let j = (y2 * nx + x2) as usize;
                if !free[j] {
                    continue;
                }
                let step = if dx != 0 && dy != 0 {
                    diag
                } else {
                    self.cell_m
                };
                let nd = d + step;
                if nd < self.dist[j] {
                    self.dist[j] = nd;
                    // Non-negative floats order like their bit patterns.
                    heap.push(Reverse((nd.to_bits(), j)));
                }
            }
        }
        Some(())
    }

    /// Distance from `p` to the goal, less a cell's diagonal (`p` may lie anywhere in its
    /// cell); `INFINITY` off the map or where the goal cannot be reached.
    pub fn at(&self, p: [f64; 2]) -> f64 {
        self.index(p).map_or(f64::INFINITY, |i| {
            (self.dist[i] - self.cell_m * std::f64::consts::SQRT_2).max(0.0)
        })
    }
}
