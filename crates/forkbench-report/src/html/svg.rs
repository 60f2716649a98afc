//! Hand-written inline SVG charts for the HTML report: stacked bars, heatmaps, histograms, lines, paired scatters.

use std::fmt::Write as _;

/// The report's order of [`crate::TAB10`] (failure kinds, series): red second, as the
/// first failure kind reads best in it.
const ORDER: [usize; 10] = [0, 3, 2, 1, 4, 5, 6, 7, 8, 9];

/// The colour of the `i`-th failure kind or series, as `#rrggbb`.
fn palette(i: usize) -> String {
    let (r, g, b) = crate::TAB10[ORDER[i % ORDER.len()]];
    format!("#{r:02x}{g:02x}{b:02x}")
}

pub use forkbench_trial::text::markup as esc;

fn open(id: &str, w: f64, h: f64) -> String {
    format!(
        "<svg data-plot=\"{}\" xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\" font-family=\"sans-serif\" font-size=\"12\">",
        esc(id)
    )
}

/// One horizontal bar per row, split into segments (kind, count) as shares of the row's
/// trials (every bar is 100 %, so a 20-trial row reads like a 460-trial one); a legend.
pub fn stacked_bars(id: &str, rows: &[(String, Vec<(String, u64)>)], kinds: &[String]) -> String {
    let (label_w, bar_w, row_h) = (330.0, 420.0, 22.0);
    let h = 40.0 + row_h * rows.len() as f64 + 22.0 * kinds.len().div_ceil(4) as f64;
    let mut s = open(id, label_w + bar_w + 100.0, h);
    for (i, (label, segs)) in rows.iter().enumerate() {
        let total = segs.iter().map(|(_, n)| *n).sum::<u64>().max(1) as f64;
        let y = 10.0 + row_h * i as f64;
        let _ = write!(
            s,
            "<text x=\"{}\" y=\"{}\" text-anchor=\"end\">{}</text>",
            label_w - 8.0,
            y + 14.0,
            esc(label)
        );
        let mut x = label_w;
        for (kind, n) in segs {
            let w = bar_w * *n as f64 / total;
            let c = palette(kinds.iter().position(|k| k == kind).unwrap_or(0));
            let _ = write!(
                s,
                "<rect x=\"{x:.1}\" y=\"{y}\" width=\"{w:.1}\" height=\"16\" fill=\"{c}\"><title>{}: {n} ({:.1} %)</title></rect>",
                esc(kind),
                100.0 * *n as f64 / total
            );
            x += w;
        }
        let _ = write!(
            s,
            "<text x=\"{:.1}\" y=\"{}\">n = {total}</text>",
            x + 4.0,
            y + 13.0
        );
    }
    let y0 = 20.0 + row_h * rows.len() as f64;
    for (i, k) in kinds.iter().enumerate() {
        let (x, y) = (
            label_w + 140.0 * (i % 4) as f64 - 200.0,
            y0 + 22.0 * (i / 4) as f64,
        );
        let c = palette(i);
        let _ = write!(
            s,
            "<rect x=\"{x}\" y=\"{y}\" width=\"12\" height=\"12\" fill=\"{c}\"/><text x=\"{}\" y=\"{}\">{}</text>",
            x + 16.0,
            y + 11.0,
            esc(k)
        );
    }
    s + "</svg>"
}

/// Success rate per (x, y) cell: green at 100 %, red at 0 %, the count in the cell.
pub fn heatmap(
    id: &str,
    title: &str,
    xs: &[f64],
    ys: &[f64],
    cell: &dyn Fn(usize, usize) -> Option<(u64, u64)>,
    (x_label, y_label): (&str, &str),
) -> String {
    let (cw, ch, left, top) = (56.0, 30.0, 70.0, 40.0);
    // Wide enough for the title even with few columns.
    let (w, h) = (
        (left + cw * xs.len() as f64 + 20.0).max(left + 7.5 * title.chars().count() as f64),
        top + ch * ys.len() as f64 + 80.0,
    );
    let mut s = open(id, w, h);
    let _ = write!(
        s,
        "<text x=\"{left}\" y=\"16\" font-weight=\"bold\">{}</text>",
        esc(title)
    );
    for (j, yv) in ys.iter().enumerate() {
        let y = top + ch * j as f64;
        let _ = write!(
            s,
            "<text x=\"{}\" y=\"{}\" text-anchor=\"end\">{yv}</text>",
            left - 6.0,
            y + 19.0
        );
        for (i, _) in xs.iter().enumerate() {
            let x = left + cw * i as f64;
            let Some((k, n)) = cell(i, j) else { continue };
            let r = k as f64 / n.max(1) as f64;
            let colour = format!(
                "rgb({},{},90)",
                (220.0 * (1.0 - r)) as u8 + 30,
                (180.0 * r) as u8 + 40
            );
            let _ = write!(
                s,
                "<rect x=\"{x}\" y=\"{y}\" width=\"{}\" height=\"{}\" fill=\"{colour}\"><title>{k}/{n}</title></rect><text x=\"{}\" y=\"{}\" text-anchor=\"middle\" fill=\"white\">{:.0}%</text><text x=\"{}\" y=\"{}\" text-anchor=\"middle\" fill=\"white\" font-size=\"9\">n={n}</text>",
                cw - 2.0,
                ch - 2.0,
                x + cw / 2.0,
                y + 13.0,
                100.0 * r,
                x + cw / 2.0,
                y + 25.0
            );
        }
    }
    let yb = top + ch * ys.len() as f64;
    for (i, xv) in xs.iter().enumerate() {
        let _ = write!(
            s,
            "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">{xv}</text>",
            left + cw * i as f64 + cw / 2.0,
            yb + 16.0
        );
    }
    let _ = write!(
        s,
        "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">{}</text><text x=\"12\" y=\"{}\" transform=\"rotate(-90 12 {})\" text-anchor=\"middle\">{}</text>",
        left + cw * xs.len() as f64 / 2.0,
        yb + 36.0,
        esc(x_label),
        top + ch * ys.len() as f64 / 2.0,
        top + ch * ys.len() as f64 / 2.0,
        esc(y_label)
    );
    colour_scale(&mut s, left, yb + 50.0);
    s + "</svg>"
}

/// The heatmap's colour key: 0 % to 100 % success in ten steps.
fn colour_scale(s: &mut String, left: f64, y: f64) {
    for i in 0..=10 {
        let r = f64::from(i) / 10.0;
        let _ = write!(
            s,
            "<rect x=\"{:.1}\" y=\"{y}\" width=\"20\" height=\"10\" fill=\"rgb({},{},90)\"/>",
            left + 20.0 * f64::from(i),
            (220.0 * (1.0 - r)) as u8 + 30,
            (180.0 * r) as u8 + 40
        );
    }
    let _ = write!(
        s,
        "<text x=\"{left}\" y=\"{}\" font-size=\"10\">0 %</text><text x=\"{}\" y=\"{}\" font-size=\"10\" text-anchor=\"end\">100 % success</text>",
        y + 22.0,
        left + 220.0,
        y + 22.0
    );
}

/// Tick values at round steps (1, 2, 2.5 or 5 × 10ᵏ) within [a, b], about four of them.
fn round_ticks(a: f64, b: f64) -> Vec<f64> {
    let span = (b - a).abs().max(1e-12);
    let raw = span / 4.0;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 2.5, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * mag);
    let first = (a / step).ceil() as i64;
    let last = (b / step + 1e-9).floor() as i64;
    (first..=last).map(|k| k as f64 * step).collect()
}

/// A tick label with the digits its size needs.
fn tick(v: f64) -> String {
    let t = format!("{v:.3}");
    let t = t.trim_end_matches('0').trim_end_matches('.');
    if t == "-0" {
        "0".to_owned()
    } else {
        t.to_owned()
    }
}

/// Title, frame and axes with ticks for a `w` × `h` plot area at (`left`, `top`), x in [x0, x1], y in [y0, y1].
#[allow(clippy::too_many_arguments)]
fn axes(
    s: &mut String,
    title: &str,
    (left, top, w, h): (f64, f64, f64, f64),
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
    x_label: &str,
    y_label: &str,
) {
    let _ = write!(
        s,
        "<text x=\"{left}\" y=\"18\" font-weight=\"bold\">{}</text><rect x=\"{left}\" y=\"{top}\" width=\"{w}\" height=\"{h}\" fill=\"none\" stroke=\"#444\"/>",
        esc(title)
    );
    for v in round_ticks(y0, y1) {
        let y = top + h * (1.0 - (v - y0) / (y1 - y0).max(1e-12));
        let _ = write!(
            s,
            "<line x1=\"{left}\" x2=\"{}\" y1=\"{y:.1}\" y2=\"{y:.1}\" stroke=\"#ddd\"/><text x=\"{}\" y=\"{:.1}\" text-anchor=\"end\">{}</text>",
            left + w,
            left - 4.0,
            y + 4.0,
            tick(v)
        );
    }
    for v in round_ticks(x0, x1) {
        let x = left + w * (v - x0) / (x1 - x0).max(1e-12);
        let _ = write!(
            s,
            "<text x=\"{x:.1}\" y=\"{}\" text-anchor=\"middle\">{}</text>",
            top + h + 16.0,
            tick(v)
        );
    }
    let _ = write!(
        s,
        "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">{}</text><text x=\"14\" y=\"{}\" transform=\"rotate(-90 14 {})\" text-anchor=\"middle\">{}</text>",
        left + w / 2.0,
        top + h + 34.0,
        esc(x_label),
        top + h / 2.0,
        top + h / 2.0,
        esc(y_label)
    );
}

/// Entry `k` of a series legend right of a plot whose top right corner is `(x, top)`.
fn legend_entry(s: &mut String, (x, top): (f64, f64), k: usize, colour: &str, label: &str) {
    let y = top + 10.0 + 18.0 * k as f64;
    let _ = write!(
        s,
        "<rect x=\"{}\" y=\"{y}\" width=\"12\" height=\"3\" fill=\"{colour}\"/><text x=\"{}\" y=\"{}\">{}</text>",
        x + 12.0,
        x + 28.0,
        y + 4.0,
        esc(label)
    );
}

/// The fraction of `values` in each of `bins` equal bins over [0, x1].
fn fractions(values: &[f64], x1: f64, bins: usize) -> Vec<f64> {
    let mut c = vec![0.0; bins];
    for x in values {
        c[((x / x1 * bins as f64) as usize).min(bins - 1)] += 1.0 / values.len() as f64;
    }
    c
}

/// Histograms (step outlines, one colour per series) of values, with a tolerance line.
pub fn histogram(
    id: &str,
    title: &str,
    series: &[(String, Vec<f64>)],
    (tolerance, unit): (f64, &str),
    x_label: &str,
) -> String {
    let (left, top, w, h) = (70.0, 30.0, 560.0, 220.0);
    let x1 = series
        .iter()
        .flat_map(|(_, v)| v.iter().copied())
        .fold(tolerance * 1.2, f64::max)
        .max(1e-9);
    let bins = 30;
    let counts: Vec<Vec<f64>> = series.iter().map(|(_, v)| fractions(v, x1, bins)).collect();
    let y1 = counts
        .iter()
        .flatten()
        .copied()
        .fold(0.0, f64::max)
        .max(1e-9);
    let mut s = open(id, left + w + 240.0, top + h + 50.0);
    axes(
        &mut s,
        title,
        (left, top, w, h),
        (0.0, x1),
        (0.0, y1),
        x_label,
        "fraction of trials",
    );
    for (k, c) in counts.iter().enumerate() {
        let colour = palette(k);
        let mut d = format!("M{left},{}", top + h);
        for (i, v) in c.iter().enumerate() {
            let (xa, xb, y) = (
                left + w * i as f64 / bins as f64,
                left + w * (i + 1) as f64 / bins as f64,
                top + h * (1.0 - v / y1),
            );
            let _ = write!(d, " L{xa:.1},{y:.1} L{xb:.1},{y:.1}");
        }
        let _ = write!(
            s,
            "<path d=\"{d} L{},{}\" fill=\"none\" stroke=\"{colour}\" stroke-width=\"2\"/>",
            left + w,
            top + h
        );
        legend_entry(&mut s, (left + w, top), k, &colour, &series[k].0);
    }
    let xt = left + w * tolerance / x1;
    let _ = write!(
        s,
        "<line data-tolerance=\"{tolerance}\" x1=\"{xt:.1}\" x2=\"{xt:.1}\" y1=\"{top}\" y2=\"{}\" stroke=\"#000\" stroke-dasharray=\"6 4\" stroke-width=\"1.5\"/><text x=\"{:.1}\" y=\"{}\">tolerance {tolerance} {unit}</text>",
        top + h,
        xt + 4.0,
        top + 12.0
    );
    s + "</svg>"
}

/// A point of a line chart: x, y and the error bar's low and high y.
pub type Point = (f64, f64, f64, f64);

/// Lines of (x, y, low, high) points with error bars; y in [0, 100] %.
pub fn lines(id: &str, title: &str, series: &[(String, Vec<Point>)], x_label: &str) -> String {
    let (left, top, w, h) = (70.0, 30.0, 560.0, 260.0);
    let x1 = series
        .iter()
        .flat_map(|(_, p)| p.iter().map(|q| q.0))
        .fold(0.0, f64::max)
        .max(1e-9);
    let mut s = open(id, left + w + 320.0, top + h + 50.0);
    axes(
        &mut s,
        title,
        (left, top, w, h),
        (0.0, x1),
        (0.0, 100.0),
        x_label,
        "success rate (%)",
    );
    let px = |x: f64| left + w * x / x1;
    let py = |y: f64| top + h * (1.0 - y / 100.0);
    for (k, (label, pts)) in series.iter().enumerate() {
        let colour = palette(k);
        let d: Vec<String> = pts
            .iter()
            .map(|p| format!("{:.1},{:.1}", px(p.0), py(p.1)))
            .collect();
        let _ = write!(
            s,
            "<polyline points=\"{}\" fill=\"none\" stroke=\"{colour}\" stroke-width=\"2\"/>",
            d.join(" ")
        );
        for p in pts {
            let _ = write!(
                s,
                "<line x1=\"{0:.1}\" x2=\"{0:.1}\" y1=\"{1:.1}\" y2=\"{2:.1}\" stroke=\"{colour}\"/><circle cx=\"{0:.1}\" cy=\"{3:.1}\" r=\"3\" fill=\"{colour}\"/>",
                px(p.0),
                py(p.2),
                py(p.3),
                py(p.1)
            );
        }
        legend_entry(&mut s, (left + w, top), k, &colour, label);
    }
    s + "</svg>"
}

/// Each pair (baseline, now) as a point, with the line of no change and the margin's line
/// (`margin` signed: above the diagonal when higher is worse); points beyond the margin
/// are drawn red.
pub fn paired_scatter(
    id: &str,
    title: &str,
    pairs: &[(f64, f64)],
    margin: f64,
    unit: &str,
) -> String {
    let (left, top, w, h) = (70.0, 30.0, 260.0, 260.0);
    let (lo, hi) = pairs
        .iter()
        .flat_map(|(a, b)| [*a, *b])
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, u), v| {
            (l.min(v), u.max(v))
        });
    let (lo, hi) = if lo.is_finite() {
        (lo.min(0.0), hi.max(lo + 1e-9))
    } else {
        (0.0, 1.0)
    };
    let hi = hi + 0.05 * (hi - lo);
    let mut s = open(id, left + w + 30.0, top + h + 50.0);
    let base = format!("baseline ({unit})");
    let now = format!("now ({unit})");
    axes(
        &mut s,
        title,
        (left, top, w, h),
        (lo, hi),
        (lo, hi),
        &base,
        &now,
    );
    let px = |x: f64| left + w * (x - lo) / (hi - lo);
    let py = |y: f64| top + h * (1.0 - (y - lo) / (hi - lo));
    let _ = write!(
        s,
        "<line x1=\"{:.1}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke=\"#888\"/>",
        px(lo),
        py(lo),
        px(hi),
        py(hi)
    );
    let _ = write!(
        s,
        "<line x1=\"{:.1}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke=\"{}\" stroke-dasharray=\"4 3\"/>",
        px(lo),
        py((lo + margin).clamp(lo, hi)),
        px(hi),
        py((hi + margin).clamp(lo, hi)),
        palette(1)
    );
    for (a, b) in pairs {
        let beyond = if margin >= 0.0 {
            b - a > margin
        } else {
            b - a < margin
        };
        let colour = if beyond { palette(1) } else { palette(0) };
        let _ = write!(
            s,
            "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"2.5\" fill=\"{colour}\" fill-opacity=\"0.7\"/>",
            px(*a),
            py(*b)
        );
    }
    s + "</svg>"
}
