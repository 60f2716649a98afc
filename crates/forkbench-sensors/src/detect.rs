//! A pallet pocket detector for 2-D scans at fork-pocket height, the way published laser detectors work: segment the scan, keep the segments a stringer face could make, find stringers spaced as the pallet's are, fit the face line.

use forkbench_core::signal::Scan;
use forkbench_core::units::wrap_angle;
use forkbench_core::{PalletSpec, Pose2};
use serde::{Deserialize, Serialize};

/// The detector's tolerances (SI).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DetectorConfig {
    /// Neighbouring returns further apart than this plus the beam spacing at their range
    /// start a new segment.
    pub break_m: f64,
    /// A run of returns bends into separate straight pieces (a stringer's face and its
    /// side seen through a pocket) where a point lies this far off their chord.
    pub split_m: f64,
    /// Fewest returns on a stringer face, as a share of the beams a whole face gets at
    /// its range (a sliver of a half-hidden one is not enough), and never below 2.
    pub min_coverage: f64,
    /// A stringer face's segment may be this much narrower or wider than the stringer.
    pub width_tolerance_m: f64,
    /// Stringer centres may sit this far from the pallet's spacing.
    pub spacing_tolerance_m: f64,
    /// With a prior, faces further than this or turned more than `roi_rad` from it are
    /// not this pallet.
    pub roi_m: f64,
    pub roi_rad: f64,
    /// A stringer's centre may lie this far off the face line through the others.
    pub line_tolerance_m: f64,
    /// `face_fit`: a return this close to the face line hit the face; farther behind it,
    /// the beam passed through an opening (or missed the pallet).
    pub edge_tolerance_m: f64,
}

impl Default for DetectorConfig {
    fn default() -> Self {
        Self {
            break_m: 0.06,
            split_m: 0.05,
            min_coverage: 0.6,
            width_tolerance_m: 0.08,
            spacing_tolerance_m: 0.08,
            roi_m: 1.0,
            roi_rad: 0.5,
            line_tolerance_m: 0.08,
            edge_tolerance_m: 0.05,
        }
    }
}

impl DetectorConfig {
    /// Every value in its documented range, naming the field (a NaN would make every
    /// comparison false and every trial `pallet_not_found`).
    pub fn validate(&self) -> Result<(), forkbench_core::SettingsError> {
        let lengths = [
            ("break_m", self.break_m),
            ("split_m", self.split_m),
            ("width_tolerance_m", self.width_tolerance_m),
            ("spacing_tolerance_m", self.spacing_tolerance_m),
            ("roi_m", self.roi_m),
            ("line_tolerance_m", self.line_tolerance_m),
            ("edge_tolerance_m", self.edge_tolerance_m),
        ];
        for (f, v) in lengths {
            if !(v.is_finite() && v > 0.0 && v <= 10.0) {
                return Err(forkbench_core::SettingsError::field(
                    f,
                    "must lie in (0, 10] m",
                ));
            }
        }
        if !(self.roi_rad > 0.0 && self.roi_rad <= std::f64::consts::PI) {
            return Err(forkbench_core::SettingsError::field(
                "roi_rad",
                "must lie in (0, π]",
            ));
        }
        if !(self.min_coverage > 0.0 && self.min_coverage <= 1.0) {
            return Err(forkbench_core::SettingsError::field(
                "min_coverage",
                "must lie in (0, 1]",
            ));
        }
        Ok(())
    }
}

/// A pallet found in a scan.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Detection {
    /// Face centre, heading into the pallet (the direction the forks travel).
    pub face: Pose2,
    /// Stringer faces the fit used (2 when one is hidden).
    pub stringers: usize,
    /// Returns on those faces, and their RMS distance from the fitted face line.
    pub points: usize,
    pub rms_m: f64,
}

/// Points further than this (or 2.5 RMS) off the first face line are left out of the
/// second fit.
const REFIT_M: f64 = 0.02;

/// One run of neighbouring returns.
#[derive(Debug, Clone)]
struct Segment {
    points: Vec<[f64; 2]>,
    centre: [f64; 2],
    width_m: f64,
}

impl Segment {
    fn of(points: Vec<[f64; 2]>) -> Self {
        let n = points.len() as f64;
        let centre = [
            points.iter().map(|p| p[0]).sum::<f64>() / n,
            points.iter().map(|p| p[1]).sum::<f64>() / n,
        ];
        let (a, b) = (points[0], points[points.len() - 1]);
        let width_m = (b[0] - a[0]).hypot(b[1] - a[1]);
        Self {
            points,
            centre,
            width_m,
        }
    }
}

/// The scan's returns split where neighbouring beams jump in range or return nothing.
fn segments(scan: &Scan, break_m: f64) -> Vec<Segment> {
    let mut out = Vec::new();
    let mut run: Vec<[f64; 2]> = Vec::new();
    let mut last_r = f64::NAN;
    let s = &scan.sensor;
    for (i, &r) in scan.ranges_m.iter().enumerate() {
        let joins = r.is_finite()
            && last_r.is_finite()
            && (r - last_r).abs() <= break_m + 2.0 * r * scan.angle_step_rad;
        if !joins && !run.is_empty() {
            out.push(Segment::of(std::mem::take(&mut run)));
        }
        if r.is_finite() {
            let a = s.heading_rad + scan.angle_min_rad + i as f64 * scan.angle_step_rad;
            run.push([s.x_m + r * a.cos(), s.y_m + r * a.sin()]);
        }
        last_r = r;
    }
    if !run.is_empty() {
        out.push(Segment::of(run));
    }
    out
}

/// `points` split into straight pieces (Douglas–Peucker): at the point farthest from
/// the chord while it lies more than `tol_m` off; a corner point ends one piece and
/// starts the next.
fn straight_pieces(points: &[[f64; 2]], tol_m: f64) -> Vec<Vec<[f64; 2]>> {
    let n = points.len();
    if n < 3 {
        return vec![points.to_vec()];
    }
    let (a, b) = (points[0], points[n - 1]);
    let len = dist(a, b).max(1e-12);
    let off =
        |p: &[f64; 2]| ((p[0] - a[0]) * (b[1] - a[1]) - (p[1] - a[1]) * (b[0] - a[0])).abs() / len;
    let (k, worst) = points[1..n - 1]
        .iter()
        .enumerate()
        .map(|(i, p)| (i + 1, off(p)))
        .fold((0, 0.0), |m, c| if c.1 > m.1 { c } else { m });
    if worst <= tol_m {
        return vec![points.to_vec()];
    }
    let mut out = straight_pieces(&points[..=k], tol_m);
    out.extend(straight_pieces(&points[k..], tol_m));
    out
}

/// Total-least-squares line through `points`: (centroid, unit direction, RMS residual).
pub(crate) fn fit_line(points: &[[f64; 2]]) -> ([f64; 2], [f64; 2], f64) {
    let n = points.len() as f64;
    let c = [
        points.iter().map(|p| p[0]).sum::<f64>() / n,
        points.iter().map(|p| p[1]).sum::<f64>() / n,
    ];
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for p in points {
        let (dx, dy) = (p[0] - c[0], p[1] - c[1]);
        sxx += dx * dx;
        sxy += dx * dy;
        syy += dy * dy;
    }
    let theta = 0.5 * (2.0 * sxy).atan2(sxx - syy);
    let d = [theta.cos(), theta.sin()];
    let rms = (points
        .iter()
        .map(|p| ((p[0] - c[0]) * -d[1] + (p[1] - c[1]) * d[0]).powi(2))
        .sum::<f64>()
        / n)
        .sqrt();
    (c, d, rms)
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// A set of stringer segments taken as one pallet face: which slots (0 left of the
/// sensor's view … 2) they fill is decided by their spacing.
struct Candidate<'a> {
    segs: Vec<&'a Segment>,
    /// Face centre offset along the face line from the first segment's centre.
    centre_from_first_m: f64,
}

/// Finds the pallet; with a `prior` (the last estimate) the candidate nearest it wins,
/// else the nearest to the sensor. `None`: no stringers spaced like this pallet's.
pub fn detect(
    cfg: &DetectorConfig,
    scan: &Scan,
    pallet: &PalletSpec,
    prior: Option<&Pose2>,
) -> Option<Detection> {
    detect_ranked(cfg, scan, pallet, prior).into_iter().next()
}

/// Most faces [`detect_ranked`] gives: a cluttered scan has many spacings that fit, and
/// each further one costs the evidence stage a pass over the scan.
pub const MAX_CANDIDATES: usize = 24;

/// Every face the scan's stringer-like pieces could make, the one [`detect`] picks first
/// and the rest in the same order of preference, faces within a centimetre and a
/// hundredth of a radian of a better one left out; at most [`MAX_CANDIDATES`].
pub fn detect_ranked(
    cfg: &DetectorConfig,
    scan: &Scan,
    pallet: &PalletSpec,
    prior: Option<&Pose2>,
) -> Vec<Detection> {
    let (edge_w, spacing) = pallet.edge_part_m();
    let widths = [edge_w, pallet.centre_part_width_m()];
    let segs: Vec<Segment> = segments(scan, cfg.break_m)
        .into_iter()
        .flat_map(|s| straight_pieces(&s.points, cfg.split_m))
        .map(Segment::of)
        .filter(|s| {
            widths
                .iter()
                .any(|&w| looks_like_a_stringer(cfg, s, scan, w))
        })
        .collect();
    let candidates = pair_up(cfg, &segs, spacing);
    let found: Vec<Detection> = candidates
        .iter()
        .filter_map(|c| face_of(c, scan, pallet))
        .collect();
    // With a prior (where the pallet should be): only faces within the region of
    // interest, the nearest to it winning and a hidden stringer costing a little.
    // Without one: three stringers beat two, then nearness to the sensor.
    let s = scan.sensor;
    let found = found.into_iter().filter(|d| {
        prior.is_none_or(|p| {
            d.face.distance_to(p) <= cfg.roi_m
                && wrap_angle(d.face.heading_rad - p.heading_rad).abs() <= cfg.roi_rad
        })
    });
    let score = |d: &Detection| match prior {
        Some(p) => {
            d.face.distance_to(p)
                + 0.5 * wrap_angle(d.face.heading_rad - p.heading_rad).abs()
                + 0.25 * (3 - d.stringers.min(3)) as f64
        }
        None => (3 - d.stringers.min(3)) as f64 * 1e6 + d.face.distance_to(&s),
    };
    let mut ranked: Vec<(f64, Detection)> = found.map(|d| (score(&d), d)).collect();
    ranked.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut out: Vec<Detection> = Vec::new();
    for (_, d) in ranked {
        let same = |o: &Detection| {
            o.face.distance_to(&d.face) < 0.01
                && wrap_angle(o.face.heading_rad - d.face.heading_rad).abs() < 0.01
        };
        if !out.iter().any(same) {
            out.push(d);
            if out.len() == MAX_CANDIDATES {
                break;
            }
        }
    }
    out
}

/// The faces stringer-like pieces could make: outer pairs (the centre one between them
/// when seen) and neighbours with the third hidden, read both ways.
fn pair_up<'a>(cfg: &DetectorConfig, segs: &'a [Segment], spacing: f64) -> Vec<Candidate<'a>> {
    let mut candidates = Vec::new();
    for (i, a) in segs.iter().enumerate() {
        for (j, b) in segs.iter().enumerate().skip(i + 1) {
            let d = dist(a.centre, b.centre);
            if (d - 2.0 * spacing).abs() <= cfg.spacing_tolerance_m {
                // The outer pair; the centre stringer, when visible, sits between them.
                let mid = [
                    (a.centre[0] + b.centre[0]) / 2.0,
                    (a.centre[1] + b.centre[1]) / 2.0,
                ];
                let mut set = vec![a, b];
                if let Some(c) = segs[i + 1..j]
                    .iter()
                    .find(|c| dist(c.centre, mid) <= cfg.line_tolerance_m)
                {
                    set.push(c);
                }
                candidates.push(Candidate {
                    segs: set,
                    centre_from_first_m: d / 2.0,
                });
            } else if (d - spacing).abs() <= cfg.spacing_tolerance_m {
                // Two neighbours, the third hidden: which two they are is ambiguous, so
                // both readings are candidates for the prior to decide.
                // (left, centre): the centre is the second; (centre, right): the first.
                for centre_from_first_m in [d, 0.0] {
                    candidates.push(Candidate {
                        segs: vec![a, b],
                        centre_from_first_m,
                    });
                }
            }
        }
    }
    candidates
}

/// Whether a straight piece could be a stringer's face: as wide as one (the returns span
/// about one beam spacing less than the face) and covered by enough of the beams that
/// fall on a face at that range.
fn looks_like_a_stringer(cfg: &DetectorConfig, s: &Segment, scan: &Scan, sw: f64) -> bool {
    let r = dist(s.centre, [scan.sensor.x_m, scan.sensor.y_m]);
    let spacing = r * scan.angle_step_rad;
    let beams_on_face = sw / spacing.max(1e-6);
    let enough = (s.points.len() as f64) >= (cfg.min_coverage * beams_on_face).max(2.0);
    enough && (s.width_m + spacing - sw).abs() <= cfg.width_tolerance_m
}

/// The face pose of a candidate: the line through its segments' points, centred.
fn face_of(c: &Candidate<'_>, scan: &Scan, pallet: &PalletSpec) -> Option<Detection> {
    let all: Vec<[f64; 2]> = c
        .segs
        .iter()
        .flat_map(|s| s.points.iter().copied())
        .collect();
    // Refit without the points far off the line (a corner of a stringer's side, a mixed
    // return): they would tilt the face. Each round tightens as the fit improves.
    let mut points = all;
    for _ in 0..3 {
        let (c0, d0, rms0) = fit_line(&points);
        let keep = REFIT_M.max(2.5 * rms0);
        points.retain(|p| ((p[0] - c0[0]) * -d0[1] + (p[1] - c0[1]) * d0[0]).abs() <= keep);
        if points.len() < 3 {
            return None;
        }
    }
    let (_, d, rms) = fit_line(&points);
    // Orient the line from the first segment towards the second.
    let (p0, p1) = (c.segs[0].centre, c.segs[1].centre);
    let along = if (p1[0] - p0[0]) * d[0] + (p1[1] - p0[1]) * d[1] >= 0.0 {
        d
    } else {
        [-d[0], -d[1]]
    };
    let centre = [
        p0[0] + c.centre_from_first_m * along[0],
        p0[1] + c.centre_from_first_m * along[1],
    ];
    // Into the pallet: the face normal pointing away from the sensor.
    let mut n = [-along[1], along[0]];
    let s = scan.sensor;
    if (centre[0] - s.x_m) * n[0] + (centre[1] - s.y_m) * n[1] < 0.0 {
        n = [-n[0], -n[1]];
    }
    // A face wider than the pallet is not this pallet.
    let width = dist(c.segs[0].centre, c.segs[1].centre);
    (width <= pallet.width_m + 0.1).then_some(Detection {
        face: Pose2::new(centre[0], centre[1], n[1].atan2(n[0])),
        stringers: c.segs.len(),
        points: points.len(),
        rms_m: rms,
    })
}

#[cfg(test)]
#[path = "detect_tests.rs"]
mod tests;
