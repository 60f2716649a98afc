//! A detector's scores over its threshold (precision, recall and false-positive rate at each) and its face errors by the labelled face's range and bearing.

use std::collections::BTreeMap;

use forkbench_core::Pose2;
use serde::Serialize;

use forkbench_sensors::evidence::best_of;

use crate::detect_eval::{Gate, Label, face_error, score};

/// Thresholds a curve is drawn at: 0 to 1 in twentieths.
pub const CURVE_STEPS: usize = 20;

/// One point of the curve: what the detector scores at `threshold`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CurvePoint {
    pub threshold: f64,
    pub precision: Option<f64>,
    pub recall: Option<f64>,
    /// False detections over the labelled scans without a pallet.
    pub false_positive_rate: Option<f64>,
    pub accuracy: Option<f64>,
}

/// The detection each scan gives at threshold `t`: the best-scoring of its candidates
/// (face, score; the detector's preferred first, which wins ties) when it reaches `t`.
pub fn at_threshold(candidates: &[Vec<(Pose2, f64)>], t: f64) -> Vec<Option<Pose2>> {
    candidates
        .iter()
        .map(|c| best_of(c).filter(|(_, s)| *s >= t).map(|(f, _)| f))
        .collect()
}

/// Precision, recall, false-positive rate and accuracy at each of 0, 1/20, …, 1.
pub fn curve(
    candidates: &[Vec<(Pose2, f64)>],
    labels: &BTreeMap<usize, Label>,
    gate: Gate,
) -> Vec<CurvePoint> {
    let empty = labels
        .iter()
        .filter(|(i, l)| !l.present && *i < &candidates.len())
        .count();
    (0..=CURVE_STEPS)
        .map(|k| {
            let t = k as f64 / CURVE_STEPS as f64;
            let found = at_threshold(candidates, t);
            // A false detection on a scan without a pallet (not a face found off its label).
            let false_on_empty = labels
                .iter()
                .filter(|(i, l)| !l.present && found.get(**i).is_some_and(Option::is_some))
                .count();
            let s = score(&found, labels, gate);
            CurvePoint {
                threshold: t,
                precision: s.precision,
                recall: s.recall,
                false_positive_rate: (empty > 0).then(|| false_on_empty as f64 / empty as f64),
                accuracy: s.accuracy,
            }
        })
        .collect()
}

/// Recall on the labelled scans with a pallet and false detections on those without,
/// among the scans whose labels name one clutter kind.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ClutterScore {
    pub kind: String,
    pub with_pallet: usize,
    pub recall: Option<f64>,
    pub without_pallet: usize,
    pub false_positive_rate: Option<f64>,
}

/// [`ClutterScore`] per clutter kind the labels name, in name order.
pub fn by_clutter(
    found: &[Option<Pose2>],
    labels: &BTreeMap<usize, Label>,
    gate: Gate,
) -> Vec<ClutterScore> {
    let mut kinds: BTreeMap<&str, [usize; 4]> = BTreeMap::new();
    for (i, l) in labels {
        let Some(det) = found.get(*i) else { continue };
        let right = match (l.present, det, l.face) {
            (true, Some(d), Some(f)) => {
                let e = face_error(&f.pose(), d);
                e[0].hypot(e[1]) <= gate.position_m && e[2].abs() <= gate.heading_rad
            }
            (true, Some(_), None) => true,
            (_, d, _) => d.is_some(),
        };
        let mut seen: Vec<&str> = l.clutter.iter().map(String::as_str).collect();
        seen.sort_unstable();
        seen.dedup();
        for k in seen {
            let c = kinds.entry(k).or_default();
            let at = if l.present { 0 } else { 2 };
            c[at] += 1;
            c[at + 1] += usize::from(right);
        }
    }
    let rate = |k: usize, n: usize| (n > 0).then(|| k as f64 / n as f64);
    kinds
        .into_iter()
        .map(|(kind, c)| ClutterScore {
            kind: kind.to_owned(),
            with_pallet: c[0],
            recall: rate(c[1], c[0]),
            without_pallet: c[2],
            false_positive_rate: rate(c[3], c[2]),
        })
        .collect()
}

/// Range bins' upper edges (m) and bearing bins' (degrees off the frame's x axis).
pub const RANGE_BINS_M: [f64; 5] = [2.0, 4.0, 6.0, 8.0, f64::INFINITY];
pub const BEARING_BINS_DEG: [f64; 4] = [15.0, 30.0, 60.0, 180.0];

/// The labelled faces in one bin: how many, how many found right, and the median
/// absolute errors of those.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Bin {
    /// The bin's upper edge (m or degrees; the last is open).
    pub upto: f64,
    pub faces: usize,
    pub found: usize,
    pub recall: Option<f64>,
    pub lateral_error_m: Option<f64>,
    pub heading_error_rad: Option<f64>,
}

/// Errors by the labelled face's range and by its bearing from the frame's origin (the
/// scanner, when the faces are given in its own frame).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ByPlace {
    pub range: Vec<Bin>,
    pub bearing: Vec<Bin>,
}

/// [`ByPlace`] of `found` against `labels` (matches within `gate`).
pub fn by_place(found: &[Option<Pose2>], labels: &BTreeMap<usize, Label>, gate: Gate) -> ByPlace {
    let mut range: Vec<Vec<Option<[f64; 3]>>> = vec![Vec::new(); RANGE_BINS_M.len()];
    let mut bearing: Vec<Vec<Option<[f64; 3]>>> = vec![Vec::new(); BEARING_BINS_DEG.len()];
    for (i, l) in labels {
        let (Some(det), Some(face)) = (found.get(*i), l.face) else {
            continue;
        };
        let truth = face.pose();
        let e = det
            .map(|d| face_error(&truth, &d))
            .filter(|e| e[0].hypot(e[1]) <= gate.position_m && e[2].abs() <= gate.heading_rad);
        let r = truth.x_m.hypot(truth.y_m);
        let b = truth.y_m.atan2(truth.x_m).to_degrees().abs();
        let ri = RANGE_BINS_M.iter().position(|u| r < *u).unwrap_or(0);
        let bi = BEARING_BINS_DEG
            .iter()
            .position(|u| b <= *u)
            .unwrap_or(BEARING_BINS_DEG.len() - 1);
        range[ri].push(e);
        bearing[bi].push(e);
    }
    let bins = |edges: &[f64], sets: Vec<Vec<Option<[f64; 3]>>>| {
        edges
            .iter()
            .zip(sets)
            .map(|(u, set)| bin(*u, &set))
            .collect()
    };
    ByPlace {
        range: bins(&RANGE_BINS_M, range),
        bearing: bins(&BEARING_BINS_DEG, bearing),
    }
}

fn bin(upto: f64, set: &[Option<[f64; 3]>]) -> Bin {
    let hits: Vec<[f64; 3]> = set.iter().flatten().copied().collect();
    let median = |k: usize| {
        let mut v: Vec<f64> = hits.iter().map(|e| e[k].abs()).collect();
        v.sort_by(f64::total_cmp);
        crate::stats::percentile_sorted(&v, 0.5)
    };
    Bin {
        upto,
        faces: set.len(),
        found: hits.len(),
        recall: (!set.is_empty()).then(|| hits.len() as f64 / set.len() as f64),
        lateral_error_m: median(0),
        heading_error_rad: median(2),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::detect_eval::parse_labels;

    #[test]
    fn the_curve_moves_with_the_threshold_and_bins_by_place() {
        let labels = parse_labels(
            r#"{"scans": [
                {"index": 0, "present": true, "face": {"x_m": 3.0, "y_m": 0.0, "heading_deg": 0.0}},
                {"index": 1, "present": true, "face": {"x_m": 0.0, "y_m": 7.0, "heading_deg": 90.0}, "kind": "epal-1"},
                {"index": 2, "present": false, "clutter": ["box"]},
                {"index": 3, "present": false}
            ]}"#,
            "l.json",
        )
        .expect("labels");
        let cands = vec![
            vec![(Pose2::new(3.0, 0.01, 0.0), 0.9)],
            vec![(Pose2::new(0.0, 7.0, std::f64::consts::FRAC_PI_2), 0.4)],
            vec![(Pose2::new(1.0, 1.0, 0.0), 0.6)],
            vec![],
        ];
        let gate = Gate {
            position_m: 0.25,
            heading_rad: 0.2,
        };
        let c = curve(&cands, &labels, gate);
        assert_eq!(c.len(), CURVE_STEPS + 1);
        // At 0 all three faces count: two right, one false on an empty scan.
        assert_eq!(c[0].recall, Some(1.0));
        assert_eq!(c[0].false_positive_rate, Some(0.5));
        // At 0.5 the 0.4 face is dropped; at 0.65 the box's too.
        assert_eq!(c[10].recall, Some(0.5));
        assert_eq!(c[13].false_positive_rate, Some(0.0));
        assert_eq!(c[13].accuracy, Some(0.75));
        let p = by_place(&at_threshold(&cands, 0.5), &labels, gate);
        assert_eq!((p.range[1].faces, p.range[1].found), (1, 1));
        assert_eq!((p.range[3].faces, p.range[3].found), (1, 0));
        assert_eq!((p.bearing[0].faces, p.bearing[3].faces), (1, 1));
        assert!((p.range[1].lateral_error_m.expect("one") - 0.01).abs() < 1e-12);
        let c = by_clutter(&at_threshold(&cands, 0.5), &labels, gate);
        assert_eq!(c.len(), 1);
        assert_eq!((c[0].kind.as_str(), c[0].without_pallet), ("box", 1));
        assert_eq!(c[0].false_positive_rate, Some(1.0));
    }
}
