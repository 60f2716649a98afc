//! `forkbench detect`'s presentation: the scores as text, and the labelled scans' face errors over the scan index, misses and false detections marked.

use std::collections::BTreeMap;

use forkbench_batch::detect_eval::{Label, Scores, Spread, face_error};
use forkbench_core::Pose2;
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::Result;

fn spread_text(name: &str, s: Option<&Spread>, unit: &str, scale: f64) -> String {
    match s {
        Some(s) => format!(
            "  {name:<16} median {:.1} {unit}, p95 {:.1} {unit}, max {:.1} {unit}\n",
            s.median * scale,
            s.p95 * scale,
            s.max * scale
        ),
        None => format!("  {name:<16} no labelled face matched\n"),
    }
}

/// Counts, precision, recall and the error spreads, as the summary's lines.
pub fn scores_text(s: &Scores) -> String {
    let pct = |v: Option<f64>| v.map_or("n/a".to_owned(), |v| format!("{:.1} %", 100.0 * v));
    let mut t = format!(
        "labelled scans {}: {} found right, {} false detections, {} missed, {} rightly empty; \
         precision {}, recall {}\n",
        s.labelled,
        s.true_positives,
        s.false_positives,
        s.false_negatives,
        s.true_negatives,
        pct(s.precision),
        pct(s.recall)
    );
    t += &spread_text("lateral error", s.lateral_error_m.as_ref(), "mm", 1e3);
    t += &spread_text("depth error", s.depth_error_m.as_ref(), "mm", 1e3);
    t += &spread_text(
        "heading error",
        s.heading_error_rad.as_ref(),
        "°",
        180.0 / std::f64::consts::PI,
    );
    t
}

/// Lateral error (mm) and heading error (°) of each labelled scan with a face, by index;
/// misses and false detections as marks on the axis.
pub fn draw(
    file: &std::path::Path,
    found: &[Option<Pose2>],
    labels: &BTreeMap<usize, Label>,
) -> Result<()> {
    crate::figure::to_file(
        file,
        (1100, 700),
        |a| draw_on(a, found, labels),
        |a| draw_on(a, found, labels),
    )
}

fn draw_on<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    found: &[Option<Pose2>],
    labels: &BTreeMap<usize, Label>,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    use crate::figure::err;
    root.fill(&WHITE).map_err(err)?;
    let (mut lateral, mut heading, mut missed, mut false_det) = (vec![], vec![], vec![], vec![]);
    for (i, l) in labels {
        let Some(det) = found.get(*i) else { continue };
        let x = *i as f64;
        match (l.present, det, l.face) {
            (true, None, _) => missed.push(x),
            (false, Some(_), _) => false_det.push(x),
            (true, Some(d), Some(f)) => {
                let e = face_error(&f.pose(), d);
                lateral.push((x, e[0] * 1e3));
                heading.push((x, e[2].to_degrees()));
            }
            _ => {}
        }
    }
    let n = found.len().max(2) as f64;
    let panels = root.split_evenly((2, 1));
    let series = [
        ("lateral error (mm)", &lateral, BLUE),
        ("heading error (°)", &heading, RED),
    ];
    for (area, (name, pts, colour)) in panels.iter().zip(series) {
        let top = pts.iter().map(|p| p.1.abs()).fold(1.0, f64::max) * 1.15;
        let mut chart = ChartBuilder::on(area)
            .margin(12)
            .x_label_area_size(35)
            .y_label_area_size(60)
            .caption(
                format!(
                    "{name}: {} matched, {} missed (grey), {} false (black)",
                    pts.len(),
                    missed.len(),
                    false_det.len()
                ),
                ("sans-serif", 17),
            )
            .build_cartesian_2d(-1.0..n, -top..top)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("scan index")
            .x_label_formatter(&|x| format!("{x:.0}"))
            .y_desc(name)
            .draw()
            .map_err(err)?;
        chart
            .draw_series(pts.iter().map(|p| Circle::new(*p, 3, colour.filled())))
            .map_err(err)?;
        let marks = |xs: &Vec<f64>, c: RGBColor| {
            xs.iter()
                .map(move |x| Cross::new((*x, 0.0), 5, c.stroke_width(2)))
                .collect::<Vec<_>>()
        };
        chart
            .draw_series(marks(&missed, RGBColor(150, 150, 150)))
            .map_err(err)?;
        chart.draw_series(marks(&false_det, BLACK)).map_err(err)?;
    }
    Ok(())
}
