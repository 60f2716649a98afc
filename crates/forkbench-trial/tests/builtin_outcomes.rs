//! The pluggable pipeline changed no built-in result: every committed trial record (both
//! planners, every embedded pick case, plan-once and replan), re-run at its own seed,
//! gives the same outcome. Seeds are taken from the records, so the check does not depend
//! on how a batch derives them.

use crate::common;

use forkbench_trial::defaults::default_scenarios;
use forkbench_trial::{TrialOptions, run_trial};
use serde_json::Value;

/// Records committed before the change (`wall_time_ms` removed, `replan` filled in).
fn committed() -> Vec<Value> {
    common::records(include_str!("data/builtin_outcomes.jsonl"))
}

/// The record re-run at its seed, in the committed records' form.
fn rerun(want: &Value) -> Value {
    // The records were made with the Gaussian models (pallet and localisation) and exact
    // odometry, before the scanners, the reflectors and odometry errors became the default.
    let scenarios: Vec<_> = default_scenarios()
        .expect("embedded scenarios")
        .into_iter()
        .map(|s| {
            let mut s = s
                .with_pallet_sensing("gaussian")
                .and_then(|s| s.with_localizer("gaussian"))
                .expect("kind");
            // …and replanned by a new plan from the truck, before replans deformed the path.
            s.replan.method = forkbench_trial::scenario::ReplanMethod::Plan;
            s.noise.odometry = forkbench_sensors::OdometryConfig {
                speed_scale_sigma: 0.0,
                steer_offset_sigma_rad: 0.0,
            };
            // …and before actuators and the NAV350's latency were modelled (both at 0 by
            // default; set here so a change of default does not move these records).
            s.noise.nav350.latency_s = 0.0;
            s
        })
        .collect();
    let (scn, case) = common::case_of(&scenarios, want);
    let replan = want["replan"].as_bool().expect("replan");
    let opts = TrialOptions {
        seed: Some(want["seed"].as_u64().expect("seed")),
        planner: Some(common::text(want, "planner")),
        tracker: None,
        no_noise: false,
        overrides: forkbench_trial::trial::Overrides {
            truck_preset: Some("ideal".to_owned()),
            ..Default::default()
        },
        // The records of plan-once came from the scenario's own setting.
        replan: replan.then_some(true),
        wall_budget_s: None,
        uncertain: Default::default(),
    };
    let out = run_trial(scn, case, &opts);
    let mut v = serde_json::to_value(&out).expect("serialises");
    let m = v.as_object_mut().expect("object");
    m.remove("wall_time_ms");
    // Fields the records predate (pallet-estimate counts and errors, every broken
    // criterion and the likely cause, the step criteria's measures, the robustness).
    for later in [
        "measures",
        "robustness",
        "estimates",
        "estimates_missed",
        "estimate_lateral_error_m",
        "estimate_heading_error_rad",
        "also_failed",
        "likely_cause",
        "fixes",
        "fixes_missed",
        "time_without_fix_s",
        "largest_fix_gap_s",
        "localization_error_mean_m",
        "localization_error_max_m",
    ] {
        m.remove(later);
    }
    assert_eq!(m.remove("tracker"), Some(Value::from("pure_pursuit")));
    m.insert("replan".into(), Value::Bool(replan));
    m.insert("trial".into(), want["trial"].clone());
    v
}

#[test]
fn built_in_outcomes_are_identical_to_the_records_before_the_change() {
    let want = committed();
    assert_eq!(
        want.len(),
        344,
        "both planners, every pick case, 2 trials, 2 modes"
    );
    common::assert_reruns_equal(&want, rerun);
}
