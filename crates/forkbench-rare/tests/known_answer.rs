//! Known tail probabilities (1e-2 to 1e-5): the estimators' intervals cover them, the search finds the most likely failure, and a seed gives the same answer.

use std::convert::Infallible;

use forkbench_rare::normal::{sf, upper_quantile};
use forkbench_rare::{
    EstimateSettings, FalsifySettings, Method, Outcome, RareError, estimate, falsify,
};

/// The event "a·z ≥ t" for a unit vector a along the first `k` axes (a·z ~ N(0, 1)).
fn half_space(t: f64, k: usize) -> impl FnMut(&[Vec<f64>]) -> Result<Vec<Outcome>, Infallible> {
    move |pts| {
        Ok(pts
            .iter()
            .map(|z| {
                let s = z[..k].iter().sum::<f64>() / (k as f64).sqrt();
                Outcome {
                    event: s >= t,
                    robustness: t - s,
                }
            })
            .collect())
    }
}

/// Coverage and mean of 100 seeded repetitions.
fn repeat(method: Method, p: f64, dims: usize, k: usize, budget: usize) -> (usize, f64) {
    let t = upper_quantile(p);
    let mut covered = 0;
    let mut mean = 0.0;
    for seed in 0..100 {
        let s = EstimateSettings::new(method, dims, budget, seed);
        let e = estimate(&s, half_space(t, k)).expect("runs");
        assert_eq!(e.trials, budget);
        if e.ci.0 <= p && p <= e.ci.1 {
            covered += 1;
        }
        mean += e.p / 100.0;
    }
    (covered, mean)
}

#[test]
fn importance_sampling_covers_known_tails_from_1e2_to_1e5() {
    for (p, dims, k) in [
        (1e-2, 2, 1),
        (1e-3, 3, 2),
        (1e-4, 4, 4),
        (1e-5, 2, 1),
        (1e-5, 6, 3),
    ] {
        let (covered, mean) = repeat(Method::Ce, p, dims, k, 4000);
        eprintln!(
            "p {p:e}, {dims} dims: covered {covered} of 100, mean / p {:.3}",
            mean / p
        );
        assert!(
            covered >= 90,
            "p {p} in {dims} dims: covered {covered} of 100"
        );
        assert!(
            (mean / p - 1.0).abs() < 0.1,
            "p {p}: mean estimate {mean:.3e} (unbiased within 10 %)"
        );
    }
}

#[test]
fn monte_carlo_covers_and_is_no_match_for_a_rare_event() {
    let (covered, mean) = repeat(Method::Mc, 1e-2, 2, 1, 2000);
    assert!(covered >= 90, "covered {covered}");
    assert!((mean / 1e-2 - 1.0).abs() < 0.1, "{mean}");
    // At 1e-5, 4,000 plain draws see nothing; the interval says only "below 1e-3".
    let s = EstimateSettings::new(Method::Mc, 2, 4000, 3);
    let e = estimate(&s, half_space(upper_quantile(1e-5), 1)).expect("runs");
    assert_eq!((e.p, e.events), (0.0, 0));
    assert!(e.ci.1 > 5e-4 && e.ci.1 < 1e-3, "{:?}", e.ci);
}

/// An event never drawn: the estimate is 0, and the interval stays open above, bounded by
/// what no event in the final stage's draws can rule out (each weight at most
/// 1 / defensive), so it still covers a truth too small to draw.
#[test]
fn importance_sampling_without_an_event_bounds_it_from_above() {
    let s = EstimateSettings::new(Method::Ce, 3, 1000, 5);
    // P = 1e-12: far beyond what 1,000 draws reach, however they adapt.
    let e = estimate(&s, half_space(upper_quantile(1e-12), 3)).expect("runs");
    assert_eq!((e.p, e.events), (0.0, 0));
    let n = (e.trials - e.adapting) as u64;
    let q_upper = forkbench_rare::clopper_pearson(0, n, 0.95).1;
    assert_eq!(e.ci.0, 0.0);
    assert!(
        (e.ci.1 - q_upper / s.ce.defensive).abs() < 1e-12,
        "upper {} against {}",
        e.ci.1,
        q_upper / s.ce.defensive
    );
    assert!(e.ci.1 > 1e-12 && e.ci.1 < 0.1, "upper {}", e.ci.1);
}

#[test]
fn importance_sampling_reports_its_spread_and_stages() {
    let s = EstimateSettings::new(Method::Ce, 4, 4000, 7);
    let e = estimate(&s, half_space(upper_quantile(1e-4), 4)).expect("runs");
    let re = e.relative_error.expect("events sampled");
    assert!(re > 0.0 && re < 0.2, "relative error {re}");
    assert!(e.ess > 50.0 && e.ess <= 2000.0, "ess {}", e.ess);
    assert!(!e.stages.is_empty() && e.stages.last().expect("a stage").level == 0.0);
    assert_eq!(e.not_rare(), None);
    // At P = 5 % the nominal first stage draws the event often: not rare, and said so.
    let common = estimate(&s, half_space(upper_quantile(0.05), 4)).expect("runs");
    let share = common.not_rare().expect("not rare");
    assert!((0.02..0.09).contains(&share), "{share}");
    // The same seed, the same numbers; another seed, others.
    let again = estimate(&s, half_space(upper_quantile(1e-4), 4)).expect("runs");
    assert_eq!(e, again);
    let other = EstimateSettings::new(Method::Ce, 4, 4000, 8);
    assert_ne!(
        estimate(&other, half_space(upper_quantile(1e-4), 4))
            .expect("runs")
            .p,
        e.p
    );
}

#[test]
fn the_search_finds_the_most_likely_failure_where_monte_carlo_finds_none() {
    let t = 4.0; // P = 3.2e-5
    let s = FalsifySettings::new(3, 1000, 5);
    let f = falsify(&s, half_space(t, 1)).expect("runs");
    let best = f.most_likely.expect("a failure found");
    assert!(best.outcome.event);
    // The most likely point of {z0 ≥ 4} is (4, 0, 0).
    assert!((best.z[0] - t).abs() < 0.1, "{:?}", best.z);
    assert!(
        best.z[1].abs() < 0.6 && best.z[2].abs() < 0.6,
        "{:?}",
        best.z
    );
    assert_eq!(f.trials, 1000);
    let mc = falsify(
        &FalsifySettings {
            monte_carlo: true,
            ..s
        },
        half_space(t, 1),
    )
    .expect("runs");
    assert!(mc.most_likely.is_none() && mc.events == 0, "{mc:?}");
    assert_eq!(mc.trials, 1000);
    assert!(mc.least_robust.expect("points").outcome.robustness > 0.0);
    assert!(sf(t) < 1e-4);
}

#[test]
fn bad_settings_and_a_short_answer_are_named() {
    let mut s = EstimateSettings::new(Method::Ce, 2, 10, 1);
    let e = estimate(&s, half_space(2.0, 1)).expect_err("budget 10");
    assert!(e.to_string().contains("budget"), "{e}");
    s.budget = 1000;
    s.confidence = 1.5;
    let e = estimate(&s, half_space(2.0, 1)).expect_err("confidence");
    assert!(e.to_string().contains("confidence"), "{e}");
    let short = |pts: &[Vec<f64>]| -> Result<Vec<Outcome>, Infallible> {
        Ok(vec![
            Outcome {
                event: false,
                robustness: 1.0
            };
            pts.len() / 2
        ])
    };
    let e = estimate(&EstimateSettings::new(Method::Mc, 2, 100, 1), short).expect_err("short");
    assert!(
        matches!(
            e,
            RareError::Answer {
                asked: 100,
                got: 50
            }
        ),
        "{e}"
    );
}

/// A budget too small for the event leaves few effective samples: the estimate says so;
/// one large enough does not.
#[test]
fn a_starved_estimate_says_its_interval_may_not_cover() {
    let mc = estimate(
        &EstimateSettings::new(Method::Mc, 2, 2000, 1),
        half_space(upper_quantile(2e-3), 1),
    )
    .expect("runs");
    assert!(
        mc.events > 0 && mc.ess < forkbench_rare::MIN_ESS,
        "{} events",
        mc.events
    );
    let why = mc.thin().expect("a warning");
    assert!(
        why.contains("effective sample size") && why.contains("--budget"),
        "{why}"
    );
    let plenty = estimate(
        &EstimateSettings::new(Method::Mc, 2, 4000, 1),
        half_space(upper_quantile(5e-2), 1),
    )
    .expect("runs");
    assert!(
        plenty.ess >= forkbench_rare::MIN_ESS && plenty.thin().is_none(),
        "{}",
        plenty.ess
    );
}
