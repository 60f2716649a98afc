//! The phases after the pick: lift and reverse out judged phase by phase, the load's criteria, and phase lists refused at load.

use std::path::Path;

use forkbench_trial::{Failure, Scenario, TrialOptions, World, run_trial};

/// scenarios/rack-pick-cycle.toml (pick from a rack bay, lift 800 kg, back out 2.5 m)
/// with `edit` applied to its text.
fn cycle(edit: impl Fn(String) -> String) -> Result<Scenario, String> {
    let dir = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenarios"));
    let text = std::fs::read_to_string(dir.join("rack-pick-cycle.toml")).expect("the scenario");
    Scenario::parse(&edit(text), "cycle.toml", |w| World::load(&dir.join(w)))
        .map_err(|e| e.to_string())
}

/// The cycle with other phases (and no phase settings).
fn with_phases(list: &str) -> Result<Scenario, String> {
    cycle(|t| {
        let from = t.find("[phase.lift]").expect("phase settings");
        let to = t.find("[replan]").expect("replan");
        format!("{}{}", &t[..from], &t[to..])
            .replace(r#"phases = ["pick", "lift", "reverse_out"]"#, list)
    })
}

fn seed(s: u64) -> TrialOptions {
    TrialOptions {
        seed: Some(s),
        ..TrialOptions::default()
    }
}

#[test]
fn a_lifted_pallet_is_carried_out_and_each_phase_is_judged() {
    let scn = cycle(|t| t).expect("valid");
    let out = run_trial(&scn, &scn.cases[0], &seed(3));
    assert!(out.success, "{}", out.verdict_line());
    let names: Vec<_> = out.phases.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["pick", "lift", "reverse_out"]);
    assert!(out.phases.iter().all(|p| p.success));
    let [pick, lift, back] = [&out.phases[0], &out.phases[1], &out.phases[2]];
    assert!(!pick.loaded && lift.loaded && back.loaded);
    assert!(
        (lift.time_s - 2.0).abs() < 0.05 && lift.distance_m < 0.01,
        "{lift:?}"
    );
    assert!((back.distance_m - 2.5).abs() < 0.15, "{back:?}");
    let total: f64 = out.phases.iter().map(|p| p.time_s).sum();
    assert!(
        (total - out.sim_time_s).abs() < 0.05,
        "{total} vs {}",
        out.sim_time_s
    );
}

#[test]
fn backing_out_without_lifting_leaves_the_pallet_standing() {
    let scn = with_phases(r#"phases = ["pick", "reverse_out"]"#).expect("valid");
    let out = run_trial(&scn, &scn.cases[0], &seed(3));
    assert!(out.success, "{}", out.verdict_line());
    assert!(!out.phases[1].loaded);
    assert!(out.phases[1].distance_m > 1.9, "{:?}", out.phases[1]);
}

/// Forks whose friction holds only 0.49 m/s²: the load slides off as the truck pulls
/// away, and the verdict names the phase and the criterion.
#[test]
fn a_load_on_slippery_forks_fails_the_phase_that_shook_it() {
    let scn =
        cycle(|t| t.replace("[replan]", "[sim]\nfork_friction = 0.05\n\n[replan]")).expect("valid");
    let out = run_trial(&scn, &scn.cases[0], &seed(3));
    assert_eq!(
        out.failure,
        Some(Failure::LoadShifted),
        "{}",
        out.verdict_line()
    );
    let last = out.phases.last().expect("phases");
    assert_eq!(last.name, "reverse_out");
    assert!(!last.success && last.failure == Some(Failure::LoadShifted));
    let detail = out.failure_detail.as_deref().unwrap_or("");
    assert!(
        detail.starts_with("reverse_out: ") && detail.contains("m/s²"),
        "{detail}"
    );
    assert!(out.phases[..2].iter().all(|p| p.success));
}

#[test]
fn a_failed_pick_ends_the_cycle_at_the_pick() {
    // A pallet estimate 0.3 m off: the forks miss the pockets.
    let scn = cycle(|t| {
        t.replace(
            "payload_kg",
            "estimate_bias = { x_m = 0.0, y_m = 0.3, heading_deg = 0.0 }\npayload_kg",
        )
    })
    .expect("valid");
    let out = run_trial(&scn, &scn.cases[0], &seed(3));
    assert!(!out.success);
    assert_eq!(out.phases.len(), 1, "{:?}", out.phases);
    assert!(!out.phases[0].success && out.phases[0].failure == out.failure);
}

#[test]
fn a_pick_without_phases_reports_none() {
    let scn = with_phases("").expect("valid");
    let out = run_trial(&scn, &scn.cases[0], &seed(3));
    assert!(out.success && out.phases.is_empty());
}

#[test]
fn phase_lists_that_cannot_run_are_refused_at_load() {
    let line = |l: &str| l.to_owned();
    let cases = [
        (
            line(r#"phases = ["lift"]"#),
            "cycle.toml:14",
            "must start with \"pick\"",
        ),
        (
            line(r#"phases = ["pick", "reverse_out", "lift"]"#),
            "phases[2]",
            "cannot follow \"reverse_out\"",
        ),
        (
            line(r#"phases = ["pick", "place"]"#),
            "phases[1]",
            "no phase \"place\"",
        ),
        (
            line("phases = [\"pick\", \"lift\"]\n[phase.lift]\ntime_s = -1.0\n"),
            "phase.lift",
            "time_s",
        ),
        (
            line("phases = [\"pick\", \"lift\"]\n[phase.lift]\nheight_m = 1.0\n"),
            "phase.lift",
            "height_m",
        ),
        (
            line("[phase.reverse_out]\ndistance_m = 1.0\n"),
            "phase.reverse_out",
            "does not list",
        ),
    ];
    for (phases, field, reason) in cases {
        // The phase list and its settings replace the file's.
        let e = with_phases(&phases).expect_err(&phases);
        assert!(e.contains(field) && e.contains(reason), "{phases}: {e}");
    }
    let heavy = cycle(|t| t.replace("payload_kg = 800.0", "payload_kg = 3500.0"));
    let e = heavy.expect_err("over the rating");
    assert!(
        e.contains("payload_kg") && e.contains("rated_capacity_kg"),
        "{e}"
    );
}
