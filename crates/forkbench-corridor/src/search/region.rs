//! Movable ranges (G regions), passability and the minimum width by bisection.

use rayon::prelude::*;

use super::{Mode, Reached, Resolution, Space};
use crate::bend::{Bend, Junction, Vehicle};

/// The movable range of one mode at one width.
#[derive(Debug)]
pub struct GRegion {
    pub space: Space,
    /// Per cell: one state on a passage through it (forward-reached and backward-reached
    /// in the same heading layer), if any.
    pub through: Vec<Option<usize>>,
    pub forward: Reached,
    pub backward: Reached,
}

impl GRegion {
    pub fn compute(bend: Bend, vehicle: Vehicle, mode: Mode, res: Resolution) -> Self {
        let space = Space::new(bend, vehicle, mode, res);
        let forward = space.search(true, false);
        let backward = space.search(false, false);
        let through = (0..space.cells())
            .map(|c| {
                (0..space.layers).map(|l| l * space.cells() + c).find(|&s| {
                    // Both searches reached the state, each with its own pose in the
                    // cell; the passage joins them by a slide, which must be free too.
                    let layer = s / space.cells();
                    forward.parent[s] != 0
                        && backward.parent[s] != 0
                        && space.free_to(&space.body(forward.pos[s], layer), backward.pos[s], layer)
                })
            })
            .collect();
        Self {
            space,
            through,
            forward,
            backward,
        }
    }

    pub fn cells(&self) -> impl Iterator<Item = usize> + '_ {
        self.through
            .iter()
            .enumerate()
            .filter_map(|(c, s)| s.map(|_| c))
    }

    pub fn area_m2(&self) -> f64 {
        self.cells().count() as f64 * self.space.res.cell_m.powi(2)
    }

    /// A whole passage through `cell`: from leg 1 to the cell, a step of at most one cell
    /// inside it, and on to leg 2.
    pub fn witness(&self, cell: usize) -> Option<Vec<([f64; 2], f64)>> {
        let s = self.through[cell]?;
        let mut path = self.space.chain(&self.forward, s);
        let mut back = self.space.chain(&self.backward, s);
        back.reverse();
        path.extend(back);
        Some(path)
    }
}

/// Whether the search finds a passage through a bend of `width_m`. A passage found is
/// real (every step is an exact sweep); a miss may be the grid's. The truck cannot slide
/// sideways, so which pose a cell keeps matters most there: it is also searched on a grid
/// shifted by half a cell diagonally, and passes if either finds a way.
pub fn passes(
    vehicle: &Vehicle,
    mode: Mode,
    junction: Junction,
    angle_rad: f64,
    res: Resolution,
    width_m: f64,
) -> bool {
    let shifts: &[[f64; 2]] = if mode == Mode::Truck {
        &[[0.0, 0.0], [0.5, 0.5]]
    } else {
        &[[0.0, 0.0]]
    };
    // The shifted searches are independent: run them on all cores, stop at the first way.
    shifts.par_iter().any(|s| {
        let mut space = Space::new(junction.bend(width_m, angle_rad), *vehicle, mode, res);
        space.shift_grid(*s);
        space.search(true, true).goal.is_some()
    })
}

/// Smallest width (bisection to a quarter cell; the grid itself limits it to about one
/// cell) at which `mode` passes the bend, or `None`
/// when even `max_width_m` does not.
pub fn min_width_m(
    vehicle: &Vehicle,
    mode: Mode,
    junction: Junction,
    angle_rad: f64,
    res: Resolution,
    max_width_m: f64,
) -> Option<f64> {
    let passes = |w: f64| passes(vehicle, mode, junction, angle_rad, res, w);
    let mut lo = vehicle.width_m;
    let mut hi = vehicle.circumscribed_m() + res.cell_m;
    while !passes(hi) {
        lo = hi;
        hi *= 1.5;
        if hi > max_width_m {
            return if passes(max_width_m) {
                bisect(lo, max_width_m, res.cell_m / 4.0, passes)
            } else {
                None
            };
        }
    }
    bisect(lo, hi, res.cell_m / 4.0, passes)
}

fn bisect(mut lo: f64, mut hi: f64, tol: f64, passes: impl Fn(f64) -> bool) -> Option<f64> {
    while hi - lo > tol {
        let mid = (lo + hi) / 2.0;
        if passes(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Some(hi)
}
