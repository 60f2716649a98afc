//! Gaps between rectangles in the plane (a truck's parts, a person's body): zero when they overlap.

use forkbench_core::Pose2;
use forkbench_core::geometry::rect_corners;

/// A rectangle: its centre pose, its length along the heading and its width.
pub type Rect = (Pose2, f64, f64);

/// The least distance between two rectangles; 0 when they touch or overlap.
pub fn rect_gap_m(a: &Rect, b: &Rect) -> f64 {
    let (pa, pb) = (rect_corners(&a.0, a.1, a.2), rect_corners(&b.0, b.1, b.2));
    if overlap(&pa, &pb) {
        return 0.0;
    }
    let mut best = f64::INFINITY;
    for (p, q) in [(&pa, &pb), (&pb, &pa)] {
        for v in p {
            for i in 0..4 {
                best = best.min(point_segment_sq(*v, q[i], q[(i + 1) % 4]));
            }
        }
    }
    best.sqrt()
}

/// A lower bound of [`rect_gap_m`] from the rectangles' enclosing circles (cheap: a
/// caller skips the exact gap when this already answers its question).
pub fn rect_gap_lower_bound_m(a: &Rect, b: &Rect) -> f64 {
    // Square roots, not `hypot`: this runs for every mover and part at every step.
    let len = |x: f64, y: f64| (x * x + y * y).sqrt();
    let centres = len(a.0.x_m - b.0.x_m, a.0.y_m - b.0.y_m);
    (centres - len(a.1, a.2) / 2.0 - len(b.1, b.2) / 2.0).max(0.0)
}

/// Separating axes of two convex quadrilaterals: they overlap when no edge normal
/// separates them.
fn overlap(a: &[[f64; 2]; 4], b: &[[f64; 2]; 4]) -> bool {
    for poly in [a, b] {
        for i in 0..4 {
            let (p, q) = (poly[i], poly[(i + 1) % 4]);
            let n = [q[1] - p[1], p[0] - q[0]];
            let span = |s: &[[f64; 2]; 4]| {
                s.iter()
                    .map(|v| v[0] * n[0] + v[1] * n[1])
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), d| {
                        (lo.min(d), hi.max(d))
                    })
            };
            let (sa, sb) = (span(a), span(b));
            if sa.1 < sb.0 || sb.1 < sa.0 {
                return false;
            }
        }
    }
    true
}

/// The squared distance from `p` to the segment `a`–`b`.
fn point_segment_sq(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (ex, ey) = (b[0] - a[0], b[1] - a[1]);
    let len2 = ex * ex + ey * ey;
    let u = if len2 > 0.0 {
        (((p[0] - a[0]) * ex + (p[1] - a[1]) * ey) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let (dx, dy) = (p[0] - a[0] - u * ex, p[1] - a[1] - u * ey);
    dx * dx + dy * dy
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gaps_between_rectangles() {
        let unit = |x: f64, y: f64, h: f64| (Pose2::new(x, y, h), 1.0, 1.0);
        assert_eq!(rect_gap_m(&unit(0.0, 0.0, 0.0), &unit(0.5, 0.5, 0.3)), 0.0);
        assert!((rect_gap_m(&unit(0.0, 0.0, 0.0), &unit(3.0, 0.0, 0.0)) - 2.0).abs() < 1e-12);
        // A diamond's corner 0.5 √2 from its centre, facing a square's side.
        let d = rect_gap_m(
            &unit(0.0, 0.0, 0.0),
            &unit(2.0, 0.0, std::f64::consts::FRAC_PI_4),
        );
        assert!((d - (1.5 - 0.5 * 2f64.sqrt())).abs() < 1e-12, "{d}");
        let (a, b) = (unit(0.0, 0.0, 0.3), unit(2.5, 1.0, 1.0));
        assert!(rect_gap_lower_bound_m(&a, &b) <= rect_gap_m(&a, &b));
    }
}
