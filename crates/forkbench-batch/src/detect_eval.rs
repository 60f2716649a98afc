//! A pallet detector scored on labelled scans: found or not against present or not (precision, recall), and the face-pose error of each match.

use std::collections::BTreeMap;

use forkbench_core::Pose2;
use forkbench_core::units::wrap_angle;
use serde::{Deserialize, Serialize};

use crate::BatchError;
use crate::stats::percentile_sorted;

/// What is true of one scan: whether the pallet is in it, and where its face is (in the
/// frame the detections are given in), when known.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Label {
    pub index: usize,
    pub present: bool,
    #[serde(default)]
    pub face: Option<LabelFace>,
    /// Where the detector is told to look for this scan, as `forkbench dataset` writes
    /// it: `detect --labels` hands it to the detector.
    #[serde(default)]
    pub prior: Option<LabelFace>,
    /// The pallet's kind, as `forkbench dataset` writes it (`pallet_kind epal-1`): a
    /// label of another kind than the pallet the detector looks for is named
    /// ([`label_problems`]).
    #[serde(default)]
    pub kind: Option<String>,
    /// The scene's clutter kinds, as `forkbench dataset` writes them: the scores are
    /// also given per kind.
    #[serde(default)]
    pub clutter: Vec<String>,
}

/// A labelled face: centre and heading into the pallet (degrees at the interface).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct LabelFace {
    pub x_m: f64,
    pub y_m: f64,
    pub heading_deg: f64,
}

impl LabelFace {
    pub fn pose(&self) -> Pose2 {
        Pose2::new(self.x_m, self.y_m, self.heading_deg.to_radians())
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct LabelFile {
    scans: Vec<Label>,
    /// What `forkbench dataset` records of the set: its settings and the faces' frame.
    #[serde(default, rename = "dataset")]
    _dataset: Option<serde::de::IgnoredAny>,
    #[serde(default, rename = "frame")]
    _frame: Option<serde::de::IgnoredAny>,
    /// The files of the set (so a later run into its folder knows them).
    #[serde(default, rename = "files")]
    _files: Option<serde::de::IgnoredAny>,
}

/// The labels of a JSON file `{"scans": [{"index": 0, "present": true, "face": {"x_m": …,
/// "y_m": …, "heading_deg": …}}, …]}`, by scan index; `file` names it in errors.
pub fn parse_labels(text: &str, file: &str) -> Result<BTreeMap<usize, Label>, BatchError> {
    let bad = |why: String| BatchError::Content(format!("{file}: {why}"));
    let f: LabelFile = serde_json::from_str(text).map_err(|e| bad(e.to_string()))?;
    let mut out = BTreeMap::new();
    for l in f.scans {
        if let Some(face) = &l.face {
            let ok = [face.x_m, face.y_m].iter().all(|v| v.abs() <= 1e4)
                && face.heading_deg.abs() <= 720.0;
            if !ok {
                return Err(bad(format!(
                    "scan {}: face beyond ±10 km or ±720°",
                    l.index
                )));
            }
            if !l.present {
                return Err(bad(format!("scan {}: a face but present false", l.index)));
            }
        }
        if l.clutter.len() > 1024 {
            return Err(bad(format!("scan {}: over 1,024 clutter items", l.index)));
        }
        let index = l.index;
        if out.insert(index, l).is_some() {
            return Err(bad(format!("scan {index} is labelled twice")));
        }
    }
    Ok(out)
}

/// What the scores cannot say about `labels` against a bag of `scans` scans read for
/// `pallet_kind`: labels of scans the bag lacks (left out), pallets labelled present
/// without a face (found wherever the detector puts it, with no pose error), labels of
/// another pallet kind. Each a sentence with its count and the first few indices.
pub fn label_problems(
    labels: &BTreeMap<usize, Label>,
    scans: usize,
    pallet_kind: &str,
) -> Vec<String> {
    let first = |v: &[usize]| {
        let shown: Vec<String> = v.iter().take(5).map(usize::to_string).collect();
        let more = if v.len() > 5 { ", …" } else { "" };
        format!("{}{more}", shown.join(", "))
    };
    let mut out = Vec::new();
    let beyond: Vec<usize> = labels.keys().copied().filter(|i| *i >= scans).collect();
    if !beyond.is_empty() {
        out.push(format!(
            "{} labels name scans the bag does not have (it has {scans}; scans {}): they are \
             left out of the scores",
            beyond.len(),
            first(&beyond)
        ));
    }
    let faceless: Vec<usize> = labels
        .iter()
        .filter(|(i, l)| **i < scans && l.present && l.face.is_none())
        .map(|(i, _)| *i)
        .collect();
    if !faceless.is_empty() {
        out.push(format!(
            "{} labels say a pallet is present without its face (scans {}): any detection \
             there counts as found, and its pose error is unknown",
            faceless.len(),
            first(&faceless)
        ));
    }
    let other: Vec<usize> = labels
        .iter()
        .filter(|(_, l)| l.kind.as_deref().is_some_and(|k| k != pallet_kind))
        .map(|(i, _)| *i)
        .collect();
    if let Some(kind) = other.first().and_then(|i| labels[i].kind.as_deref()) {
        out.push(format!(
            "{} labels are of another pallet than the scenario's {pallet_kind} (scan {} is \
             {kind}; scans {}): the detector looks for the scenario's",
            other.len(),
            other[0],
            first(&other)
        ));
    }
    out
}

/// How far a detection may be from the labelled face and still be that face; farther,
/// it is a false detection and the face a miss.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Gate {
    pub position_m: f64,
    pub heading_rad: f64,
}

/// A detection against its label: (lateral along the face, depth along the forks' way,
/// heading) error of the detection in the labelled face's frame.
pub fn face_error(label: &Pose2, found: &Pose2) -> [f64; 3] {
    let e = label.to_local(found);
    [e.y_m, e.x_m, wrap_angle(e.heading_rad)]
}

/// Median, 95th percentile (nearest rank) and largest absolute value.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Spread {
    pub median: f64,
    pub p95: f64,
    pub max: f64,
}

fn spread(values: &[f64]) -> Option<Spread> {
    let mut v: Vec<f64> = values.iter().map(|x| x.abs()).collect();
    v.sort_by(f64::total_cmp);
    Some(Spread {
        median: percentile_sorted(&v, 0.5)?,
        p95: percentile_sorted(&v, 0.95)?,
        max: *v.last()?,
    })
}

/// Counts and errors over the labelled scans.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Scores {
    pub labelled: usize,
    pub true_positives: usize,
    pub false_positives: usize,
    pub false_negatives: usize,
    pub true_negatives: usize,
    pub precision: Option<f64>,
    pub recall: Option<f64>,
    /// Scans answered right (found right or rightly empty) over the labelled ones.
    pub accuracy: Option<f64>,
    /// Over matches whose label has a face.
    pub lateral_error_m: Option<Spread>,
    pub depth_error_m: Option<Spread>,
    pub heading_error_rad: Option<Spread>,
}

/// Scores `found` (each scan's detection, by index) against `labels`; scans without a
/// label, and labels of scans the bag does not have, are left out.
pub fn score(found: &[Option<Pose2>], labels: &BTreeMap<usize, Label>, gate: Gate) -> Scores {
    let (mut tp, mut fp, mut fneg, mut tn, mut labelled) = (0, 0, 0, 0, 0);
    let mut errs: [Vec<f64>; 3] = Default::default();
    for (i, l) in labels {
        let Some(det) = found.get(*i) else { continue };
        labelled += 1;
        match (l.present, det) {
            (false, None) => tn += 1,
            (false, Some(_)) => fp += 1,
            (true, None) => fneg += 1,
            (true, Some(d)) => match l.face.map(|f| face_error(&f.pose(), d)) {
                Some(e) if e[0].hypot(e[1]) > gate.position_m || e[2].abs() > gate.heading_rad => {
                    fp += 1;
                    fneg += 1;
                }
                Some(e) => {
                    tp += 1;
                    for k in 0..3 {
                        errs[k].push(e[k]);
                    }
                }
                None => tp += 1,
            },
        }
    }
    let ratio = |a: usize, b: usize| (a + b > 0).then(|| a as f64 / (a + b) as f64);
    Scores {
        labelled,
        true_positives: tp,
        false_positives: fp,
        false_negatives: fneg,
        true_negatives: tn,
        precision: ratio(tp, fp),
        recall: ratio(tp, fneg),
        accuracy: ratio(tp + tn, labelled - tp - tn),
        lateral_error_m: spread(&errs[0]),
        depth_error_m: spread(&errs[1]),
        heading_error_rad: spread(&errs[2]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_the_scores_cannot_use_are_named() {
        let text = r#"{"scans": [
            {"index": 0, "present": true, "face": {"x_m": 3.0, "y_m": 0.0, "heading_deg": 0.0}, "kind": "pallet_kind epal-1"},
            {"index": 1, "present": true},
            {"index": 2, "present": true, "face": {"x_m": 3.0, "y_m": 0.0, "heading_deg": 0.0}, "kind": "pallet_kind field-1200"},
            {"index": 9, "present": false}
        ]}"#;
        let labels = parse_labels(text, "labels.json").expect("parses");
        let p = label_problems(&labels, 3, "pallet_kind epal-1");
        assert_eq!(p.len(), 3, "{p:?}");
        assert!(
            p[0].starts_with("1 labels name scans the bag does not have (it has 3; scans 9)"),
            "{p:?}"
        );
        assert!(p[1].contains("without its face (scans 1)"), "{p:?}");
        assert!(p[2].contains("scan 2 is pallet_kind field-1200"), "{p:?}");
        assert!(label_problems(&labels, 10, "pallet_kind epal-1").len() == 2);
    }

    fn label(index: usize, present: bool, face: Option<(f64, f64, f64)>) -> (usize, Label) {
        let face = face.map(|(x_m, y_m, heading_deg)| LabelFace {
            x_m,
            y_m,
            heading_deg,
        });
        (
            index,
            Label {
                index,
                present,
                face,
                prior: None,
                kind: None,
                clutter: Vec::new(),
            },
        )
    }

    #[test]
    fn counts_matches_misses_and_far_detections() {
        let labels: BTreeMap<usize, Label> = [
            label(0, true, Some((5.0, 0.0, 180.0))),
            label(1, true, Some((5.0, 0.0, 180.0))),
            label(2, true, None),
            label(3, false, None),
            label(4, false, None),
        ]
        .into_iter()
        .collect();
        let pi = std::f64::consts::PI;
        let found = vec![
            Some(Pose2::new(5.0, 0.01, pi)),
            Some(Pose2::new(6.0, 0.0, pi)),
            None,
            Some(Pose2::new(1.0, 1.0, 0.0)),
            None,
            Some(Pose2::new(0.0, 0.0, 0.0)),
        ];
        let gate = Gate {
            position_m: 0.25,
            heading_rad: 0.2,
        };
        let s = score(&found, &labels, gate);
        // 0 matches; 1 is a metre off (a false detection and a miss); 2 missed; 3 false;
        // 4 right; scan 5 has no label.
        assert_eq!(
            (
                s.true_positives,
                s.false_positives,
                s.false_negatives,
                s.true_negatives
            ),
            (1, 2, 2, 1)
        );
        assert_eq!(s.precision, Some(1.0 / 3.0));
        assert_eq!(s.recall, Some(1.0 / 3.0));
        assert_eq!(s.accuracy, Some(2.0 / 5.0));
        let lat = s.lateral_error_m.expect("one match");
        assert!((lat.median - 0.01).abs() < 1e-12, "{lat:?}");
        let e = parse_labels(
            r#"{"scans": [{"index": 1, "present": false}, {"index": 1, "present": true}]}"#,
            "l.json",
        );
        assert!(
            e.expect_err("twice")
                .to_string()
                .contains("l.json: scan 1 is labelled twice")
        );
    }
}
