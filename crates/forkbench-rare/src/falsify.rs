//! The most likely failure: a cross-entropy search toward the event, then the failing point of highest nominal density, pulled toward the nominal point along its ray.

use serde::Serialize;

use crate::ce::{CeSettings, Evaluated, Proposal, Stage, adapt, fit};
use crate::normal::ln_pdf;
use crate::{Outcome, RareError, run};

/// How to search.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FalsifySettings {
    pub dims: usize,
    /// Points (trials) in all, the refinement included.
    pub budget: usize,
    pub seed: u64,
    /// Plain Monte Carlo over the nominal density instead of the search (to compare).
    pub monte_carlo: bool,
    /// Bisection steps along the most likely failure's ray toward the nominal point.
    pub refine_steps: usize,
    pub ce: CeSettings,
}

impl FalsifySettings {
    pub fn new(dims: usize, budget: usize, seed: u64) -> Self {
        FalsifySettings {
            dims,
            budget,
            seed,
            monte_carlo: false,
            refine_steps: 8,
            // Short stages: a search spends its budget moving, not estimating.
            ce: CeSettings {
                per_stage: (budget / 10).clamp(20, 1000),
                ..CeSettings::default()
            },
        }
    }
}

/// A point with what it gave and its nominal log-density.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Found {
    pub z: Vec<f64>,
    pub outcome: Outcome,
    /// ln N(z; 0, I): higher is more likely.
    pub ln_density: f64,
}

impl Found {
    fn new(z: Vec<f64>, outcome: Outcome) -> Self {
        let ln_density = z.iter().map(|&x| ln_pdf(x)).sum();
        Found {
            z,
            outcome,
            ln_density,
        }
    }
}

/// What the search found.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Falsified {
    /// The failing point of highest nominal density (None: no failure found).
    pub most_likely: Option<Found>,
    /// The point of least robustness evaluated.
    pub least_robust: Option<Found>,
    pub trials: usize,
    /// Points on which the event happened.
    pub events: usize,
    pub stages: Vec<Stage>,
}

/// Searches N(0, I) in `s.dims` dimensions for the event within `s.budget` points.
pub fn falsify<E: std::error::Error + 'static>(
    s: &FalsifySettings,
    mut eval: impl FnMut(&[Vec<f64>]) -> Result<Vec<Outcome>, E>,
) -> Result<Falsified, RareError<E>> {
    s.ce.check()?;
    if !(1..=64).contains(&s.dims) || !(20..=10_000_000).contains(&s.budget) {
        return Err(RareError::Setting {
            field: "budget",
            reason: "1–64 parameters and 20–10,000,000 trials".into(),
        });
    }
    // Plain Monte Carlo has no failure to refine: it draws the whole budget.
    let search = if s.monte_carlo {
        s.budget
    } else {
        s.budget.saturating_sub(s.refine_steps)
    };
    let (stages, mut seen) = if s.monte_carlo {
        let points = Proposal::nominal(s.dims).draw(search, s.seed, 0xF1A1);
        let out = run(&mut eval, &points)?;
        (Vec::new(), points.into_iter().zip(out).collect::<Vec<_>>())
    } else {
        let (q, stages, mut seen) = adapt(s.dims, &s.ce, s.seed, search, &mut eval)?;
        toward_likely(q, s, search, &mut seen, &mut eval)?;
        (stages, seen)
    };
    let mut trials = seen.len();
    if !s.monte_carlo
        && let Some(best) = most_likely(&seen)
    {
        let refined = refine(&best, s.refine_steps, &mut eval)?;
        trials += refined.len();
        seen.extend(refined);
    }
    let events = seen.iter().filter(|(_, o)| o.event).count();
    let least = seen
        .iter()
        .min_by(|a, b| a.1.level().total_cmp(&b.1.level()))
        .map(|(z, o)| Found::new(z.clone(), *o));
    Ok(Falsified {
        most_likely: most_likely(&seen).map(|(z, o)| Found::new(z, o)),
        least_robust: least,
        trials,
        events,
        stages,
    })
}

/// The failing point nearest the nominal one (the highest density).
fn most_likely(seen: &[(Vec<f64>, Outcome)]) -> Option<(Vec<f64>, Outcome)> {
    let norm = |z: &Vec<f64>| z.iter().map(|x| x * x).sum::<f64>();
    seen.iter()
        .filter(|(_, o)| o.event)
        .min_by(|a, b| norm(&a.0).total_cmp(&norm(&b.0)))
        .cloned()
}

/// Bisection on t ∈ (0, 1] for the failing point t·z nearest the nominal one along the
/// ray (the event's boundary on it, when the ray crosses it once).
fn refine<E: std::error::Error + 'static>(
    best: &(Vec<f64>, Outcome),
    steps: usize,
    eval: &mut impl FnMut(&[Vec<f64>]) -> Result<Vec<Outcome>, E>,
) -> Result<Vec<(Vec<f64>, Outcome)>, RareError<E>> {
    let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
    let mut out = Vec::new();
    for _ in 0..steps {
        let t = 0.5 * (lo + hi);
        let z: Vec<f64> = best.0.iter().map(|x| t * x).collect();
        let o = run(eval, std::slice::from_ref(&z))?[0];
        if o.event {
            hi = t;
        } else {
            lo = t;
        }
        out.push((z, o));
    }
    Ok(out)
}

/// Spends what the adaptation left in stages fitted to the most likely failures found so
/// far (the nearest to the nominal point, a ρ share of a stage), so the proposal moves
/// along the event's boundary toward its most likely point.
fn toward_likely<E: std::error::Error + 'static>(
    mut q: Proposal,
    s: &FalsifySettings,
    search: usize,
    seen: &mut Evaluated,
    eval: &mut impl FnMut(&[Vec<f64>]) -> Result<Vec<Outcome>, E>,
) -> Result<(), RareError<E>> {
    let norm = |z: &Vec<f64>| z.iter().map(|x| x * x).sum::<f64>();
    let mut stage = 0x1000;
    while seen.len() < search {
        let n = (search - seen.len()).min(s.ce.per_stage);
        let points = q.draw(n, s.seed, stage);
        stage += 1;
        let out = run(eval, &points)?;
        seen.extend(points.into_iter().zip(out));
        let mut fails: Vec<&Vec<f64>> = seen
            .iter()
            .filter(|(_, o)| o.event)
            .map(|(z, _)| z)
            .collect();
        if fails.len() < 2 {
            continue;
        }
        fails.sort_by(|a, b| norm(a).total_cmp(&norm(b)));
        let keep = ((s.ce.elite_fraction * s.ce.per_stage as f64).ceil() as usize).max(2);
        let elite: Vec<(&Vec<f64>, f64)> = fails.into_iter().take(keep).map(|z| (z, 0.0)).collect();
        q = fit(&elite, s.dims, &s.ce);
    }
    Ok(())
}
