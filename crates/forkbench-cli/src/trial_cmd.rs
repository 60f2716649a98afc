//! `forkbench trial`: one pick trial from a scenario file, printed as text or JSON.

use std::path::Path;

use anyhow::Context as _;
use forkbench_trial::text::one_line;
use forkbench_trial::{TrialOptions, TrialOutcome};

/// `trial` (a pick, or a whole mission when the scenario has one) and `mission` (which
/// requires one and prints each leg): runs, records, prints; Ok(success).
pub fn run(
    (file, components): (&Path, Option<&Path>),
    case: Option<&str>,
    opts: &TrialOptions,
    (json, mission, profile): (bool, bool, bool),
    rec: &forkbench_log::RecordTargets,
) -> anyhow::Result<bool> {
    let scn = crate::with_components(forkbench_trial::defaults::load_scenario(file)?, components)?;
    crate::warn_slips(&scn);
    if mission && scn.mission.is_none() {
        anyhow::bail!(
            "{}: has no [mission] table; `forkbench trial` runs its pick",
            file.display()
        );
    }
    let case = scn.pick_case(case)?;
    // Unknown planner or tracker names, and overrides that cannot act, stop here, before
    // any recording file is made.
    let run = opts.check_against(&scn)?;
    // File targets are checked before the run; a viewer that cannot be reached is
    // reported and the trial runs anyway.
    let recorded = || forkbench_log::run_recorded((&scn, case), (opts, &run), rec);
    // A profile covers the recording too: its files are opened and written in it.
    let (recorded, gathered) = if profile {
        let (r, p) = forkbench_core::profile::gather(recorded);
        (r, Some(p))
    } else {
        (recorded(), None)
    };
    let forkbench_log::Recorded {
        outcome: mut out,
        written,
        viewer_error,
    } = recorded?;
    if let Some(p) = gathered {
        forkbench_trial::attach_profile(&mut out, p);
    }
    if let Some(e) = &viewer_error {
        eprintln!(
            "error: {} (the trial ran without the viewer)",
            forkbench_trial::text::visible(&e.to_string())
        );
    }
    // The outcome is printed even when a recording failed (it is computed); the error
    // then makes the exit status non-zero.
    let text = if json {
        json_report(&out)?
    } else {
        let profile = out
            .profile
            .as_ref()
            .map_or(String::new(), |p| p.lines("profile ").join("\n") + "\n");
        crate::mission_report::legs_text(&out) + &text_report(&out, &run.truck) + &profile
    };
    crate::emit(&text)?;
    written.context("writing the recording")?;
    if viewer_error.is_some() {
        anyhow::bail!("the requested rerun viewer could not be reached");
    }
    Ok(out.success)
}

/// The outcome as one JSON object; a mission's also carries its `overall` figures.
fn json_report(out: &TrialOutcome) -> anyhow::Result<String> {
    let mut v = serde_json::to_value(out).context("serialising the outcome")?;
    if let Some(summary) = forkbench_trial::MissionSummary::of(out)
        && let Some(map) = v.as_object_mut()
    {
        let summary = serde_json::to_value(summary).context("serialising the mission")?;
        map.insert("overall".into(), summary);
    }
    Ok(format!("{v}\n"))
}

/// The pick's outcome as aligned text lines, after the truck that ran it.
fn text_report(out: &TrialOutcome, truck: &forkbench_core::ForkliftSpec) -> String {
    // A trial that failed before driving has no final pose: "–", not "NaN m".
    let num = |v: f64, digits: usize, unit: &str| {
        if v.is_finite() {
            format!("{v:.digits$} {unit}")
        } else {
            "–".to_owned()
        }
    };
    let opt = |v: Option<f64>, scale: f64, unit: &str| {
        v.map_or("never entered".to_owned(), |v| num(v * scale, 4, unit))
    };
    let mut lines = verdict_lines(out);
    lines.extend([
        format!(
            "truck                {}; wheelbase {:.3} m, {:.0} kg, forks {:.3} m",
            truck.layout.describe(),
            truck.wheelbase_m,
            truck.mass_kg,
            truck.fork_length_m
        ),
        format!(
            "lateral error entry  {}",
            opt(out.lateral_error_m, 1.0, "m")
        ),
        format!(
            "heading error entry  {}",
            opt(out.heading_error_rad, 1.0, "rad")
        ),
        format!(
            "final lateral error  {}",
            num(out.final_lateral_error_m, 4, "m")
        ),
        format!(
            "final heading error  {}",
            num(out.final_heading_error_rad, 5, "rad")
        ),
        format!(
            "insertion depth      {}",
            num(out.insertion_depth_m, 3, "m")
        ),
        format!(
            "localisation         {} fixes, {} without a pose ({:.2} s); largest gap {:.2} s; \
             error mean {} / max {:.1} mm",
            out.fixes,
            out.fixes_missed,
            out.time_without_fix_s,
            out.largest_fix_gap_s,
            num(1e3 * out.localization_error_mean_m, 1, "mm"),
            1e3 * out.localization_error_max_m
        ),
        format!("max steering         {:.4} rad", out.max_steer_rad),
        format!("max contact force    {:.1} N", out.max_contact_force_n),
        format!(
            "pallet displacement  {:.4} m, {:.3}°",
            out.pallet_displacement_m,
            out.pallet_rotation_rad.to_degrees()
        ),
        format!("replans              {}", out.replans),
    ]);
    lines.extend(phase_lines(out));
    lines.extend(out.safety.iter().map(safety_line));
    lines.extend([
        format!("sim time             {:.2} s", out.sim_time_s),
        format!("wall time            {:.1} ms", out.wall_time_ms),
    ]);
    lines.join("\n") + "\n"
}

/// The trial, its verdict, the reason and likely cause, and every other criterion it
/// broke (the verdict names the first).
fn verdict_lines(out: &TrialOutcome) -> Vec<String> {
    let noise = if out.noise { "" } else { " / no noise" };
    let mut lines = vec![
        format!(
            "scenario             {} / case {} / planner {} / seed {}{noise}",
            one_line(&out.scenario),
            one_line(&out.case),
            one_line(&out.planner),
            out.seed
        ),
        format!("outcome              {}", out.verdict_word()),
    ];
    if let Some(d) = &out.failure_detail {
        // A planner's message may carry terminal escapes: shown, never obeyed.
        lines.push(format!("reason               {}", one_line(d)));
    }
    if let Some(c) = &out.likely_cause {
        lines.push(format!("likely cause         {}", one_line(c)));
    }
    for also in &out.also_failed {
        lines.push(format!("also failed          {}", one_line(also)));
    }
    lines
}

/// What the people and the safety function did.
fn safety_line(s: &forkbench_trial::SafetyOutcome) -> String {
    let closest = s
        .closest_any_m()
        .map_or("–".to_owned(), |d| format!("{d:.2} m"));
    format!(
        "safety               protective stops {} ({} with nobody in the field), {:.1} s stopped; slowdowns {}, {:.1} s slowed; contacts {}; closest {closest}",
        s.stops, s.false_trips, s.stop_time_s, s.slowdowns, s.slowdown_time_s, s.person_contacts
    )
}

/// One line per phase of a handling cycle (its verdict, time, distance and load), then
/// the cycle's totals.
fn phase_lines(out: &TrialOutcome) -> Vec<String> {
    out.phases
        .iter()
        .map(|p| {
            let verdict = match (p.success, &p.failure) {
                (true, _) => "done".to_owned(),
                (false, f) => format!(
                    "FAILED: {}: {}",
                    f.as_ref().map_or("unknown", |f| f.name()),
                    one_line(p.failure_detail.as_deref().unwrap_or(""))
                ),
            };
            format!(
                "{:<20} {verdict}; {:.2} s, {:.2} m{}",
                format!("phase {}", p.name),
                p.time_s,
                p.distance_m,
                if p.loaded { ", loaded" } else { "" }
            )
        })
        .chain(out.cycle.iter().map(|c| {
            format!(
                "cycle                {:.2} s; {:.2} m driven loaded, {:.2} m empty",
                c.time_s, c.distance_loaded_m, c.distance_unloaded_m
            )
        }))
        .collect()
}

/// Trial options from the CLI: seed, (planner, tracker) names, noise off, replanning
/// and the overrides, checked by the library's one validation.
pub fn options(
    seed: Option<u64>,
    (planner, tracker): (Option<String>, Option<String>),
    no_noise: bool,
    replan: bool,
    overrides: forkbench_trial::trial::Overrides,
) -> anyhow::Result<TrialOptions> {
    let opts = TrialOptions {
        seed,
        planner,
        tracker,
        no_noise,
        replan: replan.then_some(true),
        overrides,
        wall_budget_s: None,
        uncertain: Default::default(),
    };
    opts.validate()?;
    Ok(opts)
}
