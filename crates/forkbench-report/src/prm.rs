//! `reproduce prm --plot`: success rate against the sample count beside the paper's, and planning time per connection distance, with RRT's.

use std::path::Path;

use forkbench_nav::reproduce::StudyRow;
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::Result;

use crate::figure::{COLORS, err, to_file};

/// The paper's success rates at 10 m (Luo, Table 2; 50 nodes: 93 %, or 80 % in a rerun).
const PAPER_SUCCESS: [(usize, f64); 4] = [(15, 35.0), (50, 93.0), (100, 100.0), (500, 100.0)];

/// Draws both panels to FILE (.svg or .png).
pub fn draw(file: &Path, rows: &[StudyRow]) -> Result<()> {
    to_file(file, (1400, 560), |a| panels(a, rows), |a| panels(a, rows))
}

fn panels<DB: DrawingBackend>(area: DrawingArea<DB, Shift>, rows: &[StudyRow]) -> Result<()> {
    area.fill(&WHITE).map_err(err)?;
    let (left, right) = area.split_horizontally(700);
    success(&left, rows)?;
    times(&right, rows)?;
    area.present().map_err(err)?;
    Ok(())
}

/// PRM rows with `connect_m`, by node count.
fn series(rows: &[StudyRow], connect_m: Option<f64>) -> Vec<&StudyRow> {
    let mut v: Vec<&StudyRow> = rows
        .iter()
        .filter(|r| r.planner != "RRT" && r.connect_m == connect_m)
        .collect();
    v.sort_by_key(|r| r.nodes);
    v
}

fn success<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, rows: &[StudyRow]) -> Result<()> {
    let mut chart = ChartBuilder::on(area)
        .caption("PRM + A* success rate, 10 m connection", ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(36)
        .y_label_area_size(48)
        .build_cartesian_2d((10f64..600f64).log_scale(), 0f64..105f64)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("nodes sampled")
        .x_labels(6)
        .x_label_formatter(&|v| format!("{v:.0}"))
        .light_line_style(WHITE)
        .y_desc("success (%)")
        .draw()
        .map_err(err)?;
    let ours: Vec<(f64, f64)> = series(rows, Some(10.0))
        .iter()
        .map(|r| {
            (
                r.nodes.unwrap_or(0) as f64,
                100.0 * r.found as f64 / r.runs as f64,
            )
        })
        .collect();
    let c = COLORS[0];
    chart
        .draw_series(LineSeries::new(ours.clone(), c.stroke_width(2)))
        .map_err(err)?
        .label("forkbench (100 seeds)")
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2)));
    chart
        .draw_series(ours.iter().map(|&p| Circle::new(p, 4, c.filled())))
        .map_err(err)?;
    let p = COLORS[1];
    chart
        .draw_series(
            PAPER_SUCCESS
                .iter()
                .map(|&(n, s)| Cross::new((n as f64, s), 6, p.stroke_width(2))),
        )
        .map_err(err)?
        .label("Luo et al. (MATLAB)")
        .legend(move |(x, y)| Cross::new((x + 10, y), 5, p.stroke_width(2)));
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .position(SeriesLabelPosition::LowerRight)
        .draw()
        .map_err(err)?;
    Ok(())
}

fn times<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, rows: &[StudyRow]) -> Result<()> {
    let ms = |r: &StudyRow| (1e3 * r.median_time_s).max(1e-3);
    let top = rows.iter().map(ms).fold(1.0, f64::max) * 2.0;
    let mut chart = ChartBuilder::on(area)
        .caption("median planning time (roadmap + A*)", ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(36)
        .y_label_area_size(56)
        .build_cartesian_2d((10f64..600f64).log_scale(), (0.005f64..top).log_scale())
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("nodes sampled")
        .x_labels(6)
        .x_label_formatter(&|v| format!("{v:.0}"))
        .light_line_style(WHITE)
        .y_desc("time (ms)")
        .draw()
        .map_err(err)?;
    let settings = [
        (Some(5.0), "5 m"),
        (Some(10.0), "10 m"),
        (Some(30.0), "30 m"),
        (None, "unlimited"),
    ];
    for (i, (conn, name)) in settings.into_iter().enumerate() {
        let pts: Vec<(f64, f64)> = series(rows, conn)
            .iter()
            .map(|r| (r.nodes.unwrap_or(0) as f64, ms(r)))
            .collect();
        let c = COLORS[i % COLORS.len()];
        chart
            .draw_series(LineSeries::new(pts.clone(), c.stroke_width(2)))
            .map_err(err)?
            .label(format!("PRM, {name}"))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2)));
        chart
            .draw_series(pts.iter().map(|&p| Circle::new(p, 3, c.filled())))
            .map_err(err)?;
    }
    if let Some(rrt) = rows.iter().find(|r| r.planner == "RRT") {
        let t = ms(rrt);
        let c = COLORS[4];
        chart
            .draw_series(LineSeries::new([(10.0, t), (600.0, t)], c.stroke_width(1)))
            .map_err(err)?
            .label("RRT (1 m steps)")
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(1)));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .position(SeriesLabelPosition::UpperLeft)
        .draw()
        .map_err(err)?;
    Ok(())
}
