//! The component registry: planners, trackers, pallet detectors and localisers by name, built from their scenario settings tables.

mod catalogue;

use std::collections::BTreeMap;
use std::sync::{Arc, OnceLock};

use forkbench_core::ForkliftSpec;
use forkbench_core::settings::{Settings, SettingsError};
use forkbench_plan::external::ExternalPlanner;
use forkbench_plan::{BsplinePlanner, Planner, SpiralPlanner};
use forkbench_sensors::detector::{PalletDetector, Pockets};
use forkbench_sensors::external::ExternalDetector;
use forkbench_sensors::reflectors::Reflector;
use forkbench_sensors::scan::Surface;
use forkbench_sensors::{
    Localizer, Nav350, Nav350Config, PalletEstimateConfig, PalletEstimator, ReflectorNav,
    ReflectorNavSettings,
};
use forkbench_track::{
    DelayCompensated, ExternalTracker, PurePursuit, RegulatedPurePursuit, Tracker,
};

pub use forkbench_scenario::{
    ComponentContext, ComponentSpec, DEFAULT_LOCALIZER, POCKET_DETECTOR, Role,
};

type Ctor<T> = Arc<dyn Fn(&Settings, &ComponentContext) -> Result<T, SettingsError> + Send + Sync>;
/// Builds a planner from its settings table.
pub type PlannerCtor = Ctor<Box<dyn Planner>>;
/// Builds a tracker from its settings table.
pub type TrackerCtor = Ctor<Box<dyn Tracker>>;
/// Builds a pallet detector from its settings table.
pub type DetectorCtor = Ctor<Box<dyn PalletDetector>>;
/// Builds a localiser from its settings table and the world it measures.
pub type LocalizerCtor = Arc<
    dyn Fn(&Settings, &LocalizerContext<'_>) -> Result<Box<dyn Localizer>, SettingsError>
        + Send
        + Sync,
>;

/// What a localiser is built in: the world it measures, the truck it rides on, and the
/// scenario's NAV350 rate, latency and Gaussian σ (`[noise.nav350]`).
#[derive(Debug, Clone, Copy)]
pub struct LocalizerContext<'a> {
    pub nav350: &'a Nav350Config,
    /// Sensor noise on (off: exact measurements).
    pub noise: bool,
    /// The run's localisation noise scale (1 unless a run overrides it); only kinds
    /// registered with [`Registry::with_scaled_localizer`] are handed another value.
    pub noise_scale: f64,
    /// The world's reflectors (the device's map).
    pub reflectors: &'a [Reflector],
    /// The world's surfaces (racks and walls hide reflectors).
    pub surfaces: &'a [Surface],
    pub truck: &'a ForkliftSpec,
}
/// Builds the pallet-pose estimator from the scenario's estimate settings.
pub type EstimatorCtor =
    Arc<dyn Fn(&PalletEstimateConfig) -> Box<dyn PalletEstimator> + Send + Sync>;

/// Planners and trackers by name, and the sensor models.
#[derive(Clone)]
pub struct Registry {
    planners: BTreeMap<String, PlannerCtor>,
    trackers: BTreeMap<String, TrackerCtor>,
    detectors: BTreeMap<String, DetectorCtor>,
    localizers: BTreeMap<String, LocalizerCtor>,
    /// Localiser kinds that apply `LocalizerContext::noise_scale`.
    scaled_localizers: std::collections::BTreeSet<String>,
    /// Localiser kinds that measure the world's reflectors (so a run may take some away).
    reflector_localizers: std::collections::BTreeSet<String>,
    /// Detector kinds whose settings are the pocket detector's (`DetectorConfig`).
    pocket_detectors: std::collections::BTreeSet<String>,
    estimator: EstimatorCtor,
    /// The phases a scenario may list after the pick, in registration order.
    phases: Vec<crate::phase::PhaseKind>,
    /// The criteria every pick measures at each step, in the order of blame.
    step_criteria: Vec<crate::step_criteria::StepCtor>,
}

impl std::fmt::Debug for Registry {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Registry")
            .field("planners", &self.planners.keys().collect::<Vec<_>>())
            .field("trackers", &self.trackers.keys().collect::<Vec<_>>())
            .field("detectors", &self.detectors.keys().collect::<Vec<_>>())
            .field("localizers", &self.localizers.keys().collect::<Vec<_>>())
            .field(
                "phases",
                &self.phases.iter().map(|k| &k.name).collect::<Vec<_>>(),
            )
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
            // Delay-compensated: the same trackers steering from the pose predicted over
            // the truck's actuator delay (a Smith predictor).
            .with_tracker("pure_pursuit_compensated", |s, _| {
                let inner = Box::new(PurePursuit::from_settings(s)?);
                Ok(Box::new(DelayCompensated::new(
                    inner,
                    "pure_pursuit_compensated",
                )))
            })
            .with_tracker("regulated_pure_pursuit_compensated", |s, _| {
                let inner = Box::new(RegulatedPurePursuit::from_settings(s)?);
                let name = "regulated_pure_pursuit_compensated";
                Ok(Box::new(DelayCompensated::new(inner, name)))
            })
            .with_tracker("external", |s, cx| {
                Ok(Box::new(ExternalTracker::from_settings(
                    s,
                    cx.dir.clone(),
                    &cx.name,
                )?))
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
            localizers: BTreeMap::new(),
            scaled_localizers: std::collections::BTreeSet::new(),
            reflector_localizers: std::collections::BTreeSet::new(),
            pocket_detectors: std::collections::BTreeSet::new(),
            estimator: Arc::new(|cfg| Box::new(cfg.clone())),
            phases: crate::phase::builtin_phases(),
            step_criteria: crate::step_criteria::STEP_CRITERIA.to_vec(),
        }
        .with_scaled_localizer(DEFAULT_LOCALIZER, |s, cx| {
            forkbench_core::settings::parse::<Empty>(s)?;
            let cfg = Nav350Config {
                position_sigma_m: cx.nav350.position_sigma_m * cx.noise_scale,
                heading_sigma_rad: cx.nav350.heading_sigma_rad * cx.noise_scale,
                ..cx.nav350.clone()
            };
            Ok(Box::new(Nav350::new(cfg, cx.noise)))
        })
        .with_scaled_localizer("nav350", |s, cx| {
            let mut settings: ReflectorNavSettings = forkbench_core::settings::parse(s)?;
            let on_truck = truck_mount(s, cx.truck, &mut settings.mount)?;
            settings.validate(cx.reflectors)?;
            check_mount(&settings.mount, cx.truck).map_err(|e| match on_truck {
                true => SettingsError::field(
                    "mount",
                    format!("the truck's [mount.nav350]: {}", e.reason),
                ),
                false => e,
            })?;
            let timing = (cx.nav350.rate_hz, cx.nav350.latency_s);
            Ok(Box::new(ReflectorNav::new(
                settings,
                cx.reflectors,
                cx.surfaces,
                timing,
                if cx.noise { cx.noise_scale } else { 0.0 },
            )))
        })
        .measuring_reflectors("nav350")
        .with_pocket_settings_detector(POCKET_DETECTOR)
        .with_pocket_settings_detector("face_fit")
        .with_detector(POCKET_DETECTOR, |s, _| {
            let cfg: forkbench_sensors::detect::DetectorConfig =
                forkbench_core::settings::parse(s)?;
            cfg.validate()?;
            Ok(Box::new(Pockets { cfg }))
        })
        .with_detector("face_fit", |s, _| {
            let cfg: forkbench_sensors::detect::DetectorConfig =
                forkbench_core::settings::parse(s)?;
            cfg.validate()?;
            Ok(Box::new(forkbench_sensors::face_fit::FaceFit { cfg }))
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

    /// Adds (or replaces) a localiser kind.
    pub fn with_localizer(
        mut self,
        kind: &str,
        ctor: impl Fn(&Settings, &LocalizerContext<'_>) -> Result<Box<dyn Localizer>, SettingsError>
        + Send
        + Sync
        + 'static,
    ) -> Self {
        self.localizers.insert(kind.to_owned(), Arc::new(ctor));
        self.scaled_localizers.remove(kind);
        self
    }

    /// Adds (or replaces) a localiser kind that applies the run's localisation noise
    /// scale (`LocalizerContext::noise_scale`); a kind added with `with_localizer` is
    /// never handed one, and a run that asks for one is refused.
    pub fn with_scaled_localizer(
        mut self,
        kind: &str,
        ctor: impl Fn(&Settings, &LocalizerContext<'_>) -> Result<Box<dyn Localizer>, SettingsError>
        + Send
        + Sync
        + 'static,
    ) -> Self {
        self = self.with_localizer(kind, ctor);
        self.scaled_localizers.insert(kind.to_owned());
        self
    }

    /// Marks a localiser kind as one that measures the world's reflectors (a run's
    /// `missing_reflectors` acts on it).
    pub fn measuring_reflectors(mut self, kind: &str) -> Self {
        self.reflector_localizers.insert(kind.to_owned());
        self
    }

    /// Whether a localiser kind measures the world's reflectors.
    pub fn localizer_measures_reflectors(&self, kind: &str) -> bool {
        self.reflector_localizers.contains(kind)
    }

    /// Marks a detector kind as one whose settings are the pocket detector's
    /// (`DetectorConfig`), which the sensing's other users (the Gaussian model's detector
    /// for `scan`) take from it.
    pub fn with_pocket_settings_detector(mut self, kind: &str) -> Self {
        self.pocket_detectors.insert(kind.to_owned());
        self
    }

    /// Whether a detector kind's settings are the pocket detector's.
    pub fn detector_takes_pocket_settings(&self, kind: &str) -> bool {
        self.pocket_detectors.contains(kind)
    }

    /// Whether a localiser kind applies a localisation noise scale.
    pub fn localizer_takes_noise_scale(&self, kind: &str) -> bool {
        self.scaled_localizers.contains(kind)
    }

    /// Replaces the pallet-estimate model.
    /// Adds a phase kind a scenario may list after the pick (replacing one of its name).
    pub fn with_phase(mut self, kind: crate::phase::PhaseKind) -> Self {
        self.phases.retain(|k| k.name != kind.name);
        self.phases.push(kind);
        self
    }

    /// Adds a criterion every pick of a scenario on this registry measures at each step,
    /// judged after the ones before it (replacing one of its name, a fixed one's too).
    pub fn with_step_criterion(mut self, ctor: crate::step_criteria::StepCtor) -> Self {
        let name = ctor().name();
        self.step_criteria.retain(|c| c().name() != name);
        self.step_criteria.push(ctor);
        self
    }

    /// The pick's criteria, fresh for one trial, in the order of blame: the fixed ones
    /// ([`crate::step_criteria::PICK_CRITERIA`]), then those that measure at each step.
    pub fn step_criteria(&self) -> Vec<Box<dyn crate::step_criteria::StepCriterion>> {
        self.step_criteria.iter().map(|c| c()).collect()
    }

    /// The phase kinds, in registration order.
    pub fn phase_kinds(&self) -> &[crate::phase::PhaseKind] {
        &self.phases
    }

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
            Role::Localizer => self.localizers.keys().map(String::as_str).collect(),
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
            // On an open floor with the default truck; a scenario checks its localiser
            // against its own world and truck.
            Role::Localizer => {
                let (nav350, truck) = (Nav350Config::default(), ForkliftSpec::default());
                let cx = LocalizerContext {
                    nav350: &nav350,
                    noise: true,
                    noise_scale: 1.0,
                    reflectors: &[],
                    surfaces: &[],
                    truck: &truck,
                };
                self.localizer(spec, &cx).map(drop)
            }
        }
    }

    pub fn localizer(
        &self,
        spec: &ComponentSpec,
        cx: &LocalizerContext<'_>,
    ) -> Result<Box<dyn Localizer>, SettingsError> {
        let ctor = self
            .localizers
            .get(&spec.kind)
            .ok_or_else(|| self.unknown(Role::Localizer, &spec.kind))?;
        ctor(&spec.settings, cx)
    }

    pub fn estimator(&self, cfg: &PalletEstimateConfig) -> Box<dyn PalletEstimator> {
        (self.estimator)(cfg)
    }
}

/// A settings table that must be empty (a kind configured elsewhere).
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct Empty {}

/// The NAV350's mount from the truck into `mount`, when the truck gives one (true);
/// refused beside the localiser's own `mount` (one place says where it sits).
fn truck_mount(
    s: &forkbench_core::Settings,
    truck: &ForkliftSpec,
    mount: &mut forkbench_core::Pose2,
) -> Result<bool, SettingsError> {
    let name = forkbench_sensors::reflector_nav::MOUNT_NAME;
    let Some(m) = truck.mounts.get(name) else {
        return Ok(false);
    };
    if s.contains_key("mount") {
        return Err(SettingsError::field(
            "mount",
            forkbench_core::mounts::mounted_twice(name),
        ));
    }
    *mount = *m;
    Ok(true)
}

/// A localiser's mount on the truck: over its body or at the fork root (fork-root frame:
/// the body spans x from −length to 0, y within ± half its width).
fn check_mount(m: &forkbench_core::Pose2, truck: &ForkliftSpec) -> Result<(), SettingsError> {
    let half = truck.body_width_m / 2.0;
    if (-truck.body_length_m..=0.0).contains(&m.x_m) && m.y_m.abs() <= half {
        return Ok(());
    }
    Err(SettingsError::field(
        "mount",
        format!(
            "({}, {}) m lies outside the truck (fork-root frame: the body spans x from -{} to \
             0 m, y within ±{half} m)",
            m.x_m, m.y_m, truck.body_length_m
        ),
    ))
}
