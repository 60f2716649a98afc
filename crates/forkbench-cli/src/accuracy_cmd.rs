//! `forkbench reproduce detector`: the pallet detector's accuracy over range, angle and lateral offset, beside Lü et al. 2019's ±60 mm / ±6° at 6.5 m, 1.5 m, 15°.

use std::fmt::Write as _;
use std::path::Path as FsPath;

use forkbench_trial::trial::accuracy::{ANGLES_DEG, AccuracyRow, accuracy_study};
use forkbench_trial::{Scenario, defaults};
use plotters::coord::Shift;
use plotters::prelude::*;
use serde_json::json;

use crate::plot::{COLORS, err, to_file};

/// The paper's figure: at 6.5 m, 1.5 m lateral and 15° the estimate is within ±60 mm and
/// ±6° (read as the bound most estimates stay within, |bias| + 2σ).
const PAPER_CELL: (f64, f64, f64) = (6.5, 15.0, 1.5);
const PAPER_POSITION_M: f64 = 0.060;
const PAPER_HEADING_DEG: f64 = 6.0;

fn is_paper_cell(r: &AccuracyRow) -> bool {
    (r.range_m - PAPER_CELL.0).abs() < 1e-9
        && (r.angle_rad.to_degrees() - PAPER_CELL.1).abs() < 1e-6
        && (r.lateral_m - PAPER_CELL.2).abs() < 1e-9
}

/// Runs the study on `scenario` (default: the embedded field test, its pallet and its
/// sensing) and prints it as markdown or JSON; `plot` draws miss rate and error bounds.
pub fn run(
    scenario: Option<&FsPath>,
    draws: u32,
    json: bool,
    plot: Option<&FsPath>,
) -> anyhow::Result<()> {
    let scn = match scenario {
        Some(p) => Scenario::load(p)?,
        None => defaults::default_scenarios()?
            .into_iter()
            .find(|s| s.name == "field-test")
            .ok_or_else(|| anyhow::anyhow!("the embedded field test is missing"))?,
    };
    let rows = accuracy_study(&scn, draws, scn.seed)?;
    if let Some(file) = plot {
        to_file(file, (1100, 520), |a| draw(a, &rows), |a| draw(a, &rows))?;
    }
    let sensors = sensor_names(&scn);
    let detector = match &scn.pallet_sensing {
        forkbench_trial::scenario::sensors::PalletSensing::Scanner { detector, .. } => {
            detector.name.clone()
        }
        forkbench_trial::scenario::sensors::PalletSensing::Gaussian => "pockets".to_owned(),
    };
    let text = if json {
        let paper = rows.iter().find(|r| is_paper_cell(r));
        format!(
            "{}\n",
            json!({"scenario": scn.name, "detector": detector, "sensors": sensors, "draws": draws, "rows": rows,
                "paper": {"range_m": PAPER_CELL.0, "angle_deg": PAPER_CELL.1, "lateral_m": PAPER_CELL.2,
                    "position_m": PAPER_POSITION_M, "heading_deg": PAPER_HEADING_DEG},
                "paper_cell": paper})
        )
    } else {
        markdown(&rows, (&detector, &sensors), draws)
    };
    crate::emit(&text)
}

fn sensor_names(scn: &Scenario) -> Vec<String> {
    match &scn.pallet_sensing {
        forkbench_trial::scenario::sensors::PalletSensing::Scanner { sensors, .. } => {
            sensors.iter().map(|s| s.name.clone()).collect()
        }
        forkbench_trial::scenario::sensors::PalletSensing::Gaussian => Vec::new(),
    }
}

fn mm(s: &forkbench_trial::trial::accuracy::Spread) -> String {
    format!("{:+.0} ± {:.0}", 1e3 * s.bias, 1e3 * s.sigma)
}

fn markdown(rows: &[AccuracyRow], (detector, sensors): (&str, &[String]), draws: u32) -> String {
    let mut t = format!(
        "Detector {detector} on {} scans, {draws} draws per cell (bias ± σ of the estimate in the \
         true pallet's frame)\n\n| range (m) | angle (°) | lateral (m) | found | lateral (mm) | \
         along (mm) | heading (°) | decided by ({}) |\n|---|---|---|---|---|---|---|---|\n",
        sensors.join(" + "),
        sensors.join(" / ")
    );
    for r in rows {
        let found = r.draws - r.missed;
        let _ = writeln!(
            t,
            "| {} | {:.0} | {} | {found}/{} | {} | {} | {:+.2} ± {:.2} | {} |",
            r.range_m,
            r.angle_rad.to_degrees(),
            r.lateral_m,
            r.draws,
            mm(&r.lateral),
            mm(&r.along),
            r.heading.bias.to_degrees(),
            r.heading.sigma.to_degrees(),
            r.by_sensor
                .iter()
                .map(u32::to_string)
                .collect::<Vec<_>>()
                .join(" / ")
        );
    }
    if let Some(r) = rows.iter().find(|r| is_paper_cell(r)) {
        let pos = r.lateral.bound().max(r.along.bound());
        let _ = writeln!(
            t,
            "\nAt {} m, {}°, {} m lateral (the paper's figure: ±{:.0} mm, ±{:.0}°): found {}/{}, \
             |bias| + 2σ = {:.0} mm in position (lateral {:.0}, along {:.0}) and {:.1}° in heading.",
            PAPER_CELL.0,
            PAPER_CELL.1,
            PAPER_CELL.2,
            1e3 * PAPER_POSITION_M,
            PAPER_HEADING_DEG,
            r.draws - r.missed,
            r.draws,
            1e3 * pos,
            1e3 * r.lateral.bound(),
            1e3 * r.along.bound(),
            r.heading.bound().to_degrees()
        );
    }
    t
}

/// What a panel plots of a row.
type Metric = fn(&AccuracyRow) -> f64;

/// Left: share of draws that found the pallet against range; right: the lateral error
/// bound (|bias| + 2σ) against range; a line per angle, at the largest lateral offset.
fn draw<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    rows: &[AccuracyRow],
) -> anyhow::Result<()>
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
