//! Path figures like the papers' figures 6–8: the path (with control polygon), curvature and steering vs s.

use std::path::Path as FsPath;

use forkbench_core::{ForkliftSpec, Path};
use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use crate::Result;
use crate::figure::{err, series_colour, to_file};

/// One path to draw.
#[derive(Debug)]
pub struct Series<'a> {
    pub label: String,
    pub path: &'a Path,
    pub control_polygon: Option<Vec<[f64; 2]>>,
}

/// Draws to FILE; the format follows the extension (.svg or .png).
pub fn draw_plans(
    file: &FsPath,
    title: &str,
    series: &[Series],
    truck: &ForkliftSpec,
) -> Result<()> {
    to_file(
        file,
        (1400, 800),
        |a| draw(a, title, series, truck),
        |a| draw(a, title, series, truck),
    )
}

/// One curvature-derived panel: caption, y label, limit line, and κ ↦ plotted value.
type Panel<'a> = (&'a str, &'a str, f64, Box<dyn Fn(f64) -> f64 + 'a>);

fn draw<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    title: &str,
    series: &[Series],
    truck: &ForkliftSpec,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(err)?;
    let root = root.titled(title, ("sans-serif", 24)).map_err(err)?;
    let (left, right) = root.split_horizontally(700);
    let right_parts = right.split_evenly((2, 1));
    draw_path_panel(&left, series)?;
    draw_curvature_panels(&right_parts, series, truck)?;
    root.present().map_err(err)?;
    Ok(())
}

/// An arrow of length `len` from `at` along `heading`: its shaft and its head.
type Polyline = Vec<(f64, f64)>;

fn arrow(at: [f64; 2], heading: f64, len: f64) -> (Polyline, Polyline) {
    let (s, c) = heading.sin_cos();
    let tip = (at[0] + len * c, at[1] + len * s);
    let back = 0.35 * len;
    let side = 0.18 * len;
    let base = (tip.0 - back * c, tip.1 - back * s);
    let head = vec![
        tip,
        (base.0 - side * s, base.1 + side * c),
        (base.0 + side * s, base.1 - side * c),
    ];
    (vec![(at[0], at[1]), base], head)
}

/// The paths in the plane, equal axis scales, with control polygons and a legend when
/// there are several.
fn draw_path_panel<DB: DrawingBackend>(
    left: &DrawingArea<DB, Shift>,
    series: &[Series],
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let label = |s: &Series| {
        if series.len() > 1 {
            s.label.clone()
        } else {
            String::new()
        }
    };

    let (cx, cy, half) = square_bounds(series);
    let mut chart = ChartBuilder::on(left)
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(50)
        .caption("path (m)", ("sans-serif", 18))
        .build_cartesian_2d((cx - half)..(cx + half), (cy - half)..(cy + half))
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("x (m)")
        .y_desc("y (m)")
        .draw()
        .map_err(err)?;
    for (i, s) in series.iter().enumerate() {
        let color = series_colour(i, series.len());
        let line = chart
            .draw_series(LineSeries::new(
                s.path.samples.iter().map(|p| (p.x_m, p.y_m)),
                color.stroke_width(2),
            ))
            .map_err(err)?;
        if series.len() > 1 {
            line.label(label(s)).legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 16, y)], color.stroke_width(2))
            });
        }
        if let Some(poly) = &s.control_polygon {
            chart
                .draw_series(LineSeries::new(
                    poly.iter().map(|p| (p[0], p[1])),
                    color.mix(0.5),
                ))
                .map_err(err)?;
            chart
                .draw_series(
                    poly.iter()
                        .map(|p| Circle::new((p[0], p[1]), 3, color.filled())),
                )
                .map_err(err)?;
        }
    }
    draw_end_arrows(&mut chart, series, half)?;
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .position(SeriesLabelPosition::UpperLeft)
        .draw()
        .map_err(err)?;

    Ok(())
}

/// Curvature and equivalent steering against arc length, with the truck's limits.
fn draw_curvature_panels<DB: DrawingBackend>(
    right_parts: &[DrawingArea<DB, Shift>],
    series: &[Series],
    truck: &ForkliftSpec,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    // Curvature and steering against arc length, with the truck's limits.
    let s_max = series.iter().map(|s| s.path.length_m()).fold(0.1, f64::max);
    let k_lim = truck.max_curvature_per_m();
    let panels: [Panel; 2] = [
        ("curvature vs s", "κ (1/m)", k_lim, Box::new(|k| k)),
        (
            "equivalent steering vs s",
            "α (rad)",
            truck.max_steer_rad,
            Box::new(|k| truck.steer_for_curvature(k)),
        ),
    ];
    for (area, (caption, ylabel, limit, map)) in right_parts.iter().zip(panels) {
        let peak = series
            .iter()
            .flat_map(|s| s.path.samples.iter().map(|p| map(p.curvature_per_m).abs()))
            .fold(0.0, f64::max);
        // The limit always shows, so the plot says how far below it the path stays.
        let y = (peak * 1.15).max(limit * 1.08);
        let mut chart = ChartBuilder::on(area)
            .margin(15)
            .x_label_area_size(35)
            .y_label_area_size(55)
            .caption(caption, ("sans-serif", 18))
            .build_cartesian_2d(0.0..s_max, -y..y)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("s (m)")
            .y_desc(ylabel)
            .draw()
            .map_err(err)?;
        for (i, s) in series.iter().enumerate() {
            let color = series_colour(i, series.len());
            chart
                .draw_series(LineSeries::new(
                    s.path
                        .samples
                        .iter()
                        .map(|p| (p.s_m, map(p.curvature_per_m))),
                    color.stroke_width(2),
                ))
                .map_err(err)?;
        }
        for (i, l) in [limit, -limit].into_iter().enumerate() {
            let line = chart
                .draw_series(LineSeries::new([(0.0, l), (s_max, l)], RED.mix(0.6)))
                .map_err(err)?;
            if i == 0 {
                line.label(format!("truck limit ±{limit:.3}"))
                    .legend(|(x, y)| PathElement::new([(x, y), (x + 16, y)], RED.mix(0.6)));
            }
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(SeriesLabelPosition::LowerRight)
            .draw()
            .map_err(err)?;
    }
    Ok(())
}

/// Centre and half-side of a square around every path sample and control point, with a margin.
fn square_bounds(series: &[Series]) -> (f64, f64, f64) {
    let pts = series.iter().flat_map(|s| {
        s.path
            .samples
            .iter()
            .map(|p| (p.x_m, p.y_m))
            .chain(s.control_polygon.iter().flatten().map(|p| (p[0], p[1])))
    });
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for (x, y) in pts {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    if x0 > x1 {
        (x0, x1, y0, y1) = (0.0, 1.0, 0.0, 1.0);
    }
    let (cx, cy) = ((x0 + x1) / 2.0, (y0 + y1) / 2.0);
    let half = ((x1 - x0).max(y1 - y0) / 2.0 + 0.3).max(0.5);
    (cx, cy, half)
}

/// Arrows at the first series' start and goal poses, with legend entries.
fn draw_end_arrows<'a, DB: DrawingBackend + 'a>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    series: &[Series],
    half: f64,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let Some(first) = series.first() else {
        return Ok(());
    };
    {
        let ends = [first.path.samples.first(), first.path.samples.last()];
        let len = 0.12 * half;
        for ((p, colour), name) in ends.into_iter().zip([BLACK, GREEN]).zip(["start", "goal"]) {
            let Some(p) = p else { continue };
            let (shaft, head) = arrow([p.x_m, p.y_m], p.heading_rad, len);
            chart
                .draw_series([Polygon::new(head, colour.filled())])
                .map_err(err)?;
            chart
                .draw_series(LineSeries::new(shaft, colour.stroke_width(3)))
                .map_err(err)?
                .label(if series.len() > 1 && name == "goal" {
                    format!("goal pose ({})", first.label)
                } else {
                    format!("{name} pose")
                })
                .legend(move |(x, y)| {
                    PathElement::new([(x, y), (x + 16, y)], colour.stroke_width(3))
                });
        }
    }
    Ok(())
}
