//! Subset simulation (Au and Beck 2001): P(event) as a product of conditional probabilities of nested levels of the robustness, each level sampled by Markov chains that keep the nominal density, so failures in several regions keep their shares.

use rand::RngExt as _;
use rand_distr::StandardNormal;
use serde::Serialize;

use crate::estimate::{Estimate, EstimateSettings, Method};
use crate::normal::upper_quantile;
use crate::{Outcome, RareError, run, stream};

/// How the levels are set and sampled.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SubsetSettings {
    /// Share of a level's points below the next level's threshold: p₀ (Au and Beck's 0.1).
    pub level_fraction: f64,
    /// Points per level, N; `None`: a quarter of the budget, so four levels fit (an event
    /// down to about 1e-4 at p₀ = 0.1), a choice.
    pub per_level: Option<usize>,
}

impl Default for SubsetSettings {
    fn default() -> Self {
        SubsetSettings {
            level_fraction: 0.1,
            per_level: None,
        }
    }
}

impl SubsetSettings {
    pub(crate) fn check<E: std::error::Error>(&self, budget: usize) -> Result<(), RareError<E>> {
        let bad = |field, reason: String| Err(RareError::Setting { field, reason });
        if !(0.05..=0.5).contains(&self.level_fraction) {
            return bad("subset.level_fraction", "from 0.05 to 0.5".into());
        }
        if let Some(n) = self.per_level
            && !(20..=budget).contains(&n)
        {
            return bad(
                "subset.per_level",
                format!("from 20 to the budget ({budget}) points"),
            );
        }
        Ok(())
    }
}

/// One level of a subset simulation.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Level {
    /// The robustness threshold its points are conditioned below (∞ for the nominal one).
    pub conditioned_below: f64,
    /// Its points (seeds included) and the new ones it evaluated.
    pub points: usize,
    pub evaluated: usize,
    /// Share of its points at or below the next threshold (or within the event, last).
    pub share: f64,
    /// The chains' correlation factor γ of that share (0 for independent draws).
    pub gamma: f64,
    /// Share of the chains' candidates accepted (1 for the nominal level).
    pub acceptance: f64,
}

/// Why a subset simulation stopped before a level within the event.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Halt {
    /// The budget could not pay for another level.
    Budget,
    /// The robustness has a plateau at this value: the next threshold would not be lower,
    /// so no further level can be conditioned (a score without a slope there).
    Plateau(f64),
}

/// Target acceptance of the conditional sampler (Papaioannou et al. 2015's 0.44).
const TARGET_ACCEPTANCE: f64 = 0.44;
/// The stream the nominal level draws from, and the base of each level's chains'.
const NOMINAL: u64 = 0x5B5E_7000;

/// A level's points with their outcomes, in chains (the nominal level: one point each).
struct Sampled {
    chains: Vec<Vec<(Vec<f64>, f64)>>,
    accepted: usize,
    proposed: usize,
    /// Of the points it evaluated, those within the event.
    events: usize,
}

/// Estimates P(event) by subset simulation within `s.budget` trials.
pub(crate) fn subset<E: std::error::Error + 'static>(
    s: &EstimateSettings,
    eval: &mut impl FnMut(&[Vec<f64>]) -> Result<Vec<Outcome>, E>,
) -> Result<Estimate, RareError<E>> {
    let ss = &s.subset;
    let n = ss.per_level.unwrap_or((s.budget / 4).max(20)).min(s.budget);
    let points = crate::ce::Proposal::nominal(s.dims).draw(n, s.seed, NOMINAL);
    let out = run(eval, &points)?;
    let mut spent = n;
    let mut events = 0;
    let mut cur = Sampled {
        chains: points
            .into_iter()
            .zip(&out)
            .map(|(z, o)| vec![(z, o.level())])
            .collect(),
        accepted: n,
        proposed: n,
        events: out.iter().filter(|o| o.event).count(),
    };
    let (mut levels, mut below, mut scale) = (Vec::new(), f64::INFINITY, 0.6);
    let mut evaluated = n;
    let halt = loop {
        events += cur.events;
        let mut all: Vec<f64> = cur.chains.iter().flatten().map(|p| p.1).collect();
        all.sort_by(f64::total_cmp);
        let k = ((ss.level_fraction * all.len() as f64).ceil() as usize).clamp(1, all.len());
        let next = all[k - 1].max(0.0);
        let plateau = next >= below;
        let seeds_n = all.partition_point(|&l| l <= next);
        let last = next <= 0.0 || plateau || spent + n - seeds_n > s.budget;
        // A last level's share is the event's, whatever stopped it.
        let (share, gamma) = share_and_gamma(&cur.chains, if last { 0.0 } else { next });
        levels.push(Level {
            conditioned_below: below,
            points: all.len(),
            evaluated,
            share,
            gamma,
            acceptance: cur.accepted as f64 / cur.proposed.max(1) as f64,
        });
        if next <= 0.0 {
            break None;
        }
        if plateau {
            break Some(Halt::Plateau(next));
        }
        if last {
            break Some(Halt::Budget);
        }
        let seeds: Vec<(Vec<f64>, f64)> = cur
            .chains
            .iter()
            .flatten()
            .filter(|p| p.1 <= next)
            .cloned()
            .collect();
        let lvl = levels.len() as u64;
        (cur, scale) = sample_level(seeds, (n, next, scale), (s.seed, lvl), eval)?;
        evaluated = n - cur.chains.len();
        spent += evaluated;
        below = next;
    };
    Ok(finish(s, levels, halt, spent, events))
}

/// N points conditioned on robustness ≤ `below`, by conditional sampling from chains
/// started at `seeds`: a candidate ρx + √(1−ρ²)ξ keeps N(0, I) and is accepted only within
/// the level (Papaioannou et al. 2015). Its step σ = √(1−ρ²) starts at `scale` and adapts
/// after each round of the chains toward the target acceptance; one σ on every axis,
/// since seeds in several regions would make a per-axis spread too wide.
fn sample_level<E: std::error::Error + 'static>(
    seeds: Vec<(Vec<f64>, f64)>,
    (n, below, scale): (usize, f64, f64),
    (seed, level): (u64, u64),
    eval: &mut impl FnMut(&[Vec<f64>]) -> Result<Vec<Outcome>, E>,
) -> Result<(Sampled, f64), RareError<E>> {
    let dims = seeds[0].0.len();
    let c = seeds.len();
    let length = |j: usize| n / c + usize::from(j < n % c);
    let mut chains: Vec<Vec<(Vec<f64>, f64)>> = seeds.into_iter().map(|p| vec![p]).collect();
    let mut rng = stream(seed, NOMINAL + level);
    let (mut accepted, mut proposed, mut events, mut sigma) = (0, 0, 0, scale);
    for round in 1.. {
        let open: Vec<usize> = (0..c).filter(|&j| chains[j].len() < length(j)).collect();
        if open.is_empty() {
            break;
        }
        let rho = (1.0 - sigma * sigma).sqrt();
        let cand: Vec<Vec<f64>> = open
            .iter()
            .map(|&j| {
                let x = &chains[j].last().expect("a chain starts at its seed").0;
                (0..dims)
                    .map(|d| {
                        let u: f64 = rng.sample(StandardNormal);
                        rho * x[d] + sigma * u
                    })
                    .collect()
            })
            .collect();
        let out = run(eval, &cand)?;
        let mut took = 0;
        events += out.iter().filter(|o| o.event).count();
        for ((&j, z), o) in open.iter().zip(cand).zip(&out) {
            let step = if o.level() <= below {
                took += 1;
                (z, o.level())
            } else {
                chains[j]
                    .last()
                    .expect("a chain starts at its seed")
                    .clone()
            };
            chains[j].push(step);
        }
        let rate = took as f64 / open.len() as f64;
        sigma =
            (sigma * ((rate - TARGET_ACCEPTANCE) / f64::from(round).sqrt()).exp()).clamp(0.01, 1.0);
        accepted += took;
        proposed += open.len();
    }
    Ok((
        Sampled {
            chains,
            accepted,
            proposed,
            events,
        },
        sigma,
    ))
}

/// The share of points at or below `threshold`, and Au and Beck's γ: the indicator's
/// correlation along each chain (their eq. 29), from pairs at each lag.
fn share_and_gamma(chains: &[Vec<(Vec<f64>, f64)>], threshold: f64) -> (f64, f64) {
    let ind: Vec<Vec<f64>> = chains
        .iter()
        .map(|ch| {
            ch.iter()
                .map(|p| f64::from(u8::from(p.1 <= threshold)))
                .collect()
        })
        .collect();
    let total: usize = ind.iter().map(Vec::len).sum();
    let p = ind.iter().flatten().sum::<f64>() / total as f64;
    let longest = ind.iter().map(Vec::len).max().unwrap_or(1);
    let r0 = p * (1.0 - p);
    if longest < 2 || r0 <= 0.0 {
        return (p, 0.0);
    }
    let mut gamma = 0.0;
    for lag in 1..longest {
        let (mut sum, mut pairs) = (0.0, 0usize);
        for ch in &ind {
            for i in 0..ch.len().saturating_sub(lag) {
                sum += ch[i] * ch[i + lag];
                pairs += 1;
            }
        }
        if pairs == 0 {
            break;
        }
        let rho = (sum / pairs as f64 - p * p) / r0;
        gamma += 2.0 * (1.0 - lag as f64 / longest as f64) * rho;
    }
    (p, gamma.max(0.0))
}

/// The product of the levels' shares. Its relative error is Au and Beck's, the levels'
/// squared coefficients of variation summed as if independent (it follows the spread
/// over seeds on the known-answer functions); its interval is log-normal at their upper
/// bound, the levels fully correlated ((Σδᵢ)²), a choice: the independent sum's interval
/// undercovered there. With no point in the event, the bound is the levels reached times
/// the exact bound on none in the last level's points.
fn finish(
    s: &EstimateSettings,
    levels: Vec<Level>,
    halt: Option<Halt>,
    trials: usize,
    events: usize,
) -> Estimate {
    let deltas: Vec<f64> = levels
        .iter()
        .filter(|l| l.share > 0.0)
        .map(|l| ((1.0 - l.share) / (l.share * l.points as f64) * (1.0 + l.gamma)).sqrt())
        .collect();
    let independent = deltas.iter().map(|d| d * d).sum::<f64>().sqrt();
    let correlated: f64 = deltas.iter().sum();
    let p: f64 = levels.iter().map(|l| l.share).product();
    let z = upper_quantile((1.0 - s.confidence) / 2.0);
    let last = levels.last().expect("the nominal level");
    let ci = if p > 0.0 {
        let sd = (1.0 + correlated * correlated).ln().sqrt();
        (p * (-z * sd).exp(), (p * (z * sd).exp()).min(1.0))
    } else {
        let reached: f64 = levels[..levels.len() - 1].iter().map(|l| l.share).product();
        let none = crate::clopper_pearson(0, last.points as u64, s.confidence).1;
        (0.0, (reached * none * (z * correlated).exp()).min(1.0))
    };
    Estimate {
        method: Method::Subset,
        p,
        ci,
        confidence: s.confidence,
        std_error: p * independent,
        relative_error: (p > 0.0).then_some(independent),
        // Plain draws of the event with the same relative error.
        ess: if p > 0.0 && independent > 0.0 {
            1.0 / (independent * independent)
        } else {
            0.0
        },
        trials,
        adapting: trials - last.evaluated,
        events,
        stages: Vec::new(),
        levels,
        halt,
    }
}

/// Points of the event a subset simulation's last level needs before its share is
/// trusted: a choice, the count at which a binomial share's relative error is about 30 %.
pub const MIN_LAST_EVENTS: usize = 10;

/// Above this relative error a subset simulation's estimate is too imprecise to act on
/// (its interval spans more than a factor of about seven at 95 %): a choice.
pub const MAX_RELATIVE_ERROR: f64 = 0.5;

/// Why a subset simulation's estimate is not to be trusted, if it is not: a plateau
/// of the robustness, too few points of the event in its last level, or a relative
/// error above [`MAX_RELATIVE_ERROR`].
pub(crate) fn thin(e: &Estimate) -> Option<String> {
    let last = e.levels.last()?;
    let within = (last.share * last.points as f64).round() as usize;
    if let Some(Halt::Plateau(at)) = e.halt {
        return Some(format!(
            "the robustness has a plateau at {at:.3}: no level below it could be \
             conditioned, so the estimate rests on the {within} points of the event among \
             the {} of the last level; a score that keeps a slope toward the event is needed",
            last.points
        ));
    }
    if within < MIN_LAST_EVENTS {
        return Some(format!(
            "the estimate rests on {within} points of the event in subset simulation's last \
             level (under {MIN_LAST_EVENTS}): a larger --budget pays for more levels"
        ));
    }
    let re = e.relative_error.filter(|r| *r > MAX_RELATIVE_ERROR)?;
    Some(format!(
        "the estimate's relative error is {:.0} % (over {:.0} %; its chains' correlation \
         γ is up to {:.1}): a larger --budget, or a larger --per-level, narrows it",
        100.0 * re,
        100.0 * MAX_RELATIVE_ERROR,
        e.levels.iter().map(|l| l.gamma).fold(0.0, f64::max)
    ))
}
