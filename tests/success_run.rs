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
