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
            line(r#"phases = ["pick", "dance"]"#),
            "phases[1]",
            "no phase \"dance\"",
        ),
        (
            line("phases = [\"pick\", \"lift\"]\n[phase.lift]\ntime_s = -1.0\n"),
            "cycle.toml:15: field `phase.lift`",
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
    let e = cycle(|t| t.replace(r#""reverse_out"]"#, r#""reverse_out", "return"]"#))
        .expect_err("a return without a mission");
    assert!(e.contains("phase.return") && e.contains("[mission]"), "{e}");
    // Named at the phase list's line, as the return has no table of its own.
    assert!(
        e.split_once("cycle.toml:")
            .is_some_and(|(_, rest)| rest.starts_with(|c: char| c.is_ascii_digit())),
        "no line: {e}"
    );
    let heavy = cycle(|t| t.replace("payload_kg = 800.0", "payload_kg = 3500.0"));
    let e = heavy.expect_err("over the rating");
    assert!(
        e.contains("cycle.toml:11:") && e.contains("payload_kg") && e.contains("rated_capacity_kg"),
        "{e}"
    );
}

/// scenarios/warehouse-cycle.toml with `edit` applied to its text.
fn warehouse_cycle(edit: impl Fn(String) -> String) -> Result<Scenario, String> {
    let dir = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenarios"));
    let text = std::fs::read_to_string(dir.join("warehouse-cycle.toml")).expect("the scenario");
    Scenario::parse(&edit(text), "wc.toml", |w| World::load(&dir.join(w)))
        .map_err(|e| e.to_string())
}

#[test]
fn a_carried_pallet_is_placed_in_its_slot_and_the_truck_returns() {
    let scn = warehouse_cycle(|t| t).expect("valid");
    let out = run_trial(&scn, &scn.cases[0], &seed(5));
    assert!(out.success, "{}", out.verdict_line());
    let names: Vec<_> = out.phases.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(
        names,
        ["pick", "lift", "reverse_out", "carry", "place", "return"]
    );
    let (carry, place, back) = (&out.phases[3], &out.phases[4], &out.phases[5]);
    assert!(carry.loaded && place.loaded && !back.loaded);
    let m = &place.measures;
    assert!(m["position_error_m"] < 0.05 && m["heading_error_rad"].abs() < 2f64.to_radians());
    // The drop slot's pallet ends 0.3 m short of the north wall.
    assert!(m["clearance_m"] > 0.2 && m["clearance_m"] < 0.4, "{m:?}");
    assert!(back.measures["final_position_error_m"] < 0.3, "{back:?}");
    // Loaded: the carry and the drive to the slot (not the retract).
    let cycle = out.cycle.expect("cycle totals");
    let carried = out.phases[2].distance_m + carry.distance_m + place.distance_m;
    assert!(cycle.distance_loaded_m > carry.distance_m && cycle.distance_loaded_m < carried);
    assert!((cycle.time_s - out.sim_time_s).abs() < 1e-9);
    assert!(cycle.distance_unloaded_m > back.distance_m + out.phases[0].distance_m);
}

/// The carry ends 2 m beside the drop slot's axis and 2.5 m before it: no path within
/// the truck's curvature reaches the slot, and the place fails planning, naming it.
#[test]
fn a_slot_the_planner_cannot_reach_fails_the_place() {
    let scn = warehouse_cycle(|t| t.replace("x_m = 6.5, y_m = 19.0", "x_m = 8.5, y_m = 21.5"))
        .expect("valid");
    let out = run_trial(&scn, &scn.cases[0], &seed(5));
    assert_eq!(
        out.failure,
        Some(Failure::PlanFailed),
        "{}",
        out.verdict_line()
    );
    let detail = out.failure_detail.as_deref().unwrap_or("");
    assert!(
        detail.starts_with("place: to slot \"sorting-drop\""),
        "{detail}"
    );
    assert_eq!(out.phases.len(), 5);
}

#[test]
fn places_that_cannot_be_are_refused_at_load() {
    let without_carry = |t: String| {
        let t = t.replace("[phase.reverse_out]\ndistance_m = 2.5\n", "");
        let from = t.find("# The carry backs out").expect("carry settings");
        let to = t.find("[phase.place]").expect("place settings");
        format!("{}{}", &t[..from], &t[to..])
    };
    let cases: [(&str, &str, &str, bool); 7] = [
        (
            "pose = { x_m = 6.5",
            "pose = { x_m = 1e300",
            "within ±10000 m",
            false,
        ),
        (
            "pose = { x_m = 6.5, y_m = 19.0, heading_deg = 90.0 }",
            "pose = { x_m = 6.5, y_m = 19.0, heading_deg = 1e9 }",
            "±360°",
            false,
        ),
        (
            "slot = \"sorting-drop\"",
            "slot = \"bay9\"",
            "no such slot",
            false,
        ),
        ("slot = \"sorting-drop\"", "", "slot: name", false),
        (
            "\"lift\", \"reverse_out\", \"carry\", \"place\"",
            "\"place\"",
            "cannot follow \"pick\"",
            true,
        ),
        (
            "\"lift\", \"reverse_out\", \"carry\"",
            "\"reverse_out\", \"carry\"",
            "needs the pallet on the forks",
            false,
        ),
        (
            "pose = { x_m = 6.5",
            "to = \"sorting\"\npose = { x_m = 6.5",
            "not both",
            false,
        ),
    ];
    for (from, to, reason, drop_carry) in cases {
        let e = warehouse_cycle(|t| {
            let t = t.replace(from, to);
            if drop_carry { without_carry(t) } else { t }
        })
        .expect_err(to);
        assert!(e.contains(reason), "{to}: {e}");
    }
    // A slot whose pallet would stand in a rack: the shelf's middle frame.
    let world = forkbench_trial::World::load(Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../worlds/warehouse.toml"
    )))
    .expect("world");
    let mut inside = world.clone();
    let mut bay = inside.pallet_slot[1].clone();
    bay.name = "in-frame".into();
    bay.y_m = 10.1;
    inside.pallet_slot.push(bay);
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenarios/warehouse-cycle.toml"
    ))
    .expect("scenario")
    .replace("slot = \"sorting-drop\"", "slot = \"in-frame\"");
    let e = Scenario::parse(&text, "wc.toml", |_| Ok(inside.clone())).expect_err("in a rack");
    let e = e.to_string();
    assert!(
        e.contains("phase.place") && e.contains("overlaps rack \"shelf-frame1\""),
        "{e}"
    );
}
