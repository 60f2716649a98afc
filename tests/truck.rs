//! The truck's actuators through the binary: a step-test log identified back into a truck file that `--truck` takes, a trial's MCAP identified, a run's truck file refused naming the file, and a bad log refused naming its line and column.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn forkbench(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_forkbench"))
        .args(args)
        .output()
        .expect("binary runs")
}

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("forkbench-truck-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir.join(name)
}

fn text(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr)
}

fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8")
}

#[test]
fn a_step_test_is_identified_into_a_truck_file_a_trial_takes() {
    let (truck, log, fitted) = (tmp("hidden.toml"), tmp("log.csv"), tmp("fitted.toml"));
    std::fs::write(
        &truck,
        "preset = \"ideal\"\n[steering]\ndead_time_s = 0.2\ntime_constant_s = 0.1\n",
    )
    .expect("write");
    let out = forkbench(&[
        "step-test",
        "--truck",
        s(&truck),
        "--out",
        s(&log),
        "--runs",
        "4",
        "--run-s",
        "10",
    ]);
    assert!(out.status.success(), "{}", text(&out));
    let out = forkbench(&["identify", s(&log), "--json", "--truck-out", s(&fitted)]);
    assert!(out.status.success(), "{}", text(&out));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    let steering = &v["channels"][0];
    assert_eq!(steering["channel"], "steering");
    let d = steering["settings"]["steering.dead_time_s"]
        .as_f64()
        .expect("dead time");
    assert!((d - 0.2).abs() <= 0.02, "{v}");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/field-test.toml");
    let out = forkbench(&["trial", s(&root), "--no-noise", "--truck", s(&fitted)]);
    assert!(matches!(out.status.code(), Some(0 | 3)), "{}", text(&out));
}

/// A trial's own MCAP is a log: the realistic truck's steering delay (0.06 s, 0.01 s on
/// the bus, commands held for a 0.02 s period) and lag come back from one pick.
#[test]
fn a_trials_mcap_is_identified() {
    let mcap = tmp("pick.mcap");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/field-test.toml");
    let out = forkbench(&[
        "trial",
        s(&root),
        "--truck",
        "realistic",
        "--mcap",
        s(&mcap),
    ]);
    assert!(matches!(out.status.code(), Some(0 | 3)), "{}", text(&out));
    let out = forkbench(&["identify", s(&mcap), "--json"]);
    assert!(out.status.success(), "{}", text(&out));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    let steering = &v["channels"][0]["settings"];
    let d = steering["steering.dead_time_s"]
        .as_f64()
        .expect("dead time");
    let tau = steering["steering.time_constant_s"].as_f64().expect("lag");
    assert!(
        (0.06..=0.1).contains(&d) && (tau - 0.08).abs() < 0.016,
        "{v}"
    );
}

#[test]
fn bad_truck_files_and_logs_are_refused_naming_where() {
    let bad = tmp("bad.toml");
    std::fs::write(&bad, "[steering]\ndead_time_s = 5\n").expect("write");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/field-test.toml");
    let out = forkbench(&["trial", s(&root), "--truck", s(&bad)]);
    assert_eq!(out.status.code(), Some(1));
    let t = text(&out);
    assert!(
        t.contains("bad.toml") && t.contains("steering.dead_time_s"),
        "{t}"
    );
    let log = tmp("nan.csv");
    std::fs::write(&log, "t_s,steer_cmd_rad,steer_rad\n0,0,0\n0.01,nan,0\n").expect("write");
    let out = forkbench(&["identify", s(&log)]);
    assert_eq!(out.status.code(), Some(1));
    let t = text(&out);
    assert!(t.contains("nan.csv:3: column steer_cmd_rad"), "{t}");
}
