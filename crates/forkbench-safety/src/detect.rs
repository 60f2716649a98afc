//! Whether anything breaks a field: the surfaces around the truck sampled at the scanners' resolution, each sample counted where a scanner's field of view covers it.

use forkbench_core::Pose2;

use crate::fields::{Fields, contains};

/// A scanner on the truck: its mount in the fork-root frame and its field of view.
#[derive(Debug, Clone, Copy)]
pub struct Eye {
    pub mount: Pose2,
    pub fov_rad: f64,
}

/// What the safety scanners see of the fields.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Seen {
    /// The first point found in the protective field (fork-root frame), if one was.
    pub protective: Option<[f64; 2]>,
    pub warning: bool,
}

/// Whether each surface (segments in the fork-root frame) breaks a field: a piece of it
/// at least the resolution long lies in the field (each field a union of convex
/// polygons) within some scanner's field of view, so an object narrower than the
/// resolution is missed as the scanner misses it.
pub fn detect(
    fields: &Fields,
    segments: &[[[f64; 2]; 2]],
    eyes: &[Eye],
    resolution_m: f64,
) -> Seen {
    let (lo, hi) = bounds(&fields.warning);
    let mut seen = Seen::default();
    for &[a, b] in segments {
        let Some((a, b)) = clip(a, b, lo, hi) else {
            continue;
        };
        if seen.protective.is_none() {
            seen.protective = fields
                .protective
                .iter()
                .find_map(|poly| piece_in(poly, a, b, (eyes, fields), resolution_m));
        }
        if !seen.warning {
            seen.warning = fields
                .warning
                .iter()
                .any(|poly| piece_in(poly, a, b, (eyes, fields), resolution_m).is_some());
        }
        if seen.warning && seen.protective.is_some() {
            break;
        }
    }
    seen
}

/// A point of the piece of `a`–`b` inside the convex polygon `poly` (Cyrus–Beck) that a
/// scanner sees, when that piece is at least `resolution_m` long.
fn piece_in(
    poly: &[[f64; 2]],
    a: [f64; 2],
    b: [f64; 2],
    (eyes, fields): (&[Eye], &Fields),
    resolution_m: f64,
) -> Option<[f64; 2]> {
    let d = [b[0] - a[0], b[1] - a[1]];
    let (mut t0, mut t1) = (0.0_f64, 1.0_f64);
    let n = poly.len();
    for i in 0..n {
        let (p, q) = (poly[i], poly[(i + 1) % n]);
        // Inward normal of a counter-clockwise edge.
        let nrm = [p[1] - q[1], q[0] - p[0]];
        let num = nrm[0] * (a[0] - p[0]) + nrm[1] * (a[1] - p[1]);
        let den = nrm[0] * d[0] + nrm[1] * d[1];
        if den == 0.0 {
            if num < 0.0 {
                return None;
            }
        } else if den > 0.0 {
            t0 = t0.max(-num / den);
        } else {
            t1 = t1.min(-num / den);
        }
        if t0 > t1 {
            return None;
        }
    }
    let len = d[0].hypot(d[1]);
    if (t1 - t0) * len < resolution_m * (1.0 - 1e-9) {
        return None;
    }
    // The piece seen: sampled at half the resolution for the scanners' fields of view.
    let at = |t: f64| [a[0] + t * d[0], a[1] + t * d[1]];
    let samples = (((t1 - t0) * len) / (resolution_m / 2.0))
        .ceil()
        .clamp(1.0, 10_000.0) as usize;
    let need = 2;
    let mut run = 0;
    for k in 0..=samples {
        let p = at(t0 + (t1 - t0) * k as f64 / samples as f64);
        let ignored = fields.ignore.as_ref().is_some_and(|poly| contains(poly, p));
        run = if in_view(eyes, p) && !ignored {
            run + 1
        } else {
            0
        };
        if run > need.min(samples) {
            return Some(p);
        }
    }
    None
}

fn in_view(eyes: &[Eye], p: [f64; 2]) -> bool {
    eyes.iter().any(|e| {
        let q = e.mount.to_local(&Pose2::new(p[0], p[1], 0.0));
        q.y_m.atan2(q.x_m).abs() <= e.fov_rad / 2.0
    })
}

fn bounds(polys: &[Vec<[f64; 2]>]) -> ([f64; 2], [f64; 2]) {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for p in polys.iter().flatten() {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (lo, hi)
}

/// The part of segment `a`–`b` inside the box `lo`–`hi` (Liang–Barsky).
fn clip(a: [f64; 2], b: [f64; 2], lo: [f64; 2], hi: [f64; 2]) -> Option<([f64; 2], [f64; 2])> {
    let d = [b[0] - a[0], b[1] - a[1]];
    let (mut t0, mut t1) = (0.0_f64, 1.0_f64);
    for k in 0..2 {
        for (p, q) in [(-d[k], a[k] - lo[k]), (d[k], hi[k] - a[k])] {
            if p == 0.0 {
                if q < 0.0 {
                    return None;
                }
            } else {
                let r = q / p;
                if p < 0.0 {
                    t0 = t0.max(r);
                } else {
                    t1 = t1.min(r);
                }
            }
        }
    }
    (t0 <= t1).then(|| {
        let at = |t: f64| [a[0] + t * d[0], a[1] + t * d[1]];
        (at(t0), at(t1))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square_fields() -> Fields {
        let sq = vec![[1.0, -1.0], [3.0, -1.0], [3.0, 1.0], [1.0, 1.0]];
        let big = vec![[1.0, -2.0], [5.0, -2.0], [5.0, 2.0], [1.0, 2.0]];
        Fields {
            ignore: None,
            protective: vec![sq],
            warning: vec![big],
        }
    }

    fn front() -> Vec<Eye> {
        vec![Eye {
            mount: Pose2::new(0.0, 0.0, 0.0),
            fov_rad: 270f64.to_radians(),
        }]
    }

    #[test]
    fn a_leg_is_found_and_a_thinner_object_than_the_resolution_missed() {
        let f = square_fields();
        let leg = [[2.0, 0.0], [2.0, 0.1]];
        assert!(detect(&f, &[leg], &front(), 0.07).protective.is_some());
        assert!(detect(&f, &[leg], &front(), 0.15).protective.is_none());
        let far = [[4.0, 0.0], [4.0, 0.5]];
        let s = detect(&f, &[far], &front(), 0.07);
        assert!(s.protective.is_none() && s.warning);
        // Behind a forward scanner with a 90° view: unseen.
        let narrow = [Eye {
            mount: Pose2::new(0.0, 0.0, std::f64::consts::PI),
            fov_rad: 90f64.to_radians(),
        }];
        assert_eq!(detect(&f, &[leg], &narrow, 0.07), Seen::default());
    }
}
