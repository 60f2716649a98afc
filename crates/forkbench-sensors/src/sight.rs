//! Line of sight past fixed surfaces: the racks' and walls' edges filed in a uniform grid, so a sight line tests only the edges it passes near.

use crate::scan::{Seen, Surface};

/// Side of a grid cell.
const CELL_M: f64 = 2.0;
/// Slack on every box and band edge: far above the rounding of the crossing test, so
/// an edge the test would find is always among those tested.
const SLACK_M: f64 = 1e-6;
/// Most cells per filed edge (plus a floor): surfaces scattered far apart fall back to
/// testing every edge rather than making the grid large.
const CELLS_PER_EDGE: usize = 64;
const CELLS_FLOOR: usize = 1 << 16;

/// The fixed surfaces (pallets lie below a scanner's plane and never block).
#[derive(Debug, Clone, Default)]
pub struct Sight {
    edges: Vec<Surface>,
    grid: Option<Grid>,
}

/// Edge indices by cell, row by row from `origin`.
#[derive(Debug, Clone)]
struct Grid {
    origin: [f64; 2],
    dims: [usize; 2],
    cells: Vec<Vec<u32>>,
}

impl Sight {
    /// The fixed surfaces among `surfaces`, filed for sight-line queries.
    pub fn new(surfaces: &[Surface]) -> Self {
        let edges: Vec<Surface> = surfaces
            .iter()
            .filter(|s| s.seen == Seen::Fixed)
            .copied()
            .collect();
        let grid = Grid::build(&edges);
        Self { edges, grid }
    }

    /// Whether a fixed surface crosses the segment from `a` to `b`.
    pub fn blocked(&self, a: [f64; 2], b: [f64; 2]) -> bool {
        match &self.grid {
            Some(g) => g.any_near(a, b, |i| crosses(a, b, &self.edges[i as usize])),
            None => self.edges.iter().any(|s| crosses(a, b, s)),
        }
    }
}

impl Grid {
    fn build(edges: &[Surface]) -> Option<Self> {
        if edges.is_empty() || edges.len() > u32::MAX as usize {
            return None;
        }
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for s in edges {
            for k in 0..2 {
                lo[k] = lo[k].min(s.a[k].min(s.b[k]));
                hi[k] = hi[k].max(s.a[k].max(s.b[k]));
            }
        }
        if !(lo.iter().chain(&hi).all(|v| v.is_finite())) {
            return None;
        }
        let origin = [lo[0] - SLACK_M, lo[1] - SLACK_M];
        let span = |k: usize| ((hi[k] + SLACK_M - origin[k]) / CELL_M).floor() + 1.0;
        let budget = (edges.len().saturating_mul(CELLS_PER_EDGE)).max(CELLS_FLOOR) as f64;
        if span(0) * span(1) > budget {
            return None;
        }
        let dims = [span(0) as usize, span(1) as usize];
        let mut g = Self {
            origin,
            dims,
            cells: vec![Vec::new(); dims[0] * dims[1]],
        };
        for (i, s) in edges.iter().enumerate() {
            let (x0, x1) = g.cols(s.a[0].min(s.b[0]), s.a[0].max(s.b[0]));
            let (y0, y1) = g.rows(s.a[1].min(s.b[1]), s.a[1].max(s.b[1]));
            for y in y0..=y1 {
                for x in x0..=x1 {
                    g.cells[y * dims[0] + x].push(i as u32);
                }
            }
        }
        Some(g)
    }

    /// The cell index range along axis `k` covering `lo..=hi` with the slack, clipped.
    fn range(&self, k: usize, lo: f64, hi: f64) -> (usize, usize) {
        let cell = |v: f64| ((v - self.origin[k]) / CELL_M).floor();
        let last = (self.dims[k] - 1) as f64;
        let a = cell(lo - SLACK_M).clamp(0.0, last) as usize;
        let b = cell(hi + SLACK_M).clamp(0.0, last) as usize;
        (a, b)
    }

    fn cols(&self, lo: f64, hi: f64) -> (usize, usize) {
        self.range(0, lo, hi)
    }

    fn rows(&self, lo: f64, hi: f64) -> (usize, usize) {
        self.range(1, lo, hi)
    }

    /// Whether `test` holds for an edge filed in a cell the segment `a`–`b` passes
    /// through: row by row, the columns its stretch within that row's band covers.
    fn any_near(&self, a: [f64; 2], b: [f64; 2], mut test: impl FnMut(u32) -> bool) -> bool {
        let (y_lo, y_hi) = (a[1].min(b[1]), a[1].max(b[1]));
        let top = self.origin[1] + self.dims[1] as f64 * CELL_M;
        if y_hi < self.origin[1] - SLACK_M || y_lo > top + SLACK_M {
            return false;
        }
        let (r0, r1) = self.rows(y_lo, y_hi);
        let dy = b[1] - a[1];
        for r in r0..=r1 {
            let band = [
                self.origin[1] + r as f64 * CELL_M - SLACK_M,
                self.origin[1] + (r + 1) as f64 * CELL_M + SLACK_M,
            ];
            // The segment's x at the band's edges, within the segment.
            let x_at = |y: f64| {
                let t = ((y - a[1]) / dy).clamp(0.0, 1.0);
                a[0] + t * (b[0] - a[0])
            };
            let (xa, xb) = if dy.abs() < 1e-12 {
                (a[0], b[0])
            } else {
                (x_at(band[0]), x_at(band[1]))
            };
            let (c0, c1) = self.cols(xa.min(xb), xa.max(xb));
            for c in c0..=c1 {
                if self.cells[r * self.dims[0] + c].iter().any(|&i| test(i)) {
                    return true;
                }
            }
        }
        false
    }
}

/// Whether the segment from `a` to `b` crosses the segment `s`.
pub(crate) fn crosses(a: [f64; 2], b: [f64; 2], s: &Surface) -> bool {
    segments_cross(a, b, s.a, s.b)
}

/// Whether the segment `a`–`b` crosses the segment `c`–`e`.
pub(crate) fn segments_cross(a: [f64; 2], b: [f64; 2], c: [f64; 2], e: [f64; 2]) -> bool {
    let d = [b[0] - a[0], b[1] - a[1]];
    let e = [e[0] - c[0], e[1] - c[1]];
    let den = d[0] * e[1] - d[1] * e[0];
    if den.abs() < 1e-15 {
        return false;
    }
    let w = [c[0] - a[0], c[1] - a[1]];
    let t = (w[0] * e[1] - w[1] * e[0]) / den;
    let u = (w[0] * d[1] - w[1] * d[0]) / den;
    (0.0..=1.0).contains(&t) && (0.0..=1.0).contains(&u)
}

#[cfg(test)]
mod tests {
    use super::*;
    use forkbench_core::Pose2;
    use rand::{RngExt as _, SeedableRng as _};
    use rand_chacha::ChaCha8Rng;

    /// The grid answers as testing every edge does: random racks, and sight lines that
    /// run along cell boundaries, along the axes, through corners and off the grid.
    #[test]
    fn the_grid_answers_as_every_edge_does() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let surfaces: Vec<Surface> = (0..150)
            .flat_map(|_| {
                let c = Pose2::new(
                    rng.random_range(0.0..40.0),
                    rng.random_range(0.0..30.0),
                    rng.random_range(-3.2..3.2),
                );
                let (l, w) = (rng.random_range(0.1..6.0), rng.random_range(0.05..1.2));
                Surface::rect(&c, l, w, Seen::Fixed)
            })
            .collect();
        let sight = Sight::new(&surfaces);
        assert!(sight.grid.is_some(), "a warehouse-sized map is gridded");
        let every = Sight {
            grid: None,
            ..sight.clone()
        };
        let corners: Vec<[f64; 2]> = surfaces.iter().map(|s| s.a).collect();
        let point = |rng: &mut ChaCha8Rng| match rng.random_range(0..4) {
            0 => corners[rng.random_range(0..corners.len())],
            1 => [
                2.0 * rng.random_range(-2..23) as f64,
                rng.random_range(-5.0..35.0),
            ],
            _ => [rng.random_range(-5.0..45.0), rng.random_range(-5.0..35.0)],
        };
        let (mut blocked, mut clear) = (0, 0);
        for k in 0..20_000 {
            let a = point(&mut rng);
            let mut b = point(&mut rng);
            if k % 5 == 0 {
                b[1] = a[1];
            }
            if k % 7 == 0 {
                b[0] = a[0];
            }
            let want = every.blocked(a, b);
            assert_eq!(sight.blocked(a, b), want, "{a:?} → {b:?}");
            if want {
                blocked += 1;
            } else {
                clear += 1;
            }
        }
        assert!(
            blocked > 1000 && clear > 1000,
            "{blocked} blocked, {clear} clear"
        );
    }
}
