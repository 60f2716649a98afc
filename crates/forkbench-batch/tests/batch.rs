//! Batches: identical results whatever the jobs and shards, resume after a crash, errors kept, the regression gate, and a directory's integrity (manifest, lock, merge checks).

use std::path::{Path, PathBuf};

use forkbench_batch::{self as batch, Baseline, BatchSpec, TrialRecord};
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
        trackers: vec![],
        trials,
        seed,
        shard: (0, 1),
        overrides: Default::default(),
        replan: Some(true),
        compare_replanning: false,
        force_new: false,
        success_run: Default::default(),
        profile: false,
    }
}

/// Records without wall times (the only thing that may differ between runs), sorted.
fn records(dir: &Path) -> Vec<TrialRecord> {
    let mut v = batch::read_records(&dir.join("trials.jsonl")).expect("readable");
    for r in &mut v {
        r.outcome = r.outcome.without_wall_times();
    }
    v.sort_by_key(TrialRecord::key);
    v
}

/// The numbers of a summary: without wall times and provenance (host, times, arguments),
/// the only things that may differ between equal runs.
/// A batch's records as text: outcomes hold NaN where nothing was measured (a pallet never
/// found), which `==` never equals.
fn same(dir: &Path) -> String {
    format!("{:?}", records(dir))
}

fn without_wall(mut s: batch::Summary) -> batch::Summary {
    for r in &mut s.rows {
        r.wall_time_total_s = 0.0;
    }
    s.provenance = None;
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
    assert_eq!(same(&d1), same(&d2));
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
    assert_eq!(same(&merged_dir), same(&d1));
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
    // The manifest is written when a batch starts, so a crashed directory has it.
    std::fs::copy(full.join("manifest.json"), crashed.join("manifest.json")).expect("copy");
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
    assert_eq!(same(&crashed), same(&full));
}

#[test]
fn a_panicking_trial_becomes_an_error_outcome() {
    let s = scenario("field-test.toml");
    let out = batch::guarded(&s, "default", ("bspline", "pure_pursuit"), 99, || {
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

fn err(r: Result<batch::Summary, batch::BatchError>) -> String {
    r.expect_err("must be refused").to_string()
}

/// Defect 1: a re-run with other settings into the same --out reused the old trials.
#[test]
fn resume_refuses_other_settings_and_force_new_starts_over() {
    let d = tmp("resume-settings");
    let base = spec(vec![scenario("field-test.toml")], 6, 3);
    batch::run_batch(&base, &d, 2, &|_| {}).expect("runs");
    let mut quiet = base.clone();
    quiet.overrides.pallet_noise_scale = Some(0.0);
    let e = err(batch::run_batch(&quiet, &d, 2, &|_| {}));
    assert!(
        e.contains("pallet_noise_scale: null → 0.0") && e.contains("--force-new"),
        "{e}"
    );
    let mut seed = base.clone();
    seed.seed = 4;
    assert!(err(batch::run_batch(&seed, &d, 2, &|_| {})).contains("seed: 3 → 4"));
    let mut tol = base.clone();
    tol.scenarios[0].tolerances.lateral_m *= 0.5;
    let e = err(batch::run_batch(&tol, &d, 2, &|_| {}));
    assert!(e.contains("tolerances.lateral_m"), "{e}");
    // --force-new starts over: the same results as a fresh directory.
    quiet.force_new = true;
    let forced = batch::run_batch(&quiet, &d, 2, &|_| {}).expect("starts over");
    quiet.force_new = false;
    let fresh_dir = tmp("resume-fresh");
    let fresh = batch::run_batch(&quiet, &fresh_dir, 2, &|_| {}).expect("runs");
    assert_eq!(without_wall(forced), without_wall(fresh));
    assert_eq!(same(&d), same(&fresh_dir));
    // The same settings resume (nothing to run again).
    let seen = std::sync::atomic::AtomicU64::new(0);
    batch::run_batch(&quiet, &d, 2, &|_| {
        seen.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    })
    .expect("resumes");
    assert_eq!(seen.into_inner(), 0);
}

/// `force_new` never follows a symbolic link: a `recordings` that links elsewhere keeps
/// what it points at.
#[test]
fn force_new_does_not_follow_a_linked_recordings_folder() {
    let d = tmp("force-link");
    let elsewhere = tmp("force-link-elsewhere");
    std::fs::create_dir_all(&elsewhere).expect("dir");
    let theirs = elsewhere.join("theirs.mcap");
    std::fs::write(&theirs, "not the batch's").expect("write");
    let mut base = spec(vec![scenario("field-test.toml")], 2, 3);
    batch::run_batch(&base, &d, 2, &|_| {}).expect("runs");
    let _ = std::fs::remove_dir_all(d.join("recordings"));
    std::os::unix::fs::symlink(&elsewhere, d.join("recordings")).expect("symlink");
    base.force_new = true;
    batch::run_batch(&base, &d, 2, &|_| {}).expect("starts over");
    assert_eq!(
        std::fs::read_to_string(&theirs).expect("kept"),
        "not the batch's"
    );
    let _ = std::fs::remove_dir_all(&elsewhere);
}

/// `force_new` deletes of `recordings/` only the recordings named for the batch's own
/// trials: a recording of yours kept there survives, the folder with it.
#[test]
fn force_new_deletes_only_the_recordings_of_its_trials() {
    let d = tmp("force-own");
    let mut base = spec(vec![scenario("field-test.toml")], 2, 3);
    batch::run_batch(&base, &d, 2, &|_| {}).expect("runs");
    let rec = d.join("recordings");
    std::fs::create_dir_all(&rec).expect("dir");
    let records = batch::read_records(&d.join("trials.jsonl")).expect("records");
    let batch_own = rec.join(format!("{}.rrd", records[0].outcome.recording_stem(false)));
    std::fs::write(&batch_own, "the batch's").expect("write");
    let mine = rec.join("my-review.rrd");
    std::fs::write(&mine, "mine").expect("write");
    // Its ROS 2 bags are directories: one holding only a bag's files is the batch's, one
    // with a file of yours in it is kept whole.
    let bag = rec.join(format!("{}.ros2", records[0].outcome.recording_stem(false)));
    std::fs::create_dir_all(&bag).expect("dir");
    std::fs::write(bag.join("metadata.yaml"), "x").expect("write");
    std::fs::write(bag.join("b_0.mcap"), "x").expect("write");
    let my_bag = rec.join(format!("{}.ros2", records[1].outcome.recording_stem(false)));
    std::fs::create_dir_all(&my_bag).expect("dir");
    std::fs::write(my_bag.join("notes.txt"), "mine").expect("write");
    base.force_new = true;
    batch::run_batch(&base, &d, 2, &|_| {}).expect("starts over");
    assert!(!batch_own.exists(), "the batch's recording is deleted");
    assert!(!bag.exists(), "the batch's bag directory is deleted");
    assert_eq!(std::fs::read_to_string(&mine).expect("kept"), "mine");
    assert_eq!(
        std::fs::read_to_string(my_bag.join("notes.txt")).expect("kept"),
        "mine"
    );
}

/// Trials a directory holds from another build are not resumed: one verdict would mix
/// two versions of the code (a commit the directory names, or none recorded).
#[test]
fn resume_refuses_trials_of_another_build() {
    let d = tmp("resume-build");
    let base = spec(vec![scenario("field-test.toml")], 2, 3);
    batch::run_batch(&base, &d, 2, &|_| {}).expect("runs");
    let file = d.join("manifest.json");
    let mut m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&file).expect("reads")).expect("json");
    let ours = batch::build_commit();
    assert_eq!(m.get("build").and_then(|b| b.as_str()), ours.as_deref());
    let Some(ours) = ours else {
        // Built outside a git checkout: there is no build to tell apart.
        return;
    };
    m["build"] = "0123456789abcdef0123456789abcdef01234567".into();
    std::fs::write(&file, m.to_string()).expect("writes");
    let e = err(batch::run_batch(&base, &d, 2, &|_| {}));
    assert!(
        e.contains("commit 0123456789ab") && e.contains(&ours[..12]) && e.contains("--force-new"),
        "{e}"
    );
    // An edited commit of a control character and two-byte characters (its twelfth byte
    // inside one) is named, cut at a character and escaped, not a panic.
    m["build"] = "\u{7}éééééééééééééé".into();
    std::fs::write(&file, m.to_string()).expect("writes");
    let e = err(batch::run_batch(&base, &d, 2, &|_| {}));
    assert!(e.contains("commit \\u{7}ééééééééééé, and"), "{e}");
    m.as_object_mut().expect("object").remove("build");
    std::fs::write(&file, m.to_string()).expect("writes");
    let e = err(batch::run_batch(&base, &d, 2, &|_| {}));
    assert!(e.contains("recorded no commit"), "{e}");
    // The trials are still there, and starting over is the way out.
    assert_eq!(records(&d).len(), 2);
    let mut again = base.clone();
    again.force_new = true;
    batch::run_batch(&again, &d, 2, &|_| {}).expect("starts over");
}

/// Defect 2: merge combined shards of different batches, duplicates, missing shards,
/// no inputs, and merged into one of its inputs.
#[test]
fn merge_checks_manifests_and_shard_coverage() {
    let s = spec(vec![scenario("field-test.toml")], 4, 5);
    let shard = |i: u64, n: u64, seed: u64, name: &str| {
        let mut sp = s.clone();
        sp.shard = (i, n);
        sp.seed = seed;
        let d = tmp(name);
        batch::run_batch(&sp, &d, 1, &|_| {}).expect("runs");
        d
    };
    let (a0, a1) = (shard(0, 2, 5, "m-a0"), shard(1, 2, 5, "m-a1"));
    let b1 = shard(1, 2, 6, "m-b1");
    let c0 = shard(0, 3, 5, "m-c0");
    let out = tmp("m-out");
    let e = err(batch::merge(&[a0.clone(), b1], &out));
    assert!(e.contains("different batches") && e.contains("seed"), "{e}");
    let e = err(batch::merge(&[a0.clone(), c0], &out));
    assert!(
        e.contains("different batches") && e.contains("shard"),
        "{e}"
    );
    let e = err(batch::merge(&[a0.clone(), a0.clone()], &out));
    assert!(e.contains("shard 0/2 given twice"), "{e}");
    let e = err(batch::merge(std::slice::from_ref(&a0), &out));
    assert!(e.contains("shards 1 of 2 are missing"), "{e}");
    assert!(err(batch::merge(&[], &out)).contains("at least one input"));
    let e = err(batch::merge(&[a0.clone(), a1.clone()], &a1));
    assert!(e.contains("both an input and the output"), "{e}");
    // An unfinished shard is refused too.
    let text = std::fs::read_to_string(a1.join("trials.jsonl")).expect("written");
    let first = text.lines().next().expect("a line");
    std::fs::write(a1.join("trials.jsonl"), format!("{first}\n")).expect("write");
    let e = err(batch::merge(&[a0.clone(), a1.clone()], &out));
    assert!(e.contains("holds 1 of the 2 trials"), "{e}");
}

/// Defect 3: two writers at once duplicated records; the lock refuses the second, and
/// a directory that already has duplicates is refused rather than summarised.
#[test]
fn one_writer_at_a_time_and_no_duplicate_records() {
    let d = tmp("lock");
    let s = spec(vec![scenario("field-test.toml")], 3, 8);
    std::fs::create_dir_all(&d).expect("dir");
    let held = batch::DirLock::take(&d).expect("first writer");
    let e = err(batch::run_batch(&s, &d, 1, &|_| {}));
    assert!(e.contains("another forkbench process is writing"), "{e}");
    drop(held);
    batch::run_batch(&s, &d, 1, &|_| {}).expect("runs once the lock is free");
    let text = std::fs::read_to_string(d.join("trials.jsonl")).expect("written");
    std::fs::write(d.join("trials.jsonl"), format!("{text}{text}")).expect("write");
    assert!(err(batch::load_results(&d)).contains("3 duplicate trial records"));
    assert!(err(batch::run_batch(&s, &d, 1, &|_| {})).contains("duplicate trial records"));
}

/// Defect 4: the same file twice, or two files sharing a name, shared rows and seeds.
#[test]
fn scenario_names_must_be_unique_in_a_batch() {
    let d = tmp("names");
    let twice = spec(
        vec![scenario("field-test.toml"), scenario("field-test.toml")],
        2,
        1,
    );
    let e = err(batch::run_batch(&twice, &d, 1, &|_| {}));
    assert!(e.contains("\"field-test\" is used by both"), "{e}");
    let mut other = scenario("rack-pick.toml");
    other.name = "field-test".into();
    let clash = spec(vec![scenario("field-test.toml"), other], 2, 1);
    let e = err(batch::run_batch(&clash, &d, 1, &|_| {}));
    assert!(e.contains("rack-pick.toml"), "{e}");
}

/// Defect 5: empty or duplicate-row baselines passed everything; results read a stale
/// summary.json or an unfinished directory.
#[test]
fn results_come_from_a_complete_trials_file_and_baselines_have_rows() {
    let d = tmp("results");
    let s = spec(vec![scenario("field-test.toml")], 4, 2);
    let summary = batch::run_batch(&s, &d, 1, &|_| {}).expect("runs");
    // A stale summary.json is never read: results come from trials.jsonl.
    std::fs::write(d.join("summary.json"), "{\"stale\": true}").expect("write");
    let loaded = batch::load_results(&d).expect("complete");
    assert!(
        loaded.provenance.is_none(),
        "the stale file's provenance is not taken"
    );
    let mut expected = summary.clone();
    expected.provenance = None;
    assert_eq!(loaded, expected);
    // One with more trials than its manifest names is refused as edited, not "resume it".
    let text = std::fs::read_to_string(d.join("trials.jsonl")).expect("written");
    let mut extra: serde_json::Value =
        serde_json::from_str(text.lines().next().expect("a line")).expect("json");
    extra["trial"] = 99.into();
    std::fs::write(d.join("trials.jsonl"), format!("{text}{extra}\n")).expect("write");
    let e = err(batch::load_results(&d));
    assert!(
        e.contains("5 trials, more than the 4") && !e.contains("resume"),
        "{e}"
    );
    // An interrupted directory is refused.
    let kept: Vec<&str> = text.lines().take(2).collect();
    std::fs::write(d.join("trials.jsonl"), kept.join("\n") + "\n").expect("write");
    assert!(err(batch::load_results(&d)).contains("holds 2 of the 4 trials"));
    // Nor is a directory that is not a batch.
    let empty = tmp("results-empty");
    std::fs::create_dir_all(&empty).expect("dir");
    assert!(err(batch::load_results(&empty)).contains("no manifest.json"));
    let bad = tmp("baselines");
    std::fs::create_dir_all(&bad).expect("dir");
    let none = bad.join("none.json");
    std::fs::write(&none, r#"{"description": "x", "rows": []}"#).expect("write");
    let e = Baseline::load(&none).expect_err("empty").to_string();
    assert!(e.contains("rows is empty"), "{e}");
    let dup = bad.join("dup.json");
    let row = r#"{"scenario": "a", "planner": "bspline", "trials": 10, "successes": 5}"#;
    std::fs::write(
        &dup,
        format!(r#"{{"description": "x", "rows": [{row}, {row}]}}"#),
    )
    .expect("write");
    let e = Baseline::load(&dup).expect_err("duplicate").to_string();
    assert!(e.contains("rows[1] repeats rows[0]"), "{e}");
}

/// Defect 6: a corrupt last line ending in a newline wedged the directory.
#[test]
fn a_corrupt_last_line_is_dropped_before_resuming() {
    let d = tmp("corrupt");
    let s = spec(vec![scenario("field-test.toml")], 5, 9);
    batch::run_batch(&s, &d, 1, &|_| {}).expect("runs");
    let full = records(&d);
    let text = std::fs::read_to_string(d.join("trials.jsonl")).expect("written");
    let lines: Vec<&str> = text.lines().collect();
    std::fs::write(
        d.join("trials.jsonl"),
        format!("{}\n{{\"trial\": 3, garbage\n", lines[..3].join("\n")),
    )
    .expect("write");
    batch::run_batch(&s, &d, 1, &|_| {}).expect("resumes");
    batch::run_batch(&s, &d, 1, &|_| {}).expect("and again");
    assert_eq!(same(&d), format!("{full:?}"));
    batch::load_results(&d).expect("readable");
}

/// A record that is both a success and a failure (an edited file) is an error naming the
/// file and line, not a trial counted either way.
#[test]
fn a_record_that_contradicts_itself_is_refused() {
    let d = tmp("contradiction");
    let s = spec(vec![scenario("field-test.toml")], 3, 9);
    batch::run_batch(&s, &d, 1, &|_| {}).expect("runs");
    let path = d.join("trials.jsonl");
    let text = std::fs::read_to_string(&path).expect("written");
    let mut lines: Vec<serde_json::Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).expect("json"))
        .collect();
    lines[1]["success"] = true.into();
    lines[1]["failure"] = "collision".into();
    let edited: Vec<String> = lines.iter().map(|v| v.to_string()).collect();
    std::fs::write(&path, edited.join("\n") + "\n").expect("write");
    let err = batch::read_records(&path).expect_err("refused").to_string();
    assert!(
        err.contains("trials.jsonl") && err.contains('2') && err.contains("success is true"),
        "{err}"
    );
}

/// Recorded failures are spread over scenario × case × failure × mode, not the first ones
/// in job order (which were all one case of one scenario).
#[test]
fn recorded_failures_spread_over_scenarios_failures_and_modes() {
    // The Gaussian model: its rack pick fails now and then, so both scenarios have
    // failures to spread over.
    let gaussian = |n: &str| scenario(n).with_pallet_sensing("gaussian").expect("kind");
    let mut s = spec(
        vec![gaussian("field-test.toml"), gaussian("rack-pick.toml")],
        10,
        7,
    );
    s.replan = None;
    s.compare_replanning = true;
    let d = tmp("spread");
    batch::run_batch(&s, &d, 2, &|_| {}).expect("runs");
    let recs = records(&d);
    let jobs = batch::trials_to_record(&s, &recs, batch::RecordChoice::Failures, 4);
    assert_eq!(jobs.len(), 4);
    let scenarios: std::collections::BTreeSet<&str> =
        jobs.iter().map(|j| j.scenario.name.as_str()).collect();
    assert_eq!(scenarios.len(), 2, "both scenarios recorded");
    let jobs = batch::trials_to_record(&s, &recs, batch::RecordChoice::Failures, 12);
    let modes: std::collections::BTreeSet<Option<bool>> =
        jobs.iter().map(|j| j.options.replan).collect();
    assert_eq!(modes.len(), 2, "both modes recorded");
}

/// After a resume the provenance keeps the first run's start and lists every run.
#[test]
fn provenance_keeps_the_first_run_and_lists_each_resume() {
    let d = tmp("runs");
    let s = spec(vec![scenario("field-test.toml")], 6, 3);
    batch::run_batch(&s, &d, 2, &|_| {}).expect("runs");
    let path = d.join("trials.jsonl");
    let kept: Vec<String> = std::fs::read_to_string(&path)
        .expect("records")
        .lines()
        .take(4)
        .map(|l| format!("{l}\n"))
        .collect();
    std::fs::write(&path, kept.concat()).expect("write");
    let summary = batch::run_batch(&s, &d, 2, &|_| {}).expect("resumes");
    let p = summary.provenance.expect("provenance");
    assert_eq!(p.runs.len(), 2);
    assert_eq!((p.runs[0].trials_to_run, p.runs[1].trials_to_run), (6, 2));
    assert_eq!(p.started_at, p.runs[0].started_at);
    assert!(p.runs.iter().all(|r| r.finished_at.is_some()));
}

/// A handling cycle counts per phase in the summary, in JUnit (a case per phase, held to
/// the floor like its row) and in the CSV (phases done, the failed phase, the totals).
#[test]
fn cycles_count_per_phase_in_summaries_junit_and_csv() {
    let d = tmp("cycle");
    // Replanning by a new plan from the truck (not the default deformation) leaves some
    // picks failing, which the floor part of this test needs.
    let mut cycle = scenario("rack-pick-cycle.toml");
    cycle.replan.method = forkbench_trial::scenario::ReplanMethod::Plan;
    let s = spec(vec![cycle], 30, 1);
    let summary = batch::run_batch(&s, &d, 2, &|_| {}).expect("runs");
    let row = &summary.rows[0];
    let names: Vec<_> = row.phases.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["pick", "lift", "reverse_out"]);
    let (pick, lift) = (&row.phases[0], &row.phases[1]);
    assert_eq!((pick.attempted, pick.done), (30, row.successes));
    assert_eq!((lift.attempted, lift.done), (row.successes, row.successes));
    assert!(
        row.successes < 30,
        "some picks fail: the floor test needs one"
    );
    let cases = batch::junit::batch_cases(&summary, Some(0.99));
    let failing: Vec<_> = cases
        .iter()
        .filter(|c| c.failure.is_some())
        .map(|c| c.name.as_str())
        .collect();
    assert_eq!(cases.len(), 4);
    assert_eq!(failing.len(), 2, "{failing:?}");
    assert!(failing[1].ends_with("/ phase pick"), "{failing:?}");
    let csv = d.join("trials.csv");
    batch::write_csv(
        &batch::read_records(&d.join("trials.jsonl")).expect("read"),
        &csv,
    )
    .expect("csv");
    let mut reader = csv::Reader::from_path(&csv).expect("csv written");
    let header = reader.headers().expect("header").clone();
    let col = |n: &str| header.iter().position(|h| h == n).expect(n);
    let (done, failed) = (col("phases_done"), col("failed_phase"));
    let (ok_col, loaded) = (col("success"), col("distance_loaded_m"));
    for row in reader.records() {
        let row = row.expect("a row");
        let ok = &row[ok_col] == "true";
        assert_eq!(&row[done], if ok { "3" } else { "0" }, "{row:?}");
        assert_eq!(&row[failed], if ok { "" } else { "pick" }, "{row:?}");
        let carried = row[loaded].parse::<f64>().expect("number") > 2.0;
        assert_eq!(carried, ok, "{row:?}");
    }
}
