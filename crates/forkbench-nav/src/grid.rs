//! A binary occupancy grid (free, occupied, unknown) rasterised from rectangular obstacles, with straight-segment checks that walk the cells.

use forkbench_core::geometry::{Obstacle, rect_corners};

/// A grid cell's state, as ROS map_server's trinary mode has it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Cell {
    Free,
    Occupied,
    /// Neither (a SLAM map's unseen space); planning treats it as occupied.
    Unknown,
}

/// A grid that could not be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GridError {
    #[error("resolution {0} m: must be a finite number above 1 mm")]
    Resolution(f64),
    #[error(
        "the map would be {width} × {height} cells (more than {MAX_CELLS}): use a coarser resolution"
    )]
    TooLarge { width: usize, height: usize },
    #[error("obstacle {index}: {reason}")]
    Obstacle { index: usize, reason: String },
    #[error("the map has no extent: give obstacles or bounds")]
    Empty,
}

/// Most cells a grid may have (a 500 × 500 m site at 5 cm).
pub const MAX_CELLS: usize = 100_000_000;

/// Cells in rows from the lowest y up (ROS's convention: `origin_m` is the lower-left
/// corner of cell (0, 0)); x grows along a row.
#[derive(Debug, Clone, PartialEq)]
pub struct OccupancyGrid {
    pub resolution_m: f64,
    pub origin_m: [f64; 2],
    pub width: usize,
    pub height: usize,
    cells: Vec<Cell>,
}

impl OccupancyGrid {
    /// An all-`fill` grid of `width` × `height` cells.
    pub fn new(
        resolution_m: f64,
        origin_m: [f64; 2],
        (width, height): (usize, usize),
        fill: Cell,
    ) -> Result<Self, GridError> {
        if !(resolution_m.is_finite() && resolution_m >= 1e-3) {
            return Err(GridError::Resolution(resolution_m));
        }
        if width == 0 || height == 0 {
            return Err(GridError::Empty);
        }
        if width.saturating_mul(height) > MAX_CELLS {
            return Err(GridError::TooLarge { width, height });
        }
        Ok(Self {
            resolution_m,
            origin_m,
            width,
            height,
            cells: vec![fill; width * height],
        })
    }

    /// The origin and size in cells of [`OccupancyGrid::from_obstacles`]'s grid, without
    /// making it: a scenario's settings are refused at load when it could never be made.
    pub fn layout_for(
        obstacles: &[Obstacle],
        extra: &[[f64; 2]],
        resolution_m: f64,
        margin_m: f64,
    ) -> Result<([f64; 2], (usize, usize)), GridError> {
        if !(resolution_m.is_finite() && resolution_m >= 1e-3) {
            return Err(GridError::Resolution(resolution_m));
        }
        let mut corners = Vec::with_capacity(4 * obstacles.len() + extra.len());
        for (index, o) in obstacles.iter().enumerate() {
            let finite = [
                o.centre.x_m,
                o.centre.y_m,
                o.centre.heading_rad,
                o.length_m,
                o.width_m,
            ]
            .iter()
            .all(|v| v.is_finite());
            if !finite || o.length_m <= 0.0 || o.width_m <= 0.0 {
                let reason = "needs a finite pose and positive length and width".to_owned();
                return Err(GridError::Obstacle { index, reason });
            }
            corners.extend(rect_corners(&o.centre, o.length_m, o.width_m));
        }
        corners.extend_from_slice(extra);
        let (min, max) = bounds(&corners).ok_or(GridError::Empty)?;
        let origin = [min[0] - margin_m, min[1] - margin_m];
        // The tolerance keeps an extent of whole cells (42.4 m at 5 cm) from gaining one.
        let cells_along = |i: usize| {
            ((max[i] + margin_m - origin[i]) / resolution_m - 1e-9)
                .ceil()
                .max(1.0)
        };
        let (w, h) = (cells_along(0), cells_along(1));
        if w * h > MAX_CELLS as f64 {
            return Err(GridError::TooLarge {
                width: w as usize,
                height: h as usize,
            });
        }
        Ok((origin, (w as usize, h as usize)))
    }

    /// The obstacles rasterised onto a free floor that spans them and `extra` points, with
    /// `margin_m` around: a cell is occupied when an obstacle overlaps any part of it.
    pub fn from_obstacles(
        obstacles: &[Obstacle],
        extra: &[[f64; 2]],
        resolution_m: f64,
        margin_m: f64,
    ) -> Result<Self, GridError> {
        let (origin, (w, h)) = Self::layout_for(obstacles, extra, resolution_m, margin_m)?;
        let mut grid = Self::new(resolution_m, origin, (w, h), Cell::Free)?;
        for o in obstacles {
            grid.fill_rect(&rect_corners(&o.centre, o.length_m, o.width_m));
        }
        Ok(grid)
    }

    /// Marks every cell that the convex quadrilateral `quad` overlaps (separating axes).
    fn fill_rect(&mut self, quad: &[[f64; 2]; 4]) {
        let Some((min, max)) = bounds(quad) else {
            return;
        };
        let (x0, y0) = self.clamped_index(min);
        let (x1, y1) = self.clamped_index(max);
        for iy in y0..=y1 {
            for ix in x0..=x1 {
                if overlaps(&self.cell_square(ix, iy), quad) {
                    self.cells[iy * self.width + ix] = Cell::Occupied;
                }
            }
        }
    }

    /// The cell's four corners.
    fn cell_square(&self, ix: usize, iy: usize) -> [[f64; 2]; 4] {
        let r = self.resolution_m;
        let x = self.origin_m[0] + ix as f64 * r;
        let y = self.origin_m[1] + iy as f64 * r;
        [[x, y], [x + r, y], [x + r, y + r], [x, y + r]]
    }

    fn clamped_index(&self, p: [f64; 2]) -> (usize, usize) {
        let i = |v: f64, o: f64, n: usize| {
            ((v - o) / self.resolution_m)
                .floor()
                .clamp(0.0, (n - 1) as f64) as usize
        };
        (
            i(p[0], self.origin_m[0], self.width),
            i(p[1], self.origin_m[1], self.height),
        )
    }

    /// The cell holding `p`, if it is on the map.
    pub fn cell_of(&self, p: [f64; 2]) -> Option<(usize, usize)> {
        let fx = (p[0] - self.origin_m[0]) / self.resolution_m;
        let fy = (p[1] - self.origin_m[1]) / self.resolution_m;
        let on = fx >= 0.0 && fy >= 0.0 && fx < self.width as f64 && fy < self.height as f64;
        on.then_some((fx as usize, fy as usize))
    }

    pub fn get(&self, ix: usize, iy: usize) -> Cell {
        self.cells[iy * self.width + ix]
    }

    pub fn set(&mut self, ix: usize, iy: usize, c: Cell) {
        self.cells[iy * self.width + ix] = c;
    }

    /// Whether `p` lies on the map in a free cell.
    pub fn is_free(&self, p: [f64; 2]) -> bool {
        self.cell_of(p)
            .is_some_and(|(ix, iy)| self.get(ix, iy) == Cell::Free)
    }

    /// Whether every cell the segment `a`–`b` passes through is free (Amanatides & Woo's
    /// traversal: each crossed cell once, not dense point samples that can skip corners).
    pub fn segment_free(&self, a: [f64; 2], b: [f64; 2]) -> bool {
        let (Some(start), Some(end)) = (self.cell_of(a), self.cell_of(b)) else {
            return false;
        };
        let (mut ix, mut iy) = (start.0 as i64, start.1 as i64);
        let d = [b[0] - a[0], b[1] - a[1]];
        let step = d.map(|v| if v > 0.0 { 1_i64 } else { -1 });
        let r = self.resolution_m;
        // Parameter t along the segment at the next vertical / horizontal cell boundary,
        // and the increment of t per cell.
        let boundary = |i: i64, s: i64, o: f64| o + (i + i64::from(s > 0)) as f64 * r;
        let next = |i: i64, s: i64, o: f64, p: f64, dv: f64| {
            if dv == 0.0 {
                f64::INFINITY
            } else {
                (boundary(i, s, o) - p) / dv
            }
        };
        let mut t_max = [
            next(ix, step[0], self.origin_m[0], a[0], d[0]),
            next(iy, step[1], self.origin_m[1], a[1], d[1]),
        ];
        let t_delta = d.map(|v| if v == 0.0 { f64::INFINITY } else { r / v.abs() });
        let end = (end.0 as i64, end.1 as i64);
        // The segment crosses exactly this many cell boundaries on its way to `end`.
        let crossings = (end.0 - ix).abs() + (end.1 - iy).abs();
        for _ in 0..crossings {
            if self.get(ix as usize, iy as usize) != Cell::Free {
                return false;
            }
            if t_max[0] < t_max[1] {
                ix += step[0];
                t_max[0] += t_delta[0];
            } else {
                iy += step[1];
                t_max[1] += t_delta[1];
            }
            if ix < 0 || iy < 0 || ix >= self.width as i64 || iy >= self.height as i64 {
                return false;
            }
        }
        self.get(end.0 as usize, end.1 as usize) == Cell::Free
    }

    /// Lower-left and upper-right corners of the map.
    /// The grid as a recording signal: free 0, occupied 100, unknown 50.
    pub fn to_signal(&self) -> forkbench_core::signal::Grid {
        forkbench_core::signal::Grid {
            origin_m: self.origin_m,
            cell_m: self.resolution_m,
            cols: self.width,
            rows: self.height,
            cells: self
                .cells
                .iter()
                .map(|c| match c {
                    Cell::Free => 0,
                    Cell::Occupied => 100,
                    Cell::Unknown => 50,
                })
                .collect(),
        }
    }

    pub fn extent(&self) -> ([f64; 2], [f64; 2]) {
        let o = self.origin_m;
        let r = self.resolution_m;
        (
            o,
            [o[0] + self.width as f64 * r, o[1] + self.height as f64 * r],
        )
    }

    /// Cells by state: (free, occupied, unknown).
    pub fn counts(&self) -> (usize, usize, usize) {
        self.cells.iter().fold((0, 0, 0), |(f, o, u), c| match c {
            Cell::Free => (f + 1, o, u),
            Cell::Occupied => (f, o + 1, u),
            Cell::Unknown => (f, o, u + 1),
        })
    }
}

/// Lower-left and upper-right of `points`, or `None` for none.
fn bounds(points: &[[f64; 2]]) -> Option<([f64; 2], [f64; 2])> {
    let first = *points.first()?;
    Some(points.iter().fold((first, first), |(lo, hi), p| {
        (
            [lo[0].min(p[0]), lo[1].min(p[1])],
            [hi[0].max(p[0]), hi[1].max(p[1])],
        )
    }))
}

/// Whether two convex quadrilaterals overlap with positive area (a rack whose side lies on
/// a cell edge does not occupy the cell beyond it): no separating axis among their edge
/// normals.
fn overlaps(a: &[[f64; 2]; 4], b: &[[f64; 2]; 4]) -> bool {
    let separated_along = |poly: &[[f64; 2]; 4]| {
        (0..4).any(|i| {
            let (p, q) = (poly[i], poly[(i + 1) % 4]);
            let n = [q[1] - p[1], p[0] - q[0]];
            let project = |s: &[[f64; 2]; 4]| {
                s.iter()
                    .map(|v| v[0] * n[0] + v[1] * n[1])
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                        (lo.min(x), hi.max(x))
                    })
            };
            let (a0, a1) = project(a);
            let (b0, b1) = project(b);
            a1 <= b0 + 1e-9 || b1 <= a0 + 1e-9
        })
    };
    !separated_along(a) && !separated_along(b)
}
