//! The B-spline planner's search over (L1, L2): grid seeds, then sequential linear programming with a trust region.

use forkbench_core::Pose2;

use super::BsplineCurve;

/// Evaluates `objective` on an n × n grid from `lo` with `step`; returns the grid points
/// no worse than their 8 neighbours (the basins' seeds) with their values, unsorted.
pub(super) fn grid_seeds(
    objective: &mut impl FnMut([f64; 2]) -> f64,
    lo: f64,
    step: f64,
    n: usize,
) -> Vec<(usize, usize, f64)> {
    let mut grid = vec![f64::INFINITY; n * n];
    for i in 0..n {
        for j in 0..n {
            grid[i * n + j] = objective([lo + step * i as f64, lo + step * j as f64]);
        }
    }
    let mut seeds: Vec<(usize, usize, f64)> = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let v = grid[i * n + j];
            if !v.is_finite() {
                continue;
            }
            let mut is_min = true;
            for di in -1i64..=1 {
                for dj in -1i64..=1 {
                    let (ni, nj) = (i as i64 + di, j as i64 + dj);
                    if (di, dj) != (0, 0)
                        && (0..n as i64).contains(&ni)
                        && (0..n as i64).contains(&nj)
                        && grid[ni as usize * n + nj as usize] < v
                    {
                        is_min = false;
                    }
                }
            }
            if is_min {
                seeds.push((i, j, v));
            }
        }
    }
    seeds
}

/// Sequential linear programming with a trust region for min over (L1, L2) of max |κ|.
///
/// Each curvature peak is linearised in (L1, L2) (envelope theorem: its gradient is the
/// partial derivative at the peak's fixed u), the piecewise-linear max is minimised
/// exactly over the trust box, and the box grows or shrinks with the actual gain. This
/// walks along the ridges where two peaks are equal, where a simplex method stalls.
pub(super) fn slp_minmax(
    start: &Pose2,
    goal: &Pose2,
    x0: [f64; 2],
    step: f64,
    lo: f64,
    hi: f64,
) -> ([f64; 2], f64, usize) {
    const SAMPLES: usize = 12;
    let value =
        |x: [f64; 2]| BsplineCurve::new(start, goal, x[0], x[1]).max_abs_curvature_with(SAMPLES, 6);
    let mut used = 0;
    let mut x = x0;
    let mut fx = value(x);
    let mut radius = step / 2.0;
    let h = 1e-6;
    while radius > 1e-7 && used < 200 && fx.is_finite() {
        used += 1;
        let curve = BsplineCurve::new(start, goal, x[0], x[1]);
        let peaks = curve.peaks(SAMPLES, 0.7);
        let shifted = [
            BsplineCurve::new(start, goal, x[0] + h, x[1]),
            BsplineCurve::new(start, goal, x[0] - h, x[1]),
            BsplineCurve::new(start, goal, x[0], x[1] + h),
            BsplineCurve::new(start, goal, x[0], x[1] - h),
        ];
        let planes: Vec<(f64, [f64; 2])> = peaks
            .iter()
            .map(|&(k, u, g)| {
                let at = |c: &BsplineCurve| c.segments[k].curvature(u).abs();
                (
                    g,
                    [
                        (at(&shifted[0]) - at(&shifted[1])) / (2.0 * h),
                        (at(&shifted[2]) - at(&shifted[3])) / (2.0 * h),
                    ],
                )
            })
            .collect();
        let bx = [
            [
                (x[0] - radius).max(lo) - x[0],
                (x[0] + radius).min(hi) - x[0],
            ],
            [
                (x[1] - radius).max(lo) - x[1],
                (x[1] + radius).min(hi) - x[1],
            ],
        ];
        let (d, predicted) = min_max_planes(&planes, bx);
        let xn = [x[0] + d[0], x[1] + d[1]];
        let fnew = value(xn);
        let gain = fx - fnew;
        if gain > 0.0 {
            // Grow the box when the linear model predicted the gain well.
            if gain >= 0.5 * (fx - predicted) {
                radius = (radius * 2.0).min(step);
            }
            x = xn;
            fx = fnew;
        } else {
            radius *= 0.25;
        }
    }
    (x, fx, used)
}

/// Minimises max_k (g_k + a_k·d) over the box d ∈ bx by enumerating the arrangement's
/// vertices (box corners, pair lines on box edges, triple points): exact for a convex
/// piecewise-linear function in 2-D.
fn min_max_planes(planes: &[(f64, [f64; 2])], bx: [[f64; 2]; 2]) -> ([f64; 2], f64) {
    let model = |d: [f64; 2]| {
        planes
            .iter()
            .map(|(g, a)| g + a[0] * d[0] + a[1] * d[1])
            .fold(f64::NEG_INFINITY, f64::max)
    };
    let inside = |d: [f64; 2]| {
        let eps = 1e-12;
        d[0] >= bx[0][0] - eps
            && d[0] <= bx[0][1] + eps
            && d[1] >= bx[1][0] - eps
            && d[1] <= bx[1][1] + eps
    };
    let mut cands: Vec<[f64; 2]> = vec![[0.0, 0.0]];
    for &a in &bx[0] {
        for &b in &bx[1] {
            cands.push([a, b]);
        }
    }
    let n = planes.len();
    for i in 0..n {
        for j in i + 1..n {
            // Line where planes i and j are equal: c·d = r.
            let c = [
                planes[i].1[0] - planes[j].1[0],
                planes[i].1[1] - planes[j].1[1],
            ];
            let r = planes[j].0 - planes[i].0;
            for &a in &bx[0] {
                if c[1].abs() > 1e-15 {
                    cands.push([a, (r - c[0] * a) / c[1]]);
                }
            }
            for &b in &bx[1] {
                if c[0].abs() > 1e-15 {
                    cands.push([(r - c[1] * b) / c[0], b]);
                }
            }
            for k in j + 1..n {
                let e = [
                    planes[i].1[0] - planes[k].1[0],
                    planes[i].1[1] - planes[k].1[1],
                ];
                let q = planes[k].0 - planes[i].0;
                let det = c[0] * e[1] - c[1] * e[0];
                if det.abs() > 1e-15 {
                    cands.push([(r * e[1] - c[1] * q) / det, (c[0] * q - r * e[0]) / det]);
                }
            }
        }
    }
    cands
        .into_iter()
        .filter(|d| inside(*d))
        .map(|d| (d, model(d)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap_or(([0.0, 0.0], model([0.0, 0.0])))
}
