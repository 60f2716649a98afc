//! The fixed part of the map: the frame around start and pallet, its metre grid, the racks inside it, start and initial pallet.

use forkbench_core::Pose2;
use forkbench_core::geometry::rect_outline;
use forkbench_trial::SceneInfo;

use super::RerunRecorder;
use super::columns::{color, rgba, strip};
use super::layout::*;
use crate::{pallet_outlines, truck_outlines};

/// Space left around the truck's start and the pallet, so the drive between them and a
/// truck that overshoots stay inside the frame.
const FRAME_MARGIN_M: f64 = 2.0;

/// An axis-aligned rectangle of the map, whole metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Frame {
    pub min: [f64; 2],
    pub max: [f64; 2],
}

impl Frame {
    /// The whole-metre rectangle around `points`, with the margin.
    pub fn around(points: impl IntoIterator<Item = [f64; 2]>) -> Self {
        let (mut min, mut max) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in points {
            for i in 0..2 {
                min[i] = min[i].min(p[i]);
                max[i] = max[i].max(p[i]);
            }
        }
        Self {
            min: min.map(|v| (v - FRAME_MARGIN_M).floor()),
            max: max.map(|v| (v + FRAME_MARGIN_M).ceil()),
        }
    }

    /// Grid lines every metre across the frame.
    pub fn grid(&self) -> Vec<Vec<[f32; 2]>> {
        let [x0, y0] = self.min;
        let [x1, y1] = self.max;
        let xs =
            (x0 as i64..=x1 as i64).map(|x| vec![[x as f32, y0 as f32], [x as f32, y1 as f32]]);
        let ys =
            (y0 as i64..=y1 as i64).map(|y| vec![[x0 as f32, y as f32], [x1 as f32, y as f32]]);
        xs.chain(ys).collect()
    }

    /// `polygon` clipped to the frame (Sutherland–Hodgman; the outlines are convex), closed;
    /// `None` when nothing of it is inside.
    pub fn clip(&self, polygon: &[[f64; 2]]) -> Option<Vec<[f64; 2]>> {
        let mut pts: Vec<[f64; 2]> = polygon.to_vec();
        if pts.first() == pts.last() {
            pts.pop();
        }
        // (axis, bound, keep the side above the bound)
        let edges = [
            (0, self.min[0], true),
            (0, self.max[0], false),
            (1, self.min[1], true),
            (1, self.max[1], false),
        ];
        for (axis, bound, above) in edges {
            let inside = |p: &[f64; 2]| {
                if above {
                    p[axis] >= bound
                } else {
                    p[axis] <= bound
                }
            };
            let mut out = Vec::with_capacity(pts.len() + 2);
            for (i, cur) in pts.iter().enumerate() {
                let prev = pts[(i + pts.len() - 1) % pts.len()];
                if inside(cur) != inside(&prev) {
                    let t = (bound - prev[axis]) / (cur[axis] - prev[axis]);
                    out.push([
                        prev[0] + t * (cur[0] - prev[0]),
                        prev[1] + t * (cur[1] - prev[1]),
                    ]);
                }
                if inside(cur) {
                    out.push(*cur);
                }
            }
            pts = out;
            if pts.is_empty() {
                return None;
            }
        }
        pts.push(pts[0]);
        Some(pts)
    }
}

impl RerunRecorder {
    /// Logs the map's fixed content. Everything sits under `map`, whose transform mirrors y:
    /// the 2D view draws in image coordinates (y down), so the mirror makes the map read as
    /// a plan view (y up, left turns to the left).
    pub(super) fn draw_scene(&mut self, s: &SceneInfo<'_>) {
        let mirror = rerun::Transform3D::from_scale([1.0, -1.0, 1.0]);
        let truck0 = truck_outlines(s.truck, &s.start);
        let pallet0 = pallet_outlines(s.pallet, &s.pallet_pose);
        let frame = Frame::around(truck0.iter().chain(&pallet0).flatten().copied());
        // Each entity costs rerun a chunk to encode, so fixed things that belong together
        // share one: the metre grid rides on the mirrored `map` itself, the start arrow on
        // the pallet's initial outline.
        let grid = rerun::LineStrips2D::new(frame.grid())
            .with_colors([rgba(GRID_RGBA)])
            .with_radii([0.008])
            .with_draw_order(ORDER_GRID);
        let r = self
            .rec
            .log_static("map", &[&mirror as &dyn rerun::AsComponents, &grid]);
        self.note(r);
        self.obstacle_outlines = s
            .obstacles
            .iter()
            .map(|o| rect_outline(&o.centre, o.length_m, o.width_m))
            .collect();
        self.draw_racks(&frame);
        let pallet = rerun::LineStrips2D::new(pallet0.iter().map(|c| strip(c)))
            .with_colors([rgba(PALLET_INITIAL_RGBA)])
            .with_radii([0.012])
            .with_draw_order(ORDER_WORLD);
        let start = pose_arrow(&s.start, START_RGB);
        let r = self.rec.log_static(
            "map/initial",
            &[&pallet as &dyn rerun::AsComponents, &start],
        );
        self.note(r);
    }
}

impl RerunRecorder {
    /// The racks and walls, clipped to `frame`.
    pub(super) fn draw_racks(&mut self, frame: &Frame) {
        let racks: Vec<Vec<[f32; 2]>> = self
            .obstacle_outlines
            .iter()
            .filter_map(|o| frame.clip(o))
            .map(|c| strip(&c))
            .collect();
        if !racks.is_empty() {
            let racks = rerun::LineStrips2D::new(racks)
                .with_colors([color(RACK_RGB)])
                .with_radii([0.03])
                .with_draw_order(ORDER_WORLD);
            let r = self.rec.log_static("map/world/racks", &racks);
            self.note(r);
        }
    }
}

/// A 0.6 m arrow along a pose's heading (start and goal markers).
pub(super) fn pose_arrow(p: &Pose2, rgb: [u8; 3]) -> rerun::Arrows2D {
    let (sin, cos) = p.heading_rad.sin_cos();
    rerun::Arrows2D::from_vectors([[(0.6 * cos) as f32, (0.6 * sin) as f32]])
        .with_origins([[p.x_m as f32, p.y_m as f32]])
        .with_colors([color(rgb)])
        .with_radii([0.035])
        .with_draw_order(ORDER_MARKERS)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_frame_is_whole_metres_around_the_points_with_the_margin() {
        let f = Frame::around([[0.3, -0.2], [8.4, 1.1]]);
        assert_eq!(f.min, [-2.0, -3.0]);
        assert_eq!(f.max, [11.0, 4.0]);
        assert_eq!(f.grid().len(), 14 + 8);
    }

    #[test]
    fn outlines_are_clipped_to_the_frame() {
        let f = Frame {
            min: [0.0, 0.0],
            max: [10.0, 10.0],
        };
        let inside = [[1.0, 1.0], [2.0, 1.0], [2.0, 2.0], [1.0, 2.0], [1.0, 1.0]];
        assert_eq!(f.clip(&inside).as_deref(), Some(&inside[..]));
        assert_eq!(
            f.clip(&[[20.0, 1.0], [30.0, 1.0], [30.0, 2.0], [20.0, 1.0]]),
            None
        );
        let across = [[8.0, 1.0], [12.0, 1.0], [12.0, 2.0], [8.0, 2.0], [8.0, 1.0]];
        let c = f.clip(&across).expect("part inside");
        assert!(c.iter().all(|p| p[0] <= 10.0 && p[0] >= 8.0), "{c:?}");
        assert_eq!(c.first(), c.last());
        assert_eq!(c.len(), 5);
    }
}
