//! The pallet detector as an extension point: the scans of one or more sensors in, the pallet's face pose or "not found" out; the built-in pocket detector fuses sensors near-first.

use forkbench_core::signal::Scan;
use forkbench_core::{PalletSpec, Pose2};
use serde::Serialize;

use crate::detect::{Detection, DetectorConfig, detect, detect_ranked};

/// One sensor's scan, as the truck knows it: `scan.sensor` is the sensor's pose from the
/// truck's own localisation, so a detection is in the map as the truck believes it.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct SensorScan<'a> {
    /// The sensor model's name (`tim561`, `kinect2`).
    pub sensor: &'a str,
    pub scan: &'a Scan,
}

/// What a detector is asked: the scans (nearest-reaching sensor first), the pallet's
/// dimensions, and where the pallet should be (the last estimate, or before the first
/// the slot's nominal placement).
#[derive(Debug, Clone, Copy)]
pub struct DetectRequest<'a> {
    pub scans: &'a [SensorScan<'a>],
    pub pallet: &'a PalletSpec,
    pub prior: Option<Pose2>,
}

/// A pallet found: the detection and which sensor's scan (an index into the request).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Found {
    pub detection: Detection,
    pub sensor: usize,
    /// The detector's own confidence in [0, 1], when it gives one: the evidence stage
    /// then takes it in place of the scan's evidence (an external detector's `score`).
    pub score: Option<f64>,
}

/// Why a detector could not answer (an external process that hung, crashed or broke the
/// protocol): that trial's error, never the batch's.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("detector {detector}: {reason}")]
pub struct DetectorError {
    pub detector: String,
    pub reason: String,
}

/// Finds the pallet in scans.
pub trait PalletDetector: Send {
    fn name(&self) -> &str;

    /// The pallet's face pose, or `None` when no scan shows it.
    fn detect(&mut self, req: &DetectRequest<'_>) -> Result<Option<Found>, DetectorError>;

    /// Every face the scans could hold, the one `detect` would give first: the evidence
    /// stage ([`crate::evidence::verified`]) takes the first the scan bears out. A
    /// detector that locates one face gives it alone (the default).
    fn candidates(&mut self, req: &DetectRequest<'_>) -> Result<Vec<Found>, DetectorError> {
        Ok(self.detect(req)?.into_iter().collect())
    }

    /// The candidate the evidence chose, made final (a model fit refines it there, so
    /// only one face pays for it). The default keeps it as it is.
    fn finish(&mut self, req: &DetectRequest<'_>, found: Found) -> Found {
        let _ = req;
        found
    }
}

/// The built-in pocket detector ([`detect`]) on each scan in turn: the first sensor that
/// finds the pallet wins. The trial orders the nearest-reaching sensor first, so a depth
/// camera decides where it sees the pallet and the laser beyond (laser far, camera near,
/// as Lü et al. fuse them).
#[derive(Debug, Clone, Default)]
pub struct Pockets {
    pub cfg: DetectorConfig,
}

impl PalletDetector for Pockets {
    fn name(&self) -> &str {
        "pockets"
    }

    fn detect(&mut self, req: &DetectRequest<'_>) -> Result<Option<Found>, DetectorError> {
        Ok(req.scans.iter().enumerate().find_map(|(i, s)| {
            detect(&self.cfg, s.scan, req.pallet, req.prior.as_ref()).map(|detection| Found {
                detection,
                sensor: i,
                score: None,
            })
        }))
    }

    fn candidates(&mut self, req: &DetectRequest<'_>) -> Result<Vec<Found>, DetectorError> {
        Ok(ranked(&self.cfg, req))
    }
}

/// The pocket stage's faces in every scan, the first sensor's first.
pub(crate) fn ranked(cfg: &DetectorConfig, req: &DetectRequest<'_>) -> Vec<Found> {
    req.scans
        .iter()
        .enumerate()
        .flat_map(|(i, s)| {
            detect_ranked(cfg, s.scan, req.pallet, req.prior.as_ref())
                .into_iter()
                .map(move |detection| Found {
                    detection,
                    sensor: i,
                    score: None,
                })
        })
        .collect()
}

/// Runs `detector` on named scans (shortest-reaching sensor first): builds the request
/// the trait takes. `found.sensor` indexes `scans`.
pub fn detect_in<S: AsRef<str>>(
    detector: &mut dyn PalletDetector,
    scans: &[(S, Scan)],
    pallet: &PalletSpec,
    prior: Option<Pose2>,
) -> Result<Option<Found>, DetectorError> {
    let views: Vec<SensorScan<'_>> = scans
        .iter()
        .map(|(sensor, scan)| SensorScan {
            sensor: sensor.as_ref(),
            scan,
        })
        .collect();
    detector.detect(&DetectRequest {
        scans: &views,
        pallet,
        prior,
    })
}
