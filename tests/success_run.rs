//! A batch's success-run figures (ASTM F3499 style) in its summary, its JSON and its report.

use crate::common::{forkbench, s, text, tmp_in};

#[test]
fn a_batch_states_the_reliability_its_trials_show() {
    let dir = tmp_in("success-run", "batch");
    let o = forkbench(&[
        "batch",
        "rack-pick",
        "--trials",
        "4",
        "--out",
        s(&dir),
        "--record",
        "none",
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("summary.json")).expect("summary"))
            .expect("json");
    let row = &summary["rows"][0];
    let (k, n) = (
        row["successes"].as_u64().expect("k"),
        row["trials"].as_u64().expect("n"),
    );
    let run = &row["success_run"];
    assert_eq!(run["success_run_for_target"], 299, "{run}");
    let r = run["demonstrated"].as_f64().expect("R");
    if k == n {
        // No failure: the bound is (1 − C)^(1/n), and 299 − n more clean trials show 0.99.
        assert!((r - 0.05f64.powf(1.0 / n as f64)).abs() < 1e-9, "{run}");
        assert_eq!(run["more_clean_trials"], 299 - n, "{run}");
    } else {
        assert!(r < 0.05f64.powf(1.0 / n as f64), "{run}");
    }
    let md = std::fs::read_to_string(dir.join("summary.md")).expect("md");
    assert!(md.contains("Success run (ASTM F3499 style)"), "{md}");
    let page = tmp_in("success-run", "report.html");
    let o = forkbench(&["report", s(&dir), "--out", s(&page)]);
    assert!(o.status.success(), "{}", text(&o));
    let html = std::fs::read_to_string(&page).expect("html");
    assert!(html.contains("R demonstrated") && html.contains(&format!("{r:.4}")));
}

/// A chosen confidence and target reach the summary, its markdown and the report, and a
/// resume may restate them (how results are read, not how they were run); out of range
/// is refused naming the flag.
#[test]
fn the_confidence_and_target_are_chosen() {
    let dir = tmp_in("success-run", "chosen");
    let run = |c: &str, r: &str| {
        forkbench(&[
            "batch",
            "rack-pick",
            "--trials",
            "3",
            "--out",
            s(&dir),
            "--record",
            "none",
            "--success-confidence",
            c,
            "--success-reliability",
            r,
        ])
    };
    let o = run("0.9", "0.95");
    assert!(o.status.success(), "{}", text(&o));
    let read = || -> serde_json::Value {
        serde_json::from_slice(&std::fs::read(dir.join("summary.json")).expect("summary"))
            .expect("json")
    };
    let row = read()["rows"][0].clone();
    let figures = &row["success_run"];
    // ln 0.1 / ln 0.95 = 44.9: 45 clean runs show R 0.95 at 90 %.
    assert_eq!(figures["success_run_for_target"], 45, "{figures}");
    assert_eq!(figures["confidence"], 0.9, "{figures}");
    let md = std::fs::read_to_string(dir.join("summary.md")).expect("md");
    assert!(
        md.contains("at 90 % confidence") && md.contains("for R 0.95"),
        "{md}"
    );
    let page = tmp_in("success-run", "chosen.html");
    let o = forkbench(&["report", s(&dir), "--out", s(&page)]);
    assert!(o.status.success(), "{}", text(&o));
    let html = std::fs::read_to_string(&page).expect("html");
    assert!(html.contains("at 90 % confidence") && html.contains("show R 0.95"));
    // Resumed with another target: no trial reruns, the figures follow.
    let o = run("0.95", "0.99");
    assert!(o.status.success(), "{}", text(&o));
    assert_eq!(
        read()["rows"][0]["success_run"]["success_run_for_target"],
        299
    );
    let o = forkbench(&["report", s(&dir), "--out", s(&page)]);
    assert!(o.status.success(), "{}", text(&o));
    let html = std::fs::read_to_string(&page).expect("html");
    assert!(html.contains("at 95 % confidence") && html.contains("show R 0.99"));
    let o = run("0.95", "1.0");
    assert!(!o.status.success());
    assert!(
        text(&o).contains("--success-reliability 1: a probability from 0.5 to 0.999999"),
        "{}",
        text(&o)
    );
}
