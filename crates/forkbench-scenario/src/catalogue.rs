//! What loading a scenario asks of the components it names: the [`Catalogue`] a registry implements, the phases it builds, and what a phase sees of the scenario.

use std::sync::Arc;

use forkbench_core::{PalletSpec, Pose2, SettingsError};
use serde::Serialize;

use crate::Scenario;
use crate::component_spec::ComponentSpec;

/// The phase list's name for the pick itself (approach and insertion), always first.
pub const PICK: &str = "pick";

/// The components a scenario may name, as its loader checks them: each table is built
/// once, so a bad setting is an error at load naming its field, not a failed trial.
/// The engine's registry implements it; the format never builds a component itself.
pub trait Catalogue: std::fmt::Debug + Send + Sync + Sized + 'static {
    /// A phase after the pick, built from its settings once when the scenario loads.
    type Phase: Clone + std::fmt::Debug + Send + Sync;

    /// The built-in components, shared: what [`Scenario::load`] checks against.
    fn builtin() -> Arc<Self>;

    /// Builds `spec` once with its settings. Err: the field and why.
    fn check(&self, spec: &ComponentSpec) -> Result<(), SettingsError>;

    /// Builds the localiser `spec` once in `scn`'s world, on its truck.
    fn check_localizer(
        &self,
        spec: &ComponentSpec,
        scn: &Scenario<Self>,
    ) -> Result<(), SettingsError>;

    /// Whether detector `kind`'s settings are the pocket detector's.
    fn detector_takes_pocket_settings(&self, kind: &str) -> bool;

    /// Whether localiser `kind` measures the world's reflectors (so a run may take some
    /// away).
    fn localizer_measures_reflectors(&self, kind: &str) -> bool;

    /// The phases after the pick from the scenario's list (`names`, the pick first) and
    /// `[phase.NAME]` tables, each built against `cx`. Err: the field and why.
    fn phases(
        &self,
        names: &[String],
        settings: &toml::Table,
        cx: &dyn Context,
    ) -> Result<Vec<PhaseSpec<Self::Phase>>, (String, String)>;
}

/// A phase after the pick as a scenario lists it: its name and its `[phase.NAME]`
/// settings, and the phase they build (built once, when the scenario loads).
#[derive(Debug, Clone, Serialize)]
pub struct PhaseSpec<P> {
    pub name: String,
    pub settings: toml::Table,
    /// The built phase (the catalogue's type).
    #[serde(skip)]
    pub phase: P,
}

impl<P> PartialEq for PhaseSpec<P> {
    /// Equal settings build equal phases.
    fn eq(&self, other: &Self) -> bool {
        self.name == other.name && self.settings == other.settings
    }
}

/// What a phase's settings are checked against when the scenario loads: its pallet, the
/// world's slots and stations, and the mission's start.
pub trait Context {
    /// The scenario's pallet.
    fn pallet(&self) -> &PalletSpec;
    /// The pose of the world's pallet slot `name` (its face centre, heading in).
    fn slot_pose(&self, name: &str) -> Option<Pose2>;
    /// The world's pallet slots' names, for messages.
    fn slot_names(&self) -> Vec<String>;
    /// The pose of the world's station `name`.
    fn station_pose(&self, name: &str) -> Option<Pose2>;
    /// The world's stations' names, for messages.
    fn station_names(&self) -> Vec<String>;
    /// The rack or wall (its label) a pallet standing with its face centre at `at` would
    /// overlap; shapes may touch.
    fn pallet_overlaps(&self, at: &Pose2) -> Option<String>;
    /// The mission's start, by name and pose (a return's default destination); `None`:
    /// the scenario has no `[mission]`, whose planner and tracker drive legs.
    fn mission_start(&self) -> Option<(String, Pose2)>;
}
