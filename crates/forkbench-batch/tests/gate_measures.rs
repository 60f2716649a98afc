//! The gate on measures: a tracker 3 cm off fails at 40 paired trials although its picks
//! still succeed (its forks pass closer to the blocks), a copy of the built-in that differs by a millimetre passes, A/A
//! comparisons of the same tracker fail at most α of the time, and an old baseline without
//! measures is gated on counts with its reason said.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use forkbench_batch::{self as batch, Baseline, BatchSpec, GateOptions, Verdict, junit};
use forkbench_core::{ForkliftSpec, Path as TrackPath};
use forkbench_track::{Command, PurePursuit, Tracker, TrackerInput};
use forkbench_trial::{Registry, Scenario};

fn scenario_file(name: &str) -> PathBuf {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenarios")).join(name)
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("forkbench-gatem-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// Pure pursuit that believes the truck `.1` metres further left than it is (also the
/// gate tests' degraded build).
pub(crate) struct Shifted(pub(crate) PurePursuit, pub(crate) f64);

impl Tracker for Shifted {
    fn name(&self) -> &str {
        Tracker::name(&self.0)
    }
    fn reset(&mut self, path: &TrackPath, truck: &ForkliftSpec) {
        Tracker::reset(&mut self.0, path, truck);
    }
    fn command(&mut self, input: &TrackerInput) -> Command {
        let mut i = *input;
        let h = i.pose.heading_rad;
        i.pose.x_m -= self.1 * h.sin();
        i.pose.y_m += self.1 * h.cos();
        Tracker::command(&mut self.0, &i)
    }
}

/// The shipped field test and rack pick, their pure pursuit shifted by `shift_m`.
fn scenarios(shift_m: f64) -> Vec<Scenario> {
    let registry = Registry::builtin().with_tracker("pure_pursuit", move |s, _| {
        Ok(Box::new(Shifted(PurePursuit::from_settings(s)?, shift_m)))
    });
    let registry = Arc::new(registry);
    ["field-test.toml", "rack-pick.toml"]
        .iter()
        .map(|f| Scenario::load_with(&scenario_file(f), registry.clone()).expect("loads"))
        .collect()
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
        replan: None,
        compare_replanning: false,
        force_new: false,
        success_run: Default::default(),
        profile: false,
    }
}

/// The batch's summary, records and manifest.
fn run(s: &BatchSpec, name: &str) -> (batch::Summary, Vec<batch::TrialRecord>, batch::Manifest) {
    let d = tmp(name);
    batch::run_batch(s, &d, 2, &|_| {}).expect("runs");
    let (summary, records, manifest) = batch::load_batch(&d).expect("loads");
    let _ = std::fs::remove_dir_all(&d);
    (summary, records, manifest)
}

#[test]
fn a_tracker_3_cm_off_fails_on_how_it_enters_and_a_millimetre_passes() {
    let (s, r, _) = run(&spec(scenarios(0.0), 40, 21), "base");
    let base = Baseline::from_results(&s, &r, "built-in".into());
    assert!(base.measured);
    // The baseline's file keeps the measures, and reads back the same.
    let f = tmp("file").with_extension("json");
    base.write(&f).expect("writes");
    assert_eq!(Baseline::load(&f).expect("loads"), base);
    let _ = std::fs::remove_file(&f);

    let (s3, r3, m3) = run(&spec(scenarios(0.03), 40, 21), "shift3");
    let g = batch::regress(&base, &s3, &r3, Some(&m3), &GateOptions::default());
    eprintln!("{}", g.markdown());
    assert!(!g.passed, "{}", g.markdown());
    // The rack pick enters 8 mm off the centre line: a fork's gap to the block beside it
    // shrinks by most of the shift, and the entry error grows by more than its margin.
    let rack = g
        .rows
        .iter()
        .find(|r| r.scenario == "rack-pick")
        .expect("row");
    assert_eq!(rack.verdict, Verdict::Worse, "{}", g.markdown());
    assert!(
        rack.worse_measures().contains(&"fork_tip_clearance_mm"),
        "{}",
        g.markdown()
    );
    let lat = rack
        .measures
        .iter()
        .find(|m| m.measure == "entry_lateral_error_m");
    let lat = lat.expect("measured");
    assert!(lat.paired && lat.n >= 30, "{}", lat.numbers());
    assert!(
        lat.shift.expect("a shift").estimate > lat.margin,
        "{}",
        lat.numbers()
    );
    // A gate file's margin acts: at 0.1 m the same shift is within it.
    let mut loose = GateOptions::default();
    loose.measures.measure.insert(
        "entry_lateral_error_m".into(),
        batch::MeasureSetting {
            margin: Some(0.1),
            ..Default::default()
        },
    );
    let gl = batch::regress(&base, &s3, &r3, Some(&m3), &loose);
    let rack = gl
        .rows
        .iter()
        .find(|r| r.scenario == "rack-pick")
        .expect("row");
    let lat = rack
        .measures
        .iter()
        .find(|m| m.measure == "entry_lateral_error_m");
    let lat = lat.expect("measured");
    assert!(
        lat.p_value.is_some_and(|p| p > 0.5) && lat.margin == 0.1,
        "{}",
        lat.numbers()
    );
    assert_eq!(lat.margin_source, "the gate file");
    // JUnit names the measure, on the failing case.
    let cases = junit::regress_cases(&g, false, &[]);
    let rack = cases
        .iter()
        .find(|c| c.name.starts_with("rack-pick"))
        .expect("a case");
    assert!(rack.failure.is_some());
    assert!(
        rack.numbers.contains("entry_lateral_error_m: worse by +"),
        "{}",
        rack.numbers
    );

    let (s1, r1, m1) = run(&spec(scenarios(0.001), 40, 21), "shift1");
    let g = batch::regress(&base, &s1, &r1, Some(&m1), &GateOptions::default());
    assert!(g.passed, "{}", g.markdown());
    assert!(
        g.rows.iter().all(|r| r.measures.len() >= 5),
        "{}",
        g.markdown()
    );
    // Its power is stated: each measure's detectable worsening is at least its margin.
    for m in g.rows.iter().flat_map(|r| &r.measures) {
        assert!(
            m.detectable.is_some_and(|d| d >= m.margin),
            "{}",
            m.numbers()
        );
    }
}

/// A small deterministic generator for drawing subsets.
fn next(state: &mut u64) -> u64 {
    *state = state
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    *state >> 33
}

#[test]
fn a_a_comparisons_of_one_tracker_fail_at_most_alpha_of_the_time() {
    // One pool of 240 trials per scenario; each comparison draws two disjoint sets of 40
    // per scenario: two batches of the same tracker under different seeds, unpaired.
    let (_, pool, _) = run(&spec(scenarios(0.0), 240, 33), "pool");
    let mut failed = 0;
    let mut state = 7u64;
    for _ in 0..200 {
        let (mut a, mut b) = (Vec::new(), Vec::new());
        for name in ["field-test", "rack-pick"] {
            let mut mine: Vec<&batch::TrialRecord> =
                pool.iter().filter(|r| r.outcome.scenario == name).collect();
            for i in (1..mine.len()).rev() {
                let j = (next(&mut state) % (i as u64 + 1)) as usize;
                mine.swap(i, j);
            }
            a.extend(mine[..40].iter().map(|r| (*r).clone()));
            b.extend(mine[40..80].iter().map(|r| (*r).clone()));
        }
        let base = Baseline::from_results(&batch::summarize(&a), &a, "a".into());
        let g = batch::regress(
            &base,
            &batch::summarize(&b),
            &b,
            None,
            &GateOptions::default(),
        );
        assert!(g.rows.iter().all(|r| !r.measures.is_empty()));
        failed += usize::from(!g.passed);
    }
    eprintln!("{failed} of 200 A/A comparisons failed");
    assert!(failed <= 10, "{failed} of 200 A/A comparisons failed");
}

#[test]
fn an_old_baseline_without_measures_is_gated_on_counts_with_a_warning() {
    let (s, r, m) = run(&spec(scenarios(0.0), 6, 5), "old");
    let mut old = Baseline::from_results(&s, &r, "old".into());
    old.measured = false;
    for t in &mut old.trials {
        t.measures.clear();
    }
    let g = batch::regress(&old, &s, &r, Some(&m), &GateOptions::default());
    assert!(g.passed);
    assert!(g.rows.iter().all(|r| r.measures.is_empty()));
    let note = g.measures_note.as_deref().expect("a note");
    assert!(note.contains("forkbench baseline"), "{note}");
    assert!(g.markdown().contains("none compared"), "{}", g.markdown());
}

#[test]
fn a_gate_file_sets_margins_and_refuses_what_it_cannot_gate() {
    let dir = tmp("gatefile");
    std::fs::create_dir_all(&dir).expect("dir");
    let f = dir.join("gate.toml");
    std::fs::write(&f, "[measure.entry_lateral_error_m]\nmargin = 0.05\n").expect("w");
    let s = batch::MeasureSettings::load(&f).expect("loads");
    assert_eq!(s.measure["entry_lateral_error_m"].margin, Some(0.05));
    for (text, says) in [
        (
            "[measure.entry_lateral_error_m]\nmargin = -1.0\n",
            "margin = -1",
        ),
        (
            "[measure.my_force_n]\nmargin = 3.0\n",
            "say which way it gets worse",
        ),
        (
            "[measure.my_force_n]\nworse = \"higher\"\n",
            "margin: missing",
        ),
        ("[measure.x]\nmargin = 1.0\nbogus = 2\n", "bogus"),
    ] {
        std::fs::write(&f, text).expect("w");
        let err = batch::MeasureSettings::load(&f)
            .expect_err(text)
            .to_string();
        assert!(
            err.contains(says) && err.contains("gate.toml"),
            "{text}: {err}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn trials_auto_stops_at_the_look_that_decides_and_keeps_alpha_over_the_looks() {
    use forkbench_batch::sequential::{self, Decision, SequentialPlan};
    let (s, r, _) = run(&spec(scenarios(0.0), 40, 21), "seq-base");
    let base = Baseline::from_results(&s, &r, "built-in".into());
    assert_eq!(sequential::baseline_cap(&base), 40);
    let looks = sequential::plan_looks(sequential::FIRST_LOOK, 40);
    assert_eq!(looks, vec![10, 20, 40]);
    let run_auto = |shift_m: f64, name: &str| {
        let dir = tmp(name);
        let gate = |o: &GateOptions| {
            let (s, r, m) = batch::load_batch(&dir)?;
            Ok(batch::regress(&base, &s, &r, Some(&m), o))
        };
        let plan = SequentialPlan {
            looks: looks.clone(),
            options: GateOptions::default(),
            want_drop: sequential::DEFAULT_DECIDE_DROP,
            gate: &gate,
        };
        let mut first = spec(scenarios(shift_m), 40, 21);
        first.trials = looks[0];
        let out = sequential::run_sequential(&first, &dir, 2, &plan, &|_| {}).expect("runs");
        let kept = batch::load_batch(&dir).expect("loads").1.len();
        let _ = std::fs::remove_dir_all(&dir);
        (out, kept)
    };
    // 3 cm off: a look fails it, and no more trials are run than that look's.
    let (bad, kept) = run_auto(0.03, "seq-bad");
    let last = bad.looks.last().expect("a look");
    assert_eq!(last.decision, Decision::Regression, "{:?}", bad.looks);
    assert_eq!(kept as u64, 2 * last.trials);
    assert!(!bad.report.passed);
    // Every look ran at α over the three planned looks.
    assert!(
        bad.looks
            .iter()
            .all(|l| (l.alpha - 0.05 / 3.0).abs() < 1e-12)
    );
    assert_eq!(bad.report.alpha, bad.looks[0].alpha);
    // Unchanged: no look fails; at the cap it is undecided or passed, never a regression.
    let (same, kept) = run_auto(0.0, "seq-same");
    assert!(
        same.looks
            .iter()
            .all(|l| l.decision != Decision::Regression),
        "{:?}",
        same.looks
    );
    assert!(same.report.passed);
    assert_eq!(kept as u64, 2 * same.looks.last().expect("a look").trials);
}
