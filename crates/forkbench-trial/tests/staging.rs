//! The pick as a docking server runs it: a face not seen from the start is looked for again from a staging pose (reached by Hybrid-A*, forwards and backwards), with bounded looks and typed failures; `when_not_seen = "fail"` keeps the papers' one look.

use std::path::{Path, PathBuf};

use forkbench_trial::{Failure, Scenario, TrialOptions, World, run_trial};

fn repo(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(rel)
}

fn no_noise() -> TrialOptions {
    TrialOptions {
        no_noise: true,
        ..TrialOptions::default()
    }
}

/// A pick with the truck facing away from the pallet 6 m ahead (its scanner sees only
/// the floor behind it), with `extra` appended (a `[pick]` table, a detector).
fn facing_away(extra: &str, world: &str) -> Scenario {
    let text = format!(
        "name = \"away\"\nplanner = \"bspline\"\nstart = {{ x_m = 0, y_m = 0, heading_deg = 180 }}\n\
         pallet = {{ x_m = 6, y_m = 0, heading_deg = 0 }}\n{}[sensors.pallet]\nkind = \"tim561\"\n{extra}",
        if world.is_empty() {
            ""
        } else {
            "world = \"w.toml\"\n"
        }
    );
    let world = world.to_owned();
    Scenario::parse(&text, "away.toml", move |_| World::parse(&world, "w.toml"))
        .expect("the scenario loads")
}

#[test]
fn no_table2_case_of_either_paper_ends_pallet_not_found_without_noise() {
    for file in [
        "scenarios/spiral-table2.toml",
        "scenarios/bspline-table2.toml",
    ] {
        let scn = Scenario::load(&repo(file)).expect("loads");
        let mut staged = 0;
        for case in &scn.cases {
            let out = run_trial(&scn, case, &no_noise());
            assert_ne!(
                out.failure,
                Some(Failure::PalletNotFound),
                "{file} case {}: {:?}",
                case.name,
                out.failure_detail
            );
            assert_ne!(
                out.failure,
                Some(Failure::StagingUnreachable),
                "{file} {}",
                case.name
            );
            if out
                .legs
                .iter()
                .any(|l| l.name == forkbench_trial::trial::STAGING_LEG)
            {
                staged += 1;
                assert!(
                    out.success,
                    "{file} case {} staged and failed: {out:?}",
                    case.name
                );
            }
        }
        // The cases whose face is out of view from the start (a pallet turned away or to
        // the side) are the ones staged.
        assert!(staged >= 1, "{file}: no case staged");
    }
}

#[test]
fn a_truck_facing_away_stages_and_picks_and_fail_keeps_one_look() {
    let scn = facing_away("", "");
    let out = run_trial(&scn, &scn.cases[0], &no_noise());
    assert!(out.success, "{out:?}");
    assert_eq!(out.legs.len(), 1);
    assert_eq!(out.legs[0].name, forkbench_trial::trial::STAGING_LEG);
    assert!(out.legs[0].reverse_length_m >= 0.0);
    // One look from the start (missed), one from the staging pose (found).
    assert_eq!((out.estimates, out.estimates_missed), (2, 1));

    let scn = facing_away("[pick]\nwhen_not_seen = \"fail\"\n", "");
    let out = run_trial(&scn, &scn.cases[0], &no_noise());
    assert_eq!(out.failure, Some(Failure::PalletNotFound));
    assert!(out.legs.is_empty());
    assert_eq!((out.estimates, out.estimates_missed), (1, 1));
}

/// A detector that never finds the pallet: the looks at the staging pose are bounded,
/// and `move` backs the truck away between them.
#[test]
fn looks_are_bounded_and_move_backs_away_between_them() {
    let dir = std::env::temp_dir().join(format!("forkbench-staging-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let blind = dir.join("blind.py");
    std::fs::write(
        &blind,
        "import json, sys\nfor line in sys.stdin:\n    m = json.loads(line)\n    \
         r = {\"type\": \"hello\", \"protocol\": \"forkbench-detector\", \"version\": 1, \
         \"name\": \"blind\"} if m.get(\"type\") == \"hello\" else {\"type\": \"none\", \
         \"id\": m[\"id\"]}\n    print(json.dumps(r), flush=True)\n",
    )
    .expect("write");
    let detector = format!(
        "[sensors.pallet.detector]\nkind = \"external\"\ncommand = [\"python3\", {:?}]\n",
        blind.display().to_string()
    );
    let pick = "[pick]\nlooks = 4\nbetween_looks = \"move\"\nretry_step_m = 0.4\n";
    let scn = facing_away(&format!("{pick}{detector}"), "");
    let out = run_trial(&scn, &scn.cases[0], &no_noise());
    assert_eq!(out.failure, Some(Failure::PalletNotFound), "{out:?}");
    assert_eq!((out.estimates, out.estimates_missed), (5, 5));
    let detail = out.failure_detail.unwrap_or_default();
    assert!(detail.contains("4 looks"), "{detail}");
    assert!(out.sim_time_s > 0.0, "measurements kept on the failure");
    // Backing 3 × 0.4 m away between the looks takes simulated time that standing does
    // not.
    let stand = "[pick]\nlooks = 4\nretry_wait_s = 0.0\n";
    let still = facing_away(&format!("{stand}{detector}"), "");
    let out_still = run_trial(&still, &still.cases[0], &no_noise());
    assert_eq!(out_still.failure, Some(Failure::PalletNotFound));
    assert!(
        out.sim_time_s > out_still.sim_time_s + 1.0,
        "move {} s, wait {} s",
        out.sim_time_s,
        out_still.sim_time_s
    );
}

/// A staging pose inside a rack cannot be reached: `staging_unreachable`, with the leg.
#[test]
fn a_staging_pose_in_a_rack_is_unreachable() {
    let world = "name = \"blocked\"\n[[rack]]\nname = \"r\"\nx_m = 3.0\ny_m = 0.0\nlength_m = 1.0\nwidth_m = 3.0\n";
    let scn = facing_away("", world);
    let out = run_trial(&scn, &scn.cases[0], &no_noise());
    assert_eq!(out.failure, Some(Failure::StagingUnreachable), "{out:?}");
    assert_eq!(out.legs.len(), 1);
    assert!(!out.legs[0].success);
}

#[test]
fn pick_settings_are_range_checked() {
    for (table, field) in [
        ("[pick]\nlooks = 0\n", "pick.looks"),
        (
            "[pick]\nstaging_distance_m = 0.1\n",
            "pick.staging_distance_m",
        ),
        ("[pick]\nwhen_not_seen = \"sometimes\"\n", "when_not_seen"),
    ] {
        let text = format!(
            "name = \"x\"\nplanner = \"bspline\"\nstart = {{ x_m = 0, y_m = 0, heading_deg = 0 }}\n\
             pallet = {{ x_m = 6, y_m = 0, heading_deg = 0 }}\n{table}"
        );
        let e = Scenario::parse(&text, "x.toml", |_| unreachable!())
            .expect_err(table)
            .to_string();
        assert!(e.contains(field), "{table}: {e}");
    }
}

/// `when_not_seen = "prior"`: no staging leg; the truck plans on where the pallet should
/// stand, looks at every scanner frame on the way until the face is in view, and picks.
#[test]
fn prior_plans_on_the_prior_and_looks_on_the_way() {
    let text = std::fs::read_to_string(repo("scenarios/spiral-table2.toml")).expect("reads");
    let text = format!("{text}\n[pick]\nwhen_not_seen = \"prior\"\n");
    let scn = Scenario::parse(&text, "prior.toml", |_| Ok(World::default())).expect("loads");
    let case = scn.case("20").expect("case 20");
    let out = run_trial(&scn, case, &no_noise());
    assert!(out.success, "{out:?}");
    assert!(out.legs.is_empty());
    // Missed from the start and on the way (a look per frame), then found.
    assert!(out.estimates_missed >= 2, "{out:?}");
    assert_eq!(out.estimates, out.estimates_missed + 1, "{out:?}");
}

/// The pre-entry gap and the docked check are settings that act: a longer gap moves the
/// planners' goal back (a longer plan), a looser docked speed ends the pick sooner.
#[test]
fn the_pre_entry_gap_and_the_docked_check_are_settings() {
    let base = std::fs::read_to_string(repo("scenarios/field-test.toml")).expect("reads");
    let run = |pick: &str| {
        let text = format!("{base}\n[pick]\n{pick}");
        let scn = Scenario::parse(&text, "f.toml", |_| Ok(World::default())).expect("loads");
        run_trial(&scn, &scn.cases[0], &no_noise())
    };
    let default = run("");
    let gap = run("pre_entry_gap_m = 1.0\n");
    assert!(default.success && gap.success, "{gap:?}");
    assert!(
        (gap.path_length_m - default.path_length_m).abs() > 0.05,
        "{} vs {}",
        gap.path_length_m,
        default.path_length_m
    );
    let loose = run("docked_speed_mps = 0.3\n");
    assert!(
        loose.sim_time_s < default.sim_time_s,
        "{} vs {}",
        loose.sim_time_s,
        default.sim_time_s
    );
}
