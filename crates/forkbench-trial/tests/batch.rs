//! Batches: identical results whatever the jobs and shards, resume after a crash, errors kept, the regression gate.

use std::path::{Path, PathBuf};

use forkbench_plan::PlannerKind;
use forkbench_trial::batch::{self, Baseline, BatchSpec, TrialRecord};
use forkbench_trial::{Failure, Scenario};

fn scenario(name: &str) -> Scenario {
    Scenario::load(&Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenarios")).join(name))
        .expect("loads")
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("forkbench-batch-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn spec(scenarios: Vec<Scenario>, trials: u64, seed: u64) -> BatchSpec {
    BatchSpec {
        scenarios,
        planners: vec![],
        trials,
        seed,
        shard: (0, 1),
        pallet_noise_scale: None,
        replan: Some(true),
    }
}

/// Records without wall times (the only thing that may differ between runs), sorted.
fn records(dir: &Path) -> Vec<TrialRecord> {
    let mut v = batch::read_records(&dir.join("trials.jsonl")).expect("readable");
    for r in &mut v {
        r.outcome.wall_time_ms = 0.0;
    }
    v.sort_by_key(TrialRecord::key);
    v
}

fn without_wall(mut s: batch::Summary) -> batch::Summary {
    for r in &mut s.rows {
        r.wall_time_total_s = 0.0;
    }
    s
}

#[test]
fn same_results_whatever_jobs_and_shards() {
    let s = spec(
        vec![scenario("field-test.toml"), scenario("rack-pick.toml")],
        12,
        42,
    );
    let (d1, d2) = (tmp("j1"), tmp("j2"));
    let one = batch::run_batch(&s, &d1, 1, &|_| {}).expect("runs");
    let two = batch::run_batch(&s, &d2, 2, &|_| {}).expect("runs");
    assert_eq!(records(&d1), records(&d2));
    assert_eq!(without_wall(one.clone()), without_wall(two));
    let shards: Vec<PathBuf> = (0..3)
        .map(|i| {
            let d = tmp(&format!("shard{i}"));
            let mut sh = s.clone();
            sh.shard = (i, 3);
            batch::run_batch(&sh, &d, 2, &|_| {}).expect("runs");
            d
        })
        .collect();
    let merged_dir = tmp("merged");
    let merged = batch::merge(&shards, &merged_dir).expect("merges");
    assert_eq!(records(&merged_dir), records(&d1));
    assert_eq!(without_wall(merged), without_wall(one));
}

#[test]
fn a_crashed_batch_resumes_without_losing_or_repeating_trials() {
    let s = spec(vec![scenario("field-test.toml")], 20, 7);
    let (full, crashed) = (tmp("full"), tmp("crashed"));
    batch::run_batch(&s, &full, 2, &|_| {}).expect("runs");
    // Simulate a crash: keep 8 finished lines and a torn ninth.
    let text = std::fs::read_to_string(full.join("trials.jsonl")).expect("written");
    let lines: Vec<&str> = text.lines().collect();
    std::fs::create_dir_all(&crashed).expect("dir");
    std::fs::write(
        crashed.join("trials.jsonl"),
        format!("{}\n{}", lines[..8].join("\n"), &lines[8][..40]),
    )
    .expect("write");
    let seen = std::sync::atomic::AtomicU64::new(0);
    batch::run_batch(&s, &crashed, 2, &|_| {
        seen.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    })
    .expect("resumes");
    assert_eq!(seen.into_inner(), 12, "only the missing trials run again");
    assert_eq!(records(&crashed), records(&full));
}

#[test]
fn a_panicking_trial_becomes_an_error_outcome() {
    let s = scenario("field-test.toml");
    let out = batch::guarded(&s, "default", PlannerKind::Bspline, 99, || {
        panic!("solver exploded")
    });
    assert_eq!(out.failure, Some(Failure::Error));
    let detail = out.failure_detail.expect("detail");
    assert!(
        detail.contains("solver exploded") && detail.contains("seed 99"),
        "{detail}"
    );
}

#[test]
fn a_broken_trial_is_recorded_and_the_batch_goes_on() {
    let good = scenario("field-test.toml");
    let mut broken = scenario("rack-pick.toml");
    broken.name = "broken".into();
    broken.sim.dt_s = f64::NAN;
    let d = tmp("broken");
    let summary = batch::run_batch(&spec(vec![broken, good], 3, 1), &d, 2, &|_| {}).expect("runs");
    let row = summary
        .rows
        .iter()
        .find(|r| r.scenario == "broken")
        .expect("row");
    assert_eq!(row.failures.get("error"), Some(&3));
    assert_eq!(summary.trials, 6);
    assert!(records(&d).iter().any(|r| {
        r.outcome
            .failure_detail
            .as_deref()
            .is_some_and(|m| m.contains("dt_s"))
    }));
}

#[test]
fn regress_fails_on_a_degraded_tracker_and_passes_unchanged_code() {
    let base_dir = tmp("base");
    let base = batch::run_batch(
        &spec(vec![scenario("field-test.toml")], 120, 1),
        &base_dir,
        2,
        &|_| {},
    )
    .expect("runs");
    let baseline = Baseline::from_summary(&base, "test".into());

    // Unchanged code, independent seeds: no significant drop.
    let same = batch::run_batch(
        &spec(vec![scenario("field-test.toml")], 120, 2),
        &tmp("same"),
        2,
        &|_| {},
    )
    .expect("runs");
    let (rows, failed) = batch::regress(&baseline, &same, 0.01, None);
    assert!(!failed, "{}", batch::regress_markdown(&rows, 0.01));

    // Steering actuator 16× too slow: the truck cannot follow the curve.
    let mut slow = scenario("field-test.toml");
    slow.truck.max_steer_rate_radps = 0.05;
    let worse =
        batch::run_batch(&spec(vec![slow], 120, 2), &tmp("worse"), 2, &|_| {}).expect("runs");
    let (rows, failed) = batch::regress(&baseline, &worse, 0.01, None);
    assert!(failed, "{}", batch::regress_markdown(&rows, 0.01));
    assert_eq!(rows[0].verdict, "drop");
}

#[test]
fn baselines_reject_impossible_counts() {
    let d = tmp("bad-baseline");
    std::fs::create_dir_all(&d).expect("dir");
    let f = d.join("b.json");
    std::fs::write(&f, r#"{"description":"x","rows":[{"scenario":"s","planner":"bspline","trials":10,"successes":11}]}"#).expect("write");
    let e = Baseline::load(&f).expect_err("impossible");
    assert!(e.to_string().contains("successes 11 of 10"), "{e}");
    std::fs::write(&f, "{\n\"description\": 3\n}").expect("write");
    let e = Baseline::load(&f).expect_err("malformed");
    assert!(
        e.to_string().contains("b.json") && e.to_string().contains(":2"),
        "{e}"
    );
}
