//! Solving the endpoint equations: Newton at a fixed length, and following the solution curve in (b, c, s_f) through folds.

use super::SpiralProblem;
use super::problem::Rule;
use super::search::Candidate;

impl SpiralProblem {
    /// Damped Newton on the endpoint equations for (b, c) at a fixed length, to the
    /// accuracy of `target` (the coarse rule first, while far from the solution).
    pub(super) fn solve_bc(&self, sf: f64, guess: [f64; 2], target: Rule) -> Option<[f64; 2]> {
        let eval = |p: [f64; 2], rule: Rule| {
            let (e, j) = self.endpoint_and_jacobian(p[0], p[1], sf, rule);
            let r = [e[0] - self.x_f, e[1] - self.y_f];
            (r, j, r[0].hypot(r[1]))
        };
        let mut p = guess;
        let mut rule = Rule::Coarse;
        let (mut r, mut j, mut norm) = eval(p, rule);
        let mut kicks = 0;
        for iter in 0..30 {
            // A guess that has not come near the goal after a few steps is on a wrong
            // branch; the other guesses are cheaper than crawling.
            if iter >= 6 && norm > 1e-3 {
                return None;
            }
            if rule == Rule::Coarse && norm < Rule::Coarse.tolerance() {
                // Close enough to switch to the target rule for the last digits; a
                // one-panel target rule is the coarse rule, so nothing to redo then.
                rule = target;
                if self.panels(&self.params(p[0], p[1], sf), sf, target) > 1 {
                    (r, j, norm) = eval(p, rule);
                }
            }
            if rule == target && norm < target.tolerance() {
                return Some(p);
            }
            let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
            let scale = j.iter().map(|r| r[0] * r[0] + r[1] * r[1]).sum::<f64>();
            if det.is_nan() {
                return None;
            }
            if det.abs() <= 1e-12 * scale {
                // Singular Jacobian. Symmetric problems (a = κ_f = θ_f = 0) are singular on
                // every heading profile symmetric about s_f/2, and the solutions at most
                // lengths are asymmetric: kick the iterate along the null vector.
                if kicks == 4 {
                    return None;
                }
                let row = if j[0][0].hypot(j[0][1]) >= j[1][0].hypot(j[1][1]) {
                    j[0]
                } else {
                    j[1]
                };
                let len = row[0].hypot(row[1]);
                let v = if len > 0.0 {
                    [-row[1] / len, row[0] / len]
                } else {
                    [1.0, 0.0]
                };
                let eps = 0.1 * (1.0 + p[0].hypot(p[1])) * if kicks % 2 == 0 { 1.0 } else { -1.0 };
                kicks += 1;
                p = [p[0] + eps * v[0], p[1] + eps * v[1]];
                (r, j, norm) = eval(p, rule);
                continue;
            }
            let step = [
                -(j[1][1] * r[0] - j[0][1] * r[1]) / det,
                -(-j[1][0] * r[0] + j[0][0] * r[1]) / det,
            ];
            let mut t = 1.0;
            loop {
                let q = [p[0] + t * step[0], p[1] + t * step[1]];
                let (rq, jq, nq) = eval(q, rule);
                if nq < norm * (1.0 - 1e-4 * t) {
                    (p, r, j, norm) = (q, rq, jq, nq);
                    break;
                }
                t *= 0.5;
                // Heavy damping means the guess is on the wrong side of a fold: give up
                // early rather than crawl.
                if t < 1.0 / 16.0 {
                    return None;
                }
            }
        }
        (rule == target && norm < 10.0 * target.tolerance()).then_some(p)
    }
}

impl SpiralProblem {
    /// Damped minimum-norm Gauss–Newton in (b, c, s_f) with s_f kept in [lo, hi].
    ///
    /// Where the fixed-length solve fails, the solution curve is usually at a fold in
    /// s_f (the shortest length that reaches, e.g. a symmetric lane change); the 2 × 3
    /// Jacobian keeps full rank there, so letting s_f move finds the fold solution.
    pub(super) fn solve_free(
        &self,
        guess: [f64; 2],
        sf0: f64,
        lo: f64,
        hi: f64,
    ) -> Option<([f64; 2], f64)> {
        let eval = |q: [f64; 3], fine: bool| {
            let rule = if fine { Rule::Final } else { Rule::Coarse };
            let (e, j) = self.endpoint_and_jacobian(q[0], q[1], q[2], rule);
            let r = [e[0] - self.x_f, e[1] - self.y_f];
            (r, j, r[0].hypot(r[1]))
        };
        let mut q = [guess[0], guess[1], sf0];
        let mut pinned = 0;
        let mut fine = false;
        let (mut r, mut j, mut norm) = eval(q, fine);
        for _ in 0..40 {
            if !fine && norm < 1e-6 {
                fine = true;
                (r, j, norm) = eval(q, fine);
            }
            if fine && norm < 1e-12 {
                return Some(([q[0], q[1]], q[2]));
            }
            let step = min_norm_step(&j, r)?;
            // Pinned at a window bound for several steps: the fold lies outside the
            // window, and this solve cannot converge inside it.
            if q[2] + step[2] < lo || q[2] + step[2] > hi {
                pinned += 1;
                if pinned >= 3 {
                    return None;
                }
            } else {
                pinned = 0;
            }
            let mut t = 1.0;
            loop {
                let mut n = [q[0] + t * step[0], q[1] + t * step[1], q[2] + t * step[2]];
                n[2] = n[2].clamp(lo, hi);
                let (rn, jn, nn) = eval(n, fine);
                if nn < norm * (1.0 - 1e-4 * t) {
                    (q, r, j, norm) = (n, rn, jn, nn);
                    break;
                }
                t *= 0.5;
                if t < 1e-3 {
                    return None;
                }
            }
        }
        None
    }
}

/// The least-norm δ with A δ = −r: δ = −Aᵀ (A Aᵀ)⁻¹ r.
fn min_norm_step(a: &[[f64; 3]; 2], r: [f64; 2]) -> Option<[f64; 3]> {
    let dot = |u: &[f64; 3], v: &[f64; 3]| u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
    let (m00, m01, m11) = (dot(&a[0], &a[0]), dot(&a[0], &a[1]), dot(&a[1], &a[1]));
    let det = m00 * m11 - m01 * m01;
    if !(det.is_finite() && det.abs() > 1e-30) {
        return None;
    }
    let y = [
        (m11 * r[0] - m01 * r[1]) / det,
        (m00 * r[1] - m01 * r[0]) / det,
    ];
    Some(std::array::from_fn(|k| -(a[0][k] * y[0] + a[1][k] * y[1])))
}

/// What following the solution curve from one length toward another found.
#[derive(Debug, Clone, Copy)]
pub(super) enum Trace {
    /// The curve reached the target length: a solution (b, c, s_f) near it.
    Reached([f64; 3]),
    /// The curve turned at a fold: the turning point, and a point on the other branch
    /// back past the starting length.
    Turned { fold: [f64; 3], back: [f64; 3] },
}

impl SpiralProblem {
    /// Residual and 2 × 3 Jacobian in (b, c, s_f).
    pub(super) fn residual3(&self, q: [f64; 3], rule: Rule) -> ([f64; 2], [[f64; 3]; 2]) {
        let (e, j) = self.endpoint_and_jacobian(q[0], q[1], q[2], rule);
        ([e[0] - self.x_f, e[1] - self.y_f], j)
    }

    /// Moore–Penrose corrector: least-norm Gauss–Newton steps back onto the curve.
    pub(super) fn correct(&self, mut q: [f64; 3]) -> Option<[f64; 3]> {
        let mut last = f64::INFINITY;
        for _ in 0..8 {
            let (r, a) = self.residual3(q, Rule::Final);
            let norm = r[0].hypot(r[1]);
            if norm < 1e-11 {
                return Some(q);
            }
            if last.is_finite() && norm.partial_cmp(&(0.5 * last)) != Some(std::cmp::Ordering::Less)
            {
                return None;
            }
            last = norm;
            let d = min_norm_step(&a, r)?;
            q = std::array::from_fn(|k| q[k] + d[k]);
        }
        None
    }

    /// First-order prediction of the solution at length `sf` on the branch through `c`:
    /// (b, c) + Δs_f · d(b, c)/ds_f, with d(b, c)/ds_f = −J⁻¹ ∂(x, y)/∂s_f.
    pub(super) fn predict(&self, c: Candidate, sf: f64) -> [f64; 2] {
        let (sf0, bc) = (c.0, c.1);
        // The one-panel rule: a prediction needs no more.
        let (_, a) = self.residual3([bc[0], bc[1], sf0], Rule::Coarse);
        let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
        if !(det.is_finite()
            && det.abs() > 1e-12 * (a[0][0].hypot(a[0][1]) * a[1][0].hypot(a[1][1])))
        {
            return bc;
        }
        let (rx, ry) = (a[0][2], a[1][2]);
        let d = [
            -(a[1][1] * rx - a[0][1] * ry) / det,
            -(-a[1][0] * rx + a[0][0] * ry) / det,
        ];
        let ds = sf - sf0;
        [bc[0] + ds * d[0], bc[1] + ds * d[1]]
    }

    /// Follows the solution curve from the solution `from` toward length `toward_sf`
    /// (pseudo-arclength continuation), through a fold if the curve turns there.
    pub(super) fn trace(&self, from: [f64; 3], toward_sf: f64) -> Option<Trace> {
        let dir = (toward_sf - from[2]).signum();
        let gap = (toward_sf - from[2]).abs();
        let (mut q, mut fold) = (from, from);
        let mut prev_t: Option<[f64; 3]> = None;
        let mut h: Option<f64> = None;
        for _ in 0..40 {
            let (_, a) = self.residual3(q, Rule::Final);
            let mut t = [
                a[0][1] * a[1][2] - a[0][2] * a[1][1],
                a[0][2] * a[1][0] - a[0][0] * a[1][2],
                a[0][0] * a[1][1] - a[0][1] * a[1][0],
            ];
            let len = (t[0] * t[0] + t[1] * t[1] + t[2] * t[2]).sqrt();
            if !(len.is_finite() && len > 0.0) {
                return None;
            }
            let along = prev_t.map_or(t[2] * dir, |p| t[0] * p[0] + t[1] * p[1] + t[2] * p[2]);
            let sign = if along < 0.0 { -1.0 } else { 1.0 };
            t = t.map(|v| sign * v / len);
            let cap = 0.2 * (1.0 + q[0].hypot(q[1]));
            let mut step = h.unwrap_or(0.5 * gap / t[2].abs().max(1e-9)).min(cap);
            loop {
                let pred = std::array::from_fn(|k| q[k] + step * t[k]);
                if let Some(n) = self.correct(pred) {
                    q = n;
                    h = Some(step * 1.5);
                    break;
                }
                step *= 0.5;
                if step < 1e-6 * cap {
                    return None;
                }
            }
            prev_t = Some(t);
            if (q[2] - fold[2]) * dir > 0.0 {
                fold = q;
            }
            if (q[2] - toward_sf) * dir >= 0.0 {
                return Some(Trace::Reached(q));
            }
            if (q[2] - from[2]) * dir < 0.0 {
                return Some(Trace::Turned { fold, back: q });
            }
        }
        None
    }
}
