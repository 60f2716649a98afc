//! P(event) with its confidence interval: plain Monte Carlo (an exact binomial interval) or cross-entropy adaptive importance sampling (a final stage at a fixed proposal, so its estimate is unbiased).

use serde::Serialize;

use crate::ce::{CeSettings, Stage, adapt};
use crate::normal::upper_quantile;
use crate::subset::{Halt, Level, SubsetSettings};
use crate::{Outcome, RareError, run};

/// The estimator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// Points from the nominal density; the Clopper–Pearson interval.
    Mc,
    /// Cross-entropy adaptive importance sampling with likelihood-ratio weights.
    Ce,
    /// Subset simulation: nested levels of the robustness, sampled by Markov chains.
    Subset,
}

/// What to estimate with, and how much to spend.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct EstimateSettings {
    pub method: Method,
    /// Uncertain parameters (dimensions of z).
    pub dims: usize,
    /// Points (trials) in all, adaptation included.
    pub budget: usize,
    pub seed: u64,
    /// Two-sided confidence of the interval.
    pub confidence: f64,
    /// Share of the budget kept for the final, unbiased stage (the rest adapts).
    pub final_share: f64,
    pub ce: CeSettings,
    pub subset: SubsetSettings,
}

impl EstimateSettings {
    pub fn new(method: Method, dims: usize, budget: usize, seed: u64) -> Self {
        EstimateSettings {
            method,
            dims,
            budget,
            seed,
            confidence: 0.95,
            final_share: 0.5,
            ce: CeSettings::default(),
            subset: SubsetSettings::default(),
        }
    }

    fn check<E: std::error::Error>(&self) -> Result<(), RareError<E>> {
        let bad = |field, reason: &str| {
            Err(RareError::Setting {
                field,
                reason: reason.to_owned(),
            })
        };
        if !(1..=64).contains(&self.dims) {
            return bad("dims", "from 1 to 64 uncertain parameters");
        }
        if !(20..=10_000_000).contains(&self.budget) {
            return bad("budget", "from 20 to 10,000,000 trials");
        }
        if !(0.5..=0.999_999).contains(&self.confidence) {
            return bad("confidence", "from 0.5 to 0.999999");
        }
        if !(0.1..=0.9).contains(&self.final_share) {
            return bad("final_share", "from 0.1 to 0.9");
        }
        self.ce.check()?;
        self.subset.check(self.budget)
    }
}

/// An estimate of P(event).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Estimate {
    pub method: Method,
    pub p: f64,
    /// The two-sided interval at `confidence`.
    pub ci: (f64, f64),
    pub confidence: f64,
    /// Standard error of `p`.
    pub std_error: f64,
    /// `std_error / p` (None when no event was sampled).
    pub relative_error: Option<f64>,
    /// Effective sample size of the final stage's event weights, (Σw)² / Σw²: how many
    /// plain draws of the event the estimate is worth (the event count for Monte Carlo).
    pub ess: f64,
    /// Points evaluated in all (adaptation and final stage).
    pub trials: usize,
    /// Of them, the adaptation's (not in the estimate).
    pub adapting: usize,
    /// Points on which the event happened, over every stage.
    pub events: usize,
    /// The adaptation's stages (cross-entropy only).
    pub stages: Vec<Stage>,
    /// Subset simulation's levels, the nominal one first (subset simulation only).
    pub levels: Vec<Level>,
    /// Why subset simulation stopped before a level within the event, if it did.
    pub halt: Option<Halt>,
}

/// Events the nominal first stage must draw before the event counts as not rare.
const NOT_RARE_EVENTS: usize = 10;

/// Below this effective sample size an estimate's interval is not to be trusted: a
/// choice, where a normal interval on a weighted mean is commonly taken to need some
/// thirty effective draws.
pub const MIN_ESS: f64 = 30.0;

impl Estimate {
    /// Why the estimate's interval may not cover, when it rests on fewer than
    /// [`MIN_ESS`] effective samples of the event (a starved adaptation, or too small a
    /// budget): the sentence a run warns with.
    pub fn thin(&self) -> Option<String> {
        if self.method == Method::Subset {
            return crate::subset::thin(self);
        }
        if self.events == 0 || self.ess >= MIN_ESS {
            return None;
        }
        let re = self.relative_error.map_or(String::new(), |r| {
            format!(", relative error {:.0} %", 100.0 * r)
        });
        Some(format!(
            "the estimate rests on an effective sample size of {:.0} (under {MIN_ESS:.0}{re}): \
             its interval may not cover the true probability; a larger --budget gives the \
             adaptation and the final stage more trials",
            self.ess
        ))
    }

    /// The share of the event in the cross-entropy's first stage, drawn from the nominal
    /// density, when it drew enough events to call it not rare: there importance sampling
    /// gains little, and where the event has several causes its proposal follows one of
    /// them and can undercover, so plain Monte Carlo is the safer estimate.
    pub fn not_rare(&self) -> Option<f64> {
        let first = self.stages.first()?;
        (first.events >= NOT_RARE_EVENTS).then(|| first.events as f64 / first.points as f64)
    }
}

/// Estimates P(event) over N(0, I) in `s.dims` dimensions by evaluating points with
/// `eval` (a batch of trials at a time).
pub fn estimate<E: std::error::Error + 'static>(
    s: &EstimateSettings,
    mut eval: impl FnMut(&[Vec<f64>]) -> Result<Vec<Outcome>, E>,
) -> Result<Estimate, RareError<E>> {
    s.check()?;
    match s.method {
        Method::Mc => monte_carlo(s, &mut eval),
        Method::Ce => importance(s, &mut eval),
        Method::Subset => crate::subset::subset(s, &mut eval),
    }
}

/// The stream the final stage (or plain Monte Carlo) draws from.
const FINAL: u64 = 0xF1A1;

fn monte_carlo<E: std::error::Error + 'static>(
    s: &EstimateSettings,
    eval: &mut impl FnMut(&[Vec<f64>]) -> Result<Vec<Outcome>, E>,
) -> Result<Estimate, RareError<E>> {
    let points = crate::ce::Proposal::nominal(s.dims).draw(s.budget, s.seed, FINAL);
    let out = run(eval, &points)?;
    let k = out.iter().filter(|o| o.event).count();
    let n = out.len();
    let p = k as f64 / n as f64;
    let se = (p * (1.0 - p) / n as f64).sqrt();
    Ok(Estimate {
        method: Method::Mc,
        p,
        ci: clopper_pearson(k as u64, n as u64, s.confidence),
        confidence: s.confidence,
        std_error: se,
        relative_error: (k > 0).then(|| se / p),
        ess: k as f64,
        trials: n,
        adapting: 0,
        events: k,
        stages: Vec::new(),
        levels: Vec::new(),
        halt: None,
    })
}

fn importance<E: std::error::Error + 'static>(
    s: &EstimateSettings,
    eval: &mut impl FnMut(&[Vec<f64>]) -> Result<Vec<Outcome>, E>,
) -> Result<Estimate, RareError<E>> {
    let adapt_budget = ((1.0 - s.final_share) * s.budget as f64) as usize;
    let (q, stages, seen) = adapt(s.dims, &s.ce, s.seed, adapt_budget, eval)?;
    let n = s.budget - seen.len();
    let points = q.draw(n, s.seed, FINAL);
    let out = run(eval, &points)?;
    // y_i = 1[event] · φ(z_i) / q(z_i): an unbiased draw of P(event) each.
    let y: Vec<f64> = points
        .iter()
        .zip(&out)
        .map(|(z, o)| if o.event { q.ln_weight(z).exp() } else { 0.0 })
        .collect();
    let nf = n as f64;
    let p = y.iter().sum::<f64>() / nf;
    let var = y.iter().map(|v| (v - p).powi(2)).sum::<f64>() / (nf - 1.0);
    let se = (var / nf).sqrt();
    let z = upper_quantile((1.0 - s.confidence) / 2.0);
    let sum_sq: f64 = y.iter().map(|v| v * v).sum();
    let events =
        out.iter().filter(|o| o.event).count() + seen.iter().filter(|(_, o)| o.event).count();
    let ci = if y.iter().all(|v| *v == 0.0) {
        no_event_interval(s, n)
    } else {
        ((p - z * se).max(0.0), (p + z * se).min(1.0))
    };
    Ok(Estimate {
        method: Method::Ce,
        p,
        ci,
        confidence: s.confidence,
        std_error: se,
        relative_error: (p > 0.0).then(|| se / p),
        ess: if sum_sq > 0.0 {
            (p * nf).powi(2) / sum_sq
        } else {
            0.0
        },
        trials: s.budget,
        adapting: seen.len(),
        events,
        stages,
        levels: Vec::new(),
        halt: None,
    })
}

/// The interval when the final stage drew no event, where the normal one would collapse
/// to a point. Each draw's weight is at most 1 / defensive (the proposal keeps that share
/// of the nominal density), so P(event) ≤ P_q(event) / defensive, and P_q(event) is
/// bounded by the exact interval of 0 events in `n` draws.
fn no_event_interval(s: &EstimateSettings, n: usize) -> (f64, f64) {
    let q_upper = clopper_pearson(0, n as u64, s.confidence).1;
    let upper = if s.ce.defensive > 0.0 {
        (q_upper / s.ce.defensive).min(1.0)
    } else {
        1.0
    };
    (0.0, upper)
}

/// The exact (Clopper–Pearson) two-sided interval for `k` events in `n` draws.
pub fn clopper_pearson(k: u64, n: u64, confidence: f64) -> (f64, f64) {
    let tail = (1.0 - confidence) / 2.0;
    let lower = if k == 0 {
        0.0
    } else {
        // The p at which P(X ≥ k) = tail.
        bisect(|p| 1.0 - binom_cdf(k - 1, n, p) - tail)
    };
    let upper = if k == n {
        1.0
    } else {
        // The p at which P(X ≤ k) = tail.
        bisect(|p| tail - binom_cdf(k, n, p))
    };
    (lower, upper)
}

/// The root in (0, 1) of an increasing function.
fn bisect(f: impl Fn(f64) -> f64) -> f64 {
    let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if f(mid) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// P(X ≤ k) for X ~ Binomial(n, p), summed in logs.
fn binom_cdf(k: u64, n: u64, p: f64) -> f64 {
    if p <= 0.0 {
        return 1.0;
    }
    if p >= 1.0 {
        return if k >= n { 1.0 } else { 0.0 };
    }
    let (lp, lq) = (p.ln(), (1.0 - p).ln());
    let ln_n = libm::lgamma(n as f64 + 1.0);
    (0..=k.min(n))
        .map(|i| {
            let c = ln_n - libm::lgamma(i as f64 + 1.0) - libm::lgamma((n - i) as f64 + 1.0);
            (c + i as f64 * lp + (n - i) as f64 * lq).exp()
        })
        .sum::<f64>()
        .min(1.0)
}
