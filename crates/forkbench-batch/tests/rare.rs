//! Rare events on the physics: the field test with uncertain steering and placement (`examples/rare/field-test-tails.toml`), whose failure probability plain Monte Carlo measured once.

use forkbench_batch::rare::{Event, RareSetup, estimate, falsify};
use forkbench_trial::Scenario;

/// P(failure) of the example by plain Monte Carlo, from the reference committed beside it
/// (its events over its trials, and how they were made).
fn brute_force_p() -> f64 {
    let (_, text) = example("field-test-tails.reference.toml");
    let r: toml::Table = toml::from_str(&text).expect("the reference parses");
    let count = |k: &str| r[k].as_integer().expect("a count") as f64;
    let p = count("events") / count("trials");
    assert!(
        (p / r["p"].as_float().expect("p") - 1.0).abs() < 1e-3,
        "{p}"
    );
    p
}

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
#[ignore = "a long statistical check (6,000 trials): CI runs it, `-- --ignored`"]
fn importance_sampling_covers_the_brute_force_value_with_a_tenth_of_its_trials() {
    let (e, tried) = estimate(&setup(3), forkbench_rare::Method::Ce, 6000, None).expect("runs");
    assert_eq!(tried.len(), 6000);
    let p = brute_force_p();
    assert!(
        e.ci.0 <= p && p <= e.ci.1,
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
#[ignore = "a long statistical check (5 × 4,000 trials): CI runs it, `-- --ignored`"]
fn subset_simulation_covers_the_brute_force_value_in_four_of_five_seeds() {
    let p = brute_force_p();
    let subset = forkbench_rare::SubsetSettings {
        level_fraction: 0.3,
        per_level: None,
    };
    let method = (forkbench_rare::Method::Subset, subset);
    let mut seen = Vec::new();
    for seed in 1..=5 {
        let (e, tried) =
            forkbench_batch::rare::estimate_with(&setup(seed), method, 4000, None).expect("runs");
        assert!(tried.len() <= 4000 && e.trials == tried.len());
        seen.push((e.ci.0 <= p && p <= e.ci.1, e.p, e.ci));
    }
    let covered = seen.iter().filter(|s| s.0).count();
    assert!(covered >= 4, "{covered} of 5 cover {p:.3e}: {seen:?}");
}

#[test]
fn the_search_finds_a_failure_where_monte_carlo_with_its_budget_finds_none() {
    let (f, _) = falsify(&setup(1), 200, false, None).expect("runs");
    let m = f.most_likely.expect("a failure");
    assert!(m.outcome.event && m.outcome.robustness <= 0.0);
    let (mc, tried) = falsify(&setup(1), 200, true, None).expect("runs");
    assert_eq!((mc.events, tried.len()), (0, 200));
    assert!(mc.most_likely.is_none());
}

fn example(name: &str) -> (std::path::PathBuf, String) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/rare")
        .join(name);
    let text = std::fs::read_to_string(&path).expect("reads");
    (path, text)
}

/// A file's settings: its lines without comments and blanks.
fn settings(text: &str) -> Vec<&str> {
    text.lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with('#'))
        .collect()
}

/// The people-contact examples are the people cycle (`scenarios/warehouse-people.toml`)
/// with uncertain movers, and differ from each other only in the protective fields'
/// length; a contact estimate's trials carry the closest approach as their margin.
#[test]
fn the_people_contact_examples_are_the_people_cycle_with_uncertain_movers() {
    let base = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../scenarios/warehouse-people.toml"),
    )
    .expect("reads");
    let (path, sized) = example("people-contact.toml");
    let (short_path, short) = example("people-contact-short.toml");
    let differs = |a: &str, b: &str| -> Vec<String> {
        let (a, b) = (settings(a), settings(b));
        let ours = |l: &&str| {
            !l.starts_with("name =") && !l.starts_with("description =") && !l.starts_with("world =")
        };
        let (a, b): (Vec<_>, Vec<_>) = (
            a.into_iter().filter(ours).collect(),
            b.into_iter().filter(ours).collect(),
        );
        let head = b
            .iter()
            .position(|l| *l == "[[uncertain]]")
            .unwrap_or(b.len());
        let mut out: Vec<String> = b[..head]
            .iter()
            .filter(|l| !a.contains(l))
            .map(|l| l.to_string())
            .collect();
        out.extend(
            a.iter()
                .filter(|l| !b[..head].contains(l))
                .map(|l| format!("-{l}")),
        );
        out
    };
    assert_eq!(differs(&base, &sized), Vec::<String>::new());
    assert_eq!(
        differs(&base, &short),
        vec!["field_length_scale = 0.7".to_owned()]
    );
    assert_eq!(
        settings(&sized)
            .iter()
            .filter(|l| l.starts_with("name = \"mover."))
            .count(),
        9
    );
    let tail = |t: &str| t[t.find("[[uncertain]]").expect("declared")..].to_owned();
    assert_eq!(tail(&sized), tail(&short));
    let scenario = Scenario::load(&short_path).expect("loads");
    assert!(Scenario::load(&path).is_ok());
    let setup = RareSetup {
        scenario,
        case: "default".into(),
        planner: None,
        tracker: None,
        overrides: Default::default(),
        seed: 1,
        event: Event::Contact,
        jobs: 2,
    };
    let (e, tried) = estimate(&setup, forkbench_rare::Method::Mc, 20, None).expect("runs");
    assert_eq!((e.trials, tried.len()), (20, 20));
    for t in &tried {
        let safety = t.record.outcome.safety.as_ref().expect("monitored");
        let closest = safety.closest_any_m().expect("measured");
        assert!(closest.is_finite() && closest < 5.0, "{closest}");
        assert_eq!(safety.person_contacts > 0, closest <= 0.0, "{closest}");
        assert_eq!(t.record.outcome.uncertain.len(), 9);
    }
}
