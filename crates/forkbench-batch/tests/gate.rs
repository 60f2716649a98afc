//! The regression gate: paired on common random numbers (unchanged code has no discordant
//! pair), real degradations caught with fewer trials paired than unpaired, Holm over many
//! rows, new and missing rows, A/B `compare`, old and corrupt baselines.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use forkbench_batch::stats::Correction;
use forkbench_batch::{
    self as batch, Baseline, BatchSpec, CompareOptions, GateOptions, GateReport, Pairing, Summary,
    Verdict, junit,
};
use forkbench_track::PurePursuit;
use forkbench_trial::{Registry, Scenario};

use crate::gate_measures::Shifted;

fn scenario_file(name: &str) -> PathBuf {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenarios")).join(name)
}

/// A scenario with the Gaussian pallet model: the power figures below were measured on it.
fn scenario(name: &str) -> Scenario {
    Scenario::load(&scenario_file(name))
        .and_then(|s| s.with_pallet_sensing("gaussian"))
        .expect("loads")
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("forkbench-gate-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn spec(scenarios: Vec<Scenario>, trials: u64, seed: u64) -> BatchSpec {
    BatchSpec {
        scenarios,
        planners: vec![],
        trackers: vec![],
        trials,
        seed,
        shard: (0, 1),
        overrides: Default::default(),
        replan: Some(true),
        compare_replanning: false,
        force_new: false,
        success_run: Default::default(),
        profile: false,
    }
}

/// Runs a batch into a fresh directory; the summary and the directory.
fn run(s: &BatchSpec, name: &str) -> (Summary, PathBuf) {
    let d = tmp(name);
    let summary = batch::run_batch(s, &d, 2, &|_| {}).expect("runs");
    (summary, d)
}

fn gate(base: &Baseline, dir: &Path, o: &GateOptions) -> GateReport {
    let s = batch::load_results(dir).expect("results");
    let records = batch::read_records(&dir.join("trials.jsonl")).expect("records");
    let m = batch::Manifest::read(dir).expect("manifest");
    batch::regress(base, &s, &records, m.as_ref(), o)
}

fn baseline_of(dir: &Path) -> Baseline {
    let s = batch::load_results(dir).expect("results");
    let records = batch::read_records(&dir.join("trials.jsonl")).expect("records");
    Baseline::from_results(&s, &records, "test".into())
}

fn offset_scenario(name: &str) -> Scenario {
    let registry = Registry::builtin().with_tracker("pure_pursuit", |s, _| {
        // Pure pursuit that believes the truck 2 cm further left than it is: a subtle
        // calibration error, as a degraded build would have.
        Ok(Box::new(Shifted(PurePursuit::from_settings(s)?, 0.02)))
    });
    Scenario::load_with(&scenario_file(name), Arc::new(registry))
        .and_then(|s| s.with_pallet_sensing("gaussian"))
        .expect("loads")
}

#[test]
fn unchanged_code_has_no_discordant_pair_and_passes() {
    let (_, base_dir) = run(&spec(vec![scenario("field-test.toml")], 40, 5), "base");
    let base = baseline_of(&base_dir);
    // The file round-trips, one line per trial.
    let f = base_dir.join("baseline.json");
    base.write(&f).expect("writes");
    assert_eq!(Baseline::load(&f).expect("loads"), base);
    let (_, same) = run(&spec(vec![scenario("field-test.toml")], 40, 5), "same");
    let g = gate(&base, &same, &GateOptions::default());
    assert!(g.passed, "{}", g.markdown());
    assert_eq!(g.pairing, Pairing::Paired { pairs: 40 });
    let c = g.rows[0].paired.expect("paired");
    assert_eq!((c.pairs, c.broke, c.fixed), (40, 0, 0));
    assert_eq!(g.rows[0].p_value, Some(1.0));
    // Another batch seed: no pairs, compared unpaired, and the report says why.
    let (_, other) = run(&spec(vec![scenario("field-test.toml")], 40, 6), "other");
    let g = gate(&base, &other, &GateOptions::default());
    match &g.pairing {
        Pairing::Unpaired { reason } => assert!(
            reason.contains("batch seed 6 ≠ the baseline's 5"),
            "{reason}"
        ),
        p => panic!("{p:?}"),
    }
    assert!(g.markdown().contains("UNPAIRED"));
    // A counts-only (old) baseline works unpaired and says why.
    let old = Baseline::from_summary(&batch::load_results(&base_dir).expect("r"), "old".into());
    match gate(&old, &same, &GateOptions::default()).pairing {
        Pairing::Unpaired { reason } => {
            assert!(reason.contains("no per-trial results"), "{reason}")
        }
        p => panic!("{p:?}"),
    }
}

/// The gate on a degraded build: the code changed, the scenario settings did not, so the
/// results carry the baseline's manifest.
fn gate_as_build(base: &Baseline, dir: &Path, o: &GateOptions) -> GateReport {
    let s = batch::load_results(dir).expect("results");
    let records = batch::read_records(&dir.join("trials.jsonl")).expect("records");
    let m = base.provenance.as_ref().map(|p| p.manifest.clone());
    batch::regress(base, &s, &records, m.as_ref(), o)
}

#[test]
fn a_slow_steering_actuator_fails_the_gate_with_junit_numbers() {
    let (_, base_dir) = run(
        &spec(vec![scenario("field-test.toml")], 60, 1),
        "steer-base",
    );
    let base = baseline_of(&base_dir);
    // Steering actuator 16× too slow: the truck cannot follow the curve.
    let mut slow = scenario("field-test.toml");
    slow.truck.max_steer_rate_radps = 0.05;
    let (_, worse) = run(&spec(vec![slow], 60, 1), "steer-worse");
    // As a changed scenario: the same seeds run the same trials, so still paired, failing,
    // and the change listed.
    let g = gate(&base, &worse, &GateOptions::default());
    assert!(
        matches!(g.pairing, Pairing::Paired { .. }),
        "{:?}",
        g.pairing
    );
    assert!(
        g.setting_differences
            .iter()
            .any(|d| d.contains("truck.max_steer_rate_radps: 0.8 → 0.05")),
        "{:?}",
        g.setting_differences
    );
    assert!(!g.passed);
    // As a degraded build (same settings): paired, and failing with the numbers.
    let g = gate_as_build(&base, &worse, &GateOptions::default());
    assert!(!g.passed, "{}", g.markdown());
    assert_eq!(g.rows[0].verdict, Verdict::Drop);
    let xml = junit::junit_xml("regress", &junit::regress_cases(&g, false, &[]), None);
    let r = &g.rows[0];
    let c = r.paired.expect("paired");
    assert_eq!(c.fixed, 0, "nothing gets better with a slower actuator");
    for part in [
        "failures=\"1\"".to_owned(),
        "<testcase name=\"field-test / bspline / pure_pursuit / replan\"".to_owned(),
        "significant drop in fork-entry success".to_owned(),
        format!("{} broke / 0 fixed of 60 pairs", c.broke),
        format!("adjusted p = {:.4} (Holm)", r.p_adjusted.expect("p")),
    ] {
        assert!(xml.contains(&part), "{part} missing from\n{xml}");
    }
}

#[test]
fn a_two_centimetre_tracker_offset_is_caught_and_pairing_needs_fewer_trials() {
    // 16 trials per case of bspline-table2 (288), each scenario's own mode, batch seed 1.
    let mut s = spec(vec![scenario("bspline-table2.toml")], 16, 1);
    s.replan = None;
    let (_, base_dir) = run(&s, "offset-base");
    let base = baseline_of(&base_dir);
    let mut bad = s.clone();
    bad.scenarios = vec![offset_scenario("bspline-table2.toml")];
    let (_, worse) = run(&bad, "offset-worse");
    let want = GateOptions {
        min_detectable_drop: Some(0.03),
        ..GateOptions::default()
    };
    let paired = gate_as_build(&base, &worse, &want);
    let r = &paired.rows[0];
    let c = r.paired.expect("paired");
    assert!(c.broke > 2 * c.fixed, "{}", paired.markdown());
    assert!(r.p_value.is_some_and(|p| p < 0.05), "{}", paired.markdown());
    // The same two batches as counts only: the trials a 3 pp drop needs, unpaired.
    let counts_only =
        Baseline::from_summary(&batch::load_results(&base_dir).expect("r"), "c".into());
    let unpaired = gate(&counts_only, &worse, &want);
    // Unpaired, no count of new trials is enough against a 288-trial baseline (none).
    let (np, nu) = (
        r.trials_needed.expect("paired n"),
        unpaired.rows[0].trials_needed,
    );
    assert!(
        nu.is_none_or(|nu| 3 * np < nu),
        "paired needs {np}, unpaired {nu:?}"
    );
    assert_eq!(unpaired.rows[0].verdict, Verdict::Underpowered);
    // Power is stated: the paired row sees a smaller drop.
    let (dp, du) = (
        r.detectable_drop.expect("d"),
        unpaired.rows[0].detectable_drop,
    );
    assert!(du.is_none_or(|du| dp < du), "{dp} vs {du:?}");
}

#[test]
fn holm_over_many_rows_new_and_missing_rows() {
    let scenarios = vec![scenario("field-test.toml"), scenario("rack-pick.toml")];
    let (_, base_dir) = run(&spec(scenarios.clone(), 10, 2), "rows-base");
    let mut base = baseline_of(&base_dir);
    let (_, now) = run(&spec(vec![scenarios[0].clone()], 10, 2), "rows-now");
    // rack-pick is missing from the results: it fails.
    let g = gate(&base, &now, &GateOptions::default());
    assert!(!g.passed);
    assert!(
        g.rows
            .iter()
            .any(|r| r.scenario == "rack-pick" && r.verdict == Verdict::Missing)
    );
    // A row the baseline lacks is new: listed, unchecked, failing only with --fail-on-new.
    base.rows.retain(|r| r.scenario == "rack-pick");
    base.trials.retain(|t| t.scenario == "rack-pick");
    let (_, both) = run(&spec(scenarios, 10, 2), "rows-both");
    let g = gate(&base, &both, &GateOptions::default());
    assert!(g.passed, "{}", g.markdown());
    assert!(
        g.rows
            .iter()
            .any(|r| r.scenario == "field-test" && r.verdict == Verdict::New)
    );
    assert!(g.markdown().contains("new, unchecked"));
    let strict = GateOptions {
        fail_on_new: true,
        ..GateOptions::default()
    };
    assert!(!gate(&base, &both, &strict).passed);
    // Holm over 20 rows: raw p 0.004 on one row is no alarm (0.004 × 20 > 0.05).
    let p: Vec<f64> = std::iter::once(0.004)
        .chain(std::iter::repeat_n(0.5, 19))
        .collect();
    assert!(Correction::Holm.adjust(&p)[0] > 0.05);
    assert!(Correction::None.adjust(&p)[0] < 0.05);
}

#[test]
fn min_detectable_drop_marks_small_rows_underpowered() {
    let (_, d) = run(&spec(vec![scenario("field-test.toml")], 10, 4), "power");
    let base = baseline_of(&d);
    let want = GateOptions {
        min_detectable_drop: Some(0.05),
        ..GateOptions::default()
    };
    let g = gate(&base, &d, &want);
    let r = &g.rows[0];
    assert_eq!(r.verdict, Verdict::Underpowered, "{}", g.markdown());
    assert!(
        r.trials_needed.is_some_and(|n| n > 10),
        "{:?}",
        r.trials_needed
    );
    // A wanted drop larger than the row's rate is no easier to see than the drop to zero,
    // and a row whose detectable drop is "none" is never called detectable.
    for drop in [1.0, r.baseline_rate.expect("rate")] {
        let g = gate(
            &base,
            &d,
            &GateOptions {
                min_detectable_drop: Some(drop),
                ..GateOptions::default()
            },
        );
        let r2 = &g.rows[0];
        if r2.detectable_drop.is_none() {
            assert_eq!(r2.verdict, Verdict::Underpowered, "{}", g.markdown());
        }
    }
    let at = |drop: f64| {
        let o = GateOptions {
            min_detectable_drop: Some(drop),
            ..GateOptions::default()
        };
        let g = gate(&base, &d, &o);
        (g.rows[0].verdict, g.rows[0].trials_needed)
    };
    assert_eq!(at(1.0), at(r.baseline_rate.expect("rate")));
    // The batch side: a 5 pp drop needs more than 10 trials on any gate.
    let need = batch::paired_trials_needed(0.05, 0.05, 1).expect("n");
    assert!(need > 10, "{need}");
}

#[test]
fn compare_pairs_two_planners_and_lists_discordant_trials() {
    let mut s = spec(vec![scenario("field-test.toml")], 30, 9);
    s.planners = vec!["bspline".into(), "spiral".into()];
    let (_, d) = run(&s, "ab");
    let records = batch::read_numbered(&d.join("trials.jsonl")).expect("records");
    let o = CompareOptions {
        alpha: 0.05,
        correction: Correction::Holm,
    };
    let r = batch::compare(&records, "bspline", "spiral", &o).expect("compares");
    assert_eq!(r.kind, "planner");
    assert_eq!(r.rows.len(), 1);
    let row = &r.rows[0];
    assert_eq!(row.pairs, 30, "shared seeds pair every trial");
    assert_eq!(r.discordant.len() as u64, row.a_only + row.b_only);
    for dis in &r.discordant {
        let (_, a) = records
            .iter()
            .find(|(l, _)| *l == dis.a_line)
            .expect("line A");
        let (_, b) = records
            .iter()
            .find(|(l, _)| *l == dis.b_line)
            .expect("line B");
        assert_eq!((a.outcome.seed, b.outcome.seed), (dis.seed, dis.seed));
        assert_ne!(a.outcome.success, b.outcome.success);
    }
    let e = batch::compare(&records, "bspline", "nope", &o).expect_err("unknown");
    assert!(e.to_string().contains("planners: bspline, spiral"), "{e}");
}

#[test]
fn corrupt_and_truncated_baselines_are_errors_naming_the_file() {
    let (_, d) = run(&spec(vec![scenario("field-test.toml")], 5, 8), "corrupt");
    let base = baseline_of(&d);
    let f = d.join("b.json");
    let text = base.to_text().expect("text");
    std::fs::write(&f, &text[..text.len() / 2]).expect("write");
    let e = Baseline::load(&f).expect_err("truncated");
    assert!(e.to_string().contains("b.json"), "{e}");
    // A trial removed by hand: the counts no longer add up.
    let mut cut = base.clone();
    cut.trials.pop();
    std::fs::write(&f, cut.to_text().expect("text")).expect("write");
    let e = Baseline::load(&f).expect_err("inconsistent");
    assert!(e.to_string().contains("edited or truncated"), "{e}");
    let e = Baseline::load(Path::new("/dev/zero")).expect_err("device");
    assert!(e.to_string().contains("not a regular file"), "{e}");
}
