//! A global plan drawn on its map: obstacles, the inflated band around them, the roadmap, the path, start and goal.

use std::path::Path;

use forkbench_nav::{
    CollisionModel, GlobalPlan, GlobalPlannerKind, GlobalQuery, NavMap, OccupancyGrid, Roadmap,
};
use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use crate::Result;
use crate::figure::{err, to_file};

/// What one figure shows.
#[derive(Debug)]
pub struct MapFigure<'a> {
    pub title: String,
    /// The map as loaded, and the one the planner searched (obstacles inflated).
    pub grid: &'a OccupancyGrid,
    pub inflated: &'a OccupancyGrid,
    pub roadmap: Option<&'a Roadmap>,
    pub path: Option<&'a [[f64; 2]]>,
    /// The smoothed path, and where its swept footprint strikes an obstacle.
    pub smoothed: Option<&'a [[f64; 2]]>,
    pub strike: Option<[f64; 2]>,
    /// A Hybrid-A* manoeuvre: forward and backward segments, the truck outlined at its
    /// start, each cusp and its end.
    pub manoeuvre: Option<&'a forkbench_nav::hybrid::Manoeuvre>,
    pub truck: &'a forkbench_core::ForkliftSpec,
    pub start: [f64; 2],
    pub goal: [f64; 2],
}

/// Draws `fig` to FILE (.svg or .png), 1 m on the map the same on both axes.
pub fn draw_map(file: &Path, fig: &MapFigure) -> Result<()> {
    let (lo, hi) = fig.grid.extent();
    let (w_m, h_m) = (hi[0] - lo[0], hi[1] - lo[1]);
    let width = 1400u32;
    let height = ((f64::from(width - 80) * h_m / w_m) as u32 + 90).clamp(300, 2000);
    to_file(file, (width, height), |a| draw(a, fig), |a| draw(a, fig))
}

fn draw<DB: DrawingBackend>(area: DrawingArea<DB, Shift>, fig: &MapFigure) -> Result<()> {
    area.fill(&WHITE).map_err(err)?;
    let (lo, hi) = fig.grid.extent();
    let mut chart = ChartBuilder::on(&area)
        .caption(&fig.title, ("sans-serif", 22))
        .margin(10)
        .x_label_area_size(30)
        .y_label_area_size(40)
        .build_cartesian_2d(lo[0]..hi[0], lo[1]..hi[1])
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("x (m)")
        .y_desc("y (m)")
        .draw()
        .map_err(err)?;
    let band = RGBColor(225, 225, 225).filled();
    let solid = RGBColor(90, 90, 90).filled();
    chart
        .draw_series(
            forkbench_nav::blocked_rects(fig.inflated)
                .into_iter()
                .map(|[a, b]| Rectangle::new([(a[0], a[1]), (b[0], b[1])], band)),
        )
        .map_err(err)?;
    chart
        .draw_series(
            forkbench_nav::blocked_rects(fig.grid)
                .into_iter()
                .map(|[a, b]| Rectangle::new([(a[0], a[1]), (b[0], b[1])], solid)),
        )
        .map_err(err)?;
    if let Some(map) = fig.roadmap {
        draw_roadmap(&mut chart, map)?;
    }
    let lines = [
        (fig.path, "path", RGBColor(220, 40, 40), 3),
        (fig.smoothed, "smoothed", RGBColor(30, 90, 220), 2),
    ];
    for (points, name, colour, width) in lines {
        if let Some(p) = points {
            draw_line(&mut chart, p, name, colour.stroke_width(width))?;
        }
    }
    if let Some(m) = fig.manoeuvre {
        draw_manoeuvre(&mut chart, m, fig.truck)?;
    }
    draw_strike(&mut chart, fig.strike)?;
    for (at, name, colour) in [
        (fig.start, "start", RGBColor(30, 150, 60)),
        (fig.goal, "goal", RGBColor(230, 130, 20)),
    ] {
        chart
            .draw_series(std::iter::once(Circle::new(
                (at[0], at[1]),
                7,
                colour.filled(),
            )))
            .map_err(err)?
            .label(name)
            .legend(move |(x, y)| Circle::new((x + 10, y), 5, colour.filled()));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(err)?;
    area.present().map_err(err)?;
    Ok(())
}

/// A polyline with its legend entry.
fn draw_line<DB: DrawingBackend>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    points: &[[f64; 2]],
    name: &str,
    style: ShapeStyle,
) -> Result<()> {
    chart
        .draw_series(std::iter::once(PathElement::new(
            points.iter().map(|q| (q[0], q[1])).collect::<Vec<_>>(),
            style,
        )))
        .map_err(err)?
        .label(name)
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
    Ok(())
}

/// The roadmap's edges (thin) and nodes.
fn draw_roadmap<DB: DrawingBackend>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    map: &Roadmap,
) -> Result<()> {
    let edge = RGBColor(150, 185, 235).stroke_width(1);
    let edges = map.edges.iter().enumerate().flat_map(|(i, e)| {
        e.iter()
            .filter(move |(j, _)| *j > i)
            .map(move |&(j, _)| (i, j))
    });
    chart
        .draw_series(edges.map(|(i, j)| {
            let (a, b) = (map.nodes[i], map.nodes[j]);
            PathElement::new(vec![(a[0], a[1]), (b[0], b[1])], edge)
        }))
        .map_err(err)?;
    let node = RGBColor(60, 110, 200).filled();
    chart
        .draw_series(map.nodes.iter().map(|n| Circle::new((n[0], n[1]), 2, node)))
        .map_err(err)?;
    Ok(())
}

/// Where a smoothed path's footprint strikes an obstacle.
fn draw_strike<DB: DrawingBackend>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    strike: Option<[f64; 2]>,
) -> Result<()> {
    if let Some(at) = strike {
        chart
            .draw_series(std::iter::once(Cross::new(
                (at[0], at[1]),
                9,
                BLACK.stroke_width(3),
            )))
            .map_err(err)?
            .label("footprint strikes")
            .legend(|(x, y)| Cross::new((x + 10, y), 5, BLACK.stroke_width(2)));
    }
    Ok(())
}

/// Forward segments blue, backward ones purple, and the truck's outline (chassis and
/// forks) at the start, at each cusp and at the end.
fn draw_manoeuvre<DB: DrawingBackend>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    m: &forkbench_nav::hybrid::Manoeuvre,
    truck: &forkbench_core::ForkliftSpec,
) -> Result<()> {
    let forward = RGBColor(30, 90, 220).stroke_width(3);
    let backward = RGBColor(150, 40, 170).stroke_width(3);
    let (mut fwd_label, mut back_label) = (false, false);
    for seg in &m.segments {
        let (style, name, labelled) = if seg.reverse {
            (backward, "backwards", &mut back_label)
        } else {
            (forward, "forwards", &mut fwd_label)
        };
        let line = PathElement::new(
            seg.samples
                .iter()
                .map(|p| (p.x_m, p.y_m))
                .collect::<Vec<_>>(),
            style,
        );
        let drawn = chart.draw_series(std::iter::once(line)).map_err(err)?;
        if !*labelled {
            drawn
                .label(name)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
            *labelled = true;
        }
    }
    let mut poses: Vec<forkbench_core::Pose2> = m.poses().take(1).collect();
    poses.extend(m.cusps());
    poses.extend(m.poses().last());
    let outline = BLACK.mix(0.7).stroke_width(1);
    for pose in &poses {
        for part in forkbench_nav::truck_parts(truck, 0.0) {
            let mut c: Vec<(f64, f64)> = part.corners(pose).iter().map(|p| (p[0], p[1])).collect();
            c.push(c[0]);
            chart
                .draw_series(std::iter::once(PathElement::new(c, outline)))
                .map_err(err)?;
        }
    }
    let cusps = m.cusps();
    if !cusps.is_empty() {
        chart
            .draw_series(
                cusps
                    .iter()
                    .map(|c| TriangleMarker::new((c.x_m, c.y_m), 8, RED.filled())),
            )
            .map_err(err)?
            .label("cusp (stop, change direction)")
            .legend(|(x, y)| TriangleMarker::new((x + 10, y), 5, RED.filled()));
    }
    Ok(())
}

/// Draws one global plan on its map to FILE (.svg or .png): the grid, the inflated band,
/// the roadmap, the route, its smoothing or manoeuvre, start and goal.
pub fn draw_route(
    file: &Path,
    planner: GlobalPlannerKind,
    map_file: &Path,
    map: &NavMap,
    q: &GlobalQuery,
    plan: &GlobalPlan,
) -> Result<()> {
    let route = &plan.route;
    // The length the truck would drive: the smoothed path's when there is one.
    let drivable = match &plan.smoothed {
        Some(Ok(s)) => format!(
            "{:.1} m smoothed ({:.1} m A* polyline)",
            s.path.length_m(),
            route.length_m
        ),
        _ => format!("{:.1} m A* polyline", route.length_m),
    };
    let drivable = match &plan.manoeuvre {
        Some(m) => format!(
            "{:.1} m manoeuvre, {} cusps{}",
            m.length_m,
            m.cusps().len(),
            if plan.fallback.is_some() {
                " (Hybrid-A* fallback)"
            } else {
                ""
            }
        ),
        None => drivable,
    };
    let title = match &route.points {
        Some(_) => format!("{} on {}: {drivable}", planner.name(), map_file.display()),
        None => format!("{} on {}: no path", planner.name(), map_file.display()),
    };
    let band = match q.collision {
        CollisionModel::Inflate => q.inflate_m,
        CollisionModel::Footprint => q.truck.body_width_m / 2.0 + q.margin_m,
    };
    let inflated = map.grid.inflated(band);
    let smoothed = match &plan.smoothed {
        Some(Ok(s)) => Some(s),
        _ => None,
    };
    let line: Option<Vec<[f64; 2]>> =
        smoothed.map(|s| s.path.samples.iter().map(|p| [p.x_m, p.y_m]).collect());
    let fig = MapFigure {
        title,
        grid: &map.grid,
        inflated: &inflated,
        roadmap: plan.roadmap.as_ref(),
        // A manoeuvre's own route is the manoeuvre: the point route is drawn only when
        // the manoeuvre replaced it.
        path: route.points.as_deref().filter(|_| !planner.kinodynamic()),
        smoothed: line.as_deref(),
        strike: smoothed.and_then(|s| s.hit).map(|h| [h.x_m, h.y_m]),
        manoeuvre: plan.manoeuvre.as_ref(),
        truck: &q.truck,
        start: [q.start.x_m, q.start.y_m],
        goal: [q.goal.x_m, q.goal.y_m],
    };
    draw_map(file, &fig)
}
