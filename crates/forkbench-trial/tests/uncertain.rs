//! Uncertain parameters: drawn per trial from streams keyed by name, recorded, pinned on demand, refused with file and line when a distribution is malformed or reaches too far; and every trial's robustness agrees with its verdict.

use std::collections::BTreeMap;
use std::path::PathBuf;

use forkbench_trial::trial::{TrialOptions, run_trial};
use forkbench_trial::{Scenario, ScenarioError};

fn dir() -> PathBuf {
    let d = std::env::temp_dir().join(format!("forkbench-uncertain-{}", std::process::id()));
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

/// The field test with `extra` appended, written as `name`.toml and loaded.
fn field_test_with(name: &str, extra: &str) -> Result<Scenario, ScenarioError> {
    let base = std::fs::read_to_string(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/field-test.toml"),
    )
    .expect("field test");
    let path = dir().join(format!("{name}.toml"));
    std::fs::write(&path, format!("{base}\n{extra}")).expect("write");
    Scenario::load(&path)
}

const PALLET_Y: &str = "[[uncertain]]\nname = \"pallet.y_m\"\ndist = \"truncated_normal\"\nmean = 0.0\nsigma = 0.02\nmin = -0.06\nmax = 0.06\n";
const LAG: &str = "[[uncertain]]\nname = \"steering_time_constant_s\"\ndist = \"lognormal\"\nmedian = 0.08\nsigma_log = 0.5\n";

fn seeded(seed: u64) -> TrialOptions {
    TrialOptions {
        seed: Some(seed),
        ..TrialOptions::default()
    }
}

#[test]
fn draws_are_recorded_repeatable_and_keyed_by_name() {
    let one = field_test_with("one", PALLET_Y).expect("loads");
    let two = field_test_with("two", &format!("{LAG}{PALLET_Y}")).expect("loads");
    let a = run_trial(&one, &one.cases[0], &seeded(4));
    let b = run_trial(&two, &two.cases[0], &seeded(4));
    let y = a.uncertain["pallet.y_m"];
    assert!(y.abs() <= 0.06 && y != 0.0, "{y}");
    // Declaring another parameter before it moves none of its draws.
    assert_eq!(b.uncertain["pallet.y_m"], y);
    let lag = b.uncertain["steering_time_constant_s"];
    assert!(lag > 0.0 && lag != 0.08, "{lag}");
    assert_eq!(
        run_trial(&one, &one.cases[0], &seeded(4)).uncertain,
        a.uncertain
    );
    let other = run_trial(&one, &one.cases[0], &seeded(5));
    assert_ne!(other.uncertain["pallet.y_m"], y);
    // Values over many seeds follow the declared truncation.
    let ys: Vec<f64> = (0..200)
        .map(|s| one.uncertain.values(s, &BTreeMap::new())["pallet.y_m"])
        .collect();
    assert!(ys.iter().all(|v| v.abs() <= 0.06));
    let mean = ys.iter().sum::<f64>() / ys.len() as f64;
    assert!(mean.abs() < 0.005, "{mean}");
}

#[test]
fn a_pinned_value_is_the_one_run_and_a_slow_steering_fails_the_pick() {
    let scn = field_test_with("pinned", LAG).expect("loads");
    let case = &scn.cases[0];
    let mut opts = TrialOptions {
        no_noise: true,
        ..seeded(1)
    };
    assert!(run_trial(&scn, case, &opts).success);
    opts.uncertain
        .insert("steering_time_constant_s".into(), 0.6);
    let slow = run_trial(&scn, case, &opts);
    assert_eq!(slow.uncertain["steering_time_constant_s"], 0.6);
    assert!(!slow.success, "{:?}", slow.failure);
    assert!(
        slow.robustness.is_some_and(|r| r <= 0.0),
        "{:?}",
        slow.robustness
    );
    // A pin the scenario does not declare, or beyond its reach, is refused by name.
    opts.uncertain.insert("pallet.x_m".into(), 0.1);
    let e = opts.resolve(&scn).expect_err("undeclared").to_string();
    assert!(
        e.contains("pallet.x_m") && e.contains("steering_time_constant_s"),
        "{e}"
    );
    opts.uncertain.remove("pallet.x_m");
    opts.uncertain
        .insert("steering_time_constant_s".into(), 90.0);
    let e = opts.resolve(&scn).expect_err("too far").to_string();
    assert!(e.contains("outside what its distribution reaches"), "{e}");
}

#[test]
fn malformed_parameters_are_refused_with_file_line_and_field() {
    let cases = [
        (
            "name = \"pallet.z_m\"\ndist = \"normal\"\nmean = 0.0\nsigma = 0.01",
            "uncertain[0].name",
            "pallet.x_m",
        ),
        (
            "name = \"pallet.y_m\"\ndist = \"gamma\"\nmean = 0.0\nsigma = 0.01",
            "uncertain[0].dist",
            "lognormal",
        ),
        (
            "name = \"pallet.y_m\"\ndist = \"normal\"\nmean = 0.0",
            "uncertain[0].sigma",
            "missing",
        ),
        (
            "name = \"pallet.y_m\"\ndist = \"uniform\"\nmin = 0.1\nmax = 0.2\nsigma = 1.0",
            "uncertain[0].sigma",
            "not a key",
        ),
        (
            "name = \"pallet.y_m\"\ndist = \"uniform\"\nmin = 0.2\nmax = 0.1",
            "uncertain[0].max",
            "must exceed",
        ),
        (
            "name = \"pallet.y_m\"\ndist = \"normal\"\nmean = 0.0\nsigma = 0.5",
            "uncertain[0].dist",
            "must stay within -2 to 2 m",
        ),
        (
            "name = \"steering_dead_time_s\"\ndist = \"normal\"\nmean = 0.06\nsigma = 0.02",
            "uncertain[0].dist",
            "dead_time",
        ),
        (
            "name = \"pallet.y_m\"\ndist = \"truncated_normal\"\nmean = 0.0\nsigma = 0.01\nmin = 1.0\nmax = 1.1",
            "uncertain[0].min",
            "almost none",
        ),
        (
            "name = \"mover.0.speed_mps\"\ndist = \"uniform\"\nmin = 1.0\nmax = 1.2",
            "uncertain[0].name",
            "0 [[mover]]",
        ),
        // A drawn control period is never a whole number of physics steps: refused at
        // load, not by each trial at run time.
        (
            "name = \"control_period_s\"\ndist = \"uniform\"\nmin = 0.015\nmax = 0.035",
            "uncertain[0].dist",
            "whole number of physics steps",
        ),
    ];
    for (i, (entry, field, why)) in cases.iter().enumerate() {
        let e = field_test_with(&format!("bad{i}"), &format!("[[uncertain]]\n{entry}\n"))
            .expect_err(entry)
            .to_string();
        assert!(
            e.contains(&format!("bad{i}.toml:")) && e.contains(field) && e.contains(why),
            "{entry}: {e}"
        );
    }
    let twice = field_test_with("twice", &format!("{PALLET_Y}{PALLET_Y}")).expect_err("twice");
    assert!(twice.to_string().contains("declared twice"), "{twice}");
}

#[test]
fn robustness_is_negative_exactly_when_a_committed_trial_failed() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/default_outcomes.jsonl");
    let records = super::common::records(&std::fs::read_to_string(path).expect("records"));
    let (mut pass, mut fail) = (0, 0);
    for r in &records {
        let Some(rob) = r["robustness"].as_f64() else {
            assert!(!r["success"].as_bool().expect("success"), "{r}");
            continue;
        };
        if r["success"].as_bool().expect("success") {
            assert!(rob >= 0.0, "{r}");
            pass += 1;
        } else {
            assert!(rob <= 0.0, "{r}");
            fail += 1;
        }
    }
    assert!(pass > 50 && fail > 3, "{pass} passed, {fail} failed");
}
