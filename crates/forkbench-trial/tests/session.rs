//! A session stepped tick by tick: under its own tracker it reproduces a batch trial to the bit; under a caller's commands it ends on the criteria, the time limit, and the same way twice.

use crate::common;

use std::sync::Arc;

use forkbench_trial::defaults::default_scenarios;
use forkbench_trial::trial::{Control, Episode, Session, SessionEnd, Stage};
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
fn run(session: &mut Session, max_ticks: u64, mut control: impl FnMut(&Session) -> Control) -> u64 {
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
/// and the people cycles included), run as a session stepped with the tracker, gives the
/// record's outcome.
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
        // A handling cycle's record is the whole cycle: a cycle episode steps it all.
        let episode = if scn.phases.is_empty() {
            Episode::Pick
        } else {
            Episode::Cycle
        };
        let mut s =
            Session::start_episode(scn.clone(), &common::text(w, "case"), &opts, episode, false)
                .expect("starts");
        run(&mut s, 10_000_000, |_| Control::Tracker);
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
    // The limit counts from the drive, after the truck stood for the NAV350's first fix
    // and the detector's first estimate.
    let waited = out.sim_time_s - scn.timeout_s;
    let most = scn.noise.nav350.latency_s + scn.pallet_sensing.latency_s() + 0.011;
    assert!((-0.011..most).contains(&waited), "{}", out.sim_time_s);
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

/// A whole-cycle scenario from the repository, loaded from its file.
fn cycle_scenario(file: &str) -> Arc<Scenario> {
    let dir = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenarios"));
    let text = std::fs::read_to_string(dir.join(file)).expect("the scenario");
    let scn = Scenario::parse(&text, file, |w| forkbench_trial::World::load(&dir.join(w)))
        .expect("valid");
    Arc::new(scn)
}

/// The warehouse cycle (legs, pick, lift, reverse out, carry, place, return) and the rack
/// cycle, stepped tick by tick as whole-cycle episodes under their own controllers, give
/// `run_trial`'s outcome to the bit; the caller takes the ticks of every stage.
#[test]
fn a_cycle_episode_stepped_tick_by_tick_equals_run_trial() {
    for (file, seeds) in [
        ("warehouse-cycle.toml", 1..3),
        ("rack-pick-cycle.toml", 1..4),
    ] {
        let scn = cycle_scenario(file);
        for seed in seeds {
            let opts = options(seed, None);
            let batch = forkbench_trial::run_trial(&scn, &scn.cases[0], &opts).without_wall_times();
            let mut s =
                Session::start_episode(scn.clone(), "default", &opts, Episode::Cycle, false)
                    .expect("starts");
            let mut stages = Vec::new();
            let ticks = run(&mut s, 10_000_000, |s| {
                let stage = s.observation().stage;
                if stages.last() != Some(&stage) {
                    stages.push(stage);
                }
                Control::Tracker
            });
            let stepped = s.ended().expect("ended").0.without_wall_times();
            assert_eq!(stepped, batch, "{file} seed {seed}");
            assert!(ticks > 100, "{file} seed {seed}: {ticks} ticks");
            // Every phase the trial reached was a stage the caller stepped through.
            let reached = batch.phases.len().saturating_sub(1);
            for i in 1..=reached {
                let phase = Stage::Phase(i as u16);
                assert!(stages.contains(&phase), "{file} seed {seed}: {stages:?}");
            }
            assert!(
                stages.contains(&Stage::Pick),
                "{file} seed {seed}: {stages:?}"
            );
            if scn.mission.is_some() {
                assert_eq!(stages.first(), Some(&Stage::Leg), "{file} seed {seed}");
            }
        }
    }
}

/// A pick episode of a cycle scenario ends at the pick's verdict: no phase is run.
#[test]
fn a_pick_episode_of_a_cycle_scenario_ends_at_the_pick() {
    let scn = cycle_scenario("rack-pick-cycle.toml");
    let mut s = Session::start(scn.clone(), "default", &options(3, None)).expect("starts");
    run(&mut s, 1_000_000, |s| {
        assert_eq!(s.observation().stage, Stage::Pick);
        Control::Tracker
    });
    let out = s.ended().expect("ended").0;
    assert!(out.phases.is_empty(), "{:?}", out.phases);
    assert!(out.cycle.is_none());
}
