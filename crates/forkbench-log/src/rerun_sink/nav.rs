//! A mission's navigation layer in the map: the occupancy grid's blocked cells, the roadmap, and each leg's A* polyline and smoothed path.

use forkbench_nav::OccupancyGrid;
use forkbench_trial::recorder::RouteRecord;

use super::RerunRecorder;
use super::columns::{color, rgba, strip};
use super::layout::*;

impl RerunRecorder {
    /// The grid's blocked cells, merged into rectangles, once for the whole recording.
    pub(super) fn draw_nav_map(&mut self, grid: &OccupancyGrid) {
        let rects = forkbench_nav::blocked_rects(grid);
        let boxes = rerun::Boxes2D::from_mins_and_sizes(
            rects.iter().map(|[lo, _]| [lo[0] as f32, lo[1] as f32]),
            rects
                .iter()
                .map(|[lo, hi]| [(hi[0] - lo[0]) as f32, (hi[1] - lo[1]) as f32]),
        )
        .with_colors([rgba(OCCUPIED_RGBA)])
        .with_radii([0.01])
        .with_draw_order(ORDER_GRID);
        let r = self.rec.log_static("map/nav/occupied", &boxes);
        self.note(r);
        // The metre grid grows from the trial's frame to the whole map.
        let (lo, hi) = grid.extent();
        let frame = super::scene::Frame::around([lo, hi]);
        let mirror = rerun::Transform3D::from_scale([1.0, -1.0, 1.0]);
        let lines = rerun::LineStrips2D::new(frame.grid())
            .with_colors([rgba(GRID_RGBA)])
            .with_radii([0.008])
            .with_draw_order(ORDER_GRID);
        let r = self
            .rec
            .log_static("map", &[&mirror as &dyn rerun::AsComponents, &lines]);
        self.note(r);
        self.draw_racks(&frame);
    }

    /// A leg's roadmap (replacing the last leg's), polyline and smoothed path.
    pub(super) fn draw_route(&mut self, t_s: f64, route: &RouteRecord<'_>) {
        self.at(t_s);
        if let Some(map) = route.roadmap {
            let (nodes, edges) = (&map.nodes, &map.edges);
            let lines: Vec<Vec<[f32; 2]>> = edges
                .iter()
                .enumerate()
                .flat_map(|(i, nb)| {
                    nb.iter()
                        .filter(move |(j, _)| *j > i)
                        .map(move |(j, _)| strip(&[nodes[i], nodes[*j]]))
                })
                .collect();
            let edges = rerun::LineStrips2D::new(lines)
                .with_colors([rgba(ROADMAP_RGBA)])
                .with_radii([0.006])
                .with_draw_order(ORDER_GRID);
            let points = rerun::Points2D::new(strip(nodes))
                .with_colors([rgba(ROADMAP_RGBA)])
                .with_radii([0.04])
                .with_draw_order(ORDER_GRID);
            let r = self.rec.log(
                "map/nav/roadmap",
                &[&edges as &dyn rerun::AsComponents, &points],
            );
            self.note(r);
        }
        let path: Vec<[f64; 2]> = route.path.samples.iter().map(|p| [p.x_m, p.y_m]).collect();
        if route.path.reverse {
            let lines = rerun::LineStrips2D::new([strip(&path)])
                .with_colors([color(REVERSE_RGB)])
                .with_radii([0.03])
                .with_draw_order(ORDER_PLAN);
            let r = self
                .rec
                .log(format!("map/nav/route/{}/reverse", route.leg), &lines);
            self.note(r);
            return;
        }
        let lines = rerun::LineStrips2D::new([strip(route.polyline), strip(&path)])
            .with_colors([color(ROUTE_RGB), color(SMOOTHED_RGB)])
            .with_radii([0.012, 0.03])
            .with_draw_order(ORDER_PLAN);
        let corners = rerun::Points2D::new(strip(route.polyline))
            .with_colors([color(ROUTE_RGB)])
            .with_radii([0.06])
            .with_draw_order(ORDER_PLAN);
        let r = self.rec.log(
            format!("map/nav/route/{}", route.leg),
            &[&lines as &dyn rerun::AsComponents, &corners],
        );
        self.note(r);
    }
}
