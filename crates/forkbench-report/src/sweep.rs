//! A sweep's figure: success against a noise knob's scale, one line per scenario, Wilson 95 % bars.

use std::path::Path as FsPath;

use plotters::coord::Shift;
use plotters::prelude::*;

use forkbench_batch::Summary;

use crate::Result;
use crate::figure::{COLORS, err, to_file};

/// Draws `dir/sweep-<planner>.png` for every planner of the sweep's points.
pub fn draw_sweeps(dir: &FsPath, knob: &str, points: &[(f64, Summary)]) -> Result<()> {
    let mut planners: Vec<&str> = points
        .iter()
        .flat_map(|(_, s)| s.rows.iter().map(|r| r.planner.as_str()))
        .collect();
    planners.sort_unstable();
    planners.dedup();
    for p in planners {
        draw_sweep(&dir.join(format!("sweep-{p}.png")), (p, knob), points)?;
    }
    Ok(())
}

/// Success rate against the pallet-noise scale, one line per scenario, Wilson 95 % bars.
pub fn draw_sweep(
    file: &FsPath,
    (planner, knob): (&str, &str),
    points: &[(f64, Summary)],
) -> Result<()> {
    to_file(
        file,
        (900, 600),
        |a| draw_sweep_on(a, (planner, knob), points),
        |a| draw_sweep_on(a, (planner, knob), points),
    )
}

fn draw_sweep_on<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    (planner, knob): (&str, &str),
    points: &[(f64, Summary)],
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(err)?;
    let x_max = points.iter().map(|p| p.0).fold(0.0, f64::max).max(0.1);
    let mut chart = ChartBuilder::on(&root)
        .margin(20)
        .x_label_area_size(40)
        .y_label_area_size(55)
        .caption(
            format!(
                "{planner}: fork-entry success vs {}",
                knob.replace('_', " ")
            ),
            ("sans-serif", 20),
        )
        .build_cartesian_2d(-0.05 * x_max..1.05 * x_max, 0.0..100.0)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc(crate::knob_axis(knob))
        .y_desc("success rate (%)")
        .draw()
        .map_err(err)?;
    let series = sweep_series(points, planner);
    let several_trackers = series.iter().any(|(_, t)| *t != series[0].1);
    for (i, (sc, tr)) in series.iter().enumerate() {
        let color = COLORS[i % COLORS.len()];
        let pts = sweep_points(points, (sc, tr), planner);
        chart
            .draw_series(LineSeries::new(
                pts.iter().map(|p| (p.0, p.1)),
                color.stroke_width(2),
            ))
            .map_err(err)?
            .label(if several_trackers {
                format!("{sc} / {tr}")
            } else {
                sc.clone()
            })
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 16, y)], color.stroke_width(2))
            });
        chart
            .draw_series(
                pts.iter()
                    .map(|p| ErrorBar::new_vertical(p.0, p.2, p.1, p.3, color.filled(), 6)),
            )
            .map_err(err)?;
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(err)?;
    root.present().map_err(err)?;
    Ok(())
}

/// The (scenario, tracker) pairs of `planner` in a sweep, sorted.
fn sweep_series(points: &[(f64, Summary)], planner: &str) -> Vec<(String, String)> {
    let mut series: Vec<(String, String)> = points
        .iter()
        .flat_map(|(_, s)| {
            s.rows
                .iter()
                .filter(|r| r.planner == planner)
                .map(|r| (r.scenario.clone(), r.tracker.clone()))
        })
        .collect();
    series.sort();
    series.dedup();
    series
}

/// One series' points: (sweep value, success %, Wilson 95 % low, high).
fn sweep_points(
    points: &[(f64, Summary)],
    (sc, tr): (&str, &str),
    planner: &str,
) -> Vec<(f64, f64, f64, f64)> {
    points
        .iter()
        .filter_map(|(v, s)| {
            s.rows
                .iter()
                .find(|r| r.scenario == sc && r.tracker == tr && r.planner == planner)
                .map(|r| {
                    (
                        *v,
                        100.0 * r.success_rate,
                        100.0 * r.ci95_low,
                        100.0 * r.ci95_high,
                    )
                })
        })
        .collect()
}
