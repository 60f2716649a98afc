//! Scenario and world files (TOML, unknown fields rejected), validated into SI-unit cases before any simulation.

use std::path::{Path as FsPath, PathBuf};

use forkbench_core::{ForkliftSpec, Pose2};
use forkbench_geom::{Footprint, Obstacles};
use std::sync::Arc;

use forkbench_sensors::{Nav350Config, PalletEstimateConfig};
use forkbench_sim::{Obstacle, PalletSpec, SimConfig};
use serde::{Deserialize, Serialize};

use crate::TrialError;
use crate::components::{ComponentSpec, Registry, Role};

/// A pose as written in files: metres and degrees.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PoseDeg {
    pub x_m: f64,
    pub y_m: f64,
    pub heading_deg: f64,
}

impl PoseDeg {
    pub fn to_pose(self) -> Pose2 {
        Pose2::new(self.x_m, self.y_m, self.heading_deg.to_radians())
    }

    fn check(&self, file: &str, field: &str) -> Result<(), TrialError> {
        for (name, v) in [
            ("x_m", self.x_m),
            ("y_m", self.y_m),
            ("heading_deg", self.heading_deg),
        ] {
            if !v.is_finite() {
                return Err(invalid(
                    file,
                    &format!("{field}.{name}"),
                    "must be a finite number",
                ));
            }
        }
        for (name, v) in [("x_m", self.x_m), ("y_m", self.y_m)] {
            if v.abs() > MAX_WORLD_EXTENT_M {
                return Err(invalid(
                    file,
                    &format!("{field}.{name}"),
                    "lies beyond ±10 km: the world's extent is bounded so one trial's work is",
                ));
            }
        }
        if self.heading_deg.abs() > 1e4 {
            return Err(invalid(
                file,
                &format!("{field}.heading_deg"),
                "must lie within ±10000°",
            ));
        }
        Ok(())
    }
}

/// Largest |x| or |y| anywhere in a world or scenario file.
pub const MAX_WORLD_EXTENT_M: f64 = 1e4;

/// Most cases one scenario file may list.
pub const MAX_CASES: usize = 10_000;

fn invalid(file: &str, field: &str, reason: &str) -> TrialError {
    TrialError::Invalid {
        file: file.to_owned(),
        field: field.to_owned(),
        reason: reason.to_owned(),
    }
}

/// A fixed rectangle in a world file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RectFile {
    #[serde(default)]
    pub name: String,
    pub x_m: f64,
    pub y_m: f64,
    #[serde(default)]
    pub heading_deg: f64,
    pub length_m: f64,
    pub width_m: f64,
}

/// A named place a pallet can stand (face centre, heading into the pallet).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PalletSlot {
    pub name: String,
    pub x_m: f64,
    pub y_m: f64,
    pub heading_deg: f64,
}

/// A warehouse layout.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct World {
    pub name: String,
    #[serde(default)]
    pub description: String,
    #[serde(default)]
    pub rack: Vec<RectFile>,
    #[serde(default)]
    pub wall: Vec<RectFile>,
    #[serde(default)]
    pub pallet_slot: Vec<PalletSlot>,
}

/// Longest simulated trial a scenario may ask for: bounds the steps one trial takes.
pub const MAX_TIMEOUT_S: f64 = 600.0;

/// Largest scenario or world file read: far above any real one, and a bound on what a
/// wrong path (a device, a huge file) can make the loader read.
pub const MAX_INPUT_BYTES: u64 = 4 << 20;

/// Longest parse message passed on: toml quotes the offending input, which for a
/// pathological file can be most of it.
const MAX_MESSAGE_CHARS: usize = 2000;

fn read(path: &FsPath) -> Result<String, TrialError> {
    use std::io::Read as _;
    let err = |cause| TrialError::Read {
        file: path.display().to_string(),
        cause,
    };
    let file = std::fs::File::open(path).map_err(err)?;
    let mut text = String::new();
    file.take(MAX_INPUT_BYTES + 1)
        .read_to_string(&mut text)
        .map_err(err)?;
    if text.len() as u64 > MAX_INPUT_BYTES {
        return Err(TrialError::Parse {
            file: path.display().to_string(),
            message: format!("larger than {MAX_INPUT_BYTES} bytes; not a scenario or world file"),
        });
    }
    Ok(text)
}

fn parse<T: serde::de::DeserializeOwned>(text: &str, file: &str) -> Result<T, TrialError> {
    toml::from_str(text).map_err(|e| {
        let mut message = e.to_string().trim_end().to_owned();
        if message.chars().count() > MAX_MESSAGE_CHARS {
            message = message.chars().take(MAX_MESSAGE_CHARS).collect::<String>() + " …";
        }
        TrialError::Parse {
            file: file.to_owned(),
            message,
        }
    })
}

impl World {
    pub fn load(path: &FsPath) -> Result<Self, TrialError> {
        let file = path.display().to_string();
        Self::parse(&read(path)?, &file)
    }

    pub fn parse(text: &str, file: &str) -> Result<Self, TrialError> {
        let w: World = parse(text, file)?;
        for (kind, list) in [("rack", &w.rack), ("wall", &w.wall)] {
            for (i, r) in list.iter().enumerate() {
                let f = format!("{kind}[{i}]");
                PoseDeg {
                    x_m: r.x_m,
                    y_m: r.y_m,
                    heading_deg: r.heading_deg,
                }
                .check(file, &f)?;
                for (name, v) in [("length_m", r.length_m), ("width_m", r.width_m)] {
                    if !(v.is_finite() && v > 0.0 && v <= MAX_WORLD_EXTENT_M) {
                        return Err(invalid(
                            file,
                            &format!("{f}.{name}"),
                            "must be a positive length of at most 10 km",
                        ));
                    }
                }
            }
        }
        for (i, s) in w.pallet_slot.iter().enumerate() {
            PoseDeg {
                x_m: s.x_m,
                y_m: s.y_m,
                heading_deg: s.heading_deg,
            }
            .check(file, &format!("pallet_slot[{i}]"))?;
        }
        Ok(w)
    }

    /// Racks and walls for the footprint checker, with a label per obstacle for messages.
    pub fn footprint_obstacles(&self) -> (Obstacles, Vec<String>) {
        let mut obstacles = Obstacles::new();
        let mut labels = Vec::new();
        for (kind, list) in [("rack", &self.rack), ("wall", &self.wall)] {
            for r in list {
                obstacles.add_rect(
                    &Pose2::new(r.x_m, r.y_m, r.heading_deg.to_radians()),
                    r.length_m,
                    r.width_m,
                );
                labels.push(if r.name.is_empty() {
                    kind.to_owned()
                } else {
                    format!("{kind} {:?}", r.name)
                });
            }
        }
        (obstacles, labels)
    }

    /// Racks and walls as simulator obstacles.
    pub fn obstacles(&self) -> Vec<Obstacle> {
        self.rack
            .iter()
            .chain(&self.wall)
            .map(|r| Obstacle {
                centre: Pose2::new(r.x_m, r.y_m, r.heading_deg.to_radians()),
                length_m: r.length_m,
                width_m: r.width_m,
            })
            .collect()
    }
}

/// Where the pallet stands: a pose, or a slot of the world.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum PalletPlacement {
    Slot { slot: String },
    Pose(PoseDeg),
}

/// Which pallet.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum PalletKind {
    /// 1.2 × 1.2 m, 0.405 m pockets (the field test).
    #[serde(rename = "field-1200")]
    Field1200,
    /// 1.0 × 1.0 m (the papers' simulations).
    #[serde(rename = "sim-1000")]
    Sim1000,
}

/// Success tolerances of a pick.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Tolerances {
    /// Fork-root offset from the pocket centre line at entry.
    pub lateral_m: f64,
    pub heading_deg: f64,
    /// Required fork insertion (tips past the pallet face).
    pub insertion_depth_m: f64,
    /// Fork–pallet contact force allowed before full depth.
    pub contact_force_n: f64,
    pub pallet_displacement_m: f64,
    pub pallet_rotation_deg: f64,
}

impl Default for Tolerances {
    fn default() -> Self {
        Self {
            // 0.15 m forks in 0.405 m pockets leave ±0.1275 m; keep a margin for the
            // heading error's contribution along the fork.
            lateral_m: 0.10,
            heading_deg: 3.0,
            insertion_depth_m: 1.0,
            contact_force_n: 200.0,
            pallet_displacement_m: 0.02,
            pallet_rotation_deg: 1.0,
        }
    }
}

/// Sensor noise settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct NoiseFile {
    pub enabled: bool,
    pub nav350: Nav350Config,
    pub pallet_estimate: PalletEstimateConfig,
}

impl Default for NoiseFile {
    fn default() -> Self {
        Self {
            enabled: true,
            nav350: Nav350Config::default(),
            pallet_estimate: PalletEstimateConfig::default(),
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
}

impl Default for ReplanFile {
    fn default() -> Self {
        Self {
            enabled: false,
            position_threshold_m: 0.02,
            heading_threshold_deg: 1.0,
        }
    }
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct CaseFile {
    name: String,
    start: Option<PoseDeg>,
    pallet: Option<PalletPlacement>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ScenarioFile {
    name: String,
    #[serde(default)]
    description: String,
    /// World file, relative to this scenario file; none is an open floor.
    world: Option<PathBuf>,
    /// `planner = "bspline"` or a `[planner]` table with `kind` and its settings.
    planner: toml::Spanned<toml::Value>,
    #[serde(default)]
    seed: u64,
    #[serde(default = "default_pallet_kind")]
    pallet_kind: PalletKind,
    #[serde(default = "default_timeout")]
    timeout_s: f64,
    /// Refuse plans (and replans) whose swept truck body hits a rack or wall; off lets a
    /// colliding plan be driven, to study the collision itself.
    #[serde(default = "default_true")]
    validate_paths: bool,
    #[serde(default)]
    truck: ForkliftSpec,
    /// A `[tracker]` table: `kind` (default pure pursuit) and its settings.
    tracker: Option<toml::Spanned<toml::Value>>,
    #[serde(default)]
    sim: SimConfig,
    #[serde(default)]
    noise: NoiseFile,
    #[serde(default)]
    replan: ReplanFile,
    #[serde(default)]
    tolerances: Tolerances,
    /// Fixed error of every pallet estimate, in the pallet frame (a miscalibrated camera);
    /// kept with `--no-noise`, since it is not random.
    estimate_bias: Option<PoseDeg>,
    /// Monte-Carlo jitter of the true pallet pose: σ per axis in the pallet frame,
    /// drawn per trial (truncated at 3σ).
    pallet_jitter: Option<PoseDeg>,
    start: Option<PoseDeg>,
    pallet: Option<PalletPlacement>,
    #[serde(default)]
    case: Vec<CaseFile>,
}

fn default_true() -> bool {
    true
}

fn default_pallet_kind() -> PalletKind {
    PalletKind::Field1200
}

fn default_timeout() -> f64 {
    120.0
}

/// A loaded, validated scenario file (serialisable: a batch's manifest records it whole).
#[derive(Debug, Clone, Serialize)]
pub struct Scenario {
    pub file: String,
    pub name: String,
    pub description: String,
    pub planner: ComponentSpec,
    pub tracker: ComponentSpec,
    /// Builds the components this scenario names (and any a run asks for by name).
    #[serde(skip)]
    pub registry: Arc<Registry>,
    pub seed: u64,
    pub pallet: PalletSpec,
    pub timeout_s: f64,
    /// Plans whose swept truck body hits a rack or wall count as `plan_failed`.
    pub validate_paths: bool,
    pub truck: ForkliftSpec,
    pub sim: SimConfig,
    pub noise: NoiseFile,
    pub replan: ReplanFile,
    pub tolerances: Tolerances,
    /// Fixed pallet-estimate error in the pallet frame.
    pub estimate_bias: Pose2,
    /// σ of the per-trial jitter of the true pallet pose (pallet frame; heading in rad).
    pub pallet_jitter: Pose2,
    pub world: World,
    pub cases: Vec<Case>,
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

impl Scenario {
    pub fn load(path: &FsPath) -> Result<Self, TrialError> {
        Self::load_with(path, Registry::shared())
    }

    /// Loads with a registry that may hold the caller's own components.
    pub fn load_with(path: &FsPath, registry: Arc<Registry>) -> Result<Self, TrialError> {
        let file = path.display().to_string();
        let text = read(path)?;
        let dir = forkbench_plan::external::dir_of(path);
        let world_dir = dir.clone();
        let parsed = Self::parse(&text, &file, |world| World::load(&world_dir.join(world)));
        parsed.and_then(|s| s.with_components(&text, registry, dir))
    }

    /// Parses scenario text; `load_world` resolves the `world` path. Components are built
    /// from the built-in registry, external commands run in the working directory.
    pub fn parse(
        text: &str,
        file: &str,
        load_world: impl FnOnce(&FsPath) -> Result<World, TrialError>,
    ) -> Result<Self, TrialError> {
        let s = Self::parse_layout(text, file, load_world)?;
        s.with_components(text, Registry::shared(), PathBuf::from("."))
    }

    /// Reads the `[planner]` and `[tracker]` tables against `registry`; errors name the
    /// file, line and field.
    fn with_components(
        mut self,
        text: &str,
        registry: Arc<Registry>,
        dir: PathBuf,
    ) -> Result<Self, TrialError> {
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
            match role {
                Role::Planner => self.planner = spec,
                Role::Tracker => self.tracker = spec,
            }
        }
        self.registry = registry;
        Ok(self)
    }

    fn parse_layout(
        text: &str,
        file: &str,
        load_world: impl FnOnce(&FsPath) -> Result<World, TrialError>,
    ) -> Result<Self, TrialError> {
        let f: ScenarioFile = parse(text, file)?;
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
        f.truck
            .validate()
            .map_err(|e| invalid(file, &format!("truck.{}", e.field), e.reason))?;
        if let Some((field, reason)) = f.noise.nav350.invalid_field() {
            return Err(invalid(file, &format!("noise.nav350.{field}"), reason));
        }
        if let Some((field, reason)) = f.noise.pallet_estimate.invalid_field() {
            return Err(invalid(
                file,
                &format!("noise.pallet_estimate.{field}"),
                reason,
            ));
        }
        check_settings(&f, file)?;
        if let Some(b) = &f.estimate_bias {
            b.check(file, "estimate_bias")?;
        }
        if let Some(j) = &f.pallet_jitter {
            j.check(file, "pallet_jitter")?;
            for (name, v) in [
                ("x_m", j.x_m),
                ("y_m", j.y_m),
                ("heading_deg", j.heading_deg),
            ] {
                if v < 0.0 {
                    return Err(invalid(
                        file,
                        &format!("pallet_jitter.{name}"),
                        "a standard deviation must be ≥ 0",
                    ));
                }
            }
        }
        let pallet = match f.pallet_kind {
            PalletKind::Field1200 => PalletSpec::field_1200(),
            PalletKind::Sim1000 => PalletSpec::sim_1000(),
        };
        if f.tolerances.insertion_depth_m > pallet.depth_m.min(f.truck.fork_length_m) {
            return Err(invalid(
                file,
                "tolerances.insertion_depth_m",
                "deeper than the pallet or the forks allow",
            ));
        }
        let resolve = |p: &PalletPlacement, field: &str| -> Result<Pose2, TrialError> {
            match p {
                PalletPlacement::Pose(pd) => {
                    pd.check(file, field)?;
                    Ok(pd.to_pose())
                }
                PalletPlacement::Slot { slot } => world
                    .pallet_slot
                    .iter()
                    .find(|s| &s.name == slot)
                    .map(|s| Pose2::new(s.x_m, s.y_m, s.heading_deg.to_radians()))
                    .ok_or_else(|| {
                        invalid(
                            file,
                            &format!("{field}.slot"),
                            &format!("world has no pallet slot {slot:?}"),
                        )
                    }),
            }
        };
        if f.case.len() > MAX_CASES {
            return Err(invalid(
                file,
                "case",
                &format!("{} cases; at most {MAX_CASES} per file", f.case.len()),
            ));
        }
        let mut cases = Vec::new();
        let listed: Vec<CaseFile> = if f.case.is_empty() {
            vec![CaseFile {
                name: "default".into(),
                start: None,
                pallet: None,
            }]
        } else {
            f.case.clone()
        };
        for (i, c) in listed.iter().enumerate() {
            let field = if f.case.is_empty() {
                String::new()
            } else {
                format!("case[{i}].")
            };
            let start = c
                .start
                .or(f.start)
                .ok_or_else(|| invalid(file, &format!("{field}start"), "missing"))?;
            start.check(file, &format!("{field}start"))?;
            let placement = c
                .pallet
                .as_ref()
                .or(f.pallet.as_ref())
                .ok_or_else(|| invalid(file, &format!("{field}pallet"), "missing"))?;
            let case = Case {
                name: c.name.clone(),
                start: start.to_pose(),
                pallet: resolve(placement, &format!("{field}pallet"))?,
            };
            check_layout(&case, &f.truck, &pallet, &world, file, &field)?;
            if cases.iter().any(|k: &Case| k.name == case.name) {
                return Err(invalid(
                    file,
                    &format!("{field}name"),
                    "duplicate case name",
                ));
            }
            cases.push(case);
        }
        Ok(Scenario {
            file: file.to_owned(),
            name: f.name,
            description: f.description,
            planner: ComponentSpec::of_kind(Role::Planner, "bspline"),
            tracker: ComponentSpec::of_kind(Role::Tracker, "pure_pursuit"),
            registry: Registry::shared(),
            seed: f.seed,
            pallet,
            timeout_s: f.timeout_s,
            validate_paths: f.validate_paths,
            truck: f.truck,
            sim: f.sim,
            noise: f.noise,
            replan: f.replan,
            tolerances: f.tolerances,
            estimate_bias: f
                .estimate_bias
                .map_or(Pose2::new(0.0, 0.0, 0.0), PoseDeg::to_pose),
            pallet_jitter: f
                .pallet_jitter
                .map_or(Pose2::new(0.0, 0.0, 0.0), PoseDeg::to_pose),
            world,
            cases,
        })
    }

    pub fn case(&self, name: &str) -> Result<&Case, TrialError> {
        self.cases
            .iter()
            .find(|c| c.name == name)
            .ok_or_else(|| TrialError::UnknownCase {
                file: self.file.clone(),
                case: name.to_owned(),
                known: self
                    .cases
                    .iter()
                    .map(|c| c.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", "),
            })
    }
}

/// The truck body's footprint referenced to the fork root: the chassis ends there (forks
/// excluded, since they are meant to enter the pallet).
pub fn truck_footprint(truck: &ForkliftSpec) -> Footprint {
    Footprint {
        length_m: truck.body_length_m,
        width_m: truck.body_width_m,
        centre_ahead_m: -truck.body_length_m / 2.0,
    }
}

/// The pallet's footprint referenced to its face centre.
pub fn pallet_footprint(pallet: &PalletSpec) -> Footprint {
    Footprint {
        length_m: pallet.depth_m,
        width_m: pallet.width_m,
        centre_ahead_m: pallet.depth_m / 2.0,
    }
}

/// Layouts may touch (a pallet against a rack's back, a truck parked flush to a wall):
/// footprints are shrunk by this on every side before the overlap test.
const LAYOUT_TOLERANCE_M: f64 = 1e-3;

fn shrunk(fp: Footprint) -> Footprint {
    Footprint {
        length_m: fp.length_m - 2.0 * LAYOUT_TOLERANCE_M,
        width_m: fp.width_m - 2.0 * LAYOUT_TOLERANCE_M,
        ..fp
    }
}

fn check_layout(
    case: &Case,
    truck: &ForkliftSpec,
    pallet: &PalletSpec,
    world: &World,
    file: &str,
    field: &str,
) -> Result<(), TrialError> {
    let (obstacles, labels) = world.footprint_obstacles();
    let (pallet_fp, truck_fp) = (
        shrunk(pallet_footprint(pallet)),
        shrunk(truck_footprint(truck)),
    );
    if let Some(i) = obstacles.hit(&pallet_fp, &case.pallet) {
        return Err(invalid(
            file,
            &format!("{field}pallet"),
            &format!("pallet overlaps {}", labels[i]),
        ));
    }
    if let Some(i) = obstacles.hit(&truck_fp, &case.start) {
        return Err(invalid(
            file,
            &format!("{field}start"),
            &format!("truck starts inside {}", labels[i]),
        ));
    }
    let mut pallet_only = Obstacles::new();
    pallet_only.add_rect(
        &pallet_fp.centre(&case.pallet),
        pallet_fp.length_m,
        pallet_fp.width_m,
    );
    if pallet_only.collides(&truck_fp, &case.start) {
        return Err(invalid(
            file,
            &format!("{field}start"),
            "truck starts overlapping the pallet",
        ));
    }
    Ok(())
}

/// Run settings of a scenario file, checked at load: the trial timeout, [sim], [replan]
/// and the tolerances.
fn check_settings(f: &ScenarioFile, file: &str) -> Result<(), TrialError> {
    if !(f.timeout_s.is_finite() && f.timeout_s > 0.0 && f.timeout_s <= MAX_TIMEOUT_S) {
        return Err(invalid(
            file,
            "timeout_s",
            "must be a positive time of at most 600 s",
        ));
    }
    if let Err(forkbench_sim::SimError::Config { field, reason, .. }) = f.sim.validate() {
        return Err(invalid(file, &format!("sim.{field}"), reason));
    }
    for (name, v) in [
        ("position_threshold_m", f.replan.position_threshold_m),
        ("heading_threshold_deg", f.replan.heading_threshold_deg),
    ] {
        if !(v.is_finite() && v > 0.0) {
            return Err(invalid(
                file,
                &format!("replan.{name}"),
                "must be a positive finite number (NaN would disable the trigger)",
            ));
        }
    }
    let t = &f.tolerances;
    for (name, v) in [
        ("lateral_m", t.lateral_m),
        ("heading_deg", t.heading_deg),
        ("insertion_depth_m", t.insertion_depth_m),
        ("contact_force_n", t.contact_force_n),
        ("pallet_displacement_m", t.pallet_displacement_m),
        ("pallet_rotation_deg", t.pallet_rotation_deg),
    ] {
        if !(v.is_finite() && v > 0.0) {
            return Err(invalid(
                file,
                &format!("tolerances.{name}"),
                "must be a positive finite number",
            ));
        }
    }
    Ok(())
}

/// A component table's error at the line of the offending key (or of the table).
fn component_error(
    file: &str,
    text: &str,
    role: Role,
    span: std::ops::Range<usize>,
    e: &forkbench_core::SettingsError,
) -> TrialError {
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
            (key == k || key.trim_matches('"') == k).then_some(here)
        })
    });
    let offset = span.start + key_at.unwrap_or(0);
    let line = text[..offset.min(text.len())].matches('\n').count() + 1;
    let field = match &e.field {
        Some(f) => format!("{role}.{f}"),
        None => role.to_string(),
    };
    TrialError::Invalid {
        file: format!("{file}:{line}"),
        field,
        reason: e.reason.clone(),
    }
}
