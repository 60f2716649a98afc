//! `batch --trials auto`: refused without a baseline, its flags refused without it, and a run that gates look by look, writing its looks to OUT/sequential.json.

use crate::common::{forkbench, repo_root, s, text};

fn tmp(name: &str) -> std::path::PathBuf {
    crate::common::tmp_in("forkbench-auto", name)
}

#[test]
fn trials_auto_needs_a_baseline_and_its_flags_need_auto() {
    let scn = repo_root().join("scenarios/field-test.toml");
    let out = tmp("refused");
    let o = forkbench(&["batch", s(&scn), "--trials", "auto", "--out", s(&out)]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(text(&o).contains("give --baseline FILE"), "{}", text(&o));
    let o = forkbench(&[
        "batch",
        s(&scn),
        "--trials",
        "5",
        "--baseline",
        "b.json",
        "--out",
        s(&out),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(text(&o).contains("go with --trials auto"), "{}", text(&o));
    let o = forkbench(&["batch", s(&scn), "--trials", "many", "--out", s(&out)]);
    assert!(!o.status.success());
    assert!(text(&o).contains("or `auto`"), "{}", text(&o));
    assert!(!out.join("trials.jsonl").exists(), "nothing run");
}

#[test]
fn trials_auto_gates_each_look_and_writes_them() {
    let scn = repo_root().join("scenarios/field-test.toml");
    let (base_dir, file, out) = (tmp("base"), tmp("base.json"), tmp("auto"));
    let _ = std::fs::remove_dir_all(&out);
    let o = forkbench(&[
        "batch",
        s(&scn),
        "--trials",
        "20",
        "--record",
        "none",
        "--force-new",
        "--out",
        s(&base_dir),
    ]);
    assert!(matches!(o.status.code(), Some(0 | 3)), "{}", text(&o));
    let o = forkbench(&["baseline", s(&base_dir), "--out", s(&file)]);
    assert!(o.status.success(), "{}", text(&o));
    let o = forkbench(&[
        "batch",
        s(&scn),
        "--trials",
        "auto",
        "--baseline",
        s(&file),
        "--record",
        "none",
        "--out",
        s(&out),
    ]);
    let capped = forkbench(&[
        "batch",
        s(&scn),
        "--trials",
        "auto",
        "--baseline",
        s(&file),
        "--max-trials",
        "0",
        "--out",
        s(&tmp("capped")),
    ]);
    assert_eq!(capped.status.code(), Some(1), "{}", text(&capped));
    assert!(
        text(&capped).contains("--max-trials 0: must be 1 to"),
        "{}",
        text(&capped)
    );
    // The same code: no look fails, so the gate passes (undecided at the 20-trial cap).
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert!(
        text(&o).contains("look 1: 10 trials per case"),
        "{}",
        text(&o)
    );
    let seq: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("sequential.json")).expect("written"))
            .expect("json");
    let looks = seq["looks"].as_array().expect("looks");
    assert_eq!(looks.len(), 2, "{seq}");
    assert_eq!(looks[1]["trials"], 20);
    assert!(looks.iter().all(|l| l["decision"] != "regression"), "{seq}");
    assert!((looks[0]["alpha"].as_f64().expect("α") - 0.025).abs() < 1e-12);
}
