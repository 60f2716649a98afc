//! The pick's criteria, one mechanism: each a `StepCriterion` with its name, measurement, limit, whether a breach is final and the signal it records; the fixed ones judge the pick's measurements, the others measure at every step. The outcome's `measures`, the CSV's columns, the MCAP outcome and the recordings' verdict list them from here.

mod fork_tip_clearance;
mod phase;
mod pick;

use forkbench_core::{ForkliftSpec, PalletSpec, Pose2};

use crate::tolerances::Limits;

pub use phase::{LoadHeld, NoCollision, PHASE_CRITERIA, PalletStayed};
pub use pick::{Criterion, PICK_CRITERIA, Reading};

/// The pick's measurements the fixed criteria judge: at the end of the drive, or as they
/// stand at a step (a caller-driven pick ends on the first final breach).
#[derive(Debug, Clone, Copy)]
pub struct PickMeasures {
    pub collision: bool,
    pub timed_out: bool,
    pub max_contact_force_n: f64,
    /// The chassis and mast pressing the pallet's face, at any depth.
    pub mast_contact_force_n: f64,
    pub pallet_displacement_m: f64,
    pub pallet_rotation_rad: f64,
    /// At entry (`None`: the tips have not reached the face).
    pub lateral_error_m: Option<f64>,
    pub heading_error_rad: Option<f64>,
    pub insertion_depth_m: f64,
    /// The fork middle farthest from its pocket's centre line, laterally.
    pub worst_pocket_miss_m: f64,
}

/// What a criterion is judged with: the pick's measurements as they stand, the limits,
/// the truck and pallet.
#[derive(Debug, Clone, Copy)]
pub struct Judged<'a> {
    pub m: PickMeasures,
    pub tol: &'a Limits,
    pub truck: &'a ForkliftSpec,
    pub pallet: &'a PalletSpec,
    /// The scenario's time limit.
    pub timeout_s: f64,
}

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
    /// The truck has touched a rack or wall.
    pub collision: bool,
    /// The carried load as the physics last stepped it.
    pub load: LoadView,
}

/// The carried load as the physics last stepped it: whether it shifted on the forks, the
/// hardest the truck accelerated it, and what its friction on them holds.
#[derive(Debug, Clone, Copy, Default)]
pub struct LoadView {
    pub shifted: bool,
    pub peak_accel_mps2: f64,
    pub grip_mps2: f64,
}

impl LoadView {
    /// The load as `sim` holds it now.
    pub fn of(sim: &forkbench_sim::Sim) -> Self {
        Self {
            shifted: sim.load_shifted(),
            peak_accel_mps2: sim.peak_load_accel_mps2(),
            grip_mps2: sim.load_grip_mps2(),
        }
    }
}

/// A criterion of the pick: it may measure at every step (`observe`, `value`) and is
/// judged at the end, and at each step of a caller-driven pick (`judge`: by default its
/// own measurement, `broken`). The fixed criteria ([`PICK_CRITERIA`]) are this too, judged
/// on the pick's measurements. Adding one is a file here and a row of [`STEP_CRITERIA`];
/// from outside the crate, [`crate::Registry::with_step_criterion`].
pub trait StepCriterion: Send + std::fmt::Debug {
    /// The failure's name (snake case): the verdict, `also_failed` and the summaries
    /// count it by this.
    fn name(&self) -> &'static str;
    /// The measurement's key in the outcome's `measures`, with its unit
    /// (`fork_tip_clearance_mm`); also the CSV column and the recorded signal's name.
    /// `None`: its measurement is one of the outcome's own fields (a fixed criterion's).
    fn measure(&self) -> Option<&'static str>;
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
    /// Why the pick breaks it, with value and limit, given its measurements as they stand:
    /// a criterion that measures for itself answers from what it observed.
    fn judge(&self, judged: &Judged<'_>) -> Option<String> {
        let _ = judged;
        self.broken()
    }
    /// Signed margin to its limit, (limit − measured) / limit: negative exactly when
    /// broken; `None` when it keeps none (the pick's robustness is the least margin).
    fn margin(&self, judged: &Judged<'_>) -> Option<f64> {
        let _ = judged;
        None
    }
}

/// Makes a step criterion, fresh for one trial.
pub type StepCtor = fn() -> Box<dyn StepCriterion>;

/// The built-in criteria in the order of blame: the pick's fixed ones, then those that
/// measure at every step; a registry adds more ([`crate::Registry::with_step_criterion`]).
pub const STEP_CRITERIA: &[StepCtor] = &[
    pick::row::<0>,
    pick::row::<1>,
    pick::row::<2>,
    pick::row::<3>,
    pick::row::<4>,
    pick::row::<5>,
    pick::row::<6>,
    pick::row::<7>,
    fork_tip_clearance::build,
];

/// Each built-in step criterion, fresh.
fn build_all() -> Vec<Box<dyn StepCriterion>> {
    STEP_CRITERIA.iter().map(|b| b()).collect()
}

/// The measurement keys of every built-in step criterion, in order (the CSV's first extra
/// columns; a registered criterion's follow them).
pub fn step_measures() -> Vec<&'static str> {
    build_all().iter().filter_map(|c| c.measure()).collect()
}

/// The built-in step criterion named `name`, if one is.
pub fn step_criterion_name(name: &str) -> Option<&'static str> {
    build_all().iter().map(|c| c.name()).find(|n| *n == name)
}
