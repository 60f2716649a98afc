//! Rare events on the physics: the field test with uncertain steering and placement (`examples/rare/field-test-tails.toml`), whose failure probability plain Monte Carlo measured once.

use forkbench_batch::rare::{Event, RareSetup, estimate, falsify};
use forkbench_trial::Scenario;

/// P(failure) of the example by plain Monte Carlo: 67 failures in 60,000 trials
/// (`forkbench estimate examples/rare/field-test-tails.toml --method mc --budget 60000
/// --seed 7`), its exact 95 % interval 8.7e-4 to 1.4e-3.
const BRUTE_FORCE_P: f64 = 67.0 / 60_000.0;

fn setup(seed: u64) -> RareSetup {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/rare/field-test-tails.toml");
    RareSetup {
        scenario: Scenario::load(&path).expect("loads"),
        case: "default".into(),
        planner: None,
        tracker: None,
        overrides: Default::default(),
        seed,
        event: Event::Failure,
        jobs: 2,
    }
}

#[test]
fn importance_sampling_covers_the_brute_force_value_with_a_tenth_of_its_trials() {
    let (e, tried) = estimate(&setup(3), forkbench_rare::Method::Ce, 6000).expect("runs");
    assert_eq!(tried.len(), 6000);
    assert!(
        e.ci.0 <= BRUTE_FORCE_P && BRUTE_FORCE_P <= e.ci.1,
        "{:.3e} ({:.3e} to {:.3e})",
        e.p,
        e.ci.0,
        e.ci.1
    );
    // Every trial's record carries the values its point stands for.
    let t = &tried[10];
    assert_eq!(t.record.outcome.uncertain.len(), 4);
}

#[test]
fn the_search_finds_a_failure_where_monte_carlo_with_its_budget_finds_none() {
    let (f, _) = falsify(&setup(1), 200, false).expect("runs");
    let m = f.most_likely.expect("a failure");
    assert!(m.outcome.event && m.outcome.robustness <= 0.0);
    let (mc, tried) = falsify(&setup(1), 200, true).expect("runs");
    assert_eq!((mc.events, tried.len()), (0, 200));
    assert!(mc.most_likely.is_none());
}
