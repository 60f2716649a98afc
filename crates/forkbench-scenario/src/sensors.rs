//! `[sensors.pallet]`: how a trial estimates the pallet: the range-scaled Gaussian around the truth (`gaussian`, set in `[noise.pallet_estimate]`), or scanners the world answers (`tim561`, `kinect2`, or both fused: `tim561+kinect2`) and a detector from the registry.

use std::collections::BTreeMap;

use forkbench_core::ForkliftSpec;
use forkbench_sensors::detect::DetectorConfig;
use forkbench_sensors::scan::{SCANNER_PRESETS, ScannerConfig};
use serde::{Deserialize, Serialize};

use super::{invalid, invalid_setting};
use crate::ScenarioError;
use crate::component_spec::{ComponentSpec, Role};

/// `[sensors.pallet] kind` of the range-scaled Gaussian estimate around the truth; every
/// other kind names scanner models (`SCANNER_PRESETS`, joined by `+`).
pub const GAUSSIAN_SENSING: &str = "gaussian";

/// `[sensors]` as written.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct SensorsFile {
    pallet: Option<PalletSensorFile>,
    /// `[sensors.localizer]`: a localiser kind from the registry (`gaussian`, `nav350`)
    /// and its settings.
    pub(super) localizer: Option<toml::Spanned<toml::Value>>,
}

/// `[sensors.pallet]` as written: a kind (one scanner model or several joined by `+`),
/// settings for a single scanner (`scanner`) or by model name (`scanners.<model>`), and
/// the detector (`kind` from the registry, default `pockets`, and its settings).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct PalletSensorFile {
    kind: String,
    /// Keys over the model's own settings (its preset), not over another model's.
    scanner: Option<toml::Table>,
    #[serde(default)]
    scanners: BTreeMap<String, toml::Table>,
    detector: Option<toml::Table>,
    /// From a scan's end to its estimate reaching the controller (the scan's transfer and
    /// the detector's computation).
    latency_s: Option<f64>,
    /// Least evidence score a located face needs (`forkbench_sensors::evidence`); 0: the
    /// detector's own answer, unchecked.
    min_score: Option<f64>,
}

/// A detector's estimate reaches the controller this long after its scan ended. No
/// datasheet gives it: a choice, the scan's transfer after the sweep and a detector's
/// computation.
pub const DEFAULT_DETECTOR_LATENCY_S: f64 = 0.03;

/// Most a detector may take.
const MAX_DETECTOR_LATENCY_S: f64 = 2.0;

/// One scanner on the truck: its model's name and settings.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NamedScanner {
    pub name: String,
    pub scanner: ScannerConfig,
}

/// How a trial estimates the pallet.
#[derive(Debug, Clone, PartialEq, Serialize, Default)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum PalletSensing {
    /// A pose drawn around the true face (`[noise.pallet_estimate]`).
    #[default]
    Gaussian,
    /// Scans of the world from the truck, shortest-reaching scanner first (a depth
    /// camera before the laser), and a detector on them.
    Scanner {
        sensors: Vec<NamedScanner>,
        detector: ComponentSpec,
        /// From a scan's end to its estimate reaching the controller.
        latency_s: f64,
        /// Least evidence score a located face needs to be taken (the detector's
        /// candidates in its own order, the first that reaches it); 0: the detector's
        /// own first face, unchecked.
        min_score: f64,
    },
}

impl PalletSensing {
    pub fn is_gaussian(&self) -> bool {
        matches!(self, PalletSensing::Gaussian)
    }

    /// From a scan's end to its estimate reaching the controller (0 for the Gaussian).
    pub fn latency_s(&self) -> f64 {
        match self {
            PalletSensing::Scanner { latency_s, .. } => *latency_s,
            PalletSensing::Gaussian => 0.0,
        }
    }

    /// Sets the scans' latency (the Gaussian has none; an uncertain parameter on it is
    /// refused at load).
    pub fn set_latency_s(&mut self, v: f64) {
        if let PalletSensing::Scanner { latency_s, .. } = self {
            *latency_s = v;
        }
    }

    /// Least evidence score a located face needs (0 for the Gaussian: nothing to check).
    pub fn min_score(&self) -> f64 {
        match self {
            PalletSensing::Scanner { min_score, .. } => *min_score,
            PalletSensing::Gaussian => 0.0,
        }
    }

    /// The settings of this sensing's scanner of model `name`, if it has one.
    pub fn scanner(&self, name: &str) -> Option<&ScannerConfig> {
        match self {
            PalletSensing::Scanner { sensors, .. } => {
                sensors.iter().find(|s| s.name == name).map(|s| &s.scanner)
            }
            PalletSensing::Gaussian => None,
        }
    }

    /// The scanner of model `name`: this sensing's own settings for it when it has that
    /// scanner, else the model's preset; `Err` lists the models known.
    pub fn scanner_or_preset(
        &self,
        name: &str,
    ) -> Result<ScannerConfig, forkbench_core::UnknownChoice> {
        self.scanner(name)
            .cloned()
            .or_else(|| ScannerConfig::preset(name))
            .ok_or_else(|| {
                forkbench_core::UnknownChoice::new(
                    name,
                    format!("unknown (known: {})", SCANNER_PRESETS.join(", ")),
                )
            })
    }

    /// The pocket detector's settings, when this sensing's detector takes them (the
    /// registry says which kinds do; else their defaults).
    pub fn pocket_settings(&self, registry: &impl crate::Catalogue) -> DetectorConfig {
        match self {
            PalletSensing::Scanner { detector, .. }
                if registry.detector_takes_pocket_settings(&detector.kind) =>
            {
                forkbench_core::settings::parse(&detector.settings).unwrap_or_default()
            }
            _ => DetectorConfig::default(),
        }
    }
}

/// The sensing a scenario's `[sensors]` names, checked: known models, settings in range,
/// each scanner mounted outside the truck's body. The detector's settings are checked
/// against the registry with the other components.
pub(super) fn resolve(
    f: Option<&SensorsFile>,
    truck: &ForkliftSpec,
    file: &str,
) -> Result<PalletSensing, ScenarioError> {
    check_mount_names(truck, file)?;
    let Some(p) = f.and_then(|s| s.pallet.as_ref()) else {
        return Ok(PalletSensing::Gaussian);
    };
    let latency_s = latency_of(p, file)?;
    let min_score = min_score_of(p, file)?;
    if p.kind == GAUSSIAN_SENSING {
        return Ok(PalletSensing::Gaussian);
    }
    let names: Vec<&str> = p.kind.split('+').map(str::trim).collect();
    if names.len() > 1 && p.scanner.is_some() {
        return Err(invalid(
            file,
            "sensors.pallet.scanner",
            "names one scanner's settings, but the kind has several: use \
             [sensors.pallet.scanners.<model>]",
        ));
    }
    if let Some(k) = p.scanners.keys().find(|k| !names.contains(&k.as_str())) {
        return Err(invalid(
            file,
            &format!("sensors.pallet.scanners.{k}"),
            &format!("{k:?} is not one of this kind's scanners ({})", p.kind),
        ));
    }
    let mut sensors = Vec::new();
    for name in names {
        let Some(preset) = ScannerConfig::preset(name) else {
            return Err(invalid(
                file,
                "sensors.pallet.kind",
                &format!(
                    "{name:?} is not a pallet sensing kind (known: {GAUSSIAN_SENSING}, {}, or \
                     scanners joined by '+')",
                    SCANNER_PRESETS.join(", ")
                ),
            ));
        };
        if sensors.iter().any(|s: &NamedScanner| s.name == name) {
            return Err(invalid(
                file,
                "sensors.pallet.kind",
                &format!("{name:?} is named twice"),
            ));
        }
        let scanner = scanner_on(preset, name, p, truck, file)?;
        sensors.push(NamedScanner {
            name: name.to_owned(),
            scanner,
        });
    }
    // Shortest reach first, ties by name: the order a file lists them in never matters.
    sensors.sort_by(|a, b| {
        (a.scanner.range_max_m.total_cmp(&b.scanner.range_max_m)).then_with(|| a.name.cmp(&b.name))
    });
    Ok(PalletSensing::Scanner {
        sensors,
        detector: detector_of(p, file)?,
        latency_s,
        min_score,
    })
}

/// Scanner model `name` as `p` sets it over its `preset`, on the truck's mount for it,
/// checked (in range, outside the body).
fn scanner_on(
    preset: ScannerConfig,
    name: &str,
    p: &PalletSensorFile,
    truck: &ForkliftSpec,
    file: &str,
) -> Result<ScannerConfig, ScenarioError> {
    let table = if p.scanners.contains_key(name) {
        format!("sensors.pallet.scanners.{name}")
    } else {
        "sensors.pallet.scanner".to_owned()
    };
    let keys = p.scanners.get(name).or(p.scanner.as_ref());
    let preset = mounted_on(preset, name, truck, keys, (file, &table))?;
    let scanner = match keys {
        Some(keys) => over_preset(&preset, keys).map_err(|e| invalid_setting(file, &table, &e))?,
        None => preset,
    };
    // A mount the truck gives is named as the truck's.
    let mount_field = match truck.mounts.get(name) {
        Some(_) => format!("truck.mount.{name}"),
        None => format!("{table}.mount"),
    };
    check_scanner(&scanner, truck, file, (&table, &mount_field))?;
    Ok(scanner)
}

/// Every sensor the truck mounts is one the bench knows: a scanner model, or the
/// reflector localiser: the first that is not, and why, else `None`.
pub(crate) fn unknown_mount(truck: &ForkliftSpec) -> Option<(String, String)> {
    let localizer = forkbench_sensors::reflector_nav::MOUNT_NAME;
    let (n, _) = truck
        .mounts
        .iter()
        .find(|(n, _)| !SCANNER_PRESETS.contains(n) && *n != localizer)?;
    Some((
        n.to_owned(),
        format!(
            "{n:?} is no sensor the truck can carry (known: {}, {localizer})",
            SCANNER_PRESETS.join(", ")
        ),
    ))
}

/// The truck's mounts refused at the scenario when one names no known sensor.
fn check_mount_names(truck: &ForkliftSpec, file: &str) -> Result<(), ScenarioError> {
    match unknown_mount(truck) {
        Some((n, why)) => Err(invalid(file, &format!("truck.mount.{n}"), &why)),
        None => Ok(()),
    }
}

/// A scanner model's preset on the truck's mount for it, when the truck gives one; the
/// scenario's own `mount` for it beside the truck's is refused (one place says where a
/// sensor sits).
fn mounted_on(
    mut preset: ScannerConfig,
    name: &str,
    truck: &ForkliftSpec,
    keys: Option<&toml::Table>,
    (file, table): (&str, &str),
) -> Result<ScannerConfig, ScenarioError> {
    let Some(m) = truck.mounts.get(name) else {
        return Ok(preset);
    };
    if keys.is_some_and(|k| k.contains_key("mount")) {
        return Err(invalid(
            file,
            &format!("{table}.mount"),
            &forkbench_core::mounts::mounted_twice(name),
        ));
    }
    preset.mount = *m;
    Ok(preset)
}

/// `[sensors.pallet.detector]`: its kind (the pocket detector by default) and settings.
fn detector_of(p: &PalletSensorFile, file: &str) -> Result<ComponentSpec, ScenarioError> {
    let table = toml::Value::Table(p.detector.clone().unwrap_or_default());
    let default = Some(crate::component_spec::POCKET_DETECTOR);
    ComponentSpec::from_value(Role::Detector, &table, default, ".".into())
        .map_err(|e| invalid_setting(file, "sensors.pallet.detector", &e))
}

/// `[sensors.pallet] min_score`, in 0–1 (default `detect`'s threshold, so a trial's
/// detector is the one `detect` measures); refused for the Gaussian estimate.
fn min_score_of(p: &PalletSensorFile, file: &str) -> Result<f64, ScenarioError> {
    scanning_setting(
        p,
        file,
        (
            "min_score",
            p.min_score,
            forkbench_sensors::evidence::DEFAULT_MIN_SCORE,
        ),
        (1.0, ""),
        "the gaussian estimate has no scan to check a face against",
    )
}

/// `[sensors.pallet] latency_s`, in range; refused for the Gaussian estimate.
fn latency_of(p: &PalletSensorFile, file: &str) -> Result<f64, ScenarioError> {
    scanning_setting(
        p,
        file,
        ("latency_s", p.latency_s, DEFAULT_DETECTOR_LATENCY_S),
        (MAX_DETECTOR_LATENCY_S, " s"),
        "the gaussian estimate has no scan or detector to be late; its σ stands for the \
         whole pipeline",
    )
}

/// A `[sensors.pallet]` setting of the scans and detector (`key`, as written, default):
/// refused with the gaussian estimate (`gaussian_why`), else its value or default within
/// 0–`max` (`unit` after the numbers in the message).
fn scanning_setting(
    p: &PalletSensorFile,
    file: &str,
    (key, value, default): (&str, Option<f64>, f64),
    (max, unit): (f64, &str),
    gaussian_why: &str,
) -> Result<f64, ScenarioError> {
    let field = format!("sensors.pallet.{key}");
    if p.kind == GAUSSIAN_SENSING && value.is_some() {
        return Err(invalid(file, &field, gaussian_why));
    }
    let v = value.unwrap_or(default);
    if !(v.is_finite() && (0.0..=max).contains(&v)) {
        return Err(invalid(
            file,
            &field,
            &format!("{v}{unit} must lie in 0–{max}{unit}"),
        ));
    }
    Ok(v)
}

/// The sensing a kind names with every setting at its default (`--pallet-sensing`).
pub(crate) fn of_kind(
    kind: &str,
    truck: &ForkliftSpec,
    file: &str,
) -> Result<PalletSensing, ScenarioError> {
    let f = SensorsFile {
        localizer: None,
        pallet: Some(PalletSensorFile {
            kind: kind.to_owned(),
            scanner: None,
            scanners: BTreeMap::new(),
            detector: None,
            latency_s: None,
            min_score: None,
        }),
    };
    resolve(Some(&f), truck, file)
}

/// A model's preset with the keys a file gives laid over it (unknown keys refused).
fn over_preset(
    preset: &ScannerConfig,
    keys: &toml::Table,
) -> Result<ScannerConfig, forkbench_core::SettingsError> {
    let mut table = toml::Table::try_from(preset)
        .map_err(|e| forkbench_core::SettingsError::field("scanner", e.to_string()))?;
    for (k, v) in keys {
        table.insert(k.clone(), v.clone());
    }
    forkbench_core::settings::parse(&table)
}

/// A scanner's settings in range, and its mount outside the truck's body.
fn check_scanner(
    scanner: &ScannerConfig,
    truck: &ForkliftSpec,
    file: &str,
    (table, mount_field): (&str, &str),
) -> Result<(), ScenarioError> {
    scanner
        .validate()
        .map_err(|e| invalid_setting(file, table, &e))?;
    // The fork-root frame: the body lies behind the root (x < 0), within its half width.
    let m = &scanner.mount;
    if m.x_m < 0.0 && m.x_m > -truck.body_length_m && m.y_m.abs() < truck.body_width_m / 2.0 {
        return Err(invalid(
            file,
            mount_field,
            &format!(
                "({}, {}) m lies inside the truck's body (fork-root frame: the body \
                 spans x from -{} to 0 m, y within ±{} m); mount it at the fork root or ahead \
                 of it",
                m.x_m,
                m.y_m,
                truck.body_length_m,
                truck.body_width_m / 2.0
            ),
        ));
    }
    Ok(())
}
