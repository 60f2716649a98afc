//! Obstacle inflation: every cell within a radius of an occupied (or unknown) cell becomes occupied (Luo: 0.5 × wheelbase).

use forkbench_core::ForkliftSpec;

use crate::grid::{Cell, OccupancyGrid};

/// Largest inflation radius: several truck widths; the work grows with its square.
pub const MAX_INFLATION_M: f64 = 5.0;

/// Luo's robot-size model: obstacles inflated by half the wheelbase.
pub fn luo_inflation_m(truck: &ForkliftSpec) -> f64 {
    0.5 * truck.wheelbase_m
}

impl OccupancyGrid {
    /// A copy in which every cell whose centre lies within `radius_m` of a non-free cell's
    /// centre is occupied. Only the border of each obstacle spreads (cells with a free
    /// neighbour), so the cost grows with the obstacles' perimeter, not their area.
    pub fn inflated(&self, radius_m: f64) -> OccupancyGrid {
        let mut out = self.clone();
        let r = (radius_m / self.resolution_m).max(0.0);
        let reach = r.floor() as i64;
        let stencil: Vec<(i64, i64)> = (-reach..=reach)
            .flat_map(|dy| (-reach..=reach).map(move |dx| (dx, dy)))
            .filter(|&(dx, dy)| ((dx * dx + dy * dy) as f64) <= r * r)
            .collect();
        let (w, h) = (self.width as i64, self.height as i64);
        for iy in 0..h {
            for ix in 0..w {
                if self.get(ix as usize, iy as usize) == Cell::Free || !self.is_border(ix, iy) {
                    continue;
                }
                for &(dx, dy) in &stencil {
                    let (x, y) = (ix + dx, iy + dy);
                    if x >= 0
                        && y >= 0
                        && x < w
                        && y < h
                        && out.get(x as usize, y as usize) == Cell::Free
                    {
                        out.set(x as usize, y as usize, Cell::Occupied);
                    }
                }
            }
        }
        out
    }

    /// Whether a non-free cell has a free 4-neighbour.
    fn is_border(&self, ix: i64, iy: i64) -> bool {
        [(1, 0), (-1, 0), (0, 1), (0, -1)].iter().any(|&(dx, dy)| {
            let (x, y) = (ix + dx, iy + dy);
            x >= 0
                && y >= 0
                && (x as usize) < self.width
                && (y as usize) < self.height
                && self.get(x as usize, y as usize) == Cell::Free
        })
    }
}
