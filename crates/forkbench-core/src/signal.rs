//! The open recording vocabulary: a few typed signals that any component sends at a path and a time, and sinks draw without knowing the domain.
//!
//! A sink maps each kind to one of its own types (rerun archetypes, Foxglove schemas),
//! so a new sensor, phase or planner records itself by choosing a path and a kind; no
//! trait or sink changes. Coordinates are map metres, angles radians.

use crate::Pose2;

/// One thing to record. Borrowed, so sending costs nothing when no sink listens.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Signal<'a> {
    /// A planar pose, drawn as an arrow along its heading.
    Pose(Pose2),
    /// A polyline (open), e.g. a route.
    Path(&'a [[f64; 2]]),
    /// Separate segments, e.g. a roadmap's edges.
    Segments(&'a [[[f64; 2]; 2]]),
    /// Points, e.g. sampled nodes or detected stringer edges.
    Points(&'a [[f64; 2]]),
    /// Axis-aligned boxes as (lower-left, upper-right) corners, e.g. blocked cells.
    Boxes(&'a [[[f64; 2]; 2]]),
    /// A planar range scan.
    Scan(&'a Scan),
    /// An occupancy grid.
    Grid(&'a Grid),
    /// A number, plotted over time; the path names the series.
    Scalar(f64),
    /// A line of text, e.g. a phase starting.
    Text(&'a str),
}

impl Signal<'_> {
    /// The kind's name, for messages and tests.
    pub fn kind(&self) -> &'static str {
        match self {
            Signal::Pose(_) => "pose",
            Signal::Path(_) => "path",
            Signal::Segments(_) => "segments",
            Signal::Points(_) => "points",
            Signal::Boxes(_) => "boxes",
            Signal::Scan(_) => "scan",
            Signal::Grid(_) => "grid",
            Signal::Scalar(_) => "scalar",
            Signal::Text(_) => "text",
        }
    }
}

/// A planar scan: beams at equal angular steps from the sensor's pose in the map.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Scan {
    /// The sensor's pose in the map when it scanned.
    pub sensor: Pose2,
    /// First beam's angle in the sensor's frame, and the step between beams.
    pub angle_min_rad: f64,
    pub angle_step_rad: f64,
    /// Range limits: a return outside them is no return.
    pub range_min_m: f64,
    pub range_max_m: f64,
    /// One range per beam; NaN where the beam returned nothing.
    pub ranges_m: Vec<f64>,
}

impl Scan {
    /// The returns as map points (beams without a return left out).
    pub fn points(&self) -> Vec<[f64; 2]> {
        self.ranges_m
            .iter()
            .enumerate()
            .filter(|(_, r)| r.is_finite())
            .map(|(i, r)| {
                let a =
                    self.sensor.heading_rad + self.angle_min_rad + i as f64 * self.angle_step_rad;
                [self.sensor.x_m + r * a.cos(), self.sensor.y_m + r * a.sin()]
            })
            .collect()
    }
}

/// An occupancy grid: `cols` × `rows` cells of `cell_m`, row-major from the lower-left
/// corner at `origin_m`; 0 free, 100 occupied, between for cost or inflation.
#[derive(Debug, Clone, PartialEq)]
pub struct Grid {
    pub origin_m: [f64; 2],
    pub cell_m: f64,
    pub cols: usize,
    pub rows: usize,
    pub cells: Vec<u8>,
}

impl Grid {
    /// The non-free cells merged into few rectangles (lower-left, upper-right).
    pub fn blocked_rects(&self) -> Vec<[[f64; 2]; 2]> {
        merge_cells(
            (self.cols, self.rows),
            |ix, iy| self.cells.get(iy * self.cols + ix).is_some_and(|&c| c > 0),
            self.origin_m,
            self.cell_m,
        )
    }

    /// Its lower-left and upper-right corners.
    pub fn extent(&self) -> [[f64; 2]; 2] {
        let [x, y] = self.origin_m;
        [
            [x, y],
            [
                x + self.cols as f64 * self.cell_m,
                y + self.rows as f64 * self.cell_m,
            ],
        ]
    }
}

/// How a sink draws a signal; sinks choose their own defaults for what is not set.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Style {
    /// Colour as 8-bit RGBA.
    pub rgba: Option<[u8; 4]>,
    /// Line width or point diameter in metres.
    pub width_m: Option<f64>,
}

impl Style {
    pub const fn rgb(r: u8, g: u8, b: u8) -> Self {
        Self {
            rgba: Some([r, g, b, 255]),
            width_m: None,
        }
    }

    pub const fn rgba(rgba: [u8; 4]) -> Self {
        Self {
            rgba: Some(rgba),
            width_m: None,
        }
    }

    pub const fn width(self, width_m: f64) -> Self {
        Self {
            width_m: Some(width_m),
            ..self
        }
    }
}

/// Cells for which `blocked(ix, iy)` holds, as few rectangles (lower-left, upper-right):
/// runs of cells along rows, merged with identical runs in the rows above.
pub fn merge_cells(
    (cols, rows): (usize, usize),
    blocked: impl Fn(usize, usize) -> bool,
    origin_m: [f64; 2],
    cell_m: f64,
) -> Vec<[[f64; 2]; 2]> {
    // Open rectangles keyed by their run: (first cell, last cell) → first row.
    let mut open: std::collections::BTreeMap<(usize, usize), usize> = Default::default();
    let mut out = Vec::new();
    for iy in 0..=rows {
        let runs = if iy < rows {
            row_runs(cols, |ix| blocked(ix, iy))
        } else {
            Vec::new()
        };
        let ended: Vec<_> = open.keys().filter(|k| !runs.contains(k)).copied().collect();
        for (x0, x1) in ended {
            let y0 = open.remove(&(x0, x1)).unwrap_or(iy);
            out.push([
                [
                    origin_m[0] + x0 as f64 * cell_m,
                    origin_m[1] + y0 as f64 * cell_m,
                ],
                [
                    origin_m[0] + (x1 + 1) as f64 * cell_m,
                    origin_m[1] + iy as f64 * cell_m,
                ],
            ]);
        }
        for k in runs {
            open.entry(k).or_insert(iy);
        }
    }
    out
}

/// The runs of blocked cells in one row, as (first, last) column.
fn row_runs(cols: usize, blocked: impl Fn(usize) -> bool) -> Vec<(usize, usize)> {
    let mut runs = Vec::new();
    let mut start = None;
    for ix in 0..=cols {
        match (ix < cols && blocked(ix), start) {
            (true, None) => start = Some(ix),
            (false, Some(s)) => {
                runs.push((s, ix - 1));
                start = None;
            }
            _ => {}
        }
    }
    runs
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_l_shape_merges_into_two_rectangles() {
        // Row 0: cells 0..=2 blocked; row 1: cell 0 only.
        let g = Grid {
            origin_m: [10.0, 20.0],
            cell_m: 0.5,
            cols: 3,
            rows: 2,
            cells: vec![100, 100, 100, 100, 0, 0],
        };
        let r = g.blocked_rects();
        assert_eq!(
            r,
            vec![[[10.0, 20.0], [11.5, 20.5]], [[10.0, 20.5], [10.5, 21.0]]]
        );
        assert_eq!(g.extent(), [[10.0, 20.0], [11.5, 21.0]]);
    }

    #[test]
    fn scan_points_leave_out_beams_without_a_return() {
        let s = Scan {
            sensor: Pose2::new(1.0, 0.0, std::f64::consts::FRAC_PI_2),
            angle_min_rad: -std::f64::consts::FRAC_PI_2,
            angle_step_rad: std::f64::consts::FRAC_PI_2,
            range_min_m: 0.05,
            range_max_m: 10.0,
            ranges_m: vec![2.0, f64::NAN, 3.0],
        };
        let p = s.points();
        assert_eq!(p.len(), 2);
        assert!(
            (p[0][0] - 3.0).abs() < 1e-12 && p[0][1].abs() < 1e-12,
            "{p:?}"
        );
        assert!(
            (p[1][0] + 2.0).abs() < 1e-12 && p[1][1].abs() < 1e-12,
            "{p:?}"
        );
    }
}
