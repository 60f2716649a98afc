//! `forkbench reproduce detector`: the pallet detector's accuracy over range, angle and lateral offset, beside Lü et al. 2019's ±60 mm / ±6° at 6.5 m, 1.5 m, 15°.

use std::fmt::Write as _;
use std::path::Path as FsPath;

use forkbench_studies::accuracy::{AccuracyRow, accuracy_study};
use forkbench_trial::{Scenario, defaults};
use serde_json::json;

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
        forkbench_report::accuracy::draw_accuracy(file, &rows)?;
    }
    let sensors = sensor_names(&scn);
    let detector = match &scn.pallet_sensing {
        forkbench_trial::scenario::sensors::PalletSensing::Scanner { detector, .. } => {
            detector.name.clone()
        }
        forkbench_trial::scenario::sensors::PalletSensing::Gaussian => {
            forkbench_trial::components::POCKET_DETECTOR.to_owned()
        }
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

fn mm(s: &forkbench_studies::accuracy::Spread) -> String {
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
