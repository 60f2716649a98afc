//! The Rust planner of `examples/rust_planner.rs`, registered with one line, runs in a
//! trial and a batch beside the built-in planners.

#[path = "../../../examples/rust_planner.rs"]
mod rust_planner;

use std::path::Path;
use std::sync::Arc;

use forkbench_batch::{BatchSpec, run_batch};
use forkbench_trial::{Scenario, TrialOptions, run_trial};

fn field_test() -> Scenario {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/field-test.toml");
    Scenario::load_with(&file, Arc::new(rust_planner::registry())).expect("loads")
}

#[test]
fn the_example_planner_runs_in_a_trial_and_a_batch() {
    let scn = field_test();
    let opts = TrialOptions {
        planner: Some("bezier".into()),
        no_noise: true,
        ..TrialOptions::default()
    };
    let out = run_trial(&scn, &scn.cases[0], &opts);
    assert_eq!(out.planner, "bezier");
    assert!(out.success, "{:?}", out.failure_detail);

    let dir = std::env::temp_dir().join(format!("forkbench-rust-planner-{}", std::process::id()));
    let spec = BatchSpec {
        scenarios: vec![scn],
        planners: vec!["bezier".into(), "bspline".into()],
        trackers: vec!["pure_pursuit".into(), "regulated_pure_pursuit".into()],
        trials: 3,
        seed: 2,
        shard: (0, 1),
        overrides: Default::default(),
        replan: None,
        compare_replanning: false,
        force_new: true,
        success_run: Default::default(),
        profile: false,
    };
    let summary = run_batch(&spec, &dir, 2, &|_| {}).expect("batch");
    let rows: Vec<_> = summary
        .rows
        .iter()
        .map(|r| (r.planner.as_str(), r.tracker.as_str()))
        .collect();
    assert_eq!(
        rows,
        [
            ("bezier", "pure_pursuit"),
            ("bezier", "regulated_pure_pursuit"),
            ("bspline", "pure_pursuit"),
            ("bspline", "regulated_pure_pursuit")
        ]
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_scenario_file_names_the_example_planner_with_its_settings() {
    let dir = std::env::temp_dir().join(format!("forkbench-bezier-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let file = dir.join("bezier.toml");
    let text = "name = \"bezier\"\nstart = { x_m = 0.0, y_m = 0.0, heading_deg = 90.0 }\n\
                pallet = { x_m = 1.0, y_m = 8.5, heading_deg = 95.0 }\n\
                [planner]\nkind = \"bezier\"\nhandle_fraction = 0.35\n";
    std::fs::write(&file, text).expect("write");
    let registry = Arc::new(rust_planner::registry());
    let scn = Scenario::load_with(&file, Arc::clone(&registry)).expect("loads");
    assert_eq!(scn.planner.kind, "bezier");
    let out = run_trial(
        &scn,
        &scn.cases[0],
        &TrialOptions {
            no_noise: true,
            ..TrialOptions::default()
        },
    );
    assert_eq!(out.planner, "bezier");
    assert!(out.success, "{:?}", out.failure_detail);
    // Its own settings are checked like a built-in planner's.
    std::fs::write(&file, text.replace("0.35", "1.5")).expect("write");
    let e = Scenario::load_with(&file, registry)
        .expect_err("refused")
        .to_string();
    assert!(
        e.contains("bezier.toml:6: field `planner.handle_fraction`"),
        "{e}"
    );
    // Without the example's registry the kind is unknown.
    std::fs::write(&file, text).expect("write");
    let e = Scenario::load(&file).expect_err("unknown").to_string();
    assert!(e.contains("unknown planner \"bezier\""), "{e}");
}
