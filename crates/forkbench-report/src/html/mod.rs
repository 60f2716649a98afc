//! `forkbench report`: one self-contained HTML page per batch directory (tables, SVG plots, recordings, provenance).

mod gate_measures;
mod profile;
mod safety;
mod sections;
mod success_run;
mod svg;

use std::path::{Path, PathBuf};

use forkbench_batch::{self as batch, Baseline, GateOptions, Manifest, Summary};

use crate::Result;

const STYLE: &str = "body{font-family:sans-serif;margin:24px;max-width:1300px;color:#222}\
h1{font-size:22px}h2{font-size:18px;margin-top:28px;border-bottom:1px solid #ccc}\
table{border-collapse:collapse;margin:8px 0}td,th{border:1px solid #ccc;padding:3px 7px;font-size:13px;text-align:left}\
th{background:#f3f3f3}.ok{color:#1a7f37;font-weight:bold}.bad{color:#c62828;font-weight:bold}.warn{color:#b26a00}\
pre{font-size:11px;background:#f7f7f7;padding:6px;overflow:auto}svg{display:block;margin:10px 0}";

/// Writes `dir/report.html` (or `out`) for a batch directory or a sweep's; with a
/// baseline, the comparison and its verdicts. Returns the page's path.
pub fn write(dir: &Path, baseline: Option<&Path>) -> Result<PathBuf> {
    write_to(dir, baseline, &dir.join("report.html"))
}

pub fn write_to(dir: &Path, baseline: Option<&Path>, out: &Path) -> Result<PathBuf> {
    let body = if dir.join("sweep.json").is_file() {
        sweep_body(dir)?
    } else {
        batch_body(dir, baseline)?
    };
    let page = format!(
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>forkbench report: {0}</title><style>{STYLE}</style></head><body><h1>forkbench report: {0}</h1>{body}</body></html>\n",
        svg::esc(&dir.display().to_string())
    );
    batch::write_atomic(out, page.as_bytes())?;
    Ok(out.to_path_buf())
}

fn batch_body(dir: &Path, baseline: Option<&Path>) -> Result<String> {
    let summary: Summary = batch::load_results(dir)?;
    let numbered = batch::read_numbered(&dir.join("trials.jsonl"))?;
    let records: Vec<batch::TrialRecord> = numbered.iter().map(|(_, r)| r.clone()).collect();
    let manifest = Manifest::read(dir)?.ok_or_else(|| crate::ReportError::NoManifest {
        dir: dir.to_path_buf(),
    })?;
    let mut h = format!(
        "<p><b>{} trials, {} successes ({:.1} %)</b></p>",
        summary.trials,
        summary.successes,
        100.0 * summary.successes as f64 / summary.trials.max(1) as f64
    );
    if let Some(b) = baseline {
        let base = Baseline::load(b)?;
        let gate = batch::regress(
            &base,
            &summary,
            &records,
            Some(&manifest),
            &GateOptions::default(),
        );
        let class = if gate.passed { "ok" } else { "bad" };
        h.push_str(&format!(
            "<h2>Against the baseline {}: <span class=\"{class}\">{}</span></h2>",
            svg::esc(&b.display().to_string()),
            svg::esc(&gate.verdict_text())
        ));
        h.push_str(&sections::baseline_comparison(&gate));
        h.push_str(&gate_measures::measures_section(&gate));
    }
    h.push_str("<h2>Success per scenario × planner × tracker</h2>");
    h.push_str(&sections::success_table(&summary));
    h.push_str(&mode_pairs_table(&summary.replanning));
    let legs = sections::stage_table(&summary, "leg", |r| &r.legs);
    if !legs.is_empty() {
        h.push_str(
            "<h2>Mission legs (a trial counts for a leg once the legs before it are done)</h2>",
        );
        h.push_str(&legs);
    }
    let phases = sections::stage_table(&summary, "phase", |r| &r.phases);
    if !phases.is_empty() {
        h.push_str(
            "<h2>Phases (a trial counts for a phase once the phases before it succeeded)</h2>",
        );
        h.push_str(&phases);
    }
    let safety = safety::safety_table(&summary);
    if !safety.is_empty() {
        h.push_str("<h2>Safety: people and safety fields</h2>");
        h.push_str(&safety);
    }
    h.push_str(&success_run::table(&summary));
    h.push_str(&profile::table(&summary));
    h.push_str("<h2>Failures by first failed criterion</h2>");
    h.push_str(&sections::failure_breakdown(&summary));
    let maps = sections::heatmaps(&manifest, &records);
    if !maps.is_empty() {
        h.push_str("<h2>Success over lateral offset × pallet angle</h2>");
        h.push_str(&maps);
    }
    h.push_str("<h2>Entry errors (trials whose forks reached the face)</h2>");
    h.push_str(&sections::error_distributions(&manifest, &records));
    h.push_str("<h2>Failed trials</h2>");
    h.push_str(&sections::failed_trials(dir, &numbered));
    h.push_str("<h2>Provenance</h2>");
    h.push_str(&sections::provenance(summary.provenance.as_ref()));
    Ok(h)
}

fn sweep_body(dir: &Path) -> Result<String> {
    let (knob, points) = batch::read_sweep(dir)?;
    let words = knob.replace('_', " ");
    let mut h = format!("<h2>Success vs {}</h2>", svg::esc(&words));
    h.push_str(&sections::sweep(&knob, &points));
    for (v, s) in &points {
        h.push_str(&format!("<h2>{} scale {v}</h2>", svg::esc(&words)));
        h.push_str(&sections::success_table(s));
    }
    h.push_str("<h2>Provenance (first point)</h2>");
    h.push_str(&sections::provenance(
        points.first().and_then(|p| p.1.provenance.as_ref()),
    ));
    Ok(h)
}

/// Replanning against planning once, paired, per row run in both modes (empty without).
fn mode_pairs_table(rows: &[batch::ModePairs]) -> String {
    if rows.is_empty() {
        return String::new();
    }
    let mut h = String::from(
        "<h2>Replanning against planning once (paired: same trials and seeds)</h2><table data-plot=\"mode-pairs\"><tr><th>scenario</th><th>planner</th><th>tracker</th><th>pairs</th><th>replanning broke</th><th>replanning fixed</th><th>p (McNemar, two-sided)</th></tr>",
    );
    for r in rows {
        h.push_str(&format!(
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{:.4}</td></tr>",
            svg::esc(&r.scenario),
            svg::esc(&r.planner),
            svg::esc(&r.tracker),
            r.pairs,
            r.broke,
            r.fixed,
            r.p_value
        ));
    }
    h + "</table>"
}
