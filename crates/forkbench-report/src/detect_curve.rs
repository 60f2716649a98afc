//! A detector's scores over its threshold and its errors by place, as summary lines, and as a figure of precision, recall and false positives against the threshold beside the precision-recall curve.

use forkbench_batch::detect_curve::{Bin, ByPlace, ClutterScore, CurvePoint};
use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use crate::Result;

fn pct(v: Option<f64>) -> String {
    v.map_or("n/a".to_owned(), |v| format!("{:.1} %", 100.0 * v))
}

/// The curve at a few thresholds, the one in use marked.
pub fn curve_text(curve: &[CurvePoint], min_score: f64) -> String {
    let mut t = "  over the score threshold (precision, recall, false positives on empty scans, accuracy):\n".to_owned();
    for p in curve.iter().filter(|p| {
        let k = (p.threshold * 20.0).round() as usize;
        k.is_multiple_of(2) && k >= 4
    }) {
        let mark = if (p.threshold - min_score).abs() < 1e-9 {
            "  ← --min-score"
        } else {
            ""
        };
        t += &format!(
            "    {:.2}: {:>7} {:>7} {:>7} {:>7}{mark}\n",
            p.threshold,
            pct(p.precision),
            pct(p.recall),
            pct(p.false_positive_rate),
            pct(p.accuracy)
        );
    }
    t
}

fn bins_text(name: &str, unit: &str, bins: &[Bin]) -> String {
    let mut t = format!("  by the labelled face's {name}:\n");
    let mut lo = 0.0;
    for b in bins.iter().filter(|b| b.faces > 0) {
        let hi = if b.upto.is_finite() {
            format!("{:.0}", b.upto)
        } else {
            "∞".into()
        };
        t += &format!(
            "    {lo:.0}–{hi} {unit}: {} faces, recall {}, lateral {}, heading {}\n",
            b.faces,
            pct(b.recall),
            b.lateral_error_m
                .map_or("n/a".into(), |v| format!("{:.1} mm", v * 1e3)),
            b.heading_error_rad
                .map_or("n/a".into(), |v| format!("{:.2}°", v.to_degrees())),
        );
        lo = b.upto;
    }
    t
}

/// Recall and median errors per range and bearing bin.
pub fn by_place_text(p: &ByPlace) -> String {
    bins_text("range", "m", &p.range) + &bins_text("bearing", "°", &p.bearing)
}

/// Recall and false detections among the scans with each clutter kind.
pub fn by_clutter_text(kinds: &[ClutterScore]) -> String {
    if kinds.is_empty() {
        return String::new();
    }
    let mut t = "  by the clutter in the scene (recall with a pallet, false detections without):
"
    .to_owned();
    for k in kinds {
        t += &format!(
            "    {:<13} recall {:>7} of {:>5}, false {:>7} of {:>5}\n",
            k.kind,
            pct(k.recall),
            k.with_pallet,
            pct(k.false_positive_rate),
            k.without_pallet
        );
    }
    t
}

/// Precision, recall and false-positive rate over the threshold (the one in use
/// dashed), and the precision-recall curve.
pub fn draw(file: &std::path::Path, curve: &[CurvePoint], min_score: f64) -> Result<()> {
    crate::figure::to_file(
        file,
        (1200, 520),
        |a| draw_on(a, curve, min_score),
        |a| draw_on(a, curve, min_score),
    )
}

fn draw_on<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    curve: &[CurvePoint],
    min_score: f64,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(crate::figure::err)?;
    let panels = root.split_evenly((1, 2));
    draw_rates(&panels[0], curve, min_score)?;
    draw_pr(&panels[1], curve, min_score)
}

/// A chart of rates (0 to 1 up the side) over 0 to `x_max`, captioned and its axes named.
fn rate_chart<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    caption: &str,
    x_max: f64,
    (x_desc, y_desc): (&str, &str),
) -> Result<ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>>
where
    DB::ErrorType: 'static,
{
    use crate::figure::err;
    let mut chart = ChartBuilder::on(area)
        .margin(14)
        .x_label_area_size(40)
        .y_label_area_size(50)
        .caption(caption, ("sans-serif", 18))
        .build_cartesian_2d(0.0..x_max, 0.0..1.02)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .draw()
        .map_err(err)?;
    Ok(chart)
}

/// Precision, recall and false positives over the threshold, the one in use dashed.
fn draw_rates<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    curve: &[CurvePoint],
    min_score: f64,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    use crate::figure::err;
    let mut left = rate_chart(
        area,
        "over the score threshold",
        1.0,
        ("threshold (--min-score)", "rate"),
    )?;
    type Get = fn(&CurvePoint) -> Option<f64>;
    let series: [(&str, Get, RGBColor); 3] = [
        ("precision", |p| p.precision, BLUE),
        ("recall", |p| p.recall, RGBColor(0, 150, 0)),
        (
            "false positives on empty scans",
            |p| p.false_positive_rate,
            RED,
        ),
    ];
    for (name, get, colour) in series {
        let pts: Vec<(f64, f64)> = curve
            .iter()
            .filter_map(|p| get(p).map(|v| (p.threshold, v)))
            .collect();
        left.draw_series(LineSeries::new(pts, colour.stroke_width(2)))
            .map_err(err)?
            .label(name)
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 18, y)], colour.stroke_width(2)));
    }
    left.draw_series(DashedLineSeries::new(
        [(min_score, 0.0), (min_score, 1.02)],
        6,
        4,
        BLACK.stroke_width(1),
    ))
    .map_err(err)?;
    left.configure_series_labels()
        .border_style(BLACK)
        .background_style(WHITE.mix(0.9))
        .position(SeriesLabelPosition::LowerLeft)
        .draw()
        .map_err(err)?;
    Ok(())
}

/// Precision against recall, the threshold in use circled.
fn draw_pr<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    curve: &[CurvePoint],
    min_score: f64,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    use crate::figure::err;
    let mut right = rate_chart(
        area,
        "precision against recall (circled: the threshold in use)",
        1.02,
        ("recall", "precision"),
    )?;
    let pr: Vec<(f64, f64)> = curve
        .iter()
        .filter_map(|p| Some((p.recall?, p.precision?)))
        .collect();
    right
        .draw_series(LineSeries::new(pr.clone(), BLUE.stroke_width(2)))
        .map_err(err)?;
    right
        .draw_series(pr.iter().map(|p| Circle::new(*p, 3, BLUE.filled())))
        .map_err(err)?;
    if let Some(p) = curve
        .iter()
        .min_by(|a, b| {
            (a.threshold - min_score)
                .abs()
                .total_cmp(&(b.threshold - min_score).abs())
        })
        .and_then(|p| Some((p.recall?, p.precision?)))
    {
        right
            .draw_series([Circle::new(p, 7, BLACK.stroke_width(2))])
            .map_err(err)?;
    }
    Ok(())
}
