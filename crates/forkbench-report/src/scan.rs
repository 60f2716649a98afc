//! One scan's figure: the returns, the sensor, the pallet's truth and the detector's estimate.

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::Result;
use crate::figure::err;
use forkbench_core::Pose2;
use forkbench_trial::trial::ScanReport;

/// Draws the scan, the pallet and the estimate to FILE (.svg or .png).
pub fn draw_scan(
    file: &std::path::Path,
    r: &ScanReport,
    pallet: &forkbench_core::PalletSpec,
) -> Result<()> {
    crate::figure::to_file(
        file,
        (1000, 800),
        |a| draw_on(a, r, pallet),
        |a| draw_on(a, r, pallet),
    )
}

fn draw_on<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    r: &ScanReport,
    pallet: &forkbench_core::PalletSpec,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(err)?;
    let pts = r.scan.points();
    let s = r.scan.sensor;
    // Frame the sensor and the pallet, equal scales.
    let xs = [s.x_m, r.truth.x_m];
    let ys = [s.y_m, r.truth.y_m];
    let (cx, cy) = ((xs[0] + xs[1]) / 2.0, (ys[0] + ys[1]) / 2.0);
    let half = ((xs[0] - xs[1]).abs().max((ys[0] - ys[1]).abs()) / 2.0 + 2.0).max(3.0);
    let title = plot_title(r);
    let mut chart = ChartBuilder::on(&root)
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(50)
        .caption(title, ("sans-serif", 18))
        .build_cartesian_2d(
            (cx - half)..(cx + half),
            (cy - half * 0.8)..(cy + half * 0.8),
        )
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("x (m)")
        .y_desc("y (m)")
        .draw()
        .map_err(err)?;
    let outline = |face: &Pose2| -> Vec<Vec<(f64, f64)>> {
        pallet
            .part_boxes(face)
            .iter()
            .map(|(c, l, w)| {
                forkbench_core::geometry::rect_outline(c, *l, *w)
                    .iter()
                    .map(|p| (p[0], p[1]))
                    .collect()
            })
            .collect()
    };
    let orange = RGBColor(205, 140, 50);
    for o in outline(&r.truth) {
        chart
            .draw_series(LineSeries::new(o, orange.stroke_width(2)))
            .map_err(err)?;
    }
    if let Some(d) = &r.estimate {
        for o in outline(&d.face) {
            chart
                .draw_series(LineSeries::new(o, RED.stroke_width(1)))
                .map_err(err)?;
        }
    }
    chart
        .draw_series(
            pts.iter()
                .map(|p| Circle::new((p[0], p[1]), 2, BLUE.filled())),
        )
        .map_err(err)?;
    let (sn, cs) = s.heading_rad.sin_cos();
    chart
        .draw_series(LineSeries::new(
            [(s.x_m, s.y_m), (s.x_m + 0.6 * cs, s.y_m + 0.6 * sn)],
            BLACK.stroke_width(3),
        ))
        .map_err(err)?;
    root.present().map_err(err)?;
    Ok(())
}

/// The plot's title: the estimate's error, or that the pallet was not found.
fn plot_title(r: &ScanReport) -> String {
    match &r.estimate {
        Some(d) => {
            let e = r.truth.to_local(&d.face);
            format!(
                "{} scan: estimate off by {:+.3} m lateral, {:+.2}° (truth orange, estimate red)",
                r.sensor,
                e.y_m,
                e.heading_rad.to_degrees()
            )
        }
        None => format!("{} scan: pallet not found (truth orange)", r.sensor),
    }
}
