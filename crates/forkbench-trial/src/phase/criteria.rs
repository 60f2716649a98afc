//! How a phase judges a criterion when its move ends: one of `step_criteria`'s, under the pick's one trait, observed on the truth its host shows now.

use forkbench_core::Pose2;

use super::{Failed, PhaseHost};
use crate::outcome::Failure;
use crate::step_criteria::{LoadHeld, PalletStayed, StepCriterion};

/// A criterion as a phase's result: its failure, by its name, and why, when it is broken.
pub fn held(criterion: &dyn StepCriterion) -> Result<(), Failed> {
    match criterion.broken() {
        Some(why) => Err(Failed::new(Failure::of_criterion(criterion.name()), why)),
        None => Ok(()),
    }
}

/// `criterion` judged on the truth now: its failure and why, when it is broken.
pub fn judge_now(host: &dyn PhaseHost, mut criterion: impl StepCriterion) -> Result<(), Failed> {
    criterion.observe(&host.step_view());
    held(&criterion)
}

/// The carried load stayed on the forks ([`LoadHeld`]).
pub fn load_held(host: &dyn PhaseHost) -> Result<(), Failed> {
    judge_now(host, LoadHeld::default())
}

/// A pallet left standing stayed where it stood, `from` ([`PalletStayed`]).
pub(super) fn pallet_stayed(host: &dyn PhaseHost, from: &Pose2) -> Result<(), Failed> {
    judge_now(host, PalletStayed::new(*from, host.tolerances()))
}
