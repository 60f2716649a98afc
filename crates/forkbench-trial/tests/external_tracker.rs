//! A tracker in another language: the Python Stanley example drives the field test into the pallet; a tracker that hangs, crashes, answers garbage or breaks the conversation fails only its trial, with the reason, and the truck stops.

use std::path::{Path, PathBuf};

use forkbench_trial::{Failure, Scenario, TrialOptions, run_trial};

const PICK: &str = "name = \"s\"\nplanner = \"bspline\"\npallet_kind = \"field-1200\"\n\
    start = { x_m = 0.0, y_m = 0.0, heading_deg = 0.0 }\n\
    pallet = { x_m = 5.0, y_m = 0.4, heading_deg = 5.0 }\n";

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("forkbench-trk-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

/// A scenario in its own directory whose tracker is `script` (Python), run there.
fn with_tracker(name: &str, script: &str, timeout_s: f64) -> Scenario {
    let d = dir(name);
    std::fs::write(d.join("trk.py"), script).expect("script");
    let text = format!(
        "{PICK}[tracker]\nkind = \"external\"\nname = \"{name}\"\n\
         command = [\"python3\", \"trk.py\"]\ntimeout_s = {timeout_s}\n"
    );
    let path = d.join("s.toml");
    std::fs::write(&path, text).expect("scenario");
    Scenario::load(&path).expect("loads")
}

/// Answers the hello and every reset with `ok`, then runs `tick` (Python, with `req` the
/// parsed request) for each tick, and `reset` (default: ok) for each reset.
fn script(reset: Option<&str>, tick: &str) -> String {
    let ok = "    print(json.dumps({'type': 'ok', 'id': req['id']}), flush=True)\n";
    format!(
        "import json, sys, time\n\
         for line in sys.stdin:\n    req = json.loads(line)\n    if req['type'] == 'hello':\n        \
         print(json.dumps({{'type': 'hello', 'protocol': 'forkbench-tracker', 'version': 1}}), flush=True)\n        \
         continue\n    if req['type'] == 'reset':\n    {}        continue\n{tick}",
        reset.unwrap_or(ok)
    )
}

fn seeded(seed: u64) -> TrialOptions {
    TrialOptions {
        seed: Some(seed),
        ..TrialOptions::default()
    }
}

#[test]
fn the_python_stanley_tracker_enters_the_pallet() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/trackers/stanley-field-test.toml");
    let scn = Scenario::load(&path).expect("loads");
    let exact = TrialOptions {
        no_noise: true,
        ..seeded(1)
    };
    let out = run_trial(&scn, &scn.cases[0], &exact);
    assert!(out.success, "{:?} {:?}", out.failure, out.failure_detail);
    assert_eq!(out.tracker, "stanley");
    let lateral = out.lateral_error_m.expect("entered");
    assert!(
        lateral.abs() < 0.03,
        "{lateral} m off the pocket centre line"
    );
    // With the sensors' noise it still drives every trial to a judged entry.
    for seed in 1..=3 {
        let out = run_trial(&scn, &scn.cases[0], &seeded(seed));
        assert_ne!(out.failure, Some(Failure::Error), "seed {seed}: {out:?}");
        assert!(out.lateral_error_m.is_some(), "seed {seed}: {out:?}");
    }
}

#[test]
fn a_misbehaving_tracker_fails_only_its_trial_with_the_reason() {
    let command = "    print(json.dumps({'type': 'command', 'id': req['id'], 'speed_mps': 0.5, \
                   'steer_rad': 0.0, 'done': False}), flush=True)\n";
    let cases = [
        (
            "hang",
            script(None, "    time.sleep(30)\n"),
            "no answer within",
        ),
        ("crash", script(None, "    sys.exit(3)\n"), "exited"),
        (
            "garbage",
            script(None, "    print('{not json', flush=True)\n"),
            "invalid answer",
        ),
        (
            "nan",
            script(
                None,
                "    print(json.dumps({'type': 'command', 'id': req['id'], 'speed_mps': float('nan'), \
                 'steer_rad': 0.0, 'done': False}), flush=True)\n",
            ),
            "invalid answer",
        ),
        (
            "refuses",
            script(
                Some(
                    "    print(json.dumps({'type': 'error', 'id': req['id'], 'message': 'no model'}), flush=True)\n",
                ),
                command,
            ),
            "no model",
        ),
        (
            "muddled",
            script(
                None,
                "    print(json.dumps({'type': 'ok', 'id': req['id']}), flush=True)\n",
            ),
            "not a command",
        ),
        (
            "wrong_id",
            script(
                None,
                "    print(json.dumps({'type': 'command', 'id': req['id'] + 7, 'speed_mps': 0.5, \
                 'steer_rad': 0.0, 'done': False}), flush=True)\n",
            ),
            "expected",
        ),
    ];
    for (name, body, why) in cases {
        let scn = with_tracker(name, &body, 1.0);
        let out = run_trial(&scn, &scn.cases[0], &seeded(1));
        assert_eq!(out.failure, Some(Failure::Error), "{name}: {out:?}");
        let detail = out.failure_detail.unwrap_or_default();
        assert!(
            detail.contains(why) && detail.contains(name),
            "{name}: {detail}"
        );
        // It stopped where the tracker failed: well short of the pallet.
        assert!(out.sim_time_s < 3.0, "{name}: ran {} s", out.sim_time_s);
    }
}

#[test]
fn tracker_settings_are_checked_at_load() {
    let d = dir("bad");
    let path = d.join("s.toml");
    for (table, field) in [
        ("kind = \"external\"\ncommand = []\n", "command"),
        (
            "kind = \"external\"\ncommand = [\"x\"]\ntimeout_s = 900.0\n",
            "timeout_s",
        ),
        (
            "kind = \"external\"\ncommand = [\"x\"]\nlookahead_m = 0.7\n",
            "lookahead_m",
        ),
    ] {
        std::fs::write(&path, format!("{PICK}[tracker]\n{table}")).expect("w");
        let e = Scenario::load(&path).expect_err(table).to_string();
        assert!(e.contains(&format!("tracker.{field}")), "{table}: {e}");
    }
}

/// A tracker that answers every tick slowly, each answer within its own timeout, meets the
/// trial's wall-time budget: the trial ends as an error naming it, well before the pick.
#[test]
fn a_slow_tracker_meets_the_trials_wall_time_budget() {
    let slow = "    time.sleep(0.05)\n    print(json.dumps({'type': 'command', 'id': req['id'], \
                'speed_mps': 0.3, 'steer_rad': 0.0, 'done': False}), flush=True)\n";
    let scn = with_tracker("slow", &script(None, slow), 1.0);
    let opts = TrialOptions {
        wall_budget_s: Some(1.0),
        ..seeded(1)
    };
    let t0 = std::time::Instant::now();
    let out = run_trial(&scn, &scn.cases[0], &opts);
    assert!(t0.elapsed().as_secs_f64() < 10.0);
    assert_eq!(out.failure, Some(Failure::Error), "{out:?}");
    let detail = out.failure_detail.unwrap_or_default();
    assert!(detail.contains("wall-time budget of 1 s"), "{detail}");
    // The error keeps what the trial measured up to it: its simulated time, the fixes
    // and where the forks stood against the pallet.
    assert!(out.sim_time_s > 0.1, "sim_time_s {}", out.sim_time_s);
    assert!(out.fixes > 0, "fixes {}", out.fixes);
    assert!(
        out.final_lateral_error_m.is_finite() && out.final_lateral_error_m != 0.0,
        "{}",
        out.final_lateral_error_m
    );
    // A budget out of range is refused before the trial starts.
    let bad = TrialOptions {
        wall_budget_s: Some(f64::NAN),
        ..seeded(1)
    };
    let out = run_trial(&scn, &scn.cases[0], &bad);
    assert!(
        out.failure_detail
            .unwrap_or_default()
            .contains("wall_budget_s"),
        "refused"
    );
}

/// Each tick says when the newest fix in its pose was measured: with the NAV350's default
/// latency and 8 Hz rate, every tick's fix is at least the latency old and at most a period
/// and a control tick more.
#[test]
fn a_tick_says_when_its_pose_was_measured() {
    let tick = "    age = req['t_s'] - req['fix_measured_s']\n    \
                with open('ages.txt', 'a') as f:\n        f.write(f'{age}\\n')\n    \
                n = sum(1 for _ in open('ages.txt'))\n    \
                print(json.dumps({'type': 'command', 'id': req['id'], 'speed_mps': 0.3 if n < 50 else 0.0, \
                'steer_rad': 0.0, 'done': n >= 50}), flush=True)\n";
    let scn = with_tracker("aged", &script(None, tick), 5.0);
    let out = run_trial(&scn, &scn.cases[0], &seeded(1));
    assert_ne!(
        out.failure,
        Some(Failure::Error),
        "{:?}",
        out.failure_detail
    );
    let ages: Vec<f64> = std::fs::read_to_string(dir("aged").join("ages.txt"))
        .expect("the tracker wrote its ages")
        .lines()
        .map(|l| l.parse().expect("a number"))
        .collect();
    let nav = &scn.noise.nav350;
    let (least, most) = (nav.latency_s, nav.latency_s + 1.0 / nav.rate_hz + 0.02);
    assert!(ages.len() >= 50, "{} ticks", ages.len());
    assert!(
        ages.iter()
            .all(|a| (least - 1e-9..=most + 1e-9).contains(a)),
        "ages outside {least}..{most}: {ages:?}"
    );
    let _ = std::fs::remove_dir_all(dir("aged"));
}
