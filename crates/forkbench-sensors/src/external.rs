//! Detectors in any language: a child process speaking JSON lines (docs/external-detector.md), with the robustness of external planners: a deadline per request, crashes and bad answers fail only that trial.

use std::path::PathBuf;
use std::sync::LazyLock;

use forkbench_core::settings::{self, Settings, SettingsError};
use forkbench_core::{PalletSpec, Pose2};
use forkbench_ipc::{Breaker, Callee, clip};
use serde::{Deserialize, Serialize};

use crate::detect::Detection;
use crate::detector::{DetectRequest, DetectorError, Found, PalletDetector, SensorScan};

/// Name of the protocol in both hello messages.
pub const PROTOCOL: &str = "forkbench-detector";
/// The protocol version this forkbench speaks.
pub const VERSION: u64 = 1;
/// Settings of `[sensors.pallet.detector] kind = "external"`: the shared command settings.
pub type ExternalDetectorConfig = forkbench_ipc::CommandConfig;

/// Consecutive timeouts per command, across worker threads.
static BREAKER: LazyLock<Breaker> = LazyLock::new(Breaker::default);

/// The pallet as sent: its dimensions and the stringers derived from them.
#[derive(Debug, Clone, Serialize)]
struct PalletMsg {
    depth_m: f64,
    width_m: f64,
    pocket_width_m: f64,
    /// The face's edge parts' width (a stringer's, on a stringer pallet).
    stringer_width_m: f64,
    /// The face parts' centres across the face.
    stringer_offsets_m: [f64; 3],
    /// The face parts as lateral intervals, right to left.
    face_parts_m: [[f64; 2]; 3],
    /// Every solid part in the scan plane, in the face frame.
    parts: Vec<forkbench_core::pallet::PalletBlock>,
}

/// One scan as sent: the sensor's believed pose in the map, the beams in its frame
/// (`null` where a beam returned nothing).
#[derive(Debug, Clone, Serialize)]
struct ScanMsg<'a> {
    sensor: &'a str,
    pose: Pose2,
    angle_min_rad: f64,
    angle_step_rad: f64,
    range_min_m: f64,
    range_max_m: f64,
    ranges_m: Vec<Option<f64>>,
}

#[derive(Debug, Clone, Serialize)]
struct RequestMsg<'a> {
    #[serde(rename = "type")]
    kind: &'static str,
    id: u64,
    pallet: PalletMsg,
    prior: Option<Pose2>,
    scans: Vec<ScanMsg<'a>>,
}

/// An answer: the face found, none, or the detector's own error.
#[derive(Debug, Clone, Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
enum ResponseMsg {
    Pallet {
        id: u64,
        face: Pose2,
        /// Index of the scan it used (default 0).
        #[serde(default)]
        sensor: usize,
        /// RMS distance of the returns from the fitted face, if it has one.
        #[serde(default)]
        rms_m: Option<f64>,
        /// Its own confidence in [0, 1], thresholded in place of the scan's evidence.
        #[serde(default)]
        score: Option<f64>,
    },
    None {
        id: u64,
    },
    Error {
        id: u64,
        message: String,
    },
}

impl ResponseMsg {
    fn id(&self) -> u64 {
        match self {
            Self::Pallet { id, .. } | Self::None { id } | Self::Error { id, .. } => *id,
        }
    }
}

fn pallet_msg(p: &PalletSpec) -> PalletMsg {
    PalletMsg {
        depth_m: p.depth_m,
        width_m: p.width_m,
        pocket_width_m: p.pocket_width_m,
        stringer_width_m: p.edge_part_m().0,
        stringer_offsets_m: p.face_part_centres_m(),
        face_parts_m: p.face_solids(),
        parts: p.parts(),
    }
}

fn scan_msg<'a>(s: &SensorScan<'a>) -> ScanMsg<'a> {
    ScanMsg {
        sensor: s.sensor,
        pose: s.scan.sensor,
        angle_min_rad: s.scan.angle_min_rad,
        angle_step_rad: s.scan.angle_step_rad,
        range_min_m: s.scan.range_min_m,
        range_max_m: s.scan.range_max_m,
        ranges_m: s
            .scan
            .ranges_m
            .iter()
            .map(|r| r.is_finite().then_some(*r))
            .collect(),
    }
}

/// An external detector, as configured; its process lives in this thread's pool.
#[derive(Debug, Clone)]
pub struct ExternalDetector {
    cfg: ExternalDetectorConfig,
    dir: PathBuf,
    name: String,
}

impl ExternalDetector {
    /// From a detector table; `dir` is where the command runs, `name` what errors say.
    pub fn from_settings(s: &Settings, dir: PathBuf, name: &str) -> Result<Self, SettingsError> {
        let cfg: ExternalDetectorConfig = settings::parse(s)?;
        if let Some((field, why)) = cfg.problem("[\"python3\", \"detector.py\"]") {
            return Err(SettingsError::field(field, why));
        }
        Ok(Self {
            cfg,
            dir,
            name: name.to_owned(),
        })
    }

    /// One request on this thread's pooled detector (a new one when none waits), counted
    /// by the circuit breaker.
    fn request(
        &self,
        req: &DetectRequest<'_>,
    ) -> Result<ResponseMsg, forkbench_ipc::ExchangeError> {
        let callee = Callee {
            dir: &self.dir,
            protocol: PROTOCOL,
            version: VERSION,
            what: "detector",
            breaker: &BREAKER,
        };
        let message = |id| RequestMsg {
            kind: "detect",
            id,
            pallet: pallet_msg(req.pallet),
            prior: req.prior,
            scans: req.scans.iter().map(scan_msg).collect(),
        };
        self.cfg.call_json(callee, message, ResponseMsg::id)
    }
}

/// Why an answered face cannot be a detection: not finite, or out of every sensor's reach.
fn implausible(face: &Pose2, sensor: usize, req: &DetectRequest<'_>) -> Option<String> {
    if !face.is_finite() {
        return Some(format!("the face pose is not finite: {face:?}"));
    }
    // A heading is an angle: a detector answering 1e300 rad has lost its units.
    if face.heading_rad.abs() > 4.0 * std::f64::consts::PI {
        return Some(format!(
            "the face heading {:e} rad is not an angle within ±4π",
            face.heading_rad
        ));
    }
    let Some(s) = req.scans.get(sensor) else {
        return Some(format!(
            "sensor {sensor} does not exist ({} scans were sent)",
            req.scans.len()
        ));
    };
    let reach = s.scan.range_max_m + req.pallet.width_m;
    (face.distance_to(&s.scan.sensor) > reach).then(|| {
        format!(
            "the face ({:.2}, {:.2}) m lies beyond the sensor's reach ({reach:.1} m)",
            face.x_m, face.y_m
        )
    })
}

impl PalletDetector for ExternalDetector {
    fn name(&self) -> &str {
        &self.name
    }

    fn detect(&mut self, req: &DetectRequest<'_>) -> Result<Option<Found>, DetectorError> {
        let fail = |reason: String| DetectorError {
            detector: self.name.clone(),
            reason,
        };
        match self.request(req).map_err(|e| fail(e.message))? {
            ResponseMsg::None { .. } => Ok(None),
            ResponseMsg::Error { message, .. } => {
                Err(fail(format!("it reported: {}", clip(&message))))
            }
            ResponseMsg::Pallet {
                face,
                sensor,
                rms_m,
                score,
                ..
            } => {
                if let Some(why) = implausible(&face, sensor, req) {
                    return Err(fail(why));
                }
                if let Some(r) = rms_m.filter(|r| !(r.is_finite() && *r >= 0.0)) {
                    return Err(fail(format!(
                        "rms_m {r:e}: a residual is a finite distance ≥ 0"
                    )));
                }
                if let Some(v) = score.filter(|v| !(0.0..=1.0).contains(v)) {
                    return Err(fail(format!("score {v:e}: a confidence lies in [0, 1]")));
                }
                Ok(Some(Found {
                    detection: Detection {
                        face,
                        stringers: 0,
                        points: 0,
                        rms_m: rms_m.unwrap_or(f64::NAN),
                    },
                    sensor,
                    score,
                }))
            }
        }
    }
}
