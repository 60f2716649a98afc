//! The scans a detector got wrong against their labels, each with its label and what was found, to read the failures one by one.

use std::collections::BTreeMap;

use forkbench_core::Pose2;
use serde::Serialize;

use crate::detect_eval::{Gate, Label, LabelFace, face_error};

/// The most wrong scans listed (the count covers them all): bounds the output of a set of
/// any size.
pub const MAX_LISTED: usize = 10_000;

/// One scan the detector got wrong.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Wrong {
    pub index: usize,
    /// "missed" (a pallet, nothing found), "false detection" (no pallet, a face found) or
    /// "off the face" (found farther from the labelled face than the match gate).
    pub why: &'static str,
    /// The labelled face, when the label has one.
    pub label: Option<LabelFace>,
    /// What the detector found, in the labels' frame.
    pub found: Option<LabelFace>,
}

/// The wrong scans among the labelled ones, in scan order (at most [`MAX_LISTED`]), and
/// how many there were in all; scans without a label, and labels of scans the bag does
/// not have, are left out as the scores leave them.
pub fn wrong_scans(
    found: &[Option<Pose2>],
    labels: &BTreeMap<usize, Label>,
    gate: Gate,
) -> (Vec<Wrong>, usize) {
    let mut listed = Vec::new();
    let mut total = 0;
    for (i, l) in labels {
        let Some(det) = found.get(*i) else { continue };
        let why = match (l.present, det, l.face) {
            (true, None, _) => "missed",
            (false, Some(_), _) => "false detection",
            (true, Some(d), Some(f)) => {
                let e = face_error(&f.pose(), d);
                if e[0].hypot(e[1]) <= gate.position_m && e[2].abs() <= gate.heading_rad {
                    continue;
                }
                "off the face"
            }
            _ => continue,
        };
        total += 1;
        if listed.len() < MAX_LISTED {
            listed.push(Wrong {
                index: *i,
                why,
                label: l.face,
                found: det.map(|p| LabelFace {
                    x_m: p.x_m,
                    y_m: p.y_m,
                    heading_deg: p.heading_rad.to_degrees(),
                }),
            });
        }
    }
    (listed, total)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_wrong_scan_is_listed_with_its_label_and_what_was_found() {
        let text = r#"{"scans": [
            {"index": 0, "present": true, "face": {"x_m": 3.0, "y_m": 0.0, "heading_deg": 0.0}},
            {"index": 1, "present": true, "face": {"x_m": 3.0, "y_m": 0.0, "heading_deg": 0.0}},
            {"index": 2, "present": false},
            {"index": 3, "present": true, "face": {"x_m": 3.0, "y_m": 0.0, "heading_deg": 0.0}},
            {"index": 4, "present": false}
        ]}"#;
        let labels = crate::detect_eval::parse_labels(text, "l.json").expect("parses");
        let found = [
            Some(Pose2::new(3.01, 0.0, 0.0)),
            None,
            Some(Pose2::new(2.0, 1.0, 0.0)),
            Some(Pose2::new(3.0, 0.5, 0.0)),
            None,
        ];
        let gate = Gate {
            position_m: 0.25,
            heading_rad: 10f64.to_radians(),
        };
        let (wrong, total) = wrong_scans(&found, &labels, gate);
        let got: Vec<(usize, &str)> = wrong.iter().map(|w| (w.index, w.why)).collect();
        assert_eq!(
            got,
            [(1, "missed"), (2, "false detection"), (3, "off the face")]
        );
        assert_eq!(total, 3);
        assert_eq!(wrong[2].found.map(|f| f.y_m), Some(0.5));
        assert!(wrong[1].label.is_none() && wrong[0].found.is_none());
    }
}
