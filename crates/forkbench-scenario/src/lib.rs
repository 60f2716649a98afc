//! Scenario and world files (TOML, unknown fields rejected), validated into SI-unit cases before any simulation; the components they name are checked through a [`Catalogue`].

mod catalogue;
mod checks;
pub mod clutter;
mod component_spec;
mod error;
mod file;
pub mod footprints;
pub mod fork_play;
mod hints;
mod input;
mod limits;
mod load;
pub mod mission;
mod named;
mod pallet;
mod phases;
pub mod pose_deg;
mod runs;
mod safety;
pub mod sensors;
pub mod text;
pub mod tolerances;
pub mod truck_file;
pub mod uncertain;
pub mod uncertain_file;
mod world;

use std::path::{Path as FsPath, PathBuf};
use std::sync::Arc;

use forkbench_core::{ForkliftSpec, PalletSpec, Pose2};
use forkbench_sim::SimConfig;
use serde::Serialize;

pub use catalogue::{Catalogue, Context, PICK, PhaseSpec};
pub use checks::{ForkFit, fork_fit};
pub use component_spec::{
    ComponentContext, ComponentSpec, DEFAULT_LOCALIZER, POCKET_DETECTOR, Role,
};
pub use error::ScenarioError;
pub use file::{
    APPROACH_GAP_M, BetweenLooks, INSERTION_MARGIN_M, MAST_MARGIN_M, NoiseFile, PalletKind,
    PalletPlacement, PickFile, ReplanFile, ReplanMethod, WhenNotSeen, default_insertion_m,
};
pub use footprints::{pallet_footprint, shrunk, truck_footprint};
pub use limits::Replan;
pub use named::{BESIDE as COMPONENTS_BESIDE, load_components};
pub use pose_deg::{MAX_WORLD_EXTENT_M, PoseDeg};
pub use tolerances::{Limits, Tolerances};
pub use truck_file::{TruckSettings, apply_truck, read_truck_file, read_truck_text};
pub use world::{PalletSlot, RectFile, World};

use checks::{check_values, resolve_cases};
use file::ScenarioFile;

/// Most cases one scenario file may list.
pub const MAX_CASES: usize = 10_000;

/// The error of `field` in `file` (`file:line` where known), and why.
pub fn invalid(file: &str, field: &str, reason: &str) -> ScenarioError {
    ScenarioError::Invalid {
        file: file.to_owned(),
        field: field.to_owned(),
        reason: reason.to_owned(),
    }
}

/// A component's settings error under the scenario table it came from (`prefix`).
pub fn invalid_setting(
    file: &str,
    prefix: &str,
    e: &forkbench_core::SettingsError,
) -> ScenarioError {
    let field = match &e.field {
        Some(f) => format!("{prefix}.{f}"),
        None => prefix.to_owned(),
    };
    invalid(file, &field, &e.reason)
}

/// Longest simulated trial a scenario may ask for: bounds the steps one trial takes.
pub const MAX_TIMEOUT_S: f64 = 600.0;

pub use input::MAX_INPUT_BYTES;
use input::{parse, read};

/// A loaded, validated scenario file (serialisable: a batch's manifest records it whole),
/// its components checked against the catalogue `R`.
#[derive(Debug, Clone, Serialize)]
#[serde(bound = "")]
pub struct Scenario<R: Catalogue> {
    pub file: String,
    pub name: String,
    pub description: String,
    pub planner: ComponentSpec,
    pub tracker: ComponentSpec,
    /// Builds the components this scenario names (and any a run asks for by name).
    #[serde(skip)]
    pub registry: Arc<R>,
    /// Components defined by name in a components file, usable with `--planner` and
    /// `--tracker` (a manifest fingerprints the ones a batch uses).
    #[serde(skip)]
    named: Vec<ComponentSpec>,
    pub seed: u64,
    pub pallet: PalletSpec,
    /// How the scenario names its pallet (`pallet_kind epal-1`, `pallet_model NAME`);
    /// the geometry in `pallet` is what a run and a manifest use.
    #[serde(skip)]
    pub pallet_kind: String,
    pub timeout_s: f64,
    /// Plans whose swept truck body hits a rack or wall count as `plan_failed`.
    pub validate_paths: bool,
    pub truck: ForkliftSpec,
    pub sim: SimConfig,
    pub noise: NoiseFile,
    pub replan: Replan,
    /// Staging and looking when the face is not seen from where the pick begins.
    pub pick: PickFile,
    pub tolerances: Limits,
    /// How the pallet is estimated; the Gaussian default is left out of manifests, so
    /// scenarios without `[sensors]` keep their settings hash.
    #[serde(skip_serializing_if = "sensors::PalletSensing::is_gaussian")]
    pub pallet_sensing: sensors::PalletSensing,
    /// The localiser (`[sensors.localizer]`); the Gaussian default is left out of
    /// manifests for the same reason.
    #[serde(skip_serializing_if = "is_gaussian_localizer")]
    pub localizer: ComponentSpec,
    /// Fixed pallet-estimate error in the pallet frame.
    pub estimate_bias: Pose2,
    /// σ of the per-trial jitter of the true pallet pose (pallet frame; heading in rad).
    pub pallet_jitter: Pose2,
    pub world: World,
    pub cases: Vec<Case>,
    /// Legs driven before the pick: the truck starts at the mission's start and each
    /// case's start is the staging pose the last leg ends at.
    pub mission: Option<mission::MissionSpec>,
    /// The phases after the pick, in order (none: the trial is the pick).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub phases: Vec<PhaseSpec<R::Phase>>,
    /// How the truck's safety fields are sized (`[safety]`; none: the defaults, and the
    /// settings hash of scenarios without it is kept).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub safety: Option<forkbench_safety::SafetyConfig>,
    /// People and other vehicles on routes through the world (`[[mover]]`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub movers: Vec<forkbench_safety::MoverSpec>,
    /// Settings each trial draws (`[[uncertain]]`).
    #[serde(skip_serializing_if = "uncertain::UncertainSet::is_empty")]
    pub uncertain: uncertain::UncertainSet,
    /// Likely slips the file is still valid with (radians in a degrees key), as
    /// `file:line: …`; front ends print them.
    #[serde(skip)]
    pub warnings: Vec<String>,
    /// The text it was read from and its folder: what [`Scenario::with_truck`] checks a
    /// run's truck against.
    #[serde(skip)]
    source: Option<Arc<String>>,
    /// The files it was read from (its own, the world's, the truck's, components files):
    /// what no output of a run may replace.
    #[serde(skip)]
    read_from: Vec<PathBuf>,
}

/// One start/pallet geometry of a scenario.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Case {
    pub name: String,
    /// Fork-root start pose.
    pub start: Pose2,
    /// Pallet front-face centre, heading into the pallet.
    pub pallet: Pose2,
}

impl<R: Catalogue> Scenario<R> {
    /// Parses scenario text; `load_world` resolves the `world` path. Components are built
    /// from the built-in registry, external commands run in the working directory.
    pub fn parse(
        text: &str,
        file: &str,
        load_world: impl FnOnce(&FsPath) -> Result<World, ScenarioError>,
    ) -> Result<Self, ScenarioError> {
        Self::parse_with(text, file, load_world, R::builtin())
    }

    /// As [`Scenario::parse`], with a registry that may hold the caller's own components
    /// and phases.
    pub fn parse_with(
        text: &str,
        file: &str,
        load_world: impl FnOnce(&FsPath) -> Result<World, ScenarioError>,
        registry: Arc<R>,
    ) -> Result<Self, ScenarioError> {
        let load_truck = |p: &str| truck_file::read_truck_file(FsPath::new(p));
        let s = Self::parse_layout(text, file, load_world, &load_truck, None)?;
        s.with_components(text, registry, PathBuf::from("."))
    }

    /// Reads the `[planner]` and `[tracker]` tables against `registry`; errors name the
    /// file, line and field.
    fn with_components(
        mut self,
        text: &str,
        registry: Arc<R>,
        dir: PathBuf,
    ) -> Result<Self, ScenarioError> {
        let f: ScenarioFile = parse(text, &self.file)?;
        let pure_pursuit = Some("pure_pursuit");
        let planner = Some(&f.planner);
        for (role, value, default_kind) in [
            (Role::Planner, planner, None),
            (Role::Tracker, f.tracker.as_ref(), pure_pursuit),
        ] {
            let spec = match value {
                Some(v) => ComponentSpec::from_value(role, v.get_ref(), default_kind, dir.clone())
                    .and_then(|spec| registry.check(&spec).map(|()| spec))
                    .map_err(|e| component_error(&self.file, text, role, v.span(), &e))?,
                None => ComponentSpec::of_kind(role, "pure_pursuit"),
            };
            if role == Role::Planner {
                self.planner = spec;
            } else {
                self.tracker = spec;
            }
        }
        let localizer = f.sensors.as_ref().and_then(|s| s.localizer.as_ref());
        if let Some(v) = localizer {
            self.localizer =
                ComponentSpec::from_value(Role::Localizer, v.get_ref(), None, dir.clone())
                    .and_then(|spec| registry.check_localizer(&spec, &self).map(|()| spec))
                    .map_err(|e| localizer_error(&self.file, text, v.span(), &e))?;
        }
        if let sensors::PalletSensing::Scanner { detector, .. } = &mut self.pallet_sensing {
            detector.dir = dir;
            registry
                .check(detector)
                .map_err(|e| invalid_setting(&self.file, "sensors.pallet.detector", &e))?;
        }
        self.phases = phases::resolve(
            &f,
            (&self.world, &self.pallet, self.mission.as_ref()),
            (text, &self.file),
            &*registry,
        )?;
        self.registry = registry;
        Ok(self)
    }

    /// Everything but the components: world, truck, sensors, settings and cases; a
    /// truck file is read by `load_truck`, and `truck` (a run's) stands for the file's own.
    fn parse_layout(
        text: &str,
        file: &str,
        load_world: impl FnOnce(&FsPath) -> Result<World, ScenarioError>,
        load_truck: &dyn Fn(&str) -> Result<TruckSettings, ScenarioError>,
        truck: Option<&ForkliftSpec>,
    ) -> Result<Self, ScenarioError> {
        let mut f: ScenarioFile = parse(text, file)?;
        f.truck = match truck {
            Some(t) => t.clone(),
            None => truck_file::resolve_entry(f.truck_entry.as_ref(), load_truck, (file, text))?,
        };
        let world = match &f.world {
            Some(p) => load_world(p).map_err(|e| {
                invalid(
                    file,
                    "world",
                    &format!("{} could not be loaded: {e}", p.display()),
                )
            })?,
            None => World::default(),
        };
        check_values(&f, file)?;
        let (pallet, pallet_label) = pallet::resolve(&f, (file, text))?;
        checks::check_payload(&f.truck, &pallet, (file, text))?;
        safety::check(&f, (file, text))?;
        safety::check_movers(&f, &world, (file, text))?;
        let short_target = checks::check_geometry(&f, (&pallet, &pallet_label), file)?;
        let wide_tolerance =
            fork_play::wide_tolerance(f.tolerances.lateral_m, &f.truck, (&pallet, &pallet_label))
                .map(|w| format!("{file}: {w}"));
        pallet::check_thickness(&f, (&pallet, &pallet_label), file)?;
        let cases = cases_of(&f, (&world, &pallet), (file, text))?;
        let mission = match &f.mission {
            Some(m) => Some(m.resolve(&world, file)?),
            None => None,
        };
        let zero = Pose2::new(0.0, 0.0, 0.0);
        let pallet_sensing = sensors::resolve(f.sensors.as_ref(), &f.truck, file)?;
        let uncertain = uncertain_file::resolve(&f.uncertain, &f.mover, (file, text))?;
        uncertain_file::check_sensing(&uncertain, pallet_sensing.is_gaussian(), file)?;
        Ok(Scenario {
            file: file.to_owned(),
            name: f.name,
            description: f.description,
            planner: ComponentSpec::of_kind(Role::Planner, "bspline"),
            tracker: ComponentSpec::of_kind(Role::Tracker, "pure_pursuit"),
            registry: R::builtin(),
            named: Vec::new(),
            seed: f.seed,
            pallet,
            pallet_kind: pallet_label,
            timeout_s: f.timeout_s,
            validate_paths: f.validate_paths,
            truck: f.truck,
            sim: f.sim,
            noise: f.noise,
            replan: f.replan.into(),
            pick: f.pick,
            tolerances: f.tolerances.into(),
            pallet_sensing,
            localizer: ComponentSpec::of_kind(Role::Localizer, DEFAULT_LOCALIZER),
            estimate_bias: f.estimate_bias.map_or(zero, PoseDeg::to_pose),
            pallet_jitter: f.pallet_jitter.map_or(zero, PoseDeg::to_pose),
            world,
            cases,
            mission,
            phases: Vec::new(),
            safety: f.safety,
            movers: f.mover,
            uncertain,
            warnings: hints::unit_warnings(text, file)
                .into_iter()
                .chain(short_target)
                .chain(wide_tolerance)
                .collect(),
            source: Some(Arc::new(text.to_owned())),
            read_from: Vec::new(),
        })
    }

    /// The same scenario estimating the pallet with `kind` (`gaussian`, `tim561`,
    /// `kinect2`, `tim561+kinect2`) at its default settings and the pocket detector: how
    /// a run compares sensing models on the same seeds.
    pub fn with_pallet_sensing(mut self, kind: &str) -> Result<Self, ScenarioError> {
        self.pallet_sensing = self.sensing_for(Some(kind))?;
        Ok(self)
    }

    /// How this scenario's forks fit its pallet (checked at load; printed by `check`).
    pub fn fork_fit(&self) -> ForkFit {
        fork_fit(
            &self.truck,
            &self.pallet,
            self.tolerances.insertion_depth_m,
            self.insertion_m(),
        )
    }

    /// How deep the pick drives the fork tips past the face (`[pick] insertion_m`, or the
    /// default from the forks and the pallet).
    pub fn insertion_m(&self) -> f64 {
        self.pick.insertion_for(&self.truck, &self.pallet)
    }

    pub fn case(&self, name: &str) -> Result<&Case, ScenarioError> {
        self.cases
            .iter()
            .find(|c| c.name == name)
            .ok_or_else(|| ScenarioError::UnknownCase {
                file: self.file.clone(),
                case: name.to_owned(),
                known: self.case_names(),
            })
    }

    /// The case a run asked for: the one named, or the only one (naming none of several
    /// is [`ScenarioError::CaseNeeded`]).
    pub fn pick_case(&self, name: Option<&str>) -> Result<&Case, ScenarioError> {
        match (name, self.cases.as_slice()) {
            (Some(n), _) => self.case(n),
            (None, [only]) => Ok(only),
            (None, all) => Err(ScenarioError::CaseNeeded {
                file: self.file.clone(),
                count: all.len(),
                known: self.case_names(),
            }),
        }
    }

    /// The cases' names, comma-separated.
    fn case_names(&self) -> String {
        self.cases
            .iter()
            .map(|c| c.name.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// The file's cases resolved; a missing key's error says where it may have landed.
fn cases_of(
    f: &ScenarioFile,
    (world, pallet): (&World, &PalletSpec),
    (file, text): (&str, &str),
) -> Result<Vec<Case>, ScenarioError> {
    resolve_cases(f, world, pallet, file).map_err(|e| match e {
        ScenarioError::Invalid {
            file,
            field,
            reason,
        } if reason == "missing" => {
            let key = field.rsplit('.').next().unwrap_or(&field);
            let hint = hints::misplaced_key(text, &format!("missing field `{key}`"), None);
            ScenarioError::Invalid {
                file,
                field,
                reason: hint.map_or(reason, |h| format!("missing; {h}")),
            }
        }
        e => e,
    })
}

fn is_gaussian_localizer(spec: &ComponentSpec) -> bool {
    spec.kind == DEFAULT_LOCALIZER && spec.settings.is_empty()
}

/// A `[sensors.localizer]` error at its line, its field under `sensors.`.
fn localizer_error(
    file: &str,
    text: &str,
    span: std::ops::Range<usize>,
    e: &forkbench_core::SettingsError,
) -> ScenarioError {
    match component_error(file, text, Role::Localizer, span, e) {
        ScenarioError::Invalid {
            file,
            field,
            reason,
        } => ScenarioError::Invalid {
            file,
            field: format!("sensors.{field}"),
            reason,
        },
        other => other,
    }
}

/// A component table's error at the line of the offending key (or of the table).
fn component_error(
    file: &str,
    text: &str,
    role: Role,
    span: std::ops::Range<usize>,
    e: &forkbench_core::SettingsError,
) -> ScenarioError {
    // A table's span may cover only its header: search on to the next table header.
    let rest = text.get(span.start..).unwrap_or("");
    let end = rest
        .match_indices('\n')
        .map(|(i, _)| i + 1)
        .find(|&i| rest[i..].trim_start().starts_with('['))
        .unwrap_or(rest.len())
        .max(span.len().min(rest.len()));
    let region = &rest[..end];
    let key_at = e.field.as_deref().and_then(|k| {
        let mut at = 0;
        region.split_inclusive('\n').find_map(|l| {
            let here = at;
            at += l.len();
            let t = l.trim_start();
            let key = t.split(['=', ' ', '\t']).next().unwrap_or("");
            // A nested field (`measurement.range_sigma_m`) is at its outer key's line.
            let k = k.split('.').next().unwrap_or(k);
            (key == k || key.trim_matches('"') == k).then_some(here)
        })
    });
    let offset = span.start + key_at.unwrap_or(0);
    let line = text[..offset.min(text.len())].matches('\n').count() + 1;
    let field = match &e.field {
        Some(f) => format!("{role}.{f}"),
        None => role.to_string(),
    };
    ScenarioError::Invalid {
        file: format!("{file}:{line}"),
        field,
        reason: e.reason.clone(),
    }
}
