//! The report's sections as HTML fragments: tables, failure breakdown, heatmaps, error distributions, sweep, failed trials, provenance.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;
use std::path::Path;

use forkbench_batch::{
    self as batch, GateReport, Manifest, Provenance, Summary, TrialRecord, Verdict,
};

use super::svg::{self, esc};

fn pct(v: f64) -> String {
    format!("{:.1} %", 100.0 * v)
}

fn row_label(scenario: &str, planner: &str, tracker: &str, replan: Option<bool>) -> String {
    match replan {
        Some(m) => format!(
            "{scenario} / {planner} / {tracker} / {}",
            batch::mode_name(m)
        ),
        None => format!("{scenario} / {planner} / {tracker}"),
    }
}

/// The success table with Wilson intervals.
pub fn success_table(s: &Summary) -> String {
    let mut h = String::from(
        "<table><tr><th>scenario</th><th>planner</th><th>tracker</th><th>mode</th><th>trials</th><th>successes</th><th>success rate</th><th>95 % CI (Wilson)</th><th>lateral mean / p95 (mm)</th><th>heading mean / p95 (°)</th></tr>",
    );
    let mm = |v: Option<f64>| v.map_or("–".into(), |v| format!("{:.1}", v * 1e3));
    let deg = |v: Option<f64>| v.map_or("–".into(), |v| format!("{:.2}", v.to_degrees()));
    for r in &s.rows {
        let _ = write!(
            h,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}–{}</td><td>{} / {}</td><td>{} / {}</td></tr>",
            esc(&r.scenario),
            esc(&r.planner),
            esc(&r.tracker),
            batch::mode_name(r.replan),
            r.trials,
            r.successes,
            pct(r.success_rate),
            pct(r.ci95_low),
            pct(r.ci95_high),
            mm(r.lateral_error_mean_m),
            mm(r.lateral_error_p95_m),
            deg(r.heading_error_mean_rad),
            deg(r.heading_error_p95_rad)
        );
    }
    h + "</table>"
}

/// Success per stage (mission leg or cycle phase, as `stages` picks) over the trials that
/// reached it, the stage named in the `column` column (empty when no row has any).
pub fn stage_table(
    s: &Summary,
    column: &str,
    stages: fn(&batch::SummaryRow) -> &[batch::LegSummary],
) -> String {
    let mut h = format!(
        "<table><tr><th>scenario</th><th>planner</th><th>tracker</th><th>mode</th><th>{column}</th><th>attempted</th><th>done</th><th>success rate</th><th>95 % CI (Wilson)</th></tr>",
    );
    let mut any = false;
    for r in &s.rows {
        for l in stages(r) {
            any = true;
            let _ = write!(
                h,
                "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}–{}</td></tr>",
                esc(&r.scenario),
                esc(&r.planner),
                esc(&r.tracker),
                batch::mode_name(r.replan),
                esc(&l.name),
                l.attempted,
                l.done,
                pct(l.success_rate),
                pct(l.ci95_low),
                pct(l.ci95_high)
            );
        }
    }
    if any { h + "</table>" } else { String::new() }
}

/// Successes and failures by first failed criterion, one bar per row.
pub fn failure_breakdown(s: &Summary) -> String {
    let mut kinds: Vec<String> = vec!["success".into()];
    let mut found: BTreeSet<String> = BTreeSet::new();
    for r in &s.rows {
        found.extend(r.failures.keys().cloned());
    }
    kinds.extend(found);
    let rows: Vec<(String, Vec<(String, u64)>)> = s
        .rows
        .iter()
        .map(|r| {
            let mut segs = vec![("success".to_owned(), r.successes)];
            segs.extend(r.failures.iter().map(|(k, n)| (k.clone(), *n)));
            (
                row_label(&r.scenario, &r.planner, &r.tracker, Some(r.replan)),
                segs,
            )
        })
        .collect();
    svg::stacked_bars("failures", &rows, &kinds)
}

/// Success over lateral offset × pallet angle, per scenario (with at least 4 cases) and
/// planner × tracker × mode ([`batch::case_grids`]).
pub fn heatmaps(manifest: &Manifest, records: &[TrialRecord]) -> String {
    let mut h = String::new();
    for ((scenario, planner, tracker, replan), grid) in batch::case_grids(manifest, records, 4) {
        let xs: Vec<i64> = grid
            .keys()
            .map(|k| k.0)
            .collect::<BTreeSet<_>>()
            .into_iter()
            .collect();
        let ys: Vec<i64> = grid
            .keys()
            .map(|k| k.1)
            .collect::<BTreeSet<_>>()
            .into_iter()
            .collect();
        let xf: Vec<f64> = xs.iter().map(|x| *x as f64).collect();
        let yf: Vec<f64> = ys.iter().map(|y| *y as f64 / 10.0).collect();
        let cell = |i: usize, j: usize| grid.get(&(xs[i], ys[j])).copied();
        let mode = batch::mode_name(replan);
        let id = format!(
            "heatmap-{scenario}-{planner}-{tracker}-{}",
            mode.replace(' ', "-")
        );
        let title = format!("{scenario}: {planner} / {tracker} / {mode}");
        h.push_str(&svg::heatmap(
            &id,
            &title,
            &xf,
            &yf,
            &cell,
            ("goal lateral offset D (cm, right +)", "pallet angle θ (°)"),
        ));
    }
    h
}

/// |lateral| and |heading| error at entry per planner × tracker × mode, with the limits
/// that judged them: a pair of histograms per distinct pair of limits (each scenario's
/// own), titled with its scenarios when there is more than one pair.
pub fn error_distributions(manifest: &Manifest, records: &[TrialRecord]) -> String {
    let groups = batch::error_groups(manifest, records);
    let several = groups.len() > 1;
    let mut h = String::new();
    for (k, g) in groups.iter().enumerate() {
        let (lat_m, head_deg) = g.limits.unwrap_or((0.0, 0.0));
        let suffix = if several {
            format!("-{k}")
        } else {
            String::new()
        };
        if several {
            let _ = write!(
                h,
                "<h3>Limits ±{:.0} mm, ±{head_deg}°: {}</h3>",
                lat_m * 1e3,
                esc(&g.scenarios.join(", "))
            );
        }
        let lat: Vec<_> = g.lateral_mm.clone().into_iter().collect();
        let head: Vec<_> = g.heading_deg.clone().into_iter().collect();
        h += &svg::histogram(
            &format!("errors-lateral{suffix}"),
            "|lateral error| at entry",
            &lat,
            (lat_m * 1e3, "mm"),
            "|lateral error| (mm)",
        );
        h += &svg::histogram(
            &format!("errors-heading{suffix}"),
            "|heading error| at entry",
            &head,
            (head_deg, "°"),
            "|heading error| (°)",
        );
    }
    h
}

/// Failed trials: reason, and links to their recordings where the batch wrote them.
pub fn failed_trials(dir: &Path, records: &[(usize, TrialRecord)]) -> String {
    const MAX_ROWS: usize = 2000;
    let rec_dir = dir.join("recordings");
    let trials_file = dir.join("trials.jsonl").display().to_string();
    let mut h = String::from(
        "<p><input id=\"failed-filter\" placeholder=\"filter: scenario, case, mode, failure, seed…\" size=\"60\" oninput=\"const q=this.value.toLowerCase();for(const r of document.querySelectorAll('#failed tr.f'))r.style.display=r.textContent.toLowerCase().includes(q)?'':'none'\"></p><table id=\"failed\"><tr><th>scenario</th><th>case</th><th>planner / tracker</th><th>mode</th><th>trial</th><th>seed</th><th>failure</th><th>recording</th><th>replay</th></tr>",
    );
    let mut failed: Vec<&(usize, TrialRecord)> =
        records.iter().filter(|(_, r)| !r.outcome.success).collect();
    failed.sort_by_key(|(_, r)| r.key());
    let shown = failed.len().min(MAX_ROWS);
    for (line, r) in &failed[..shown] {
        let o = &r.outcome;
        let stem = o.recording_stem(r.replan == Some(true));
        let links: Vec<String> = ["rrd", "mcap"]
            .iter()
            .filter(|ext| rec_dir.join(format!("{stem}.{ext}")).is_file())
            .map(|ext| format!("<a href=\"recordings/{}.{ext}\">.{ext}</a>", esc(&stem)))
            .collect();
        // The replay writes what this batch's build wrote: an .rrd needs rerun built in.
        let again = if rec_dir.join(format!("{stem}.rrd")).is_file() {
            "--rrd t.rrd"
        } else {
            "--mcap t.mcap"
        };
        let _ = write!(
            h,
            "<tr class=\"f\"><td>{}</td><td>{}</td><td>{} / {}</td><td>{}</td><td>{}</td><td>{}</td><td><b>{}</b>: {}</td><td>{}</td><td><code>forkbench replay {} --line {line} {}</code></td></tr>",
            esc(&o.scenario),
            esc(&o.case),
            esc(&o.planner),
            esc(&o.tracker),
            batch::mode_name(r.replan == Some(true)),
            r.trial,
            o.seed,
            o.failure.as_ref().map_or("?", |f| f.name()),
            esc(o.failure_detail.as_deref().unwrap_or("")),
            if links.is_empty() {
                "–".to_owned()
            } else {
                links.join(" ")
            },
            esc(&trials_file),
            again
        );
    }
    let _ = write!(
        h,
        "</table><p>{} failed trials{}.</p>",
        failed.len(),
        if shown < failed.len() {
            format!(
                ", the first {shown} in key order listed (all are in trials.jsonl and trials.csv)"
            )
        } else {
            String::new()
        }
    );
    h
}

/// The comparison with a baseline, a verdict per row: pairing, discordant pairs, raw and
/// adjusted p, and the drop each row can see.
pub fn baseline_comparison(g: &GateReport) -> String {
    let mut h = format!("<p>{}</p>", esc(&g.pairing_text()));
    if !g.setting_differences.is_empty() {
        h.push_str("<p class=\"warn\">The baseline's batch had other scenario settings (not comparable row for row):</p><ul>");
        for d in &g.setting_differences {
            let _ = write!(h, "<li>{}</li>", esc(d));
        }
        h.push_str("</ul>");
    }
    h.push_str("<table><tr><th>scenario / planner / tracker</th><th>baseline</th><th>now</th><th>broke / fixed</th><th>p (drop)</th><th>p adjusted</th><th>detectable drop (80 % power)</th><th>verdict</th></tr>");
    let p = |v: Option<f64>| v.map_or("–".into(), |p| format!("{p:.4}"));
    for r in &g.rows {
        let class = match r.verdict {
            Verdict::Ok => "ok",
            Verdict::New => "warn",
            _ => "bad",
        };
        let rate =
            |v: Option<f64>, n: u64| v.map_or("–".into(), |v| format!("{} (n={n})", pct(v)));
        let _ = write!(
            h,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td class=\"{class}\">{}</td></tr>",
            esc(&row_label(&r.scenario, &r.planner, &r.tracker, r.replan)),
            rate(r.baseline_rate, r.baseline_trials),
            rate(r.now_rate, r.now_trials),
            esc(&r.pairs_text()),
            p(r.p_value),
            p(r.p_adjusted),
            esc(&r.detectable_text()),
            esc(r.verdict.name())
        );
    }
    let _ = write!(
        h,
        "</table><p>α = {} over all rows, {} correction; a row fails on adjusted p &lt; α, a rate below the floor, or when missing. Detectable drop: at level α/m = {:.4}.</p>",
        g.alpha,
        esc(g.correction.name()),
        g.power_level
    );
    h
}

/// The provenance block: who ran what, where, when; every scenario's resolved settings.
pub fn provenance(p: Option<&Provenance>) -> String {
    let Some(p) = p else {
        return "<p>No provenance recorded (results from an older forkbench).</p>".into();
    };
    let m = &p.manifest;
    let mut h = String::from("<table class=\"kv\">");
    let items = [
        ("forkbench", p.forkbench_version.clone()),
        (
            "git commit",
            p.git_commit
                .clone()
                .unwrap_or_else(|| "not built from a checkout".into()),
        ),
        ("host", p.host.clone()),
        (
            "CPU",
            format!(
                "{} ({} cores, {} worker threads)",
                p.cpu_model, p.cores, p.jobs
            ),
        ),
        (
            "started / finished (UTC)",
            format!("{} / {}", p.started_at, p.finished_at),
        ),
        ("command", p.arguments.join(" ")),
        ("batch", batch_in_words(m)),
    ];
    for (k, v) in items {
        let _ = write!(h, "<tr><th>{k}</th><td>{}</td></tr>", esc(&v));
    }
    h.push_str("</table>");
    if p.runs.len() > 1 {
        h.push_str("<p>Runs that wrote trials here (the first, then each resume):</p><table><tr><th>run</th><th>started / finished (UTC)</th><th>trials to run</th><th>host, threads</th><th>command</th></tr>");
        for (i, r) in p.runs.iter().enumerate() {
            let _ = write!(
                h,
                "<tr><td>{}</td><td>{} / {}</td><td>{}</td><td>{}, {}</td><td>{}</td></tr>",
                if i == 0 {
                    "first".to_owned()
                } else {
                    format!("resume {i}")
                },
                esc(&r.started_at),
                esc(r.finished_at.as_deref().unwrap_or("interrupted")),
                r.trials_to_run,
                esc(&r.host),
                r.jobs,
                esc(&r.arguments.join(" "))
            );
        }
        h.push_str("</table>");
    }
    for s in &m.scenarios {
        let text = serde_json::to_string_pretty(&s.settings).unwrap_or_default();
        let _ = write!(
            h,
            "<details><summary>scenario {} ({}), settings {}</summary><pre>{}</pre></details>",
            esc(&s.name),
            esc(&s.file),
            esc(&s.settings_hash),
            esc(&text)
        );
    }
    h
}

/// The batch's arguments in words (not Rust's debug output).
fn batch_in_words(m: &Manifest) -> String {
    let list = |v: &[String], none: &str| {
        if v.is_empty() {
            none.to_owned()
        } else {
            v.join(", ")
        }
    };
    let o = &m.overrides;
    let mut noise: Vec<String> = forkbench_trial::trial::NOISE_KNOBS
        .iter()
        .filter_map(|k| o.scale(k).map(|x| format!("{} × {x}", k.replace('_', " "))))
        .collect();
    for (what, v) in [
        ("localiser", &o.localizer),
        ("pallet sensing", &o.pallet_sensing),
    ] {
        if let Some(v) = v {
            noise.push(format!("{what} {v}"));
        }
    }
    if let Some(m) = &o.missing_reflectors {
        noise.push(format!("reflectors missing: {}", m.join(", ")));
    }
    let noise = if noise.is_empty() {
        "as each scenario sets it".to_owned()
    } else {
        noise.join(", ")
    };
    let modes = match (m.compare_replanning, m.replan) {
        (true, _) => "both (plan once and replan, same seeds)",
        (false, Some(true)) => "replan always",
        (false, Some(false)) => "plan once always",
        (false, None) => "each scenario's own",
    };
    format!(
        "seed {}, {} trials per row and case, shard {} of {}; planners: {}; trackers: {}; noise and sensing: {noise}; replanning: {modes}",
        m.seed,
        m.trials,
        m.shard[0] + 1,
        m.shard[1],
        list(&m.planners, "each scenario's own"),
        list(&m.trackers, "each scenario's own"),
    )
}

/// Success against a noise knob's scale, a line per scenario × planner × tracker.
pub fn sweep(knob: &str, points: &[(f64, Summary)]) -> String {
    let mut series: BTreeMap<String, Vec<(f64, f64, f64, f64)>> = BTreeMap::new();
    for (v, s) in points {
        for r in &s.rows {
            series
                .entry(row_label(
                    &r.scenario,
                    &r.planner,
                    &r.tracker,
                    Some(r.replan),
                ))
                .or_default()
                .push((
                    *v,
                    100.0 * r.success_rate,
                    100.0 * r.ci95_low,
                    100.0 * r.ci95_high,
                ));
        }
    }
    let series: Vec<_> = series.into_iter().collect();
    svg::lines(
        "sweep",
        &format!("fork-entry success vs {}", knob.replace('_', " ")),
        &series,
        &crate::knob_axis(knob),
    )
}
