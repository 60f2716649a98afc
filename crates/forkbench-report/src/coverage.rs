//! The reflector-coverage heatmap: a NAV350 fix's predicted 1σ over a world's free cells.

use std::path::Path;

use forkbench_studies::coverage::Coverage;
use forkbench_trial::World;
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::Result;
use crate::figure::{err, to_file};

/// The σ the colour scale saturates at.
const SCALE_MAX_M: f64 = 0.010;

/// Draws the heatmap of `cov` over `world` with its racks, walls and reflectors to FILE
/// (.svg or .png); `missing` are the reflectors left out (red crosses).
pub fn draw_coverage(
    file: &Path,
    world: &World,
    cov: &Coverage,
    missing: &[[f64; 2]],
) -> Result<()> {
    let [lo, hi] = cov.bounds;
    let width = 1400u32;
    let height =
        ((f64::from(width - 160) * (hi[1] - lo[1]) / (hi[0] - lo[0])) as u32 + 90).clamp(300, 2000);
    let gone = if missing.is_empty() {
        String::new()
    } else {
        format!(", {} missing", missing.len())
    };
    let title = format!(
        "{}: NAV350 fix 1σ with {} reflectors{gone} (grey: fewer than 3 in sight)",
        forkbench_trial::text::one_line(&world.name),
        world.reflector.len()
    );
    let obstacles: Vec<[[f64; 2]; 4]> = world
        .obstacles()
        .iter()
        .map(forkbench_core::geometry::Obstacle::corners)
        .collect();
    let fig = Figure {
        title: &title,
        cov,
        obstacles: &obstacles,
        reflectors: &world
            .reflector
            .iter()
            .map(|r| [r.x_m, r.y_m])
            .collect::<Vec<_>>(),
        missing,
    };
    to_file(file, (width, height), |d| draw(d, &fig), |d| draw(d, &fig))
}

struct Figure<'a> {
    title: &'a str,
    cov: &'a Coverage,
    /// Racks and walls, as corners.
    obstacles: &'a [[[f64; 2]; 4]],
    reflectors: &'a [[f64; 2]],
    /// Reflectors left out (drawn as red crosses).
    missing: &'a [[f64; 2]],
}

/// Blue (good) through yellow to red (the scale's top).
fn colour(sigma_m: f64) -> RGBColor {
    let t = (sigma_m / SCALE_MAX_M).clamp(0.0, 1.0);
    let lerp = |a: f64, b: f64, u: f64| (a + (b - a) * u) as u8;
    if t < 0.5 {
        let u = t / 0.5;
        RGBColor(
            lerp(40.0, 250.0, u),
            lerp(90.0, 220.0, u),
            lerp(200.0, 60.0, u),
        )
    } else {
        let u = (t - 0.5) / 0.5;
        RGBColor(250, lerp(220.0, 40.0, u), lerp(60.0, 30.0, u))
    }
}

fn draw<DB: DrawingBackend>(area: DrawingArea<DB, Shift>, fig: &Figure) -> Result<()>
where
    DB::ErrorType: 'static,
{
    area.fill(&WHITE).map_err(err)?;
    let (map_area, key_area) = area.split_horizontally(area.dim_in_pixel().0 - 150);
    let [lo, hi] = fig.cov.bounds;
    let mut chart = ChartBuilder::on(&map_area)
        .caption(fig.title, ("sans-serif", 20))
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
    let h = fig.cov.resolution_m / 2.0;
    chart
        .draw_series(fig.cov.cells.iter().map(|c| {
            let fill = c.sigma_m.map_or(RGBColor(200, 200, 200), colour);
            Rectangle::new(
                [(c.x_m - h, c.y_m - h), (c.x_m + h, c.y_m + h)],
                fill.filled(),
            )
        }))
        .map_err(err)?;
    chart
        .draw_series(fig.obstacles.iter().map(|k| {
            Polygon::new(
                k.map(|p| (p[0], p[1])).to_vec(),
                RGBColor(40, 40, 40).filled(),
            )
        }))
        .map_err(err)?;
    chart
        .draw_series(
            fig.reflectors
                .iter()
                .map(|p| TriangleMarker::new((p[0], p[1]), 7, BLACK.filled())),
        )
        .map_err(err)?
        .label("reflector")
        .legend(|(x, y)| TriangleMarker::new((x + 8, y), 5, BLACK.filled()));
    if !fig.missing.is_empty() {
        chart
            .draw_series(
                fig.missing
                    .iter()
                    .map(|p| Cross::new((p[0], p[1]), 7, RED.stroke_width(3))),
            )
            .map_err(err)?
            .label("missing reflector")
            .legend(|(x, y)| Cross::new((x + 8, y), 5, RED.stroke_width(3)));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(err)?;
    draw_key(&key_area)
}

/// The colour scale: σ in millimetres.
fn draw_key<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let mut key = ChartBuilder::on(area)
        .margin_top(60)
        .margin_bottom(60)
        .margin_right(20)
        .y_label_area_size(50)
        .caption("1σ (mm)", ("sans-serif", 16))
        .build_cartesian_2d(0.0..1.0, 0.0..1e3 * SCALE_MAX_M)
        .map_err(err)?;
    key.configure_mesh()
        .disable_x_mesh()
        .disable_x_axis()
        .draw()
        .map_err(err)?;
    let steps = 50;
    let dy = 1e3 * SCALE_MAX_M / f64::from(steps);
    key.draw_series((0..steps).map(|k| {
        let y = f64::from(k) * dy;
        Rectangle::new(
            [(0.0, y), (1.0, y + dy)],
            colour((y + dy / 2.0) / 1e3).filled(),
        )
    }))
    .map_err(err)?;
    Ok(())
}
