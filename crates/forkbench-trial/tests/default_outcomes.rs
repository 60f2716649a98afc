//! Committed trial records of the main job (the embedded scenarios with their own sensing:
//! TiM561 scans, NAV350 reflector fixes, odometry errors, the warehouse mission, the
//! handling cycle and the people cycles; two trials of every scenario × case × planner ×
//! mode), re-run at their own seeds, give the same outcomes to the bit: the records of the
//! default (realistic) truck at the defaults, and those made before actuators and sensor
//! timing were modelled with `--truck ideal`.

use crate::common;

use forkbench_trial::defaults::default_scenarios;
use forkbench_trial::{TrialOptions, run_trial};
use serde_json::Value;

/// Records made by `batch --trials 20` (trials 0 and 1 of each row), with the wall and
/// planning times removed: at the defaults (`tools/regen-committed-outcomes`), or, for
/// `ideal`, before the actuators were modelled.
fn committed(ideal: bool) -> Vec<Value> {
    common::records(if ideal {
        include_str!("data/ideal_outcomes.jsonl")
    } else {
        include_str!("data/default_outcomes.jsonl")
    })
}

/// Removes what a re-run cannot reproduce: the times measured on the clock.
fn without_clock_times(v: &mut Value) {
    let m = v.as_object_mut().expect("object");
    m.remove("wall_time_ms");
    if let Some(Value::Array(legs)) = m.get_mut("legs") {
        for leg in legs {
            leg.as_object_mut()
                .expect("leg object")
                .remove("planning_time_s");
        }
    }
}

/// The record re-run at its seed, in the committed records' form.
fn rerun(want: &Value, scenarios: &[forkbench_trial::Scenario], ideal: bool) -> Value {
    let (scn, case) = common::case_of(scenarios, want);
    let replan = want["replan"].as_bool().expect("replan");
    let opts = TrialOptions {
        seed: Some(want["seed"].as_u64().expect("seed")),
        planner: Some(common::text(want, "planner")),
        tracker: Some(common::text(want, "tracker")),
        no_noise: false,
        overrides: forkbench_trial::trial::Overrides {
            truck_preset: ideal.then(|| "ideal".to_owned()),
            ..Default::default()
        },
        replan: Some(replan),
        wall_budget_s: None,
        uncertain: Default::default(),
    };
    let mut v = serde_json::to_value(run_trial(scn, case, &opts)).expect("serialises");
    without_clock_times(&mut v);
    let m = v.as_object_mut().expect("object");
    m.insert("replan".into(), Value::Bool(replan));
    m.insert("trial".into(), want["trial"].clone());
    v
}

fn check(ideal: bool) {
    let want = committed(ideal);
    let scenarios = default_scenarios().expect("embedded scenarios");
    let rows: std::collections::BTreeSet<_> = want
        .iter()
        .map(|w| {
            (
                w["scenario"].to_string(),
                w["case"].to_string(),
                w["replan"].to_string(),
            )
        })
        .collect();
    assert_eq!(want.len(), 2 * rows.len(), "two trials of every row");
    assert!(
        want.iter().any(|w| w["scenario"] == "warehouse-mission"),
        "the mission is among the records"
    );
    common::assert_reruns_equal(&want, |w| rerun(w, &scenarios, ideal));
}

#[test]
fn default_outcomes_are_identical_to_the_committed_records() {
    check(false);
}

/// The `ideal` preset is the bench's first truck, to the bit.
#[test]
fn the_ideal_preset_reproduces_the_first_trucks_records() {
    check(true);
}
