//! A pallet detector run over every scan of a recording (a ROS 2 bag or a forkbench MCAP): each scan placed in the frame asked for, detected, and reported as it comes.

use std::path::Path as FsPath;

use forkbench_core::{PalletSpec, Pose2};
use forkbench_sensors::detector::{DetectRequest, DetectorError, PalletDetector, SensorScan};
use forkbench_sensors::evidence::verified;
use serde::Serialize;

use crate::LogError;
use crate::bag::{BagEvent, BagScan, BagSummary, Frames, bag_files, read_bag};

/// What to read and where to give the faces.
#[derive(Debug, Clone, Default)]
pub struct DetectOptions {
    /// Laser-scan topics to read (all when empty).
    pub topics: Vec<String>,
    /// Give faces (and take the prior) in this frame, placing each scan through the
    /// bag's transforms; `None`: each scan's `frame_id` (a ROS 2 scanner's own frame, or
    /// the frame a forkbench scan's pose is given in).
    pub frame: Option<String>,
    /// Where the pallet should be, in that frame, for every scan.
    pub prior: Option<Pose2>,
    /// Where the pallet should be for the scan of each index (a labelled set's own
    /// priors), before `prior`.
    pub priors: std::collections::BTreeMap<usize, Pose2>,
    /// Least evidence score (`forkbench_sensors::evidence`) a located face needs to be
    /// reported found: below it the scan says there is no pallet there.
    pub min_score: f64,
}

pub use forkbench_sensors::evidence::DEFAULT_MIN_SCORE;

/// One scan and what the detector made of it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ScanResult {
    /// 0-based, over the scans read, in file order.
    pub index: usize,
    pub topic: String,
    pub stamp_s: f64,
    pub frame_id: String,
    pub beams: usize,
    /// Beams with a return.
    pub returns: usize,
    pub found: bool,
    /// The face centre and heading into the pallet, in the frame asked for.
    pub face: Option<Pose2>,
    /// Returns on the stringer faces used, their RMS distance from the face line, and
    /// how many stringer faces.
    pub points: Option<usize>,
    pub rms_m: Option<f64>,
    pub stringers: Option<usize>,
    /// Why the scan could not be used (malformed, or not placeable in the frame).
    pub error: Option<String>,
    /// The evidence score of the face found, or when every located face fell below
    /// `min_score` (the scan counts as no pallet) the best of theirs.
    pub score: Option<f64>,
    /// The best-scoring located face when the evidence turned every one down.
    pub rejected: Option<Pose2>,
    /// Every located face and its score, the detector's preferred first: at another
    /// threshold the detection is the best of them if it reaches it.
    #[serde(skip)]
    pub candidates: Vec<(Pose2, f64)>,
}

/// Why a run stopped early: the detector could not answer, or the file could not be read
/// further. The scans before it were reported.
#[derive(Debug, thiserror::Error)]
pub enum DetectRunError {
    #[error(transparent)]
    Bag(#[from] LogError),
    #[error(transparent)]
    Detector(#[from] DetectorError),
}

/// Runs `detector` on every scan of `path` (an MCAP file, or a rosbag2 directory of
/// them), calling `on` with each result in file order.
pub fn detect_bag(
    path: &FsPath,
    opts: &DetectOptions,
    detector: &mut dyn PalletDetector,
    pallet: &PalletSpec,
    on: &mut dyn FnMut(&ScanResult),
) -> Result<BagSummary, DetectRunError> {
    let mut frames = Frames::default();
    let mut index = 0;
    let mut failed: Option<DetectorError> = None;
    let mut bad_tf: (usize, Option<String>) = (0, None);
    let mut each = |e: BagEvent| {
        if failed.is_some() {
            return;
        }
        let result = match e {
            BagEvent::Transform {
                parent,
                child,
                pose,
            } => return frames.set(&parent, &child, pose),
            BagEvent::BadTransform { topic, reason } => {
                bad_tf.0 += 1;
                bad_tf.1.get_or_insert(format!("{topic}: {reason}"));
                return;
            }
            BagEvent::Malformed { topic, reason } => blank(index, topic, Some(reason.to_string())),
            BagEvent::Scan(s) => match one(&s, opts, &frames, detector, pallet, index) {
                Ok(r) => r,
                Err(e) => {
                    failed = Some(e);
                    return;
                }
            },
        };
        on(&result);
        index += 1;
    };
    let mut summary = BagSummary::default();
    for file in bag_files(path)? {
        let part = read_bag(&file, &opts.topics, &mut each)?;
        for (t, n) in part.scan_topics {
            *summary.scan_topics.entry(t).or_insert(0) += n;
        }
        summary.topics.extend(part.topics);
    }
    (summary.bad_transforms, summary.first_bad_transform) = bad_tf;
    match failed {
        Some(e) => Err(e.into()),
        None => Ok(summary),
    }
}

fn blank(index: usize, topic: String, error: Option<String>) -> ScanResult {
    ScanResult {
        index,
        topic,
        stamp_s: f64::NAN,
        frame_id: String::new(),
        beams: 0,
        returns: 0,
        found: false,
        face: None,
        points: None,
        rms_m: None,
        stringers: None,
        error,
        score: None,
        rejected: None,
        candidates: Vec::new(),
    }
}

fn one(
    s: &BagScan,
    opts: &DetectOptions,
    frames: &Frames,
    detector: &mut dyn PalletDetector,
    pallet: &PalletSpec,
    index: usize,
) -> Result<ScanResult, DetectorError> {
    let mut r = blank(index, s.topic.clone(), None);
    r.stamp_s = s.stamp_s;
    r.frame_id = s.frame_id.clone();
    r.beams = s.scan.ranges_m.len();
    r.returns = s.scan.ranges_m.iter().filter(|x| x.is_finite()).count();
    let mut scan = s.scan.clone();
    if let Some(target) = &opts.frame {
        match frames.pose_in(&s.frame_id, target) {
            Some(p) => scan.sensor = p.to_world(&scan.sensor),
            None if s.frame_id.trim_start_matches('/') == target => {}
            None => {
                r.error = Some(format!(
                    "no transform from {:?} to {target:?} before this scan",
                    s.frame_id
                ));
                return Ok(r);
            }
        }
    }
    let views = [SensorScan {
        sensor: s.topic.as_str(),
        scan: &scan,
    }];
    let req = DetectRequest {
        scans: &views,
        pallet,
        prior: opts.priors.get(&index).copied().or(opts.prior),
    };
    let v = verified(detector, &req, opts.min_score)?;
    match &v.chosen {
        Some((f, score)) => {
            let d = f.detection;
            r.score = Some(*score);
            r.found = true;
            r.face = Some(d.face);
            r.points = Some(d.points);
            r.rms_m = Some(d.rms_m);
            r.stringers = Some(d.stringers);
        }
        None => {
            let best = v.best();
            r.score = best.map(|b| b.1);
            r.rejected = best.map(|b| b.0);
        }
    }
    r.candidates = v.scored;
    Ok(r)
}
