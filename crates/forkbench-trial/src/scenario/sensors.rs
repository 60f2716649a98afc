//! `[sensors.pallet]`: how a trial estimates the pallet: the range-scaled Gaussian around the truth (`gaussian`, the default, set in `[noise.pallet_estimate]`), or a scanner the world answers (`tim561`) with the pocket detector.

use forkbench_core::ForkliftSpec;
use forkbench_sensors::detect::DetectorConfig;
use forkbench_sensors::scan::ScannerConfig;
use serde::{Deserialize, Serialize};

use super::{invalid, invalid_setting};
use crate::TrialError;

/// `[sensors]` as written.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct SensorsFile {
    pallet: Option<PalletSensorFile>,
}

/// `[sensors.pallet]` as written: a kind, and for a scanner its settings and the
/// detector's (each defaulting to the kind's own).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct PalletSensorFile {
    kind: String,
    scanner: Option<ScannerConfig>,
    detector: Option<DetectorConfig>,
}

/// How a trial estimates the pallet.
#[derive(Debug, Clone, PartialEq, Serialize, Default)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum PalletSensing {
    /// A pose drawn around the true face (`[noise.pallet_estimate]`).
    #[default]
    Gaussian,
    /// A scan of the world from the truck, and the pocket detector on it.
    Scanner {
        name: String,
        scanner: ScannerConfig,
        detector: DetectorConfig,
    },
}

impl PalletSensing {
    pub fn is_gaussian(&self) -> bool {
        matches!(self, PalletSensing::Gaussian)
    }
}

/// The sensing a scenario's `[sensors]` names, checked: a known kind, settings in range,
/// the scanner mounted outside the truck's body.
pub(super) fn resolve(
    f: Option<&SensorsFile>,
    truck: &ForkliftSpec,
    file: &str,
) -> Result<PalletSensing, TrialError> {
    let Some(p) = f.and_then(|s| s.pallet.as_ref()) else {
        return Ok(PalletSensing::Gaussian);
    };
    let scanner = match (p.kind.as_str(), ScannerConfig::preset(&p.kind)) {
        ("gaussian", _) => return Ok(PalletSensing::Gaussian),
        (_, Some(preset)) => p.scanner.clone().unwrap_or(preset),
        (other, None) => {
            return Err(invalid(
                file,
                "sensors.pallet.kind",
                &format!(
                    "{other:?} is not a pallet sensing kind (known: gaussian, {})",
                    forkbench_sensors::scan::SCANNER_PRESETS.join(", ")
                ),
            ));
        }
    };
    scanner
        .validate()
        .map_err(|e| invalid_setting(file, "sensors.pallet.scanner", &e))?;
    // The fork-root frame: the body lies behind the root (x < 0), within its half width.
    let m = &scanner.mount;
    if m.x_m < 0.0 && m.x_m > -truck.body_length_m && m.y_m.abs() < truck.body_width_m / 2.0 {
        return Err(invalid(
            file,
            "sensors.pallet.scanner.mount",
            &format!(
                "({}, {}) m lies inside the truck's body (fork-root frame: the body spans x from \
                 -{} to 0 m, y within ±{} m); mount it at the fork root or ahead of it",
                m.x_m,
                m.y_m,
                truck.body_length_m,
                truck.body_width_m / 2.0
            ),
        ));
    }
    Ok(PalletSensing::Scanner {
        name: p.kind.clone(),
        scanner,
        detector: p.detector.clone().unwrap_or_default(),
    })
}
