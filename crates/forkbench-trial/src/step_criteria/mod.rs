//! Criteria that measure while the pick drives: each owns its measurement, its limit, whether a breach is final, and the signal it records; the outcome's `measures`, the CSV's columns, the MCAP outcome and the recordings' verdict list them from here.

mod fork_tip_clearance;

use forkbench_core::{ForkliftSpec, PalletSpec, Pose2};

/// What a step criterion sees after each physics step of the pick: the truth.
#[derive(Debug, Clone, Copy)]
pub struct StepView<'a> {
    pub t_s: f64,
    pub truck: &'a ForkliftSpec,
    pub pallet: &'a PalletSpec,
    /// The true fork-root pose.
    pub fork_root: Pose2,
    /// The true pallet face pose.
    pub pallet_pose: Pose2,
}

/// A criterion of the pick that measures at every step and judges its measurement at the
/// end. Adding one is a file here and a row of [`STEP_CRITERIA`]; from outside the crate,
/// [`crate::Registry::with_step_criterion`].
pub trait StepCriterion: Send + std::fmt::Debug {
    /// The failure's name (snake case): the verdict, `also_failed` and the summaries
    /// count it by this.
    fn name(&self) -> &'static str;
    /// The measurement's key in the outcome's `measures`, with its unit
    /// (`fork_tip_clearance_mm`); also the CSV column and the recorded signal's name.
    fn measure(&self) -> &'static str;
    /// One line: what it measures, for documents and listings.
    fn describe(&self) -> &'static str;
    /// Takes one step's view.
    fn observe(&mut self, view: &StepView<'_>);
    /// The measurement so far (`None`: nothing to measure yet).
    fn value(&self) -> Option<f64>;
    /// Why the measurement breaks the limit, with both, if it does.
    fn broken(&self) -> Option<String>;
    /// Whether a breach is final: no later step can undo it, so an episode a caller
    /// drives ends on it.
    fn irreversible(&self) -> bool {
        true
    }
}

/// Makes a step criterion, fresh for one trial.
pub type StepCtor = fn() -> Box<dyn StepCriterion>;

/// The built-in step criteria in the order of blame, after the pick's fixed criteria; a
/// registry adds more ([`crate::Registry::with_step_criterion`]).
pub const STEP_CRITERIA: &[StepCtor] = &[fork_tip_clearance::build];

/// Each built-in step criterion, fresh.
fn build_all() -> Vec<Box<dyn StepCriterion>> {
    STEP_CRITERIA.iter().map(|b| b()).collect()
}

/// The measurement keys of every built-in step criterion, in order (the CSV's first extra
/// columns; a registered criterion's follow them).
pub fn step_measures() -> Vec<&'static str> {
    build_all().iter().map(|c| c.measure()).collect()
}

/// The built-in step criterion named `name`, if one is.
pub fn step_criterion_name(name: &str) -> Option<&'static str> {
    build_all().iter().map(|c| c.name()).find(|n| *n == name)
}
