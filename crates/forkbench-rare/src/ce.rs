//! The cross-entropy method's proposal (a diagonal Gaussian mixed with the nominal density) and its adaptation toward the event, stage by stage.

use serde::Serialize;

use crate::{Outcome, RareError, run};

/// How the proposal is adapted (Rubinstein and Kroese's cross-entropy method with
/// likelihood-ratio weights, and a defensive share of nominal draws, Hesterberg 1995).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CeSettings {
    /// Points per adaptation stage.
    pub per_stage: usize,
    /// Share of a stage kept as its elite (the lowest robustness): ρ.
    pub elite_fraction: f64,
    /// Least σ per axis, so one heavy point cannot collapse the proposal.
    pub min_sigma: f64,
    /// Share of every stage drawn from the nominal density; bounds each likelihood
    /// ratio by its inverse, so a proposal that missed part of the event costs variance,
    /// not bias.
    pub defensive: f64,
    /// Factor on each fitted σ: a proposal a little wider than the elite keeps the
    /// likelihood ratios of the event's far side from dominating (an over-dispersed
    /// proposal), which the interval's normal approximation needs.
    pub inflation: f64,
}

impl Default for CeSettings {
    fn default() -> Self {
        // Choices within the ranges the method's literature uses (ρ 0.01–0.2).
        CeSettings {
            per_stage: 500,
            elite_fraction: 0.1,
            min_sigma: 0.3,
            defensive: 0.1,
            inflation: 1.5,
        }
    }
}

impl CeSettings {
    pub(crate) fn check<E: std::error::Error>(&self) -> Result<(), RareError<E>> {
        let bad = |field, reason: &str| {
            Err(RareError::Setting {
                field,
                reason: reason.to_owned(),
            })
        };
        if !(20..=1_000_000).contains(&self.per_stage) {
            return bad("per_stage", "from 20 to 1,000,000 points");
        }
        if !(0.01..=0.5).contains(&self.elite_fraction) {
            return bad("elite_fraction", "from 0.01 to 0.5");
        }
        if !(0.05..=1.0).contains(&self.min_sigma) {
            return bad("min_sigma", "from 0.05 to 1");
        }
        if !(0.0..=0.5).contains(&self.defensive) {
            return bad("defensive", "from 0 to 0.5");
        }
        if !(1.0..=3.0).contains(&self.inflation) {
            return bad("inflation", "from 1 to 3");
        }
        Ok(())
    }
}

pub use crate::mixture::{Component, Proposal};

/// One adaptation stage: the level its elite reached and the proposal it gave.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Stage {
    /// The elite's robustness threshold (0 once the event itself is the elite).
    pub level: f64,
    /// Points of this stage on which the event happened, and its points.
    pub events: usize,
    pub points: usize,
    pub proposal: Proposal,
}

/// Every point evaluated, with its outcome.
pub type Evaluated = Vec<(Vec<f64>, Outcome)>;

/// Adapts the proposal toward the event within `budget` points: stages of `per_stage`
/// until a stage's elite lies within the event (level 0) or the budget is spent.
pub(crate) fn adapt<E: std::error::Error + 'static>(
    dims: usize,
    s: &CeSettings,
    seed: u64,
    budget: usize,
    eval: &mut impl FnMut(&[Vec<f64>]) -> Result<Vec<Outcome>, E>,
) -> Result<(Proposal, Vec<Stage>, Evaluated), RareError<E>> {
    let mut q = Proposal::nominal(dims);
    let (mut stages, mut seen) = (Vec::new(), Vec::new());
    let mut spent = 0;
    while spent + s.per_stage <= budget {
        let points = q.draw(s.per_stage, seed, stages.len() as u64 + 1);
        let out = run(eval, &points)?;
        spent += points.len();
        let mut levels: Vec<f64> = out.iter().map(Outcome::level).collect();
        levels.sort_by(f64::total_cmp);
        let k = ((s.elite_fraction * levels.len() as f64).ceil() as usize).max(1);
        let level = levels[k - 1].max(0.0);
        let events = out.iter().filter(|o| o.event).count();
        let drawn = points.len();
        let next = refit(&q, &points, &out, level, s);
        seen.extend(points.into_iter().zip(out));
        stages.push(Stage {
            level,
            events,
            points: drawn,
            proposal: next.clone(),
        });
        q = next;
        if level <= 0.0 {
            break;
        }
    }
    Ok((q, stages, seen))
}

/// The weighted elite's mean and spread: the cross-entropy update.
fn refit(
    q: &Proposal,
    points: &[Vec<f64>],
    out: &[Outcome],
    level: f64,
    s: &CeSettings,
) -> Proposal {
    let elite: Vec<(&Vec<f64>, f64)> = points
        .iter()
        .zip(out)
        .filter(|(_, o)| o.level() <= level)
        .map(|(z, _)| (z, q.ln_weight(z)))
        .collect();
    fit(&elite, q.components[0].mean.len(), s)
}

/// The mixture fitted to `elite` points weighted by their log weights (see
/// [`crate::mixture::fit`]), σ at least the floor, widened by the inflation.
pub(crate) fn fit(elite: &[(&Vec<f64>, f64)], dims: usize, s: &CeSettings) -> Proposal {
    crate::mixture::fit(elite, dims, (s.min_sigma, s.inflation, s.defensive))
}
