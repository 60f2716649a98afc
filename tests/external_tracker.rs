//! The Python tracker of examples/trackers/ runs in a batch beside pure pursuit on the same
//! seeds, is reported under its name in the summary and the paired comparison, and is
//! recorded like the built-in trackers.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn forkbench(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_forkbench"))
        .args(args)
        .current_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join("../.."))
        .output()
        .expect("binary runs")
}

fn ok(out: &Output) -> String {
    assert!(
        out.status.success() || out.status.code() == Some(3),
        "status {:?}\nstdout: {}\nstderr: {}",
        out.status,
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("forkbench-trk-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir.join(name)
}

const SCENARIO: &str = "examples/trackers/stanley-field-test.toml";

#[test]
fn the_python_tracker_sits_beside_pure_pursuit_in_a_batch() {
    let dir = tmp("batch");
    let d = dir.to_str().expect("utf-8");
    ok(&forkbench(&[
        "batch",
        SCENARIO,
        "--tracker",
        "stanley",
        "pure_pursuit",
        "--trials",
        "4",
        "--record",
        "all",
        "--max-recordings",
        "1",
        "--out",
        d,
        "--force-new",
    ]));
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("summary.json")).expect("summary"))
            .expect("json");
    let rows = summary["rows"].as_array().expect("rows");
    let trackers: Vec<&str> = rows
        .iter()
        .map(|r| r["tracker"].as_str().expect("tracker"))
        .collect();
    assert_eq!(trackers, ["pure_pursuit", "stanley"]);
    for r in rows {
        assert_eq!(r["trials"], 4, "{r}");
    }
    // Every Stanley trial was driven to a judged end, none stopped by a protocol error.
    let records = std::fs::read_to_string(dir.join("trials.jsonl")).expect("records");
    let stanley: Vec<serde_json::Value> = records
        .lines()
        .map(|l| serde_json::from_str(l).expect("json"))
        .filter(|v: &serde_json::Value| v["tracker"] == "stanley")
        .collect();
    assert_eq!(stanley.len(), 4);
    assert!(
        stanley.iter().all(|v| v["failure"] != "error"),
        "{stanley:?}"
    );
    // Paired on the same seeds, the comparison names both.
    let text = ok(&forkbench(&[
        "compare",
        d,
        "--a",
        "pure_pursuit",
        "--b",
        "stanley",
    ]));
    assert!(
        text.contains("stanley") && text.contains("pure_pursuit"),
        "{text}"
    );
}
