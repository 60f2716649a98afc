//! `--profile`: a trial's and a batch's time by stage, which accounts for the whole wall time, names the components, and changes no outcome.

use crate::common::{forkbench, repo_root, s, text, tmp_in};

fn json(o: &std::process::Output) -> serde_json::Value {
    serde_json::from_slice(&o.stdout).unwrap_or_else(|e| panic!("{e}: {}", text(o)))
}

/// The outcome without what differs from run to run (its times, its profile).
fn outcome_only(mut v: serde_json::Value) -> serde_json::Value {
    let m = v.as_object_mut().expect("an object");
    m.remove("wall_time_ms");
    m.remove("profile");
    v
}

#[test]
fn a_trials_profile_accounts_for_its_time_and_names_its_components() {
    let field = repo_root().join("scenarios/field-test.toml");
    let run = |extra: &[&str]| {
        let mut args = vec!["trial", s(&field), "--json", "--seed", "11"];
        args.extend_from_slice(extra);
        let o = forkbench(&args);
        assert!(matches!(o.status.code(), Some(0 | 3)), "{}", text(&o));
        json(&o)
    };
    let (plain, profiled) = (run(&[]), run(&["--profile"]));
    assert!(plain.get("profile").is_none(), "no profile unless asked");
    let p = profiled["profile"].clone();
    assert_eq!(
        outcome_only(plain),
        outcome_only(profiled),
        "profiling moved the outcome"
    );
    let wall = p["wall_ms"].as_f64().expect("wall");
    let stages = p["stages"].as_array().expect("stages");
    let sum: f64 = stages
        .iter()
        .map(|s| s["time_ms"].as_f64().expect("time"))
        .sum();
    assert!(
        (sum - wall).abs() <= 1e-6 * wall.max(1.0),
        "stages {sum} ms, wall {wall} ms"
    );
    let named = |stage: &str| {
        stages
            .iter()
            .find(|s| s["stage"] == stage)
            .unwrap_or_else(|| panic!("no {stage} in {p}"))
    };
    assert!(
        named("physics")["calls"].as_u64().expect("calls") > 100,
        "{p}"
    );
    assert_eq!(named("planning")["component"], "bspline");
    assert_eq!(named("tracking")["component"], "pure_pursuit");
    assert_eq!(named("scan")["component"], "tim561");
    assert_eq!(stages.last().expect("a stage")["stage"], "other");
    // The text report prints it after the outcome.
    let o = forkbench(&["trial", s(&field), "--seed", "11", "--profile"]);
    let t = text(&o);
    assert!(
        t.contains("profile physics") && t.contains("profile tracking (pure_pursuit)"),
        "{t}"
    );
}

#[test]
fn a_batchs_profile_sums_its_trials_into_the_summary_and_the_report() {
    let field = repo_root().join("scenarios/field-test.toml");
    let out = tmp_in("profile-batch", "out");
    let _ = std::fs::remove_dir_all(&out);
    let o = forkbench(&[
        "batch",
        s(&field),
        "--trials",
        "6",
        "--record",
        "none",
        "--out",
        s(&out),
        "--profile",
        "--report",
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let t = text(&o);
    assert!(
        t.contains("where the trials' time went (6 profiled trials"),
        "{t}"
    );
    // The closing line's clock names what the batch spent its time on.
    assert!(t.contains("elapsed ") && t.contains("trials "), "{t}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).expect("read"))
            .expect("json");
    let total = &summary["profile"];
    assert_eq!(total["trials"], 6, "{total}");
    let rows = summary["rows"].as_array().expect("rows");
    let row_wall: f64 = rows
        .iter()
        .map(|r| r["profile"]["wall_ms"].as_f64().expect("a row's profile"))
        .sum();
    let wall = total["wall_ms"].as_f64().expect("wall");
    assert!(
        (row_wall - wall).abs() <= 1e-6 * wall,
        "{row_wall} vs {wall}"
    );
    let page = std::fs::read_to_string(out.join("report.html")).expect("report");
    assert!(page.contains("<h2>Where the time went</h2>") && page.contains("physics"));
    let _ = std::fs::remove_dir_all(out.parent().expect("folder"));
}
