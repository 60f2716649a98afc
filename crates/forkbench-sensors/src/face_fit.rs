//! The pallet's face model fitted to every beam near its face: the face line through all returns on it, and its place along that line where the model's solid parts and openings agree with which beams hit the face and which passed through, to a fraction of a beam step.

use forkbench_core::signal::Scan;
use forkbench_core::{PalletSpec, Pose2};

use crate::detect::{Detection, DetectorConfig, detect, fit_line};
use crate::detector::{DetectRequest, DetectorError, Found, PalletDetector};

/// The pocket detector finds the face (anywhere in view, or near a prior); the model fit
/// then refines it from all the beams that fall on or through the face.
#[derive(Debug, Clone, Default)]
pub struct FaceFit {
    pub cfg: DetectorConfig,
}

impl PalletDetector for FaceFit {
    fn name(&self) -> &str {
        "face_fit"
    }

    fn detect(&mut self, req: &DetectRequest<'_>) -> Result<Option<Found>, DetectorError> {
        Ok(req.scans.iter().enumerate().find_map(|(i, s)| {
            let first = detect(&self.cfg, s.scan, req.pallet, req.prior.as_ref())?;
            Some(Found {
                detection: refine(&self.cfg, s.scan, req.pallet, &first),
                sensor: i,
                score: None,
            })
        }))
    }

    fn candidates(&mut self, req: &DetectRequest<'_>) -> Result<Vec<Found>, DetectorError> {
        Ok(crate::detector::ranked(&self.cfg, req))
    }

    fn finish(&mut self, req: &DetectRequest<'_>, found: Found) -> Found {
        let scan = req.scans[found.sensor].scan;
        Found {
            detection: refine(&self.cfg, scan, req.pallet, &found.detection),
            ..found
        }
    }
}

/// What a beam did at the face line: hit it, passed through an opening, or was stopped
/// before it (by something in front, which says nothing about the face).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Beam {
    On,
    Through,
    Blocked,
}

/// A beam in the face's frame (x into the pallet, y along the face) where it crosses the
/// face line: its index, direction, measured range, range to the line `t` and lateral
/// place `u` there.
#[derive(Debug, Clone, Copy)]
struct FaceBeam {
    index: usize,
    dir: [f64; 2],
    range_m: f64,
    t: f64,
    u: f64,
}

/// The sensor's place in the face's frame, and the beams that cross the face line ahead
/// of it within `reach` of the face's centre.
fn face_beams(scan: &Scan, face: &Pose2, reach: f64) -> ([f64; 2], Vec<FaceBeam>) {
    let s = face.to_local(&scan.sensor);
    let beams = scan
        .ranges_m
        .iter()
        .enumerate()
        .filter_map(|(index, r)| {
            let a = s.heading_rad + scan.angle_min_rad + index as f64 * scan.angle_step_rad;
            let (dy, dx) = a.sin_cos();
            let t = -s.x_m / dx;
            let u = s.y_m + t * dy;
            (dx > 1e-6 && t > 0.0 && u.abs() <= reach).then_some(FaceBeam {
                index,
                dir: [dx, dy],
                range_m: *r,
                t,
                u,
            })
        })
        .collect();
    ([s.x_m, s.y_m], beams)
}

/// A beam's crossing of the face line: its lateral place `u`, and where it hit the face
/// (map frame) when it did.
#[derive(Debug, Clone, Copy)]
struct Crossing {
    u: f64,
    point: Option<[f64; 2]>,
}

/// The beams crossing the face line of `face` within the pallet's width and a margin.
fn crossings(tol_m: f64, scan: &Scan, pallet: &PalletSpec, face: &Pose2) -> Vec<Crossing> {
    let (_, beams) = face_beams(scan, face, pallet.width_m / 2.0 + 0.3);
    beams
        .iter()
        .map(|b| {
            let r = b.range_m;
            let beam = if !r.is_finite() || r > b.t + tol_m {
                Beam::Through
            } else if r < b.t - tol_m {
                Beam::Blocked
            } else {
                Beam::On
            };
            let point = (beam == Beam::On).then(|| {
                let w = scan.sensor.heading_rad
                    + scan.angle_min_rad
                    + b.index as f64 * scan.angle_step_rad;
                [scan.sensor.x_m + r * w.cos(), scan.sensor.y_m + r * w.sin()]
            });
            Crossing { u: b.u, point }
        })
        .collect()
}

/// The face line refitted through every beam that hit it near the solid parts, the face
/// kept at the same place along it and turned to the new line; and the tolerance that
/// tells a hit on the face from a beam that went behind it: three robust standard
/// deviations of the hits (the median absolute deviation), within 3 mm and `max_m`.
fn refit_line(max_m: f64, scan: &Scan, pallet: &PalletSpec, face: &Pose2) -> (Pose2, f64, usize) {
    let solid = pallet.face_solids();
    let pts: Vec<[f64; 2]> = crossings(max_m, scan, pallet, face)
        .iter()
        .filter(|c| solid.iter().any(|[lo, hi]| c.u >= *lo && c.u <= *hi))
        .filter_map(|c| c.point)
        .collect();
    if pts.len() < 3 {
        return (*face, max_m, 0);
    }
    let (c, d, _) = fit_line(&pts);
    let res: Vec<f64> = pts
        .iter()
        .map(|p| ((p[0] - c[0]) * -d[1] + (p[1] - c[1]) * d[0]).abs())
        .collect();
    let mut sorted = res.clone();
    sorted.sort_by(f64::total_cmp);
    let sigma = 1.4826 * sorted[sorted.len() / 2];
    let tol = (3.0 * sigma).clamp(0.003, max_m);
    let kept: Vec<[f64; 2]> = pts
        .iter()
        .zip(&res)
        .filter(|(_, r)| **r <= tol)
        .map(|(p, _)| *p)
        .collect();
    let used = kept.len();
    let (c, d) = if used >= 3 {
        let (c, d, _) = fit_line(&kept);
        (c, d)
    } else {
        (c, d)
    };
    // The normal on the same side as before (into the pallet).
    let (fs, fc) = face.heading_rad.sin_cos();
    let mut n = [-d[1], d[0]];
    if n[0] * fc + n[1] * fs < 0.0 {
        n = [-n[0], -n[1]];
    }
    // The old centre moved onto the new line along its normal.
    let off = (face.x_m - c[0]) * d[0] + (face.y_m - c[1]) * d[1];
    let moved = Pose2::new(c[0] + off * d[0], c[1] + off * d[1], n[1].atan2(n[0]));
    (moved, tol, used)
}

/// The solid parts (stringers or blocks) as boxes `[front, back, right, left]` in the
/// face frame.
fn solid_parts(pallet: &PalletSpec) -> Vec<[f64; 4]> {
    pallet
        .parts()
        .iter()
        .map(|b| {
            let ([x0, x1], [y0, y1]) = (b.x_range(), b.y_range());
            [x0, x1, y0, y1]
        })
        .collect()
}

/// The range at which a beam from `o` along `d` (face frame) first meets a solid part of
/// the model placed `du` along the face.
fn model_range(o: [f64; 2], d: [f64; 2], parts: &[[f64; 4]], du: f64) -> f64 {
    let mut best = f64::INFINITY;
    for [x0, x1, lo, hi] in parts {
        let (lo, hi) = (lo + du, hi + du);
        // Slab intersection with [x0, x1] × [lo, hi].
        let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
        for (o, d, a, b) in [(o[0], d[0], *x0, *x1), (o[1], d[1], lo, hi)] {
            if d.abs() < 1e-12 {
                if o < a || o > b {
                    t1 = -1.0;
                }
                continue;
            }
            let (ta, tb) = ((a - o) / d, (b - o) / d);
            t0 = t0.max(ta.min(tb));
            t1 = t1.min(ta.max(tb));
        }
        if t0 <= t1 && t0 < best {
            best = t0;
        }
    }
    best
}

/// Only this far behind the face does a beam tell where the solid parts are: deeper, a
/// small error in the face's heading would move the parts' long sides by more than the
/// fit resolves.
const ZONE_M: f64 = 0.15;

/// How well the model placed `du` along the face explains the beams: within the zone
/// behind the face, each beam's range against the range it would have to the model's
/// solid parts, squared and capped at `cap_m`; a return in the zone where the model has
/// none (or the other way round) costs the cap; a beam stopped in front of the face
/// costs nothing (it says nothing of the pallet).
fn misfit(origin: [f64; 2], beams: &[FaceBeam], parts: &[[f64; 4]], du: f64, cap_m: f64) -> f64 {
    beams
        .iter()
        .map(|b| {
            let r = b.range_m;
            if r < b.t - cap_m {
                return 0.0;
            }
            let deep = b.t + ZONE_M / b.dir[0];
            let want = model_range(origin, b.dir, parts, du);
            match (r.is_finite() && r <= deep, want <= deep) {
                (false, false) => 0.0,
                (true, true) => (r - want).abs().min(cap_m).powi(2),
                _ => cap_m * cap_m,
            }
        })
        .sum()
}

/// How far along the face the model sits: the offset (within ±0.1 m) at which its solid
/// parts best explain every beam that falls on or through the face, searched in 2 mm
/// steps then 0.1 mm, the middle of the best offsets where several fit equally.
fn lateral_offset(scan: &Scan, pallet: &PalletSpec, face: &Pose2, tol_m: f64) -> Option<f64> {
    let (origin, beams) = face_beams(scan, face, pallet.width_m / 2.0 + 0.12);
    if beams.len() < 4 {
        return None;
    }
    let parts = solid_parts(pallet);
    let cap = tol_m.max(0.01);
    let cost = |du: f64| misfit(origin, &beams, &parts, du, cap);
    let best_of = |centre: f64, step: f64, n: i32| {
        let costs: Vec<(f64, f64)> = (-n..=n)
            .map(|k| centre + k as f64 * step)
            .map(|du| (du, cost(du)))
            .collect();
        let min = costs.iter().map(|c| c.1).fold(f64::INFINITY, f64::min);
        let ties: Vec<f64> = costs
            .iter()
            .filter(|c| c.1 <= min + 1e-12)
            .map(|c| c.0)
            .collect();
        ties.iter().sum::<f64>() / ties.len() as f64
    };
    let coarse = best_of(0.0, 0.002, 50);
    Some(best_of(coarse, 0.0001, 25))
}

/// The first detection refined: its line refitted through all the face's returns, then
/// moved along it to where the model fits the beams.
pub fn refine(
    cfg: &DetectorConfig,
    scan: &Scan,
    pallet: &PalletSpec,
    first: &Detection,
) -> Detection {
    let mut face = first.face;
    let mut tol = cfg.edge_tolerance_m;
    let mut used = 0;
    for _ in 0..3 {
        (face, tol, used) = refit_line(cfg.edge_tolerance_m.min(tol * 2.0), scan, pallet, &face);
    }
    // Far fewer returns than the first fit used (noise trimmed them): its line is the better
    // informed one, kept through the same centre.
    if used * 3 < first.points * 2 {
        let back = first.face.to_local(&face);
        face = first.face.to_world(&Pose2::new(0.0, back.y_m, 0.0));
    }
    if let Some(du) = lateral_offset(scan, pallet, &face, tol) {
        face = face.to_world(&Pose2::new(0.0, du, 0.0));
    }
    let on: Vec<[f64; 2]> = crossings(tol, scan, pallet, &face)
        .iter()
        .filter_map(|c| c.point)
        .collect();
    let (sn, cn) = face.heading_rad.sin_cos();
    let rms = (on
        .iter()
        .map(|p| ((p[0] - face.x_m) * cn + (p[1] - face.y_m) * sn).powi(2))
        .sum::<f64>()
        / on.len().max(1) as f64)
        .sqrt();
    Detection {
        face,
        stringers: first.stringers,
        points: on.len(),
        rms_m: rms,
    }
}
