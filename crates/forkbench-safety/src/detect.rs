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
/// resolution is missed as the scanner misses it. `range_bias_m`: how much further than
/// true the scanner reads each range (its worst-case error), so a surface is judged
/// where it is measured.
pub fn detect(
    fields: &Fields,
    segments: &[[[f64; 2]; 2]],
    eyes: &[Eye],
    (resolution_m, range_bias_m): (f64, f64),
) -> Seen {
    if range_bias_m > 0.0 {
        return detect_measured(fields, segments, eyes, resolution_m, range_bias_m);
    }
    let views: Vec<View> = eyes.iter().map(View::of).collect();
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
                .find_map(|poly| piece_in(poly, a, b, (&views, fields), resolution_m));
        }
        if !seen.warning {
            seen.warning = fields
                .warning
                .iter()
                .any(|poly| piece_in(poly, a, b, (&views, fields), resolution_m).is_some());
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
    (views, fields): (&[View], &Fields),
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
        run = if views.iter().any(|v| v.sees(p).is_some()) && !ignored {
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

/// [`detect`] with each range read `bias_m` long: the surfaces are sampled at half the
/// resolution, each sample moved away from the nearest scanner that sees it.
fn detect_measured(
    fields: &Fields,
    segments: &[[[f64; 2]; 2]],
    eyes: &[Eye],
    resolution_m: f64,
    bias_m: f64,
) -> Seen {
    let (lo, hi) = bounds(&fields.warning);
    let step = resolution_m / 2.0;
    let views: Vec<View> = eyes.iter().map(View::of).collect();
    let boxed = |polys: &[Vec<[f64; 2]>]| -> Vec<([f64; 2], [f64; 2])> {
        polys
            .iter()
            .map(|p| bounds(std::slice::from_ref(p)))
            .collect()
    };
    let (pboxes, wboxes) = (boxed(&fields.protective), boxed(&fields.warning));
    let inside = |polys: &[Vec<[f64; 2]>], boxes: &[([f64; 2], [f64; 2])], p: [f64; 2]| {
        polys.iter().zip(boxes).any(|(poly, (lo, hi))| {
            (lo[0]..=hi[0]).contains(&p[0]) && (lo[1]..=hi[1]).contains(&p[1]) && contains(poly, p)
        })
    };
    let ignored = |p: [f64; 2]| fields.ignore.as_ref().is_some_and(|i| contains(i, p));
    let mut seen = Seen::default();
    // Moving a point away from a scanner inside the (convex) bounds never brings it
    // inside them, so clipping the true surfaces first loses nothing.
    for &[a, b] in segments {
        let Some((a, b)) = clip(a, b, lo, hi) else {
            continue;
        };
        let d = [b[0] - a[0], b[1] - a[1]];
        let n = ((d[0].hypot(d[1]) / step).ceil()).clamp(1.0, 100_000.0) as usize;
        let (mut run_p, mut run_w) = (0, 0);
        for k in 0..=n {
            let u = k as f64 / n as f64;
            let m = measured(&views, [a[0] + u * d[0], a[1] + u * d[1]], bias_m)
                .filter(|m| !ignored(*m));
            let inw = m.is_some_and(|m| inside(&fields.warning, &wboxes, m));
            let inp = m.is_some_and(|m| inside(&fields.protective, &pboxes, m));
            run_p = if inp { run_p + 1 } else { 0 };
            run_w = if inw { run_w + 1 } else { 0 };
            // A run of samples as long as the resolution (or the whole of a shorter
            // surface, as the exact test would not count it).
            if run_p > 2.min(n) && seen.protective.is_none() {
                seen.protective = m;
            }
            seen.warning |= run_w > 2.min(n);
        }
        if seen.warning && seen.protective.is_some() {
            break;
        }
    }
    seen
}

/// A scanner's mount and view, ready for many points.
struct View {
    at: [f64; 2],
    facing: [f64; 2],
    cos_half_fov: f64,
}

impl View {
    fn of(e: &Eye) -> Self {
        let (s, c) = e.mount.heading_rad.sin_cos();
        View {
            at: [e.mount.x_m, e.mount.y_m],
            facing: [c, s],
            cos_half_fov: (e.fov_rad / 2.0).min(std::f64::consts::PI).cos(),
        }
    }
}

impl View {
    /// Where `p` lies from the scanner (range, and its offsets), if within its view.
    fn sees(&self, p: [f64; 2]) -> Option<(f64, f64, f64)> {
        let (dx, dy) = (p[0] - self.at[0], p[1] - self.at[1]);
        let r = dx.hypot(dy);
        let along = dx * self.facing[0] + dy * self.facing[1];
        (along >= r * self.cos_half_fov).then_some((r, dx, dy))
    }
}

/// Where the nearest scanner that sees `p` measures it, reading `bias_m` long.
fn measured(views: &[View], p: [f64; 2], bias_m: f64) -> Option<[f64; 2]> {
    let (r, dx, dy) = views
        .iter()
        .filter_map(|v| v.sees(p))
        .min_by(|a, b| a.0.total_cmp(&b.0))?;
    if r == 0.0 {
        return Some(p);
    }
    let k = bias_m / r;
    Some([p[0] + dx * k, p[1] + dy * k])
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
        assert!(
            detect(&f, &[leg], &front(), (0.07, 0.0))
                .protective
                .is_some()
        );
        assert!(
            detect(&f, &[leg], &front(), (0.15, 0.0))
                .protective
                .is_none()
        );
        let far = [[4.0, 0.0], [4.0, 0.5]];
        let s = detect(&f, &[far], &front(), (0.07, 0.0));
        assert!(s.protective.is_none() && s.warning);
        // Behind a forward scanner with a 90° view: unseen.
        let narrow = [Eye {
            mount: Pose2::new(0.0, 0.0, std::f64::consts::PI),
            fov_rad: 90f64.to_radians(),
        }];
        assert_eq!(detect(&f, &[leg], &narrow, (0.07, 0.0)), Seen::default());
    }

    #[test]
    fn a_range_read_long_moves_what_is_seen_away_from_the_scanner() {
        let f = square_fields();
        // A leg 0.2 m inside the protective field's far edge (x = 3).
        let leg = [[2.8, -0.05], [2.8, 0.05]];
        assert!(
            detect(&f, &[leg], &front(), (0.07, 0.0))
                .protective
                .is_some()
        );
        assert!(
            detect(&f, &[leg], &front(), (0.07, 0.1))
                .protective
                .is_some()
        );
        let s = detect(&f, &[leg], &front(), (0.07, 0.3));
        assert!(s.protective.is_none() && s.warning, "read at 3.1 m: {s:?}");
        // The sampled and the exact test agree without a bias worth the name.
        let near = [[1.5, -0.5], [1.5, 0.5]];
        assert_eq!(
            detect(&f, &[near], &front(), (0.07, 1e-9))
                .protective
                .is_some(),
            detect(&f, &[near], &front(), (0.07, 0.0))
                .protective
                .is_some()
        );
    }
}
