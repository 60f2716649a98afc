//! Rare failures measured: the probability of an event over uncertain parameters (plain Monte Carlo, cross-entropy adaptive importance sampling, or subset simulation) and the most likely failure, all in standard-normal space.
//!
//! Every uncertain parameter is a transform of one standard normal variable (its
//! quantile at Φ(z)), so a trial is a point `z` of ℝᵈ with the nominal density N(0, I).
//! The caller evaluates points (runs trials) and says for each whether the event
//! happened and its robustness: a signed margin, ≤ 0 exactly when the event happened,
//! which the search descends. Draws come from ChaCha8 streams keyed by the seed and
//! the stage they are for, so a seed gives the same points whatever evaluates them.

pub mod ce;
pub mod estimate;
pub mod falsify;
pub mod mixture;
pub mod normal;
pub mod subset;

pub use estimate::{Estimate, EstimateSettings, MIN_ESS, Method, clopper_pearson, estimate};
pub use falsify::{Falsified, FalsifySettings, falsify};
pub use subset::{Halt, Level, SubsetSettings};

/// What a trial at a point gave.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Outcome {
    /// The event happened (a failure, a contact).
    pub event: bool,
    /// Signed margin to the event: ≤ 0 when it happened, > 0 when not, smaller nearer.
    pub robustness: f64,
}

impl Outcome {
    /// The robustness made consistent with `event` (an evaluator's NaN, or a margin
    /// that disagrees with the verdict, is pinned to the boundary's side the verdict says).
    pub fn level(&self) -> f64 {
        match (self.event, self.robustness.is_nan()) {
            (true, true) => 0.0,
            (false, true) => f64::INFINITY,
            (true, false) => self.robustness.min(0.0),
            (false, false) => self.robustness.max(f64::MIN_POSITIVE),
        }
    }
}

/// What can stop an estimate or a search.
#[derive(Debug, thiserror::Error)]
pub enum RareError<E: std::error::Error + 'static> {
    /// A setting out of its range, named.
    #[error("{field}: {reason}")]
    Setting { field: &'static str, reason: String },
    /// The evaluator failed (a trial could not run).
    #[error("evaluating trials: {0}")]
    Evaluate(#[source] E),
    /// The evaluator answered for a different number of points than it was given.
    #[error("the evaluator answered {got} outcomes for {asked} points")]
    Answer { asked: usize, got: usize },
}

/// Evaluates `points`, checking the evaluator answered for each.
pub(crate) fn run<E: std::error::Error + 'static>(
    eval: &mut impl FnMut(&[Vec<f64>]) -> Result<Vec<Outcome>, E>,
    points: &[Vec<f64>],
) -> Result<Vec<Outcome>, RareError<E>> {
    let out = eval(points).map_err(RareError::Evaluate)?;
    if out.len() != points.len() {
        return Err(RareError::Answer {
            asked: points.len(),
            got: out.len(),
        });
    }
    Ok(out)
}

/// The random stream for `purpose` (a stage's index, or a named constant) under `seed`.
pub(crate) fn stream(seed: u64, purpose: u64) -> rand_chacha::ChaCha8Rng {
    use rand::SeedableRng as _;
    rand_chacha::ChaCha8Rng::seed_from_u64(seed ^ purpose.wrapping_mul(0x9E37_79B9_7F4A_7C15))
}
