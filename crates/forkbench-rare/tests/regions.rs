//! Known answers with several failure regions: subset simulation's intervals cover the exact union probability where one cross-entropy Gaussian undercovers, with ten times fewer trials than plain Monte Carlo, and a plateau of the robustness is reported, not passed off as an estimate.

use std::convert::Infallible;

use forkbench_rare::normal::upper_quantile;
use forkbench_rare::{EstimateSettings, Halt, Method, Outcome, RareError, estimate};

/// The event "sᵢ·z[dᵢ] ≥ tᵢ for some region i": independent axes, so
/// P = 1 − Π(1 − qᵢ) exactly. The robustness is the least margin over the regions.
struct Regions(Vec<(usize, f64, f64)>);

impl Regions {
    fn new(spec: &[(usize, f64, f64)]) -> Self {
        Regions(
            spec.iter()
                .map(|&(d, s, q)| (d, s, upper_quantile(q)))
                .collect(),
        )
    }

    fn exact(spec: &[(usize, f64, f64)]) -> f64 {
        1.0 - spec.iter().map(|r| 1.0 - r.2).product::<f64>()
    }

    fn eval(&self) -> impl FnMut(&[Vec<f64>]) -> Result<Vec<Outcome>, Infallible> + '_ {
        move |pts| {
            Ok(pts
                .iter()
                .map(|z| {
                    let r = self
                        .0
                        .iter()
                        .map(|&(d, s, t)| t - s * z[d])
                        .fold(f64::INFINITY, f64::min);
                    Outcome {
                        event: r <= 0.0,
                        robustness: r,
                    }
                })
                .collect())
        }
    }
}

/// Over 100 seeds: intervals covering the exact value, and the trials plain Monte Carlo
/// would need for the spread seen ((1 − p) / (p r²), r the RMS relative error) over
/// the trials spent.
fn over_seeds(method: Method, spec: &[(usize, f64, f64)], dims: usize) -> (usize, f64) {
    let (f, p) = (Regions::new(spec), Regions::exact(spec));
    let (mut covered, mut sq, mut trials) = (0, 0.0, 0.0);
    for seed in 0..100 {
        let e = estimate(&EstimateSettings::new(method, dims, 4000, seed), f.eval()).expect("runs");
        assert!(e.trials <= 4000, "{} trials over the budget", e.trials);
        covered += usize::from(e.ci.0 <= p && p <= e.ci.1);
        sq += (e.p / p - 1.0).powi(2);
        trials += e.trials as f64;
    }
    let r2 = sq / 100.0;
    (covered, (1.0 - p) / (p * r2) / (trials / 100.0))
}

const TWO: [(usize, f64, f64); 2] = [(0, 1.0, 1e-4), (1, 1.0, 3e-5)];
const THREE: [(usize, f64, f64); 3] = [(0, 1.0, 5e-5), (1, 1.0, 3e-5), (2, -1.0, 2e-5)];

#[test]
fn subset_simulation_covers_two_and_three_regions_at_ten_times_fewer_trials() {
    for (spec, dims) in [
        (&TWO[..], 2),
        (&TWO[..], 8),
        (&THREE[..], 4),
        (&THREE[..], 8),
    ] {
        let (covered, gain) = over_seeds(Method::Subset, spec, dims);
        assert!(
            covered >= 90,
            "{spec:?} in {dims} dims: covered {covered} of 100"
        );
        assert!(
            gain >= 10.0,
            "{spec:?} in {dims} dims: {gain:.1}x plain Monte Carlo"
        );
    }
}

#[test]
fn one_cross_entropy_gaussian_undercovers_two_unequal_regions() {
    // The reason subset simulation is offered: CE follows the likelier region.
    let (covered, _) = over_seeds(Method::Ce, &TWO, 4);
    assert!(covered < 90, "cross-entropy covered {covered} of 100");
}

#[test]
fn a_seed_gives_the_same_levels_and_another_seed_other_ones() {
    let f = Regions::new(&THREE);
    let run = |seed| {
        estimate(
            &EstimateSettings::new(Method::Subset, 4, 4000, seed),
            f.eval(),
        )
    };
    let [a, b, c] = [7, 7, 8].map(|seed| run(seed).expect("runs"));
    assert_eq!(a, b);
    assert_ne!(a.p, c.p);
    assert!(a.levels.len() >= 3, "{} levels", a.levels.len());
    assert!(
        a.levels
            .windows(2)
            .all(|w| w[1].conditioned_below < w[0].conditioned_below)
    );
    assert!(
        a.levels[1..]
            .iter()
            .all(|l| (0.2..0.7).contains(&l.acceptance))
    );
    assert!(a.thin().is_none(), "{:?}", a.thin());
}

#[test]
fn the_trials_and_events_reported_are_those_evaluated() {
    let f = Regions::new(&THREE);
    let (mut points, mut events) = (0, 0);
    let mut inner = f.eval();
    let counted = |pts: &[Vec<f64>]| {
        let out = inner(pts)?;
        points += out.len();
        events += out.iter().filter(|o| o.event).count();
        Ok::<_, Infallible>(out)
    };
    let e = estimate(&EstimateSettings::new(Method::Subset, 4, 4000, 7), counted).expect("runs");
    assert_eq!((e.trials, e.events), (points, events));
}

#[test]
fn a_plateau_of_the_robustness_halts_the_levels_and_says_so() {
    // The margin holds at 1.5 short of the event, as a protective stop holds the truck.
    let t = upper_quantile(1e-5);
    let held = |pts: &[Vec<f64>]| -> Result<Vec<Outcome>, Infallible> {
        Ok(pts
            .iter()
            .map(|z| {
                let r = t - z[0];
                Outcome {
                    event: r <= 0.0,
                    robustness: if r > 0.0 { r.max(1.5) } else { r },
                }
            })
            .collect())
    };
    let e = estimate(&EstimateSettings::new(Method::Subset, 3, 4000, 1), held).expect("runs");
    assert_eq!(e.halt, Some(Halt::Plateau(1.5)));
    let why = e.thin().expect("a plateau warns");
    assert!(why.contains("plateau at 1.500"), "{why}");
    assert!(
        e.ci.1 >= 1e-5,
        "the bound {:.2e} is below the truth",
        e.ci.1
    );
}

#[test]
fn a_budget_short_of_the_event_bounds_it_and_warns() {
    let f = Regions::new(&[(0, 1.0, 1e-9)]);
    let e = estimate(&EstimateSettings::new(Method::Subset, 2, 400, 3), f.eval()).expect("runs");
    assert_eq!(e.halt, Some(Halt::Budget));
    assert!(e.trials <= 400);
    assert!(e.thin().is_some());
    assert!(e.ci.1 >= 1e-9 && e.ci.1 < 1e-2, "{:?}", e.ci);
}

#[test]
fn an_imprecise_subset_estimate_warns_of_its_relative_error() {
    // 40 points a level over three regions: a relative error well over 50 %.
    let f = Regions::new(&THREE);
    let mut s = EstimateSettings::new(Method::Subset, 4, 4000, 2);
    s.subset.per_level = Some(40);
    let e = estimate(&s, f.eval()).expect("runs");
    let re = e.relative_error.expect("events");
    assert!(re > 0.5, "relative error {re}");
    let why = e.thin().expect("warns");
    assert!(why.contains("relative error"), "{why}");
}

#[test]
fn subset_settings_out_of_range_are_named() {
    let f = Regions::new(&TWO);
    let mut s = EstimateSettings::new(Method::Subset, 2, 1000, 0);
    s.subset.level_fraction = 0.9;
    let e = estimate(&s, f.eval()).expect_err("p0 0.9");
    assert!(
        matches!(
            e,
            RareError::Setting {
                field: "subset.level_fraction",
                ..
            }
        ),
        "{e}"
    );
    s.subset.level_fraction = 0.1;
    s.subset.per_level = Some(2000);
    let e = estimate(&s, f.eval()).expect_err("N over the budget");
    assert!(e.to_string().contains("subset.per_level"), "{e}");
}
