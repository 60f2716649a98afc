//! A session stepped tick by tick: under its own tracker it reproduces a batch trial to the bit; under a caller's commands it ends on the criteria, the time limit, and the same way twice.

mod common;

use std::sync::Arc;

use forkbench_trial::defaults::default_scenarios;
use forkbench_trial::trial::{Control, Session, SessionEnd};
use forkbench_trial::{Failure, Scenario, TrialOptions};
use serde_json::Value;

fn options(seed: u64, replan: Option<bool>) -> TrialOptions {
    TrialOptions {
        seed: Some(seed),
        replan,
        ..TrialOptions::default()
    }
}

/// Steps a session to its end under `control`, at most `max_ticks` ticks.
fn run(session: &mut Session, max_ticks: u64, control: impl Fn(&Session) -> Control) -> u64 {
    for tick in 0..max_ticks {
        if session.ended().is_some() || session.step(control(session)).is_some() {
            return tick;
        }
    }
    panic!("no end within {max_ticks} ticks");
}

fn field_test() -> Arc<Scenario> {
    let scn = default_scenarios().expect("embedded scenarios");
    Arc::new(
        scn.into_iter()
            .find(|s| s.name == "field-test")
            .expect("field-test"),
    )
}

/// Every committed main-job record (each scenario × case × planner × mode, the mission
/// included), run as a session stepped with the tracker, gives the record's outcome.
#[test]
fn a_session_under_its_tracker_reproduces_the_committed_trials() {
    let want = common::records(include_str!("data/default_outcomes.jsonl"));
    let scenarios: Vec<Arc<Scenario>> = default_scenarios()
        .expect("embedded scenarios")
        .into_iter()
        .map(Arc::new)
        .collect();
    common::assert_reruns_equal(&want, |w| {
        let name = common::text(w, "scenario");
        let scn = scenarios.iter().find(|s| s.name == name).expect("scenario");
        let mut opts = options(w["seed"].as_u64().expect("seed"), w["replan"].as_bool());
        opts.planner = Some(common::text(w, "planner"));
        let mut s = Session::start(scn.clone(), &common::text(w, "case"), &opts).expect("starts");
        run(&mut s, 1_000_000, |_| Control::Tracker);
        let out = s.ended().expect("ended").0.without_wall_times();
        let mut v = serde_json::to_value(out).expect("serialises");
        let m = v.as_object_mut().expect("object");
        m.remove("wall_time_ms");
        for leg in m
            .get_mut("legs")
            .and_then(Value::as_array_mut)
            .into_iter()
            .flatten()
        {
            leg.as_object_mut().expect("leg").remove("planning_time_s");
        }
        m.insert("replan".into(), w["replan"].clone());
        m.insert("trial".into(), w["trial"].clone());
        v
    });
}

/// A truck told to stand still stands until the time limit, and the verdict is a timeout
/// at exactly the scenario's limit.
#[test]
fn standing_still_ends_at_the_time_limit() {
    let scn = field_test();
    let mut s = Session::start(scn.clone(), "default", &options(3, None)).expect("starts");
    let first = *s.observation();
    assert!(first.time_left_s > 0.0 && first.pose.x_m.is_finite());
    run(&mut s, 1_000_000, |_| Control::Command {
        speed_mps: 0.0,
        steer_rad: 0.0,
    });
    let (out, end) = s.ended().expect("ended");
    assert_eq!(end, SessionEnd::TimeLimit);
    assert_eq!(
        out.failure,
        Some(Failure::Timeout),
        "{:?}",
        out.failure_detail
    );
    assert!(
        (out.sim_time_s - scn.timeout_s).abs() < 0.011,
        "{}",
        out.sim_time_s
    );
}

/// Steering at the goal without ever stopping pushes the pallet: the episode ends there,
/// judged, before the time limit; two sessions at one seed under the same commands end
/// identically.
#[test]
fn caller_commands_are_judged_and_deterministic() {
    let scn = field_test();
    let drive = |seed: u64| {
        let mut s = Session::start(scn.clone(), "default", &options(seed, None)).expect("starts");
        let ticks = run(&mut s, 1_000_000, |s| {
            let o = s.observation();
            let bearing = (o.goal.y_m - o.pose.y_m).atan2(o.goal.x_m - o.pose.x_m);
            let off = forkbench_core::units::wrap_angle(bearing - o.pose.heading_rad);
            Control::Command {
                speed_mps: 1.0,
                steer_rad: 2.0 * off,
            }
        });
        (ticks, s.ended().expect("ended").0.without_wall_times())
    };
    let (ticks, out) = drive(5);
    assert!(!out.success);
    assert!(
        matches!(
            out.failure,
            Some(Failure::Collision | Failure::PalletDisplaced | Failure::ContactForce)
        ),
        "{:?}: {:?}",
        out.failure,
        out.failure_detail
    );
    assert!(
        (ticks as f64) < scn.timeout_s * 50.0,
        "ended early: {ticks} ticks"
    );
    assert_eq!(drive(5), (ticks, out));
}
