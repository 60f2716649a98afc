//! The pluggable pipeline changed no built-in result: per-trial outcomes of both planners
//! at a fixed seed equal the records committed before the change (plan-once and replan).

use std::collections::BTreeMap;

use forkbench_trial::batch::{BatchSpec, read_records, run_batch};
use forkbench_trial::defaults::default_scenarios;
use serde_json::Value;

type Key = (bool, String, String, String, u64);

fn key(v: &Value) -> Key {
    let s = |f: &str| v[f].as_str().expect("string field").to_owned();
    (
        v["replan"].as_bool().unwrap_or(false),
        s("scenario"),
        s("case"),
        s("planner"),
        v["trial"].as_u64().expect("trial"),
    )
}

/// Records committed before the change (`wall_time_ms` removed, `replan` filled in).
fn committed() -> BTreeMap<Key, Value> {
    include_str!("data/builtin_outcomes.jsonl")
        .lines()
        .map(|l| {
            let v: Value = serde_json::from_str(l).expect("json");
            (key(&v), v)
        })
        .collect()
}

fn run(replan: Option<bool>) -> Vec<Value> {
    let dir = std::env::temp_dir().join(format!(
        "forkbench-builtin-{}-{replan:?}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    let spec = BatchSpec {
        // The pick scenarios the records were made with (the mission came later).
        scenarios: default_scenarios()
            .expect("embedded scenarios")
            .into_iter()
            .filter(|s| s.mission.is_none())
            .collect(),
        planners: vec!["bspline".into(), "spiral".into()],
        trackers: vec![],
        trials: 2,
        seed: 11,
        shard: (0, 1),
        pallet_noise_scale: None,
        replan,
        compare_replanning: false,
        force_new: false,
    };
    run_batch(&spec, &dir, 2, &|_| {}).expect("batch runs");
    let records = read_records(&dir.join("trials.jsonl")).expect("records");
    let _ = std::fs::remove_dir_all(&dir);
    records
        .iter()
        .map(|r| {
            let mut v = serde_json::to_value(r).expect("serialises");
            let m = v.as_object_mut().expect("object");
            m.remove("wall_time_ms");
            assert_eq!(m.remove("tracker"), Some(Value::from("pure_pursuit")));
            // Records now always carry the mode they ran in; the committed ones carry the
            // batch's override (absent when none).
            m.insert("replan".into(), Value::Bool(replan.unwrap_or(false)));
            v
        })
        .collect()
}

#[test]
fn built_in_outcomes_are_identical_to_the_records_before_the_change() {
    let want = committed();
    let mut got = run(None);
    got.extend(run(Some(true)));
    assert_eq!(got.len(), want.len(), "same trials");
    let mut differing = Vec::new();
    for v in &got {
        let k = key(v);
        let w = want
            .get(&k)
            .unwrap_or_else(|| panic!("no committed record for {k:?}"));
        if w != v {
            differing.push(k);
        }
    }
    assert!(
        differing.is_empty(),
        "{} of {} trials differ, first: {:?}",
        differing.len(),
        got.len(),
        differing.first()
    );
}
