//! The component registry: planners, trackers and pallet detectors by name, built from their scenario settings tables.

mod spec;

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::{Arc, OnceLock};

use forkbench_core::settings::{Settings, SettingsError};
use forkbench_plan::external::ExternalPlanner;
use forkbench_plan::{BsplinePlanner, Planner, SpiralPlanner};
use forkbench_sensors::detector::{PalletDetector, Pockets};
use forkbench_sensors::external::ExternalDetector;
use forkbench_sensors::{Localizer, Nav350, Nav350Config, PalletEstimateConfig, PalletEstimator};
use forkbench_track::{PurePursuit, RegulatedPurePursuit, Tracker};

pub use spec::{ComponentSpec, Role};

/// What a constructor knows besides the settings: the component's name and where the
/// defining file lives.
#[derive(Debug, Clone, Default)]
pub struct ComponentContext {
    /// What results are reported under (the table's `name`, or its kind).
    pub name: String,
    /// Directory of the scenario file that configured the component.
    pub dir: PathBuf,
}

type Ctor<T> = Arc<dyn Fn(&Settings, &ComponentContext) -> Result<T, SettingsError> + Send + Sync>;
/// Builds a planner from its settings table.
pub type PlannerCtor = Ctor<Box<dyn Planner>>;
/// Builds a tracker from its settings table.
pub type TrackerCtor = Ctor<Box<dyn Tracker>>;
/// Builds a pallet detector from its settings table.
pub type DetectorCtor = Ctor<Box<dyn PalletDetector>>;
/// Builds the localisation sensor from the scenario's NAV350 settings (noise on or off).
pub type LocalizerCtor = Arc<dyn Fn(&Nav350Config, bool) -> Box<dyn Localizer> + Send + Sync>;
/// Builds the pallet-pose estimator from the scenario's estimate settings.
pub type EstimatorCtor =
    Arc<dyn Fn(&PalletEstimateConfig) -> Box<dyn PalletEstimator> + Send + Sync>;

/// Planners and trackers by name, and the sensor models.
#[derive(Clone)]
pub struct Registry {
    planners: BTreeMap<String, PlannerCtor>,
    trackers: BTreeMap<String, TrackerCtor>,
    detectors: BTreeMap<String, DetectorCtor>,
    localizer: LocalizerCtor,
    estimator: EstimatorCtor,
}

impl std::fmt::Debug for Registry {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Registry")
            .field("planners", &self.planners.keys().collect::<Vec<_>>())
            .field("trackers", &self.trackers.keys().collect::<Vec<_>>())
            .field("detectors", &self.detectors.keys().collect::<Vec<_>>())
            .finish_non_exhaustive()
    }
}

impl Registry {
    /// The components forkbench ships. A new one is one line here.
    pub fn builtin() -> Self {
        Self::sensors_only()
            .with_planner("bspline", |s, _| {
                Ok(Box::new(BsplinePlanner::from_settings(s)?))
            })
            .with_planner("spiral", |s, _| {
                Ok(Box::new(SpiralPlanner::from_settings(s)?))
            })
            .with_planner("external", |s, cx| {
                Ok(Box::new(
                    ExternalPlanner::from_settings(s, cx.dir.clone())?.named(&cx.name),
                ))
            })
            .with_tracker("pure_pursuit", |s, _| {
                Ok(Box::new(PurePursuit::from_settings(s)?))
            })
            .with_tracker("regulated_pure_pursuit", |s, _| {
                Ok(Box::new(RegulatedPurePursuit::from_settings(s)?))
            })
    }

    /// The built-in registry, shared.
    pub fn shared() -> Arc<Registry> {
        static BUILTIN: OnceLock<Arc<Registry>> = OnceLock::new();
        Arc::clone(BUILTIN.get_or_init(|| Arc::new(Self::builtin())))
    }

    /// No planners or trackers; the NAV350, the range-scaled pallet estimate, and the
    /// pallet detectors (the pocket detector and `external`).
    pub fn sensors_only() -> Self {
        Self {
            planners: BTreeMap::new(),
            trackers: BTreeMap::new(),
            detectors: BTreeMap::new(),
            localizer: Arc::new(|cfg, noise| Box::new(Nav350::new(cfg.clone(), noise))),
            estimator: Arc::new(|cfg| Box::new(cfg.clone())),
        }
        .with_detector("pockets", |s, _| {
            Ok(Box::new(Pockets {
                cfg: forkbench_core::settings::parse(s)?,
            }))
        })
        .with_detector("external", |s, cx| {
            Ok(Box::new(ExternalDetector::from_settings(
                s,
                cx.dir.clone(),
                &cx.name,
            )?))
        })
    }

    /// Adds (or replaces) a planner kind.
    pub fn with_planner(
        mut self,
        kind: &str,
        ctor: impl Fn(&Settings, &ComponentContext) -> Result<Box<dyn Planner>, SettingsError>
        + Send
        + Sync
        + 'static,
    ) -> Self {
        self.planners.insert(kind.to_owned(), Arc::new(ctor));
        self
    }

    /// Adds (or replaces) a tracker kind.
    pub fn with_tracker(
        mut self,
        kind: &str,
        ctor: impl Fn(&Settings, &ComponentContext) -> Result<Box<dyn Tracker>, SettingsError>
        + Send
        + Sync
        + 'static,
    ) -> Self {
        self.trackers.insert(kind.to_owned(), Arc::new(ctor));
        self
    }

    /// Adds (or replaces) a pallet detector kind.
    pub fn with_detector(
        mut self,
        kind: &str,
        ctor: impl Fn(&Settings, &ComponentContext) -> Result<Box<dyn PalletDetector>, SettingsError>
        + Send
        + Sync
        + 'static,
    ) -> Self {
        self.detectors.insert(kind.to_owned(), Arc::new(ctor));
        self
    }

    /// Replaces the localisation sensor model.
    pub fn with_localizer(mut self, ctor: LocalizerCtor) -> Self {
        self.localizer = ctor;
        self
    }

    /// Replaces the pallet-estimate model.
    pub fn with_estimator(mut self, ctor: EstimatorCtor) -> Self {
        self.estimator = ctor;
        self
    }

    /// Registered kinds of a role, sorted.
    pub fn kinds(&self, role: Role) -> Vec<&str> {
        match role {
            Role::Planner => self.planners.keys().map(String::as_str).collect(),
            Role::Tracker => self.trackers.keys().map(String::as_str).collect(),
            Role::Detector => self.detectors.keys().map(String::as_str).collect(),
        }
    }

    fn unknown(&self, role: Role, kind: &str) -> SettingsError {
        SettingsError::field(
            "kind",
            format!(
                "unknown {role} {kind:?} (known: {})",
                self.kinds(role).join(", ")
            ),
        )
    }

    pub fn planner(&self, spec: &ComponentSpec) -> Result<Box<dyn Planner>, SettingsError> {
        let ctor = self
            .planners
            .get(&spec.kind)
            .ok_or_else(|| self.unknown(Role::Planner, &spec.kind))?;
        ctor(&spec.settings, &spec.context())
    }

    pub fn tracker(&self, spec: &ComponentSpec) -> Result<Box<dyn Tracker>, SettingsError> {
        let ctor = self
            .trackers
            .get(&spec.kind)
            .ok_or_else(|| self.unknown(Role::Tracker, &spec.kind))?;
        ctor(&spec.settings, &spec.context())
    }

    pub fn detector(&self, spec: &ComponentSpec) -> Result<Box<dyn PalletDetector>, SettingsError> {
        let ctor = self
            .detectors
            .get(&spec.kind)
            .ok_or_else(|| self.unknown(Role::Detector, &spec.kind))?;
        ctor(&spec.settings, &spec.context())
    }

    /// Checks a spec by building it once (external planners start no process for this).
    pub fn check(&self, spec: &ComponentSpec) -> Result<(), SettingsError> {
        match spec.role {
            Role::Planner => self.planner(spec).map(drop),
            Role::Tracker => self.tracker(spec).map(drop),
            Role::Detector => self.detector(spec).map(drop),
        }
    }

    pub fn localizer(&self, cfg: &Nav350Config, noise: bool) -> Box<dyn Localizer> {
        (self.localizer)(cfg, noise)
    }

    pub fn estimator(&self, cfg: &PalletEstimateConfig) -> Box<dyn PalletEstimator> {
        (self.estimator)(cfg)
    }
}
