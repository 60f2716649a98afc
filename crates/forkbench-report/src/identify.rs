//! The identification's figure: each channel's validation run, command, measured response and the fitted model's, one panel per channel.

use std::path::Path as FsPath;

use plotters::coord::Shift;
use plotters::prelude::*;

use forkbench_identify::{ChannelFit, Identified};

use crate::Result;
use crate::figure::{COLORS, err, to_file};

/// Draws FILE (.svg or .png): a panel per fitted channel.
pub fn draw(file: &FsPath, fit: &Identified) -> Result<()> {
    let h = 320 * fit.channels.len().max(1) as u32;
    to_file(file, (1000, h), |a| draw_on(a, fit), |a| draw_on(a, fit))
}

fn draw_on<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, fit: &Identified) -> Result<()>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(err)?;
    let panels = root.split_evenly((fit.channels.len().max(1), 1));
    for (c, area) in fit.channels.iter().zip(panels) {
        panel(&area, c)?;
    }
    Ok(())
}

fn panel<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, c: &ChannelFit) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let tr = &c.trace;
    let t_max = tr.t_s.last().copied().unwrap_or(1.0).max(1e-3);
    let all = tr.command.iter().chain(&tr.measured).chain(&tr.fitted);
    let (lo, hi) = all.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
        (a.min(*v), b.max(*v))
    });
    let pad = ((hi - lo) * 0.05).max(1e-3);
    let unit = if c.channel == "steering" {
        "rad"
    } else {
        "m/s"
    };
    let mut chart = ChartBuilder::on(area)
        .margin(12)
        .x_label_area_size(35)
        .y_label_area_size(55)
        .caption(
            match c.held_out_runs {
                0 => format!(
                    "{}: the fitted run (none held out), fit {:.1} % on it",
                    c.channel, c.fit_percent
                ),
                n => format!(
                    "{}: a held-out run, fit {:.1} % over the {n} held-out run(s)",
                    c.channel, c.fit_percent
                ),
            },
            ("sans-serif", 18),
        )
        .build_cartesian_2d(0.0..t_max, (lo - pad)..(hi + pad))
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("time (s)")
        .y_desc(unit)
        .draw()
        .map_err(err)?;
    let lines = [
        ("command", &tr.command, RGBColor(150, 150, 150)),
        ("measured", &tr.measured, COLORS[0]),
        ("fitted model", &tr.fitted, COLORS[1]),
    ];
    for (name, ys, color) in lines {
        chart
            .draw_series(LineSeries::new(
                tr.t_s.iter().copied().zip(ys.iter().copied()),
                color.stroke_width(2),
            ))
            .map_err(err)?
            .label(name)
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 18, y)], color.stroke_width(2)));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(err)?;
    Ok(())
}
