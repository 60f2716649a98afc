//! External planners that attack the batch: a planner that stops reading, one whose child
//! floods stdout, children that outlive it, exits that hide their status, and commands
//! that keep timing out. Each was a hang, an abort or an orphan before.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use forkbench_batch::{BatchSpec, read_records, run_batch};
use forkbench_trial::{Failure, Scenario, TrialOptions, run_trial};

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("forkbench-hostile-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("dir");
    d
}

fn script() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../forkbench-trial/tests/planners/misbehaving.py")
}

/// A pick straight ahead planned by the misbehaving planner in `mode` (extra arguments
/// after its marker), in a world with `racks` small racks away from the path.
fn scenario(mode: &str, extra: &str, racks: usize, timeout_s: f64, dir: &Path) -> Scenario {
    let mut world = String::from("name = \"many-racks\"\n");
    for i in 0..racks {
        world.push_str(&format!(
            "[[rack]]\nname = \"r{i}\"\nx_m = {}\ny_m = {}\nlength_m = 0.2\nwidth_m = 0.2\n",
            (i % 30) as f64 * 0.5 - 7.0,
            -10.0 - (i / 30) as f64 * 0.5
        ));
    }
    std::fs::write(dir.join("world.toml"), world).expect("world");
    let text = format!(
        r#"name = "hostile-{mode}"
world = "world.toml"
start = {{ x_m = 0.0, y_m = 0.0, heading_deg = 0.0 }}
pallet = {{ x_m = 8.0, y_m = 0.0, heading_deg = 0.0 }}

[planner]
kind = "external"
name = "hostile"
command = ["python3", {script:?}, "{mode}", "unused-marker", "{extra}"]
timeout_s = {timeout_s}
"#,
        script = script().display().to_string(),
    );
    let file = dir.join(format!("{mode}.toml"));
    std::fs::write(&file, text).expect("write");
    Scenario::load(&file).expect("loads")
}

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

fn no_noise() -> TrialOptions {
    TrialOptions {
        no_noise: true,
        ..TrialOptions::default()
    }
}

/// Processes whose command line contains `needle`.
fn running(needle: &str) -> usize {
    let out = std::process::Command::new("pgrep")
        .args(["-f", needle])
        .output()
        .expect("pgrep");
    String::from_utf8_lossy(&out.stdout).lines().count()
}

#[test]
fn a_planner_that_stops_reading_cannot_block_the_request() {
    let dir = tmp("deaf");
    // 600 racks make the request far larger than a pipe's 64 KiB buffer.
    let s = scenario("deaf", "", 600, 2.0, &dir);
    let t0 = Instant::now();
    let out = run_trial(&s, &s.cases[0], &no_noise());
    assert!(t0.elapsed() < Duration::from_secs(10), "{:?}", t0.elapsed());
    assert_eq!(out.failure, Some(Failure::PlanFailed));
    let detail = out.failure_detail.unwrap_or_default();
    assert!(detail.contains("no answer within 2.000 s"), "{detail}");
}

#[test]
fn output_while_idle_is_bounded_and_retires_the_process() {
    let dir = tmp("chatty");
    let s = scenario("chatty", "", 0, 5.0, &dir);
    let t0 = Instant::now();
    let summary = run_batch(&spec(s, 6), &dir.join("out"), 1, &|_| {}).expect("finishes");
    assert_eq!(summary.trials, 6);
    assert!(t0.elapsed() < Duration::from_secs(60), "{:?}", t0.elapsed());
    // Every trial ended: planned by a fresh process (the chatty one retired), or, when the
    // flood began after the pool's check, failed on the garbled answer: a protocol
    // violation, that trial's own. Retirement itself is tested in forkbench-ipc.
    let recs = read_records(&dir.join("out/trials.jsonl")).expect("records");
    assert!(
        recs.iter().all(|r| match r.outcome.failure {
            None => true,
            Some(Failure::PlanFailed) => r
                .outcome
                .failure_detail
                .as_deref()
                .is_some_and(|d| d.contains("invalid JSON") || d.contains("answered request")),
            Some(_) => false,
        }),
        "{recs:?}"
    );
    // This process held at most a line or two of the flood: its peak resident size stays
    // small (it was gigabytes before).
    let status = std::fs::read_to_string("/proc/self/status").expect("status");
    let hwm_kb: u64 = status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
        .expect("VmHWM");
    assert!(hwm_kb < 1_000_000, "peak {hwm_kb} kB");
}

#[test]
fn a_planners_children_and_an_eof_ignoring_planner_do_not_outlive_the_batch() {
    let dir = tmp("orphans");
    let marker = format!("{}", 900_000 + std::process::id() % 90_000);
    let s = scenario("forks_sleeper", &marker, 0, 5.0, &dir);
    run_batch(&spec(s, 4), &dir.join("out"), 2, &|_| {}).expect("finishes");
    let deadline = Instant::now() + Duration::from_secs(5);
    while running(&format!("sleep {marker}")) > 0 && Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(50));
    }
    assert_eq!(
        running(&format!("sleep {marker}")),
        0,
        "a planner's child outlived the batch"
    );
    let s = scenario("ignores_eof", &marker, 0, 5.0, &dir);
    run_batch(&spec(s, 2), &dir.join("out2"), 2, &|_| {}).expect("finishes");
    let needle = format!("ignores_eof unused-marker {marker}");
    while running(&needle) > 0 && Instant::now() < deadline + Duration::from_secs(5) {
        std::thread::sleep(Duration::from_millis(50));
    }
    assert_eq!(
        running(&needle),
        0,
        "a planner that ignores end of input outlived the batch"
    );
}

#[test]
fn an_exit_reports_its_status_and_stderr_even_when_a_child_holds_stdout() {
    let dir = tmp("exits");
    for (mode, status, said) in [
        ("exit_child_holds_stdout", "7", "bye"),
        ("exit_mid_line", "3", "oops"),
    ] {
        let s = scenario(mode, "", 0, 20.0, &dir);
        let t0 = Instant::now();
        let out = run_trial(&s, &s.cases[0], &no_noise());
        let detail = out.failure_detail.unwrap_or_default();
        assert!(
            t0.elapsed() < Duration::from_secs(5),
            "{mode}: waited out the timeout"
        );
        assert!(
            detail.contains(&format!("exit status: {status}")) && detail.contains(said),
            "{mode}: {detail}"
        );
    }
}

#[test]
fn a_command_that_keeps_timing_out_opens_the_circuit_breaker() {
    let dir = tmp("breaker");
    let s = scenario("hang", "breaker", 0, 1.0, &dir);
    let t0 = Instant::now();
    run_batch(&spec(s, 8), &dir.join("out"), 1, &|_| {}).expect("finishes");
    // Three timeouts of 1 s, then the other five fail at once (8 s without the breaker).
    assert!(t0.elapsed() < Duration::from_secs(7), "{:?}", t0.elapsed());
    let recs = read_records(&dir.join("out/trials.jsonl")).expect("records");
    let open = recs
        .iter()
        .filter(|r| {
            r.outcome
                .failure_detail
                .as_deref()
                .is_some_and(|d| d.contains("circuit breaker"))
        })
        .count();
    assert_eq!(open, 5, "{recs:?}");
}
