//! External planners: every misbehaviour is the trial's `plan_failed` with its reason, the
//! batch goes on, and a crashed process is restarted for the next trial.

use std::path::{Path, PathBuf};

use forkbench_batch::{BatchSpec, read_records, run_batch};
use forkbench_trial::{Failure, Scenario, TrialOptions, run_trial};

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("forkbench-ext-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("dir");
    d
}

fn script() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../forkbench-trial/tests/planners/misbehaving.py")
}

/// An open-floor pick straight ahead, planned by the misbehaving planner in `mode`.
fn scenario(mode: &str, dir: &Path) -> Scenario {
    let marker = dir.join("crashed-once");
    let text = format!(
        r#"name = "ext-{mode}"
start = {{ x_m = 0.0, y_m = 0.0, heading_deg = 0.0 }}
pallet = {{ x_m = 8.0, y_m = 0.0, heading_deg = 0.0 }}

[planner]
kind = "external"
name = "misbehaving"
command = ["python3", {script:?}, "{mode}", {marker:?}]
timeout_s = 2.0
"#,
        script = script().display().to_string(),
        marker = marker.display().to_string(),
    );
    let file = dir.join(format!("{mode}.toml"));
    std::fs::write(&file, text).expect("write");
    Scenario::load(&file).expect("loads")
}

fn no_noise() -> TrialOptions {
    TrialOptions {
        no_noise: true,
        ..TrialOptions::default()
    }
}

#[test]
fn a_well_behaved_external_planner_picks_the_pallet() {
    let dir = tmp("good");
    let s = scenario("good", &dir);
    let out = run_trial(&s, &s.cases[0], &no_noise());
    assert!(out.success, "{:?}", out.failure_detail);
    assert_eq!(out.planner, "misbehaving");
}

#[test]
fn each_misbehaviour_is_a_plan_failure_with_its_reason() {
    let dir = tmp("bad");
    let cases = [
        ("crash", "simulated segfault"),
        ("hang", "no answer within 2.000 s"),
        ("bad_json", "invalid JSON"),
        ("nan", "non-finite value"),
        ("off_start", "does not start at the start"),
        ("off_goal", "does not end at the goal"),
        ("curvature", "> κ_max"),
        ("wrong_version", "protocol version 99"),
        ("silent_hello", "no answer within"),
    ];
    for (mode, reason) in cases {
        let s = scenario(mode, &dir);
        let out = run_trial(&s, &s.cases[0], &no_noise());
        assert_eq!(out.failure, Some(Failure::PlanFailed), "{mode}: {out:?}");
        let detail = out.failure_detail.unwrap_or_default();
        assert!(detail.contains(reason), "{mode}: {detail}");
        // In a batch too: the trial records the reason and the batch finishes.
        let out_dir = dir.join(format!("batch-{mode}"));
        let summary = run_batch(&spec(s, 2), &out_dir, 2, &|_| {}).expect("batch finishes");
        assert_eq!(
            summary.rows[0].failures.get("plan_failed"),
            Some(&2),
            "{mode}"
        );
        let recs = read_records(&out_dir.join("trials.jsonl")).expect("records");
        assert!(
            recs.iter().all(|r| r
                .outcome
                .failure_detail
                .as_deref()
                .is_some_and(|d| d.contains(reason))),
            "{mode}: {recs:?}"
        );
    }
}

/// A small batch of `s` with a perfect pallet estimate.
fn spec(s: Scenario, trials: u64) -> BatchSpec {
    BatchSpec {
        scenarios: vec![s],
        planners: vec![],
        trackers: vec![],
        trials,
        seed: 5,
        shard: (0, 1),
        overrides: forkbench_trial::trial::Overrides {
            pallet_noise_scale: Some(0.0),
            ..Default::default()
        },
        replan: None,
        compare_replanning: false,
        force_new: false,
        success_run: Default::default(),
        profile: false,
    }
}

#[test]
fn a_crashed_planner_is_restarted_and_the_batch_goes_on() {
    let dir = tmp("batch");
    // One worker: the first trial's process crashes, the next trials get a new one.
    let out = dir.join("once");
    run_batch(&spec(scenario("crash_once", &dir), 3), &out, 1, &|_| {}).expect("finishes");
    let mut recs = read_records(&out.join("trials.jsonl")).expect("records");
    recs.sort_by_key(|r| r.trial);
    let failures: Vec<_> = recs.iter().map(|r| r.outcome.failure.clone()).collect();
    assert_eq!(failures[0], Some(Failure::PlanFailed), "{recs:?}");
    assert!(
        recs[1..]
            .iter()
            .all(|r| r.outcome.failure != Some(Failure::PlanFailed)),
        "restarted: {failures:?}"
    );
    // Every trial of a planner that always hangs fails on its own; the batch finishes.
    let out = dir.join("hang");
    let summary = run_batch(&spec(scenario("hang", &dir), 3), &out, 2, &|_| {}).expect("finishes");
    assert_eq!(summary.trials, 3);
    assert_eq!(summary.rows[0].failures.get("plan_failed"), Some(&3));
}
