//! The gate's measures in the report: each row's measures against their margins, and a paired plot of candidate against baseline per seed.

use std::fmt::Write as _;

use forkbench_batch::{GateReport, MeasureTest, RegressRow};

use super::svg::{self, esc};

/// Plots a row's failing measures and its entry lateral error (every measure would be a
/// page of plots on a many-row batch).
fn plotted(r: &RegressRow) -> Vec<&MeasureTest> {
    r.measures
        .iter()
        .filter(|m| {
            !m.pairs.is_empty() && (m.worse_beyond_margin || m.measure == "entry_lateral_error_m")
        })
        .collect()
}

/// A p-value to four decimals, or in exponent form below 0.001.
fn p_text(p: f64) -> String {
    if p >= 1e-3 {
        format!("{p:.4}")
    } else {
        format!("{p:.2e}")
    }
}

fn num(v: Option<f64>) -> String {
    v.map_or("–".into(), forkbench_batch::gate_num)
}

/// The measures' table per row, with its paired plots; empty when nothing was measured.
pub fn measures_section(g: &GateReport) -> String {
    let mut h = String::new();
    if let Some(note) = &g.measures_note {
        let _ = write!(
            h,
            "<p class=\"warn\">Measures not compared: {}.</p>",
            esc(note)
        );
    }
    let rows: Vec<&RegressRow> = g.rows.iter().filter(|r| !r.measures.is_empty()).collect();
    if rows.is_empty() {
        return h;
    }
    h.push_str("<h3>How well, not only whether: each measure against its margin</h3><p>Worse by: the Hodges–Lehmann shift of the results against the baseline (positive is worse), with one-sided bounds at α; paired on the same seeds (Wilcoxon's signed-rank test), else the rank-sum test. A measure fails when it is worse than its margin with confidence after Holm's correction over every row's success and measures, not when it merely differs.</p>");
    for r in rows {
        let _ = write!(
            h,
            "<h4>{} / {} / {}</h4><table><tr><th>measure</th><th>margin</th><th>baseline median</th><th>now median</th><th>worse by [bounds]</th><th>n</th><th>p adjusted</th><th>detectable (80 %)</th><th>verdict</th></tr>",
            esc(&r.scenario),
            esc(&r.planner),
            esc(&r.tracker)
        );
        for m in &r.measures {
            let class = if m.worse_beyond_margin { "bad" } else { "ok" };
            let _ = write!(
                h,
                "<tr><td>{}</td><td title=\"{}\">{}</td><td>{}</td><td>{}</td><td>{}</td><td>{} {}</td><td>{}</td><td>{}</td><td class=\"{class}\">{}</td></tr>",
                esc(&m.measure),
                esc(&m.margin_source),
                num(Some(m.margin)),
                num(m.baseline_median),
                num(m.now_median),
                esc(&m.shift_text()),
                m.n,
                if m.paired { "pairs" } else { "values" },
                m.p_adjusted.map_or("–".into(), p_text),
                num(m.detectable),
                esc(m.verdict_text())
            );
        }
        h.push_str("</table>");
        for m in plotted(r) {
            let margin = m.worse.sign() * m.margin;
            let id = format!(
                "paired-{}-{}-{}-{}",
                r.scenario, r.planner, r.tracker, m.measure
            );
            let title = format!("{} per seed", m.measure);
            h.push_str(&svg::paired_scatter(
                &id, &title, &m.pairs, margin, &m.measure,
            ));
        }
    }
    h.push_str("<p>Paired plots: one point per seed, the baseline's value across and the results' up; grey is no change, the dashed line the margin, red points lie beyond it.</p>");
    h
}
