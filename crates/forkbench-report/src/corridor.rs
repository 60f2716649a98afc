//! Corridor-bend figures: minimum width per turning mode and angle, and the G regions at one width.

use std::path::Path as FsPath;

use forkbench_corridor::{GRegion, Mode, Vehicle, WidthRow as Row, compare};
use plotters::prelude::*;

use crate::Result;
use crate::figure::{COLORS, err, to_file};

/// Draws to FILE the G regions when there is one angle at a given width, else the
/// minimum widths against angle.
pub fn draw_corridor(
    file: &FsPath,
    v: &Vehicle,
    rows: &[Row],
    regions: Option<&[(f64, GRegion)]>,
) -> Result<()> {
    match regions {
        Some(r) => plot_regions(file, v, r),
        None => plot_widths(file, v, rows),
    }
}

fn plot_widths(file: &FsPath, v: &Vehicle, rows: &[Row]) -> Result<()> {
    to_file(
        file,
        (1000, 650),
        |a| widths_on(a, v, rows),
        |a| widths_on(a, v, rows),
    )
}

fn widths_on<DB: DrawingBackend>(
    area: DrawingArea<DB, plotters::coord::Shift>,
    v: &Vehicle,
    rows: &[Row],
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    {
        area.fill(&WHITE).map_err(err)?;
        let ws: Vec<f64> = rows.iter().filter_map(|r| r.min_width_m).collect();
        let top = ws.iter().copied().fold(v.circumscribed_m(), f64::max) * 1.05;
        let a0 = rows
            .iter()
            .map(|r| r.angle_deg)
            .fold(f64::INFINITY, f64::min);
        let a1 = rows
            .iter()
            .map(|r| r.angle_deg)
            .fold(f64::NEG_INFINITY, f64::max)
            .max(a0 + 1.0);
        let mut chart = ChartBuilder::on(&area)
            .caption(
                format!(
                    "minimum corridor width, {:.2} × {:.2} m",
                    v.length_m, v.width_m
                ),
                ("sans-serif", 22),
            )
            .margin(15)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(a0..a1, v.width_m * 0.95..top)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("bend angle θ (°)")
            .y_desc("W_min (m)")
            .draw()
            .map_err(err)?;
        for (i, mode) in Mode::ALL.iter().enumerate() {
            let pts: Vec<(f64, f64)> = rows
                .iter()
                .filter(|r| r.mode == *mode)
                .filter_map(|r| r.min_width_m.map(|w| (r.angle_deg, w)))
                .collect();
            if pts.is_empty() {
                continue;
            }
            let c = COLORS[i];
            chart
                .draw_series(LineSeries::new(pts, c.stroke_width(2)))
                .map_err(err)?
                .label(mode.name())
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], c.stroke_width(2)));
        }
        draw_references(&mut chart, v, [a0, a1])?;
        // Lower right: below the curves, which rise with the angle.
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK)
            .position(SeriesLabelPosition::LowerRight)
            .draw()
            .map_err(err)?;
        area.present().map_err(err)
    }
}

fn plot_regions(file: &FsPath, v: &Vehicle, regions: &[(f64, GRegion)]) -> Result<()> {
    let n = regions.len().max(1);
    to_file(
        file,
        (520 * n as u32, 560),
        |a| regions_on(a, v, regions),
        |a| regions_on(a, v, regions),
    )
}

fn regions_on<DB: DrawingBackend>(
    area: DrawingArea<DB, plotters::coord::Shift>,
    v: &Vehicle,
    regions: &[(f64, GRegion)],
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let n = regions.len().max(1);
    {
        area.fill(&WHITE).map_err(err)?;
        let panels = area.split_evenly((1, n));
        for ((_, g), panel) in regions.iter().zip(panels.iter()) {
            let s = &g.space;
            let (x1, y1) = (
                s.x0 + s.nx as f64 * s.res.cell_m,
                s.y0 + s.ny as f64 * s.res.cell_m,
            );
            let c = compare(g);
            let mut chart = ChartBuilder::on(panel)
                .caption(
                    format!(
                        "{}: G {:.3} m² (inscribed claims {:.3})",
                        s.mode.name(),
                        c.g_area_m2,
                        c.inscribed_area_m2
                    ),
                    ("sans-serif", 16),
                )
                .margin(8)
                .x_label_area_size(30)
                .y_label_area_size(40)
                .build_cartesian_2d(s.x0..x1, s.y0..y1)
                .map_err(err)?;
            chart
                .configure_mesh()
                .x_desc("x (m)")
                .y_desc("y (m)")
                .draw()
                .map_err(err)?;
            let h = s.res.cell_m;
            let cells = (0..s.cells()).filter_map(|cell| {
                let p = s.cell_centre(cell);
                if !s.in_window(p) {
                    return None;
                }
                let colour = if g.through[cell].is_some() {
                    RGBColor(44, 160, 44).filled()
                } else if s.bend.clearance(p) >= v.inscribed_m() / 2.0 {
                    RGBColor(214, 39, 40).filled()
                } else {
                    RGBColor(225, 225, 225).filled()
                };
                Some(Rectangle::new(
                    [
                        (p[0] - h / 2.0, p[1] - h / 2.0),
                        (p[0] + h / 2.0, p[1] + h / 2.0),
                    ],
                    colour,
                ))
            });
            chart.draw_series(cells).map_err(err)?;
            region_key(&mut chart, [s.x0, s.y0])?;
        }
        area.present().map_err(err)
    }
}

/// The colour key of a G-region panel, as legend entries.
fn region_key<'a, DB: DrawingBackend + 'a>(
    chart: &mut ChartContext<
        'a,
        DB,
        Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
    >,
    at: [f64; 2],
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let key = [
        ("G: the reference point passes here", RGBColor(44, 160, 44)),
        (
            "inside the inscribed-circle band, not in G",
            RGBColor(214, 39, 40),
        ),
        ("neither", RGBColor(225, 225, 225)),
    ];
    for (label, c) in key {
        // A zero-size square: only its legend entry shows.
        chart
            .draw_series([Rectangle::new([(at[0], at[1]), (at[0], at[1])], c.filled())])
            .map_err(err)?
            .label(label)
            .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 12, y + 5)], c.filled()));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK)
        .label_font(("sans-serif", 12))
        .position(SeriesLabelPosition::LowerRight)
        .draw()
        .map_err(err)?;
    Ok(())
}

/// The vehicle's inscribed and circumscribed diameters as dashed, labelled lines.
fn draw_references<'a, DB: DrawingBackend + 'a>(
    chart: &mut ChartContext<
        'a,
        DB,
        Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
    >,
    v: &Vehicle,
    [a0, a1]: [f64; 2],
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let references = [
        (
            "Li, inscribed-circle diameter (the width)",
            v.inscribed_m(),
            RGBColor(120, 120, 120),
        ),
        (
            "L0, circumscribed-circle diameter",
            v.circumscribed_m(),
            BLACK,
        ),
    ];
    for (label, w, c) in references {
        // Dashed, so the references are not read as grid lines.
        let dashes = (0..40).map(|k| {
            let t = |j: f64| a0 + (a1 - a0) * (f64::from(k) * 2.0 + j) / 80.0;
            PathElement::new([(t(0.0), w), (t(1.0), w)], c.stroke_width(2))
        });
        chart
            .draw_series(dashes)
            .map_err(err)?
            .label(format!("{label}: {w:.3} m"))
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], c.stroke_width(2)));
    }
    Ok(())
}
