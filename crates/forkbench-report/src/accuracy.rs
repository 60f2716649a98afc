//! The pallet detector's accuracy study drawn: share found and the lateral error bound against range.

use std::path::Path;

use forkbench_studies::accuracy::{ANGLES_DEG, AccuracyRow};
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::Result;
use crate::figure::{COLORS, err, to_file};

/// Draws the study's miss rate and error bounds to FILE (.svg or .png).
pub fn draw_accuracy(file: &Path, rows: &[AccuracyRow]) -> Result<()> {
    to_file(file, (1100, 520), |a| draw(a, rows), |a| draw(a, rows))
}

/// What a panel plots of a row.
type Metric = fn(&AccuracyRow) -> f64;

/// Left: share of draws that found the pallet against range; right: the lateral error
/// bound (|bias| + 2σ) against range; a line per angle, at the largest lateral offset.
fn draw<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, rows: &[AccuracyRow]) -> Result<()>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(err)?;
    let (left, right) = root.split_horizontally(550);
    let lateral = rows.iter().map(|r| r.lateral_m).fold(0.0, f64::max);
    let panels: [(&DrawingArea<DB, Shift>, &str, f64, Metric); 2] = [
        (&left, "found (%)", 100.0, |r| {
            100.0 * f64::from(r.draws - r.missed) / f64::from(r.draws.max(1))
        }),
        (&right, "lateral |bias| + 2σ (mm)", 150.0, |r| {
            1e3 * r.lateral.bound()
        }),
    ];
    for (area, y_desc, y_max, value) in panels {
        let mut chart = ChartBuilder::on(area)
            .margin(15)
            .x_label_area_size(40)
            .y_label_area_size(55)
            .caption(
                format!("{y_desc}, pallet {lateral} m off the axis"),
                ("sans-serif", 18),
            )
            .build_cartesian_2d(0.0..8.5, 0.0..y_max)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("range to the pallet face (m)")
            .y_desc(y_desc)
            .draw()
            .map_err(err)?;
        for (i, angle) in ANGLES_DEG.iter().enumerate() {
            let color = COLORS[i % COLORS.len()];
            let pts: Vec<(f64, f64)> = rows
                .iter()
                .filter(|r| {
                    (r.angle_rad.to_degrees() - angle).abs() < 1e-6 && r.lateral_m == lateral
                })
                .map(|r| (r.range_m, value(r).min(y_max)))
                .filter(|p| p.1.is_finite())
                .collect();
            chart
                .draw_series(LineSeries::new(pts.clone(), color.stroke_width(2)))
                .map_err(err)?
                .label(format!("pallet at {angle:.0}°"))
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 16, y)], color.stroke_width(2))
                });
            chart
                .draw_series(pts.iter().map(|p| Circle::new(*p, 3, color.filled())))
                .map_err(err)?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()
            .map_err(err)?;
    }
    Ok(())
}
