//! The scenario file as written: its tables and their defaults, before validation.

use std::path::PathBuf;

use forkbench_core::ForkliftSpec;
use forkbench_sensors::{Nav350Config, OdometryConfig, PalletEstimateConfig};
use forkbench_sim::SimConfig;
use serde::{Deserialize, Serialize};

use super::PoseDeg;
use crate::tolerances::Tolerances;

/// Gap between the fork tips and the pallet face at the end of the approach curve: the
/// default of `[pick] pre_entry_gap_m`.
pub const APPROACH_GAP_M: f64 = 0.3;

/// Where the pallet stands: a pose, or a slot of the world.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum PalletPlacement {
    Slot { slot: String },
    Pose(PoseDeg),
}

/// Which built-in pallet: a row of [`forkbench_core::pallet::PALLET_KINDS`], by its name.
#[derive(Debug, Clone, Copy)]
pub struct PalletKind(pub &'static forkbench_core::pallet::PalletKind);

impl PalletKind {
    /// The default kind (the field test's pallet).
    pub fn field_1200() -> Self {
        Self::by_name("field-1200").expect("field-1200 is a built-in kind")
    }

    /// The built-in kind `name`; refused with the known names.
    pub fn by_name(name: &str) -> Result<Self, forkbench_core::UnknownChoice> {
        forkbench_core::pallet::PalletKind::by_name(name).map(Self)
    }

    pub fn name(self) -> &'static str {
        self.0.name
    }
}

impl PartialEq for PalletKind {
    fn eq(&self, other: &Self) -> bool {
        self.name() == other.name()
    }
}

impl Eq for PalletKind {}

impl Serialize for PalletKind {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

impl<'de> Deserialize<'de> for PalletKind {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let name = String::deserialize(d)?;
        Self::by_name(&name).map_err(serde::de::Error::custom)
    }
}

/// Sensor noise settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct NoiseFile {
    pub enabled: bool,
    pub nav350: Nav350Config,
    pub pallet_estimate: PalletEstimateConfig,
    /// The truck's own odometry errors (dead reckoning between fixes).
    pub odometry: OdometryConfig,
}

impl Default for NoiseFile {
    fn default() -> Self {
        Self {
            enabled: true,
            nav350: Nav350Config::default(),
            pallet_estimate: PalletEstimateConfig::default(),
            odometry: OdometryConfig::default(),
        }
    }
}

/// Replanning when a new pallet estimate arrives.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ReplanFile {
    /// Off reproduces the papers: plan once from the first estimate.
    pub enabled: bool,
    pub position_threshold_m: f64,
    pub heading_threshold_deg: f64,
    /// Ranges (fork root to the estimated face) at which a new estimate is taken; absent:
    /// `[noise.pallet_estimate] reestimate_at_m`, where it used to live.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reestimate_at_m: Option<Vec<f64>>,
    /// How a new estimate changes the path: `deform` the remaining path onto it (the
    /// default), or `plan` anew from the truck's pose with the scenario's planner.
    pub method: ReplanMethod,
}

/// How a replan changes the path the tracker follows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ReplanMethod {
    /// The path ahead of the truck moved by the rigid motion that carries the old
    /// estimate onto the new one, blended in over the approach (falls back to `plan`
    /// where that would exceed κ_max or touch a rack).
    #[default]
    Deform,
    /// A new plan from the truck's pose and steering to the new estimate.
    Plan,
}

impl Default for ReplanFile {
    fn default() -> Self {
        Self {
            enabled: false,
            position_threshold_m: 0.02,
            heading_threshold_deg: 1.0,
            reestimate_at_m: None,
            method: ReplanMethod::Deform,
        }
    }
}

/// The pick as a docking server runs it (`[pick]`): what the truck does when the pallet's
/// face is not found from where the pick begins.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PickFile {
    pub when_not_seen: WhenNotSeen,
    /// Fork root to the prior face at the staging pose, facing the pallet.
    pub staging_distance_m: f64,
    /// Detections tried at the staging pose before `pallet_not_found`.
    pub looks: u32,
    /// What the truck does between two looks.
    pub between_looks: BetweenLooks,
    /// `wait`: how long it stands (new scans, new noise).
    pub retry_wait_s: f64,
    /// `move`: how far it backs away along the staging line (a wider view).
    pub retry_step_m: f64,
    /// Fork tips to the face where the planned approach curve ends; the forks go in
    /// straight from there.
    pub pre_entry_gap_m: f64,
    /// Docked: the tracker reports the goal reached and the truck moves slower than this.
    pub docked_speed_mps: f64,
    /// How deep past the face the fork tips are driven (the pick's goal); by default
    /// [`default_insertion_m`]: 5 cm short of the pallet's back, or the mast's face 10 cm
    /// short of its front, the shallower. It must reach `tolerances.insertion_depth_m`, or
    /// no pick could succeed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub insertion_m: Option<f64>,
}

/// The margin the default insertion keeps the fork tips short of the pallet's back: a
/// choice, the paper's truck's (its forks are longer than the pallet is deep).
pub const INSERTION_MARGIN_M: f64 = 0.05;

/// The margin the default insertion keeps the fork root (the mast's face) short of the
/// pallet's face, for forks not much longer than the pallet is deep: a choice that
/// covers where a docked truck stops about its goal with the default sensing, whose
/// pallet estimate moves the goal along the pallet's axis (docs/truck.md gives the
/// spread measured).
pub const MAST_MARGIN_M: f64 = 0.10;

/// The pick's default insertion: the tips [`INSERTION_MARGIN_M`] short of the pallet's
/// back, and the mast's face at least [`MAST_MARGIN_M`] short of its front, the
/// shallower of the two.
pub fn default_insertion_m(
    truck: &forkbench_core::ForkliftSpec,
    pallet: &forkbench_core::PalletSpec,
) -> f64 {
    (pallet.depth_m - INSERTION_MARGIN_M).min(truck.fork_length_m - MAST_MARGIN_M)
}

/// What a pick does when the first look finds no pallet.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WhenNotSeen {
    /// Drive (Hybrid-A*, forwards and backwards) to a staging pose before the prior face,
    /// look again there, up to `looks` times.
    #[default]
    Stage,
    /// Plan on the prior (where the pallet should stand) and drive; look at every scanner
    /// frame until the face is found, then replan onto it once.
    Prior,
    /// End the trial `pallet_not_found` (the papers' setting: one look, from the start).
    Fail,
}

/// Between two looks at the staging pose.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BetweenLooks {
    #[default]
    Wait,
    Move,
}

impl Default for PickFile {
    fn default() -> Self {
        Self {
            when_not_seen: WhenNotSeen::Stage,
            staging_distance_m: 3.0,
            looks: 3,
            between_looks: BetweenLooks::Wait,
            retry_wait_s: 0.5,
            retry_step_m: 0.5,
            pre_entry_gap_m: APPROACH_GAP_M,
            docked_speed_mps: 0.01,
            insertion_m: None,
        }
    }
}

impl PickFile {
    /// Every value in its range, naming the field.
    pub fn check(&self) -> Result<(), forkbench_core::SettingsError> {
        if !(1..=20).contains(&self.looks) {
            return Err(forkbench_core::SettingsError::field(
                "looks",
                format!("must be 1 to 20 (got {})", self.looks),
            ));
        }
        forkbench_core::settings::in_ranges(&[
            ("staging_distance_m", self.staging_distance_m, 0.5, 20.0),
            ("retry_wait_s", self.retry_wait_s, 0.0, 10.0),
            ("retry_step_m", self.retry_step_m, 0.0, 5.0),
            ("pre_entry_gap_m", self.pre_entry_gap_m, 0.0, 5.0),
            ("docked_speed_mps", self.docked_speed_mps, 0.001, 0.5),
            ("insertion_m", self.insertion_m.unwrap_or(1.0), 0.05, 5.0),
        ])
    }

    /// The insertion a pick with `truck` and `pallet` aims for: [`Self::insertion_m`] or
    /// the default.
    pub fn insertion_for(
        &self,
        truck: &forkbench_core::ForkliftSpec,
        pallet: &forkbench_core::PalletSpec,
    ) -> f64 {
        self.insertion_m
            .unwrap_or_else(|| default_insertion_m(truck, pallet))
    }
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct CaseFile {
    pub(super) name: String,
    pub(super) start: Option<PoseDeg>,
    pub(super) pallet: Option<PalletPlacement>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ScenarioFile {
    pub(super) name: String,
    #[serde(default)]
    pub(super) description: String,
    /// World file, relative to this scenario file; none is an open floor.
    pub(super) world: Option<PathBuf>,
    /// `planner = "bspline"` or a `[planner]` table with `kind` and its settings.
    pub(super) planner: toml::Spanned<toml::Value>,
    #[serde(default)]
    pub(super) seed: u64,
    /// A built-in pallet (default `field-1200`); or `[pallet_model]`, a custom one.
    pub(super) pallet_kind: Option<PalletKind>,
    /// A custom pallet kind: its parts, notches and entry faces.
    pub(super) pallet_model: Option<forkbench_core::pallet::PalletModel>,
    /// The face the forks enter (default `front`).
    pub(super) pallet_entry: Option<forkbench_core::pallet::PalletFace>,
    /// Goods on the pallet: they press it on the floor (a pushed pallet resists more)
    /// and, once lifted, load the truck.
    #[serde(default)]
    pub(super) payload_kg: f64,
    #[serde(default = "default_timeout")]
    pub(super) timeout_s: f64,
    /// Refuse plans (and replans) whose swept truck body hits a rack or wall; off lets a
    /// colliding plan be driven, to study the collision itself.
    #[serde(default = "default_true")]
    pub(super) validate_paths: bool,
    /// A `[truck]` table, `truck = "FILE"` (a truck file, relative to this scenario), or
    /// a table with `file = "FILE"` whose other keys override the file's.
    #[serde(default, rename = "truck")]
    pub(super) truck_entry: Option<toml::Spanned<toml::Value>>,
    /// The truck the entry resolves to (filled after parsing).
    #[serde(skip)]
    pub(super) truck: ForkliftSpec,
    /// A `[tracker]` table: `kind` (default pure pursuit) and its settings.
    pub(super) tracker: Option<toml::Spanned<toml::Value>>,
    #[serde(default)]
    pub(super) sim: SimConfig,
    #[serde(default)]
    pub(super) noise: NoiseFile,
    #[serde(default)]
    pub(super) replan: ReplanFile,
    #[serde(default)]
    pub(super) pick: PickFile,
    #[serde(default)]
    pub(super) tolerances: Tolerances,
    /// Fixed error of every pallet estimate, in the pallet frame (a miscalibrated camera);
    /// kept with `--no-noise`, since it is not random.
    pub(super) estimate_bias: Option<PoseDeg>,
    /// Monte-Carlo jitter of the true pallet pose: σ per axis in the pallet frame,
    /// drawn per trial (truncated at 3σ).
    pub(super) pallet_jitter: Option<PoseDeg>,
    pub(super) start: Option<PoseDeg>,
    pub(super) pallet: Option<PalletPlacement>,
    #[serde(default)]
    pub(super) case: Vec<CaseFile>,
    /// The handling cycle: `"pick"`, then the phases after it (`"lift"`,
    /// `"reverse_out"`, `"carry"`, `"place"`, `"return"`), in order; none is the pick alone.
    pub(super) phases: Option<toml::Spanned<Vec<String>>>,
    /// Settings of listed phases, `[phase.NAME]`.
    #[serde(default)]
    pub(super) phase: toml::Table,
    /// A warehouse mission that ends where the pick starts.
    pub(super) mission: Option<super::mission::MissionFile>,
    /// The truck's safety fields (`[safety]`): the scanner, response times, supplements
    /// and the speed ranges that switch field sets.
    pub(super) safety: Option<forkbench_safety::SafetyConfig>,
    /// People and other vehicles moving on routes (`[[mover]]`).
    #[serde(default)]
    pub(super) mover: Vec<forkbench_safety::MoverSpec>,
    /// Sensors beyond the defaults (`[sensors.pallet]`).
    pub(super) sensors: Option<super::sensors::SensorsFile>,
    /// Settings left to chance (`[[uncertain]]`).
    #[serde(default)]
    pub(super) uncertain: Vec<toml::Spanned<super::uncertain_file::UncertainFile>>,
}

fn default_true() -> bool {
    true
}

fn default_timeout() -> f64 {
    120.0
}
