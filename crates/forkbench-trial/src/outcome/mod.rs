//! The judged result of one trial, in SI units, serialisable as one JSON object.

mod nan_as_null;
mod safety;

pub use safety::SafetyOutcome;

use std::borrow::Cow;

use serde::{Deserialize, Serialize};

/// The criteria a pick can fail, in the order they are checked.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum Failure {
    /// A mission leg before the pick failed (no drivable path, a collision, or the truck
    /// did not arrive).
    LegFailed,
    /// The planner refused the (estimated) goal.
    PlanFailed,
    /// The truck touched a rack or wall.
    Collision,
    /// A fork pushed on the pallet harder than the threshold before full depth.
    ContactForce,
    /// The pallet moved or turned more than the tolerance.
    PalletDisplaced,
    /// Fork root off the pocket centre line when the tips reached the pallet face.
    LateralError,
    /// Fork root heading off the pallet axis when the tips reached the pallet face.
    HeadingError,
    /// The truck did not stop at the goal within the time limit.
    Timeout,
    /// The forks ended short of the required depth (or never entered).
    InsertionDepth,
    /// A fork ended outside its pocket.
    ForkOutsidePocket,
    /// The trial itself broke (panic or non-finite state).
    Error,
    /// The pallet sensing never found the pallet (from where the pick began, nor in the
    /// looks from the staging pose), so there was nothing to plan to.
    PalletNotFound,
    /// The face was not seen from where the pick began and no drive reached the staging
    /// pose before it.
    StagingUnreachable,
    /// The lift phase could not lift the pallet (forks not under it, over the truck's
    /// rating, or it would tip the truck).
    LiftFailed,
    /// The carried load was accelerated harder than its friction on the forks holds.
    LoadShifted,
    /// The placed pallet stands farther from its slot, or turned more, than the place
    /// tolerances allow.
    PlacementError,
    /// A criterion outside the fixed ones, by its name: one that measures while the pick
    /// drives (`STEP_CRITERIA`), or a registered phase's own. Built-in names are
    /// borrowed; names read back from records are owned.
    Criterion(Cow<'static, str>),
}

/// Every failure with a fixed name, for reading names back.
const NAMED: [Failure; 16] = [
    Failure::LegFailed,
    Failure::PlanFailed,
    Failure::Collision,
    Failure::ContactForce,
    Failure::PalletDisplaced,
    Failure::LateralError,
    Failure::HeadingError,
    Failure::Timeout,
    Failure::InsertionDepth,
    Failure::ForkOutsidePocket,
    Failure::Error,
    Failure::PalletNotFound,
    Failure::StagingUnreachable,
    Failure::LiftFailed,
    Failure::LoadShifted,
    Failure::PlacementError,
];

impl Failure {
    /// The failure a name stands for: a fixed one, else a criterion's (a step criterion's
    /// or a registered phase's) when the name is one a criterion can have.
    pub fn from_name(name: &str) -> Option<Failure> {
        Self::fixed(name)
            .or_else(|| is_criterion_name(name).then(|| Failure::Criterion(name.to_owned().into())))
    }

    /// The failure of the criterion called `name`.
    pub fn criterion(name: impl Into<Cow<'static, str>>) -> Failure {
        Failure::Criterion(name.into())
    }

    /// The failure a criterion's `name` stands for: the fixed one so named, else its own.
    pub fn of_criterion(name: &'static str) -> Failure {
        Self::fixed(name).unwrap_or(Failure::Criterion(Cow::Borrowed(name)))
    }

    /// The fixed failure called `name`, if one is.
    fn fixed(name: &str) -> Option<Failure> {
        NAMED.iter().find(|f| f.name() == name).cloned()
    }
}

/// The longest criterion name.
const MAX_CRITERION_NAME_BYTES: usize = 64;

/// Whether `name` can be a criterion's: a snake-case word of at most 64 bytes.
fn is_criterion_name(name: &str) -> bool {
    !name.is_empty()
        && name.len() <= MAX_CRITERION_NAME_BYTES
        && name.starts_with(|c: char| c.is_ascii_lowercase())
        && name
            .bytes()
            .all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'_')
}

impl Serialize for Failure {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

impl<'de> Deserialize<'de> for Failure {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let name = String::deserialize(d)?;
        Failure::from_name(&name).ok_or_else(|| {
            serde::de::Error::custom(format!(
                "unknown failure `{name}` (a criterion's name is a snake-case word of at most \
                 {MAX_CRITERION_NAME_BYTES} bytes)"
            ))
        })
    }
}

impl Failure {
    pub fn name(&self) -> &str {
        match self {
            Failure::Criterion(name) => name,
            fixed => fixed.fixed_name().unwrap_or_default(),
        }
    }

    /// A fixed failure's name (`None`: a criterion's own, by its name).
    pub fn fixed_name(&self) -> Option<&'static str> {
        Some(match self {
            Failure::LegFailed => "leg_failed",
            Failure::PlanFailed => "plan_failed",
            Failure::Collision => "collision",
            Failure::ContactForce => "contact_force",
            Failure::PalletDisplaced => "pallet_displaced",
            Failure::LateralError => "lateral_error",
            Failure::HeadingError => "heading_error",
            Failure::Timeout => "timeout",
            Failure::InsertionDepth => "insertion_depth",
            Failure::ForkOutsidePocket => "fork_outside_pocket",
            Failure::Error => "error",
            Failure::PalletNotFound => "pallet_not_found",
            Failure::StagingUnreachable => "staging_unreachable",
            Failure::LiftFailed => "lift_failed",
            Failure::LoadShifted => "load_shifted",
            Failure::PlacementError => "placement_error",
            Failure::Criterion(_) => return None,
        })
    }
}

/// Everything a trial reports.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrialOutcome {
    pub scenario: String,
    pub case: String,
    pub planner: String,
    /// Records written before trackers were pluggable have none: pure pursuit.
    #[serde(default = "default_tracker")]
    pub tracker: String,
    pub seed: u64,
    pub noise: bool,
    pub success: bool,
    /// First failed criterion in check order, if any.
    pub failure: Option<Failure>,
    pub failure_detail: Option<String>,
    /// Fork-root offset from the pocket centre line when the fork tips reached the face.
    pub lateral_error_m: Option<f64>,
    pub heading_error_rad: Option<f64>,
    /// The same errors when the truck stopped.
    #[serde(with = "nan_as_null")]
    pub final_lateral_error_m: f64,
    #[serde(with = "nan_as_null")]
    pub final_heading_error_rad: f64,
    #[serde(with = "nan_as_null")]
    pub insertion_depth_m: f64,
    pub max_steer_rad: f64,
    /// Largest truck–pallet contact force before full depth (forks, chassis and mast).
    pub max_contact_force_n: f64,
    /// Largest force the chassis and mast pressed the pallet's face with, at any depth
    /// (0, left out of records: they never touched it).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub mast_contact_force_n: f64,
    pub pallet_displacement_m: f64,
    pub pallet_rotation_rad: f64,
    pub replans: u32,
    /// New estimates whose replan the planner refused (the old plan was kept).
    pub replans_failed: u32,
    /// Pallet estimates taken, and how many of them found no pallet (a scanner's
    /// detector; the Gaussian model always finds it).
    #[serde(default)]
    pub estimates: u32,
    #[serde(default)]
    pub estimates_missed: u32,
    /// The error of the estimate the truck last aimed at, against the true face then,
    /// in the pallet frame (lateral, heading): the usual root of an entry failure.
    #[serde(default)]
    pub estimate_lateral_error_m: Option<f64>,
    #[serde(default)]
    pub estimate_heading_error_rad: Option<f64>,
    /// Localiser measurements that gave a pose, and those that gave none (a NAV350
    /// seeing fewer than three known reflectors).
    #[serde(default)]
    pub fixes: u32,
    #[serde(default)]
    pub fixes_missed: u32,
    /// The time the controller ran without a fix: missed measurements × their period.
    #[serde(default)]
    pub time_without_fix_s: f64,
    /// The longest time between two fixes (the start and the end count as ends of a gap).
    #[serde(default)]
    pub largest_fix_gap_s: f64,
    /// The controller's own pose (the last fix carried on by odometry) against the true
    /// fork root, over every control step: mean and largest position error.
    #[serde(default, with = "nan_as_null")]
    pub localization_error_mean_m: f64,
    #[serde(default)]
    pub localization_error_max_m: f64,
    pub path_length_m: f64,
    pub sim_time_s: f64,
    pub wall_time_ms: f64,
    /// Where the trial's time went, stage by stage, when the run asked (`--profile`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub profile: Option<forkbench_core::profile::Profile>,
    /// What the pick's step criteria measured, by name with its unit
    /// (`fork_tip_clearance_mm`).
    #[serde(default, skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub measures: std::collections::BTreeMap<String, f64>,
    /// Every other criterion the trial broke, after the first, each with its value and
    /// limit (`criterion: detail`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub also_failed: Vec<String>,
    /// What most likely made the trial fail (the estimate's error, a saturated steer),
    /// when the bench can tell.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub likely_cause: Option<String>,
    /// Signed margin to failure: the least over the pick's criteria of (limit −
    /// measured) / limit, −1 for a broken criterion with no continuous measure; capped
    /// at 0 when the trial failed on something no margin covers (a step criterion, a
    /// phase, an error). Negative or 0 exactly when the trial failed; `None` when it
    /// ended before anything was measured.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub robustness: Option<f64>,
    /// The scenario's uncertain parameters as this trial drew them (or was given them).
    #[serde(default, skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub uncertain: std::collections::BTreeMap<String, f64>,
    /// A mission's legs before the pick, in order (empty for a pick trial).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub legs: Vec<LegOutcome>,
    /// The pick and the phases after it, in order, up to the first that failed (empty
    /// when the scenario lists no phase after the pick).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub phases: Vec<PhaseOutcome>,
    /// The handling cycle's totals (with phases after the pick).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cycle: Option<CycleTotals>,
    /// People, other vehicles and the safety function (scenarios with `[[mover]]` or
    /// `[safety]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub safety: Option<SafetyOutcome>,
}

/// A handling cycle's time and the distance the fork root travelled with and without the
/// pallet on the forks (mission legs included).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CycleTotals {
    pub time_s: f64,
    pub distance_loaded_m: f64,
    pub distance_unloaded_m: f64,
}

/// One phase of the handling cycle: the pick, or one after it (lift, reverse out, carry,
/// place, return).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PhaseOutcome {
    pub name: String,
    pub success: bool,
    /// Its first failed criterion, with the value and limit.
    pub failure: Option<Failure>,
    pub failure_detail: Option<String>,
    /// Simulated time the phase took.
    pub time_s: f64,
    /// Distance the fork root travelled in it.
    pub distance_m: f64,
    /// Whether the truck carried the pallet through it.
    pub loaded: bool,
    /// What the phase measured, by name with its unit (a place's `position_error_m`,
    /// `heading_error_rad`, `clearance_m`).
    #[serde(default, skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub measures: std::collections::BTreeMap<String, f64>,
}

/// One mission leg: backing out of the station it starts at (if any), then the global
/// path to the next place.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LegOutcome {
    /// "from → to".
    pub name: String,
    pub success: bool,
    pub failure_detail: Option<String>,
    /// Length of the reverse segment out of the station (0: none).
    pub reverse_length_m: f64,
    /// The A* polyline's length and the smoothed path's.
    #[serde(with = "nan_as_null")]
    pub route_length_m: f64,
    #[serde(with = "nan_as_null")]
    pub planned_length_m: f64,
    /// Planning wall time, all attempts (sampling, connection, search, smoothing).
    pub planning_time_s: f64,
    /// Seeds tried before a drivable path was found.
    pub planning_attempts: u32,
    /// "ok", or why smoothing found no drivable path.
    pub smoothing: String,
    /// Smallest planned clearance of the swept footprint (forward and reverse).
    #[serde(with = "nan_as_null")]
    pub min_clearance_m: f64,
    /// Steps on which the truck touched a rack or wall.
    pub collisions: u32,
    #[serde(with = "nan_as_null")]
    pub cross_track_mean_m: f64,
    #[serde(with = "nan_as_null")]
    pub cross_track_max_m: f64,
    pub time_s: f64,
    /// Where the truck stopped against the leg's goal.
    #[serde(with = "nan_as_null")]
    pub final_position_error_m: f64,
    #[serde(with = "nan_as_null")]
    pub final_heading_error_rad: f64,
    /// Localiser measurements without a pose on this leg, the longest time between two
    /// fixes, and the controller's largest position error against the truth.
    #[serde(default)]
    pub fixes_missed: u32,
    #[serde(default)]
    pub largest_fix_gap_s: f64,
    #[serde(default)]
    pub localization_error_max_m: f64,
}

impl TrialOutcome {
    /// `SUCCESS`, or `FAILED: <criterion>`: the one short form of the verdict.
    pub fn verdict_word(&self) -> String {
        match (self.success, &self.failure) {
            (true, _) => "SUCCESS".to_owned(),
            (false, Some(f)) => format!("FAILED: {}", f.name()),
            (false, None) => "FAILED".to_owned(),
        }
    }

    /// The verdict in one line: success with the entry errors, or the failed criterion
    /// with its value and limit (the recordings' last log line).
    pub fn verdict_line(&self) -> String {
        match (self.success, &self.failure, self.failure_detail.as_deref()) {
            (true, ..) => format!(
                "SUCCESS: entry {:.3} m off the pocket centre line, {:.2}° off the pallet axis; forks {:.2} m deep",
                self.lateral_error_m.unwrap_or(f64::NAN),
                self.heading_error_rad.unwrap_or(f64::NAN).to_degrees(),
                self.insertion_depth_m
            ),
            (false, Some(_), Some(d)) => {
                let mut line = format!("{}: {d}", self.verdict_word());
                if let Some(c) = &self.likely_cause {
                    line += &format!("; likely cause: {c}");
                }
                if !self.also_failed.is_empty() {
                    line += &format!("; also {}", self.also_failed.join("; "));
                }
                line
            }
            _ => self.verdict_word(),
        }
    }

    /// The file stem of this trial's recordings, `<scenario>-<case>-<planner>-<tracker>-seed<seed>`
    /// (`-replan` for a trial that replans), safe as a file name ([`crate::text::safe_file_stem`]).
    pub fn recording_stem(&self, replan: bool) -> String {
        let mode = if replan { "-replan" } else { "" };
        let (s, c, p, t) = (&self.scenario, &self.case, &self.planner, &self.tracker);
        crate::text::safe_file_stem(&format!("{s}-{c}-{p}-{t}-seed{}{mode}", self.seed))
    }

    /// A not-yet-judged outcome: nothing measured (NaN where a value would be), no failure.
    pub fn blank(
        scenario: &str,
        case: &str,
        (planner, tracker): (&str, &str),
        seed: u64,
        noise: bool,
    ) -> Self {
        Self {
            scenario: scenario.to_owned(),
            case: case.to_owned(),
            planner: planner.to_owned(),
            tracker: tracker.to_owned(),
            seed,
            noise,
            success: false,
            failure: None,
            failure_detail: None,
            lateral_error_m: None,
            heading_error_rad: None,
            final_lateral_error_m: f64::NAN,
            final_heading_error_rad: f64::NAN,
            insertion_depth_m: f64::NAN,
            max_steer_rad: 0.0,
            max_contact_force_n: 0.0,
            mast_contact_force_n: 0.0,
            pallet_displacement_m: 0.0,
            pallet_rotation_rad: 0.0,
            replans: 0,
            replans_failed: 0,
            estimates: 0,
            estimates_missed: 0,
            estimate_lateral_error_m: None,
            estimate_heading_error_rad: None,
            fixes: 0,
            fixes_missed: 0,
            time_without_fix_s: 0.0,
            largest_fix_gap_s: 0.0,
            localization_error_mean_m: f64::NAN,
            localization_error_max_m: 0.0,
            path_length_m: 0.0,
            sim_time_s: 0.0,
            wall_time_ms: 0.0,
            profile: None,
            legs: Vec::new(),
            phases: Vec::new(),
            cycle: None,
            safety: None,
            measures: std::collections::BTreeMap::new(),
            also_failed: Vec::new(),
            likely_cause: None,
            robustness: None,
            uncertain: Default::default(),
        }
    }
}

impl TrialOutcome {
    /// Caps the robustness at 0 when the trial failed on something the pick's margins do
    /// not cover (a step criterion, a phase, a leg, an error), so its sign is the verdict.
    pub(crate) fn settle_robustness(&mut self) {
        if !self.success {
            self.robustness = self.robustness.map(|r| r.min(0.0));
        }
    }

    /// The outcome with its wall times zeroed (the trial's and each leg's planning time):
    /// all that may differ between two runs of the same trial.
    pub fn without_wall_times(&self) -> TrialOutcome {
        let mut o = self.clone();
        o.wall_time_ms = 0.0;
        o.profile = None;
        for l in &mut o.legs {
            l.planning_time_s = 0.0;
        }
        o
    }

    /// Marks the trial failed on `failure` with its detail.
    pub fn fail(&mut self, failure: Failure, detail: String) {
        self.success = false;
        self.failure = Some(failure);
        self.failure_detail = Some(crate::text::compact_numbers(&detail));
    }
}

fn default_tracker() -> String {
    "pure_pursuit".to_owned()
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}
