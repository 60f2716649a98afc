//! Whether a scan bears out a detected pallet face: the face's parts return where the face is, the beams through the pockets go deeper, and nothing stands in front; a score in [0, 1].

use forkbench_core::Pose2;
use forkbench_core::pallet::PalletSpec;
use forkbench_core::profile::{self, Stage};
use forkbench_core::signal::Scan;
use serde::Serialize;

use crate::detector::{DetectRequest, DetectorError, Found, PalletDetector};

/// How much a return may stray from the face line and still be the face: a scanner's
/// range noise and the face's own unevenness, growing with range (beam divergence).
const FACE_TOLERANCE_M: f64 = 0.05;
const FACE_TOLERANCE_PER_M: f64 = 0.01;
/// How far inside a part's or a pocket's edge a beam must cross the face to count, so a
/// beam grazing an edge counts for neither.
const EDGE_MARGIN_M: f64 = 0.02;
/// How much deeper than the face a beam through a pocket must return: half the pallet's
/// depth, at most this (a pocket is open through the pallet; a wall is not).
const MAX_POCKET_DEPTH_M: f64 = 0.4;
/// A return this much in front of the face is something standing before it.
const FRONT_CLEARANCE_M: f64 = 0.15;
/// A pocket beam that could not go this much deeper before meeting the pocket's side
/// (an oblique one near it) cannot tell a pocket from a wall, and is not counted.
const MIN_DISCERNIBLE_M: f64 = 0.1;

/// What the scan says of one face hypothesis.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Default)]
pub struct Evidence {
    /// The product of the three fractions below and the share of the face's parts and
    /// pockets some beam met: 1 when every beam agrees and each was met.
    pub score: f64,
    /// Beams at the face's parts, and how many returned from the face line.
    pub part_beams: usize,
    pub part_hits: usize,
    /// Beams through the pockets' openings, and how many went deeper (or returned nothing).
    pub pocket_beams: usize,
    pub pocket_through: usize,
    /// Beams across the face that returned well in front of it.
    pub blocked: usize,
}

/// The default least score a face needs (a choice): on generated cluttered sets of the
/// field pallet (`forkbench dataset`, seeds 1 and 11) the lowest threshold at which no
/// clutter scene was taken for a pallet. A face seen whole that bears out every part
/// and pocket scores near 1; rack uprights, or two parts without the middle one, near 2/3.
pub const DEFAULT_MIN_SCORE: f64 = 0.85;

/// What the evidence stage made of a request's candidate faces.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Verdict {
    /// The detector's first candidate whose score reaches the threshold, made final by
    /// the detector, with its score.
    pub chosen: Option<(Found, f64)>,
    /// Every candidate's face and score in the detector's order, so a threshold other
    /// than the one asked for can be applied afterwards (a precision-recall curve).
    pub scored: Vec<(Pose2, f64)>,
}

impl Verdict {
    /// The best-scoring candidate (the first of equals) and its score.
    pub fn best(&self) -> Option<(Pose2, f64)> {
        best_of(&self.scored)
    }
}

/// The best-scoring of faces in the detector's order of preference (the first of equals).
pub fn best_of(scored: &[(Pose2, f64)]) -> Option<(Pose2, f64)> {
    scored
        .iter()
        .copied()
        .reduce(|b, c| if c.1 > b.1 { c } else { b })
}

/// The location stage, then the evidence: each of `detector`'s candidate faces scored
/// against its scan (or by the detector's own score when it gives one), and the first
/// in the detector's order of preference that reaches `min_score` taken: the evidence
/// vetoes, the detector ranks (its best fit is often the truer face when two pass). A
/// scan that bears none out holds no pallet. At `min_score` 0 the evidence chooses
/// nothing: the detector's own first face is taken, as its `detect` gives it.
pub fn verified(
    detector: &mut dyn PalletDetector,
    req: &DetectRequest<'_>,
    min_score: f64,
) -> Result<Verdict, DetectorError> {
    let mut v = Verdict::default();
    let mut chosen: Option<(Found, f64)> = None;
    for c in detector.candidates(req)? {
        let Some(s) = req.scans.get(c.sensor) else {
            continue;
        };
        let score = c.score.unwrap_or_else(|| {
            let _timed = profile::enter(Stage::Evidence);
            face_evidence(s.scan, req.pallet, &c.detection.face).score
        });
        v.scored.push((c.detection.face, score));
        if chosen.is_none() && score >= min_score {
            chosen = Some((c, score));
        }
    }
    v.chosen = chosen.map(|(c, score)| (detector.finish(req, c), score));
    Ok(v)
}

/// The evidence `scan` holds for a face at `face` (centre, heading into the pallet, in
/// the scan's frame) of `pallet`: a fraction is 1 when no beam falls in its class.
pub fn face_evidence(scan: &Scan, pallet: &PalletSpec, face: &Pose2) -> Evidence {
    let (parts, pockets) = face_spans(pallet);
    let half = pallet.width_m / 2.0;
    let deeper = (pallet.depth_m / 2.0).min(MAX_POCKET_DEPTH_M);
    let (hc, hs) = (face.heading_rad.cos(), face.heading_rad.sin());
    let mut e = Evidence::default();
    let mut across = 0usize;
    // Which parts and pockets some beam told about: a face of which the scan saw only a
    // part has less for it than one seen whole.
    let mut told = vec![false; parts.len() + pockets.len()];
    for (i, &r) in scan.ranges_m.iter().enumerate() {
        let a = scan.sensor.heading_rad + scan.angle_min_rad + i as f64 * scan.angle_step_rad;
        let (dx, dy) = (a.cos(), a.sin());
        // The beam must come at the face from in front (along the heading into the pallet).
        let toward = dx * hc + dy * hs;
        if toward < 0.2 {
            continue;
        }
        let (ox, oy) = (face.x_m - scan.sensor.x_m, face.y_m - scan.sensor.y_m);
        let t = (ox * hc + oy * hs) / toward;
        if t <= 0.0 {
            continue;
        }
        // Lateral place (left of the heading positive) where the beam crosses the face line.
        let (px, py) = (dx * t - ox, dy * t - oy);
        let s = -px * hs + py * hc;
        if s.abs() > half {
            continue;
        }
        across += 1;
        let returned = r.is_finite();
        if returned && r < t - FRONT_CLEARANCE_M {
            e.blocked += 1;
            continue;
        }
        let inside = |span: &[f64; 2]| well_inside(s, span);
        if let Some(k) = parts.iter().position(inside) {
            told[k] = true;
            e.part_beams += 1;
            let tol = FACE_TOLERANCE_M + FACE_TOLERANCE_PER_M * t;
            e.part_hits += usize::from(returned && (r - t).abs() <= tol);
        } else if let Some(k) = pockets.iter().position(inside) {
            let span = &pockets[k];
            // How deep the beam can go before the pocket's side: an oblique beam meets it
            // early, so it is asked for less.
            let slope = (-dx * hs + dy * hc) / toward;
            let room = if slope > 0.0 {
                span[1] - s
            } else {
                s - span[0]
            };
            let reach = if slope.abs() < 1e-9 {
                f64::INFINITY
            } else {
                room / slope.abs()
            };
            let need = deeper.min(0.8 * reach);
            if need < MIN_DISCERNIBLE_M {
                continue;
            }
            told[parts.len() + k] = true;
            e.pocket_beams += 1;
            e.pocket_through += usize::from(!returned || r >= t + need);
        }
    }
    let frac = |k: usize, n: usize| if n == 0 { 1.0 } else { k as f64 / n as f64 };
    // A face no beam meets at its parts (seen edge-on, from behind, or out of view) has
    // no evidence for it, which is not evidence.
    if e.part_beams == 0 {
        return e;
    }
    let seen = told.iter().filter(|t| **t).count() as f64 / told.len().max(1) as f64;
    e.score = frac(e.part_hits, e.part_beams)
        * frac(e.pocket_through, e.pocket_beams)
        * (1.0 - e.blocked as f64 / across.max(1) as f64)
        * seen;
    e
}

/// Whether a beam crossing the face at `s` falls inside `span` by the edge margin, at
/// most a quarter of the span (a GMA's 35 mm stringers keep a middle for beams to meet).
fn well_inside(s: f64, span: &[f64; 2]) -> bool {
    let m = EDGE_MARGIN_M.min((span[1] - span[0]) / 4.0);
    s > span[0] + m && s < span[1] - m
}

/// The lateral spans `[right, left]` of the parts at the face (those starting within a
/// few centimetres of it) and of the openings between them.
fn face_spans(pallet: &PalletSpec) -> (Vec<[f64; 2]>, Vec<[f64; 2]>) {
    let mut parts: Vec<[f64; 2]> = pallet
        .parts()
        .iter()
        .filter(|b| b.x_range()[0] <= 0.05)
        .map(|b| b.y_range())
        .collect();
    parts.sort_by(|a, b| a[0].total_cmp(&b[0]));
    let pockets = parts
        .windows(2)
        .filter(|w| w[1][0] > w[0][1])
        .map(|w| [w[0][1], w[1][0]])
        .collect();
    (parts, pockets)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 270° scan from the origin at 0.25° steps of a world made of `segments`.
    fn scan_of(segments: &[[[f64; 2]; 2]]) -> Scan {
        let step = 0.25f64.to_radians();
        let n = 1081;
        let ranges = (0..n)
            .map(|i| {
                let a = -135f64.to_radians() + i as f64 * step;
                let (dx, dy) = (a.cos(), a.sin());
                segments
                    .iter()
                    .filter_map(|&[p, q]| {
                        let (ex, ey) = (q[0] - p[0], q[1] - p[1]);
                        let den = dx * ey - dy * ex;
                        if den.abs() < 1e-12 {
                            return None;
                        }
                        let t = (p[0] * ey - p[1] * ex) / den;
                        let u = (p[0] * dy - p[1] * dx) / den;
                        (t > 0.0 && (0.0..=1.0).contains(&u)).then_some(t)
                    })
                    .fold(f64::NAN, |m, t| if m.is_nan() || t < m { t } else { m })
            })
            .collect();
        Scan {
            sensor: Pose2::new(0.0, 0.0, 0.0),
            angle_min_rad: -135f64.to_radians(),
            angle_step_rad: step,
            range_min_m: 0.05,
            range_max_m: 20.0,
            ranges_m: ranges,
        }
    }

    /// The pallet's face parts at `x` (facing the origin along +x), and a wall behind.
    fn pallet_scene(p: &PalletSpec, x: f64) -> Vec<[[f64; 2]; 2]> {
        let (parts, _) = face_spans(p);
        let mut segs: Vec<[[f64; 2]; 2]> = parts.iter().map(|s| [[x, s[0]], [x, s[1]]]).collect();
        segs.push([[x + 4.0, -5.0], [x + 4.0, 5.0]]);
        segs
    }

    #[test]
    fn a_pallet_scores_high_and_a_wall_or_a_blocked_face_low() {
        let p = PalletSpec::field_1200();
        let face = Pose2::new(3.0, 0.0, 0.0);
        let real = face_evidence(&scan_of(&pallet_scene(&p, 3.0)), &p, &face);
        assert!(real.score > 0.9 && real.pocket_beams > 5, "{real:?}");
        // A wall where the face would be: its pockets return at the face line.
        let wall = face_evidence(&scan_of(&[[[3.0, -5.0], [3.0, 5.0]]]), &p, &face);
        assert!(wall.score < 0.1 && wall.pocket_through == 0, "{wall:?}");
        // A box standing in front of the face across its width.
        let mut boxed = pallet_scene(&p, 3.0);
        boxed.push([[2.0, -1.0], [2.0, 1.0]]);
        let blocked = face_evidence(&scan_of(&boxed), &p, &face);
        assert!(blocked.score < 0.1, "{blocked:?}");
    }

    /// Segments of the pallet's parts as rectangles (the scan plane's cut) with its face
    /// at `face` (heading into it), and a wall `behind_m` beyond the face.
    fn placed_pallet(p: &PalletSpec, face: &Pose2, behind_m: f64) -> Vec<[[f64; 2]; 2]> {
        let at = |x: f64, y: f64| {
            let w = face.to_world(&Pose2::new(x, y, 0.0));
            [w.x_m, w.y_m]
        };
        let mut segs = Vec::new();
        for b in p.parts() {
            let ([x0, x1], [y0, y1]) = (b.x_range(), b.y_range());
            let c = [at(x0, y0), at(x0, y1), at(x1, y1), at(x1, y0)];
            segs.extend((0..4).map(|k| [c[k], c[(k + 1) % 4]]));
        }
        segs.push([at(behind_m, -6.0), at(behind_m, 6.0)]);
        segs
    }

    /// A pallet-like façade: boxes of the face parts' widths, `proud_m` deep, on a wall
    /// (what a wall with pilasters, or goods on a shelf, shows a scanner).
    fn facade(p: &PalletSpec, face: &Pose2, proud_m: f64) -> Vec<[[f64; 2]; 2]> {
        let mut q = p.clone();
        q.depth_m = proud_m;
        q.blocks = face_spans(p)
            .0
            .iter()
            .map(|s| forkbench_core::pallet::PalletBlock {
                x_m: proud_m / 2.0,
                y_m: (s[0] + s[1]) / 2.0,
                length_m: proud_m,
                width_m: s[1] - s[0],
            })
            .collect();
        placed_pallet(&q, face, proud_m)
    }

    /// Both location stages on simulated scenes, without a prior: a pallet at 2–6 m and
    /// ±20° is still found, and what they locate on walls and façades is turned down.
    #[test]
    fn the_evidence_turns_down_facades_and_keeps_pallets() {
        use crate::detector::{PalletDetector, detect_in};
        let p = PalletSpec::field_1200();
        let faces: Vec<Pose2> = [2.0, 4.0, 6.0]
            .iter()
            .flat_map(|&d| {
                [-20.0f64, 0.0, 20.0].map(|a| Pose2::new(d, 0.3 * a.signum(), a.to_radians()))
            })
            .collect();
        let scenes = |f: &dyn Fn(&Pose2) -> Vec<[[f64; 2]; 2]>| -> Vec<(Scan, Pose2)> {
            faces
                .iter()
                .map(|face| (scan_of(&f(face)), *face))
                .collect()
        };
        let pallets = scenes(&|face| placed_pallet(&p, face, 3.0));
        let mut fakes = scenes(&|face| facade(&p, face, 0.15));
        fakes.extend(scenes(&|face| facade(&p, face, 0.3)));
        fakes.extend(scenes(&|face| {
            vec![
                [
                    face.to_world(&Pose2::new(0.0, -5.0, 0.0)),
                    face.to_world(&Pose2::new(0.0, 5.0, 0.0)),
                ]
                .map(|q| [q.x_m, q.y_m]),
            ]
        }));
        let mut detectors: Vec<Box<dyn PalletDetector>> = vec![
            Box::new(crate::detector::Pockets::default()),
            Box::new(crate::face_fit::FaceFit::default()),
        ];
        for d in &mut detectors {
            let mut count = |set: &[(Scan, Pose2)]| {
                let (mut located, mut kept) = (0, 0);
                for (scan, _) in set {
                    let found = detect_in(d.as_mut(), &[("laser", scan.clone())], &p, None)
                        .expect("detects");
                    if let Some(f) = found {
                        located += 1;
                        kept +=
                            usize::from(face_evidence(scan, &p, &f.detection.face).score >= 0.5);
                    }
                }
                (located, kept)
            };
            let (pl, pk) = count(&pallets);
            let (fl, fk) = count(&fakes);
            eprintln!(
                "{}: pallets located {pl} kept {pk} of {}; fakes located {fl} kept {fk} of {}",
                d.name(),
                pallets.len(),
                fakes.len()
            );
            assert_eq!(pk, pl, "{}: a located pallet was turned down", d.name());
            assert_eq!(fk, 0, "{}: a façade was kept", d.name());
        }
    }
}
