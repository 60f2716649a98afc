//! Quartic polynomial-spiral pick planner (Shen et al. 2022): exact endpoint, minimum ∫½κ² over the free length.

use forkbench_core::units::wrap_angle;
use forkbench_core::{Path, PathSample, Pose2};
use serde::{Deserialize, Serialize};

use crate::numeric::{GaussLegendre, brent_min, max_abs_on_interval};
use crate::{Plan, PlanError, PlanParams, PlanRequest, PlannerKind};

/// Settings of the spiral planner.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SpiralConfig {
    /// Keep the paper's empirical window 1 + θ²/5 ≤ s_f ≤ 2 + θ²/5 (normalised);
    /// when false the window widens to 1 ≤ s_f ≤ 3 + θ².
    pub enforce_length_window: bool,
    /// Lengths tried across the window before the local refinement.
    pub length_grid_points: usize,
    /// Largest arc-length spacing of the output samples.
    pub sample_spacing_m: f64,
}

impl Default for SpiralConfig {
    fn default() -> Self {
        Self {
            enforce_length_window: true,
            length_grid_points: 12,
            sample_spacing_m: 0.01,
        }
    }
}

/// Coefficients of κ(s) = a + b s + c s² + d s³ + e s⁴ on the normalised problem.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SpiralParams {
    pub a: f64,
    pub b: f64,
    pub c: f64,
    pub d: f64,
    pub e: f64,
    pub sf: f64,
    /// R: the start–goal distance that normalises the problem onto the unit circle.
    pub scale_m: f64,
    /// The goal lay on the −y side of the start frame and the problem was mirrored.
    pub mirrored: bool,
}

impl SpiralParams {
    pub fn curvature(&self, s: f64) -> f64 {
        (((self.e * s + self.d) * s + self.c) * s + self.b) * s + self.a
    }

    pub fn heading(&self, s: f64) -> f64 {
        ((((self.e / 5.0 * s + self.d / 4.0) * s + self.c / 3.0) * s + self.b / 2.0) * s + self.a)
            * s
    }
}

/// The normalised two-point problem: start [0, 0, 0, a], goal [x_f, y_f, θ_f, κ_f] on the unit circle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpiralProblem {
    pub a: f64,
    pub x_f: f64,
    pub y_f: f64,
    pub theta_f: f64,
    pub kappa_f: f64,
    /// |κ| bound in normalised units: R / r_min.
    pub kappa_limit: f64,
    pub scale_m: f64,
    pub mirrored: bool,
}

/// Quality of one (b, c, s_f) on a problem: what the paper's table is checked with.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpiralEvaluation {
    pub params: SpiralParams,
    /// Normalised ∫½κ² ds.
    pub cost: f64,
    /// Endpoint position error in metres (normalised error × R).
    pub endpoint_error_m: f64,
    /// Largest |κ| in m⁻¹ (normalised / R).
    pub max_abs_curvature_per_m: f64,
}

impl SpiralProblem {
    /// Normalises a request: goal in the start frame, mirrored onto +y, scaled by R.
    pub fn from_request(req: &PlanRequest, goal_curvature_per_m: f64) -> Self {
        let local = req.start.to_local(&req.goal);
        let r = local.x_m.hypot(local.y_m);
        let mirrored = local.y_m < 0.0;
        let sign = if mirrored { -1.0 } else { 1.0 };
        SpiralProblem {
            // `+ 0.0` turns the −0.0 of a mirrored zero curvature into +0.0 for printing.
            a: sign * r * req.start_curvature_per_m + 0.0,
            x_f: local.x_m / r,
            y_f: sign * local.y_m / r,
            theta_f: sign * local.heading_rad,
            kappa_f: sign * r * goal_curvature_per_m + 0.0,
            kappa_limit: r * req.truck.max_curvature_per_m(),
            scale_m: r,
            mirrored,
        }
    }

    /// d and e from κ(s_f) = κ_f and θ(s_f) = θ_f (the paper's closed form).
    pub fn params(&self, b: f64, c: f64, sf: f64) -> SpiralParams {
        let (a, kf, tf) = (self.a, self.kappa_f, self.theta_f);
        let (s2, s3, s4, s5) = (sf * sf, sf.powi(3), sf.powi(4), sf.powi(5));
        let d =
            (-4.0 * kf / s3 + 20.0 * tf / s4 - 16.0 * a / s3) - 6.0 * b / s2 - 8.0 * c / (3.0 * sf);
        let e =
            (5.0 * kf / s4 - 20.0 * tf / s5 + 15.0 * a / s4) + 5.0 * b / s3 + 5.0 * c / (3.0 * s2);
        SpiralParams {
            a,
            b,
            c,
            d,
            e,
            sf,
            scale_m: self.scale_m,
            mirrored: self.mirrored,
        }
    }

    /// End position (x(s_f), y(s_f)) and its Jacobian with respect to (b, c).
    ///
    /// Composite 12-point Gauss–Legendre: one panel per ~6 rad of turning (its error
    /// scales like (T/24)^24 for a turning T per panel), so
    /// spirals that sweep through large angles are integrated as accurately as gentle ones.
    /// With `fine` false a single panel is used: cheap, and accurate enough to steer
    /// Newton while it is far from the solution.
    fn endpoint_and_jacobian(
        &self,
        b: f64,
        c: f64,
        sf: f64,
        fine: bool,
    ) -> ([f64; 2], [[f64; 2]; 2]) {
        let p = self.params(b, c, sf);
        let gl = GaussLegendre::rule12();
        let panels = if fine { self.panels(&p, sf) } else { 1 };
        let width = sf / panels as f64;
        let half = width / 2.0;
        let (mut x, mut y) = (0.0, 0.0);
        let mut jac = [[0.0; 2]; 2];
        let (inv_s2, inv_s3) = (1.0 / (sf * sf), 1.0 / sf.powi(3));
        for k in 0..panels {
            let s0 = width * k as f64;
            for (xi, wi) in gl.nodes.iter().zip(&gl.weights) {
                let s = s0 + half * (1.0 + xi);
                let w = half * wi;
                let (sin, cos) = p.heading(s).sin_cos();
                let (s2, s3) = (s * s, s * s * s);
                let (s4, s5) = (s2 * s2, s2 * s3);
                // ∂θ/∂b and ∂θ/∂c through b, c directly and through d(b, c), e(b, c).
                let dtb = s2 / 2.0 - 1.5 * s4 * inv_s2 + s5 * inv_s3;
                let dtc = s3 / 3.0 - (2.0 / 3.0) * s4 / sf + s5 * inv_s2 / 3.0;
                x += w * cos;
                y += w * sin;
                jac[0][0] -= w * sin * dtb;
                jac[0][1] -= w * sin * dtc;
                jac[1][0] += w * cos * dtb;
                jac[1][1] += w * cos * dtc;
            }
        }
        ([x, y], jac)
    }

    /// Panels the accurate rule needs: total turning ≤ s_f · max|κ|, with max|κ| from a
    /// coarse polynomial sample (no trig, so cheap); coefficient bounds are useless
    /// here, they cancel heavily.
    fn panels(&self, p: &SpiralParams, sf: f64) -> usize {
        let peak = (0..=16)
            .map(|i| p.curvature(sf * i as f64 / 16.0).abs())
            .fold(0.0, f64::max);
        let turning = 1.25 * sf * peak;
        if turning.is_finite() {
            (turning / 6.0).ceil().clamp(1.0, 12.0) as usize
        } else {
            1
        }
    }

    /// Normalised ∫₀^{s_f} ½ κ² ds (exact: the integrand is a degree-8 polynomial).
    pub fn cost(&self, b: f64, c: f64, sf: f64) -> f64 {
        let p = self.params(b, c, sf);
        let gl = GaussLegendre::rule16();
        let half = sf / 2.0;
        gl.nodes
            .iter()
            .zip(&gl.weights)
            .map(|(xi, wi)| {
                let k = p.curvature(half * (1.0 + xi));
                half * wi * 0.5 * k * k
            })
            .sum()
    }

    /// Largest normalised |κ| over [0, s_f].
    pub fn max_abs_curvature(&self, b: f64, c: f64, sf: f64) -> f64 {
        let p = self.params(b, c, sf);
        max_abs_on_interval(|s| p.curvature(s), 0.0, sf, 24, 8).1
    }

    /// Scores given (b, c, s_f), e.g. the paper's, with this project's integration.
    pub fn evaluate(&self, b: f64, c: f64, sf: f64) -> SpiralEvaluation {
        let (end, _) = self.endpoint_and_jacobian(b, c, sf, true);
        SpiralEvaluation {
            params: self.params(b, c, sf),
            cost: self.cost(b, c, sf),
            endpoint_error_m: (end[0] - self.x_f).hypot(end[1] - self.y_f) * self.scale_m,
            max_abs_curvature_per_m: self.max_abs_curvature(b, c, sf) / self.scale_m,
        }
    }

    /// The window of normalised lengths searched.
    pub fn length_window(&self, enforce: bool) -> (f64, f64) {
        let t2 = self.theta_f * self.theta_f;
        if enforce {
            (1.0 + t2 / 5.0, 2.0 + t2 / 5.0)
        } else {
            (1.0, 3.0 + t2)
        }
    }

    /// Heading profile (arc-length fraction, unwrapped heading) of a cubic Bézier from the
    /// start to the goal: a loop-free shape to fit the first guess of (b, c) to.
    fn bezier_heading_profile(&self) -> Vec<(f64, f64)> {
        const N: usize = 32;
        let h = 0.4;
        let p = [
            [0.0, 0.0],
            [h, 0.0],
            [
                self.x_f - h * self.theta_f.cos(),
                self.y_f - h * self.theta_f.sin(),
            ],
            [self.x_f, self.y_f],
        ];
        let point = |t: f64| {
            let u = 1.0 - t;
            let w = [u * u * u, 3.0 * u * u * t, 3.0 * u * t * t, t * t * t];
            [
                w.iter().zip(&p).map(|(w, q)| w * q[0]).sum::<f64>(),
                w.iter().zip(&p).map(|(w, q)| w * q[1]).sum::<f64>(),
            ]
        };
        let tangent = |t: f64| {
            let u = 1.0 - t;
            let w = [
                -3.0 * u * u,
                3.0 * u * u - 6.0 * u * t,
                6.0 * u * t - 3.0 * t * t,
                3.0 * t * t,
            ];
            [
                w.iter().zip(&p).map(|(w, q)| w * q[0]).sum::<f64>(),
                w.iter().zip(&p).map(|(w, q)| w * q[1]).sum::<f64>(),
            ]
        };
        let mut out = Vec::with_capacity(N + 1);
        let (mut arc, mut prev, mut heading) = (0.0, point(0.0), 0.0);
        for i in 0..=N {
            let t = i as f64 / N as f64;
            let q = point(t);
            arc += (q[0] - prev[0]).hypot(q[1] - prev[1]);
            prev = q;
            let d = tangent(t);
            heading += wrap_angle(d[1].atan2(d[0]) - heading);
            out.push((arc, heading));
        }
        let total = arc.max(1e-12);
        out.iter_mut().for_each(|(a, _)| *a /= total);
        out
    }

    /// Least-squares (b, c) whose heading θ(σ s_f) follows a reference profile; θ is
    /// linear in (b, c) once d and e are eliminated, so this is a 2×2 solve.
    fn fit_bc(&self, sf: f64, profile: &[(f64, f64)]) -> [f64; 2] {
        let base = self.params(0.0, 0.0, sf);
        let (inv_s2, inv_s3) = (1.0 / (sf * sf), 1.0 / sf.powi(3));
        let (mut m, mut r) = ([[0.0; 2]; 2], [0.0; 2]);
        for &(sigma, target) in profile {
            let s = sigma * sf;
            let (s2, s3) = (s * s, s * s * s);
            let (s4, s5) = (s2 * s2, s2 * s3);
            let phi = [
                s2 / 2.0 - 1.5 * s4 * inv_s2 + s5 * inv_s3,
                s3 / 3.0 - (2.0 / 3.0) * s4 / sf + s5 * inv_s2 / 3.0,
            ];
            let resid = target - base.heading(s);
            for i in 0..2 {
                r[i] += phi[i] * resid;
                for j in 0..2 {
                    m[i][j] += phi[i] * phi[j];
                }
            }
        }
        let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
        if det.abs() < 1e-300 {
            return [0.0, 0.0];
        }
        [
            (m[1][1] * r[0] - m[0][1] * r[1]) / det,
            (m[0][0] * r[1] - m[1][0] * r[0]) / det,
        ]
    }

    /// Damped Newton on the endpoint equations for (b, c) at a fixed length.
    fn solve_bc(&self, sf: f64, guess: [f64; 2]) -> Option<[f64; 2]> {
        let eval = |p: [f64; 2], fine: bool| {
            let (e, j) = self.endpoint_and_jacobian(p[0], p[1], sf, fine);
            let r = [e[0] - self.x_f, e[1] - self.y_f];
            (r, j, r[0].hypot(r[1]))
        };
        let mut p = guess;
        let mut fine = false;
        let (mut r, mut j, mut norm) = eval(p, fine);
        let mut kicks = 0;
        for iter in 0..30 {
            // A guess that has not come near the goal after a few steps is on a wrong
            // branch; the other guesses are cheaper than crawling.
            if iter >= 8 && norm > 1e-3 {
                return None;
            }
            if !fine && norm < 1e-6 {
                // Close enough to switch to the accurate rule for the last digits; a
                // one-panel accurate rule is the coarse rule, so nothing to redo then.
                fine = true;
                if self.panels(&self.params(p[0], p[1], sf), sf) > 1 {
                    (r, j, norm) = eval(p, fine);
                }
            }
            if fine && norm < 1e-11 {
                return Some(p);
            }
            let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
            let scale = j.iter().flatten().map(|v| v * v).sum::<f64>();
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
                (r, j, norm) = eval(p, fine);
                continue;
            }
            let step = [
                -(j[1][1] * r[0] - j[0][1] * r[1]) / det,
                -(-j[1][0] * r[0] + j[0][0] * r[1]) / det,
            ];
            let mut t = 1.0;
            loop {
                let q = [p[0] + t * step[0], p[1] + t * step[1]];
                let (rq, jq, nq) = eval(q, fine);
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
        (fine && norm < 1e-10).then_some(p)
    }
}

impl SpiralProblem {
    /// Damped minimum-norm Gauss–Newton in (b, c, s_f) with s_f kept in [lo, hi].
    ///
    /// Where the fixed-length solve fails, the solution curve is usually at a fold in
    /// s_f (the shortest length that reaches, e.g. a symmetric lane change); the 2 × 3
    /// Jacobian keeps full rank there, so letting s_f move finds the fold solution.
    fn solve_free(&self, guess: [f64; 2], sf0: f64, lo: f64, hi: f64) -> Option<([f64; 2], f64)> {
        let eval = |q: [f64; 3], fine: bool| {
            let (e, j) = self.endpoint_and_jacobian(q[0], q[1], q[2], fine);
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
            // ∂(x, y)/∂s_f by central difference (d and e depend on s_f rationally).
            let h = 1e-7 * q[2];
            let (ep, _) = self.endpoint_and_jacobian(q[0], q[1], q[2] + h, fine);
            let (em, _) = self.endpoint_and_jacobian(q[0], q[1], q[2] - h, fine);
            let js = [(ep[0] - em[0]) / (2.0 * h), (ep[1] - em[1]) / (2.0 * h)];
            let a = [[j[0][0], j[0][1], js[0]], [j[1][0], j[1][1], js[1]]];
            // δ = −Aᵀ (A Aᵀ)⁻¹ r
            let m = [
                [
                    a[0].iter().map(|v| v * v).sum::<f64>(),
                    (0..3).map(|k| a[0][k] * a[1][k]).sum::<f64>(),
                ],
                [0.0, a[1].iter().map(|v| v * v).sum::<f64>()],
            ];
            let m10 = m[0][1];
            let det = m[0][0] * m[1][1] - m10 * m10;
            if !(det.is_finite() && det.abs() > 1e-30) {
                return None;
            }
            let y = [
                (m[1][1] * r[0] - m10 * r[1]) / det,
                (m[0][0] * r[1] - m10 * r[0]) / det,
            ];
            let step: [f64; 3] = std::array::from_fn(|k| -(a[0][k] * y[0] + a[1][k] * y[1]));
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

/// Result of the spiral planner.
#[derive(Debug, Clone, PartialEq)]
pub struct SpiralPlan {
    pub params: SpiralParams,
    /// Normalised ∫½κ² ds.
    pub cost: f64,
    pub max_abs_curvature_per_m: f64,
    pub path: Path,
    /// Fixed-length Newton solves of the endpoint equations the search used.
    pub newton_solves: usize,
}

impl SpiralPlan {
    pub fn into_plan(self) -> Plan {
        Plan {
            planner: PlannerKind::Spiral,
            params: PlanParams::Spiral(self.params),
            cost: self.cost,
            path: self.path,
        }
    }
}

impl SpiralConfig {
    fn validate(&self) -> Result<(), PlanError> {
        if self.length_grid_points < 3 {
            return Err(PlanError::InvalidInput {
                what: "spiral.length_grid_points",
                reason: "must be at least 3".into(),
            });
        }
        if !(self.sample_spacing_m.is_finite() && self.sample_spacing_m > 0.0) {
            return Err(PlanError::InvalidInput {
                what: "spiral.sample_spacing_m",
                reason: "must be a positive finite length".into(),
            });
        }
        Ok(())
    }
}

/// One solved length: (s_f, [b, c], cost, max normalised |κ|).
type Candidate = (f64, [f64; 2], f64, f64);

/// Plans the spiral: for each length s_f the endpoint is met exactly by Newton on (b, c);
/// the cost ∫½κ² is minimised over s_f (grid with continuation, then golden section).
pub fn plan(req: &PlanRequest, cfg: &SpiralConfig) -> Result<SpiralPlan, PlanError> {
    req.validate()?;
    cfg.validate()?;
    let prob = SpiralProblem::from_request(req, 0.0);
    let (lo, hi) = prob.length_window(cfg.enforce_length_window);
    let mut newton_solves = 0usize;
    let mut solve = |sf: f64, guesses: &[[f64; 2]]| -> Option<Candidate> {
        // Several starts can land on different branches; the least-cost one is the
        // natural, loop-free spiral.
        let mut best: Option<Candidate> = None;
        for g in guesses {
            newton_solves += 1;
            if let Some(bc) = prob.solve_bc(sf, *g) {
                let cost = prob.cost(bc[0], bc[1], sf);
                if best.is_none_or(|b| cost < b.2 - 1e-12) {
                    best = Some((sf, bc, cost, prob.max_abs_curvature(bc[0], bc[1], sf)));
                }
            }
        }
        best
    };
    let m = cfg.length_grid_points;
    let profile = prob.bezier_heading_profile();
    // The cheapest spirals are the short ones, just above the shortest length that can
    // reach the goal, so grid points crowd toward the window's lower end (cubic spacing).
    let grid_sf = |i: usize| lo + (hi - lo) * (i as f64 / (m - 1) as f64).powi(3);
    let mut grid: Vec<Option<Candidate>> = vec![None; m];
    let mut warm: Option<[f64; 2]> = None;
    // Long lengths solve easily; continue from them down toward the short-length fold.
    for i in (0..m).rev() {
        let sf = grid_sf(i);
        let mut guesses = vec![prob.fit_bc(sf, &profile), [0.0, 0.0]];
        guesses.extend(warm);
        let cand = solve(sf, &guesses);
        warm = cand.map(|c| c.1).or(warm);
        grid[i] = cand;
    }
    // Where the short end of the window failed, the cheapest spiral may sit at a fold in
    // s_f (the shortest length that reaches; e.g. a symmetric lane change), where the
    // fixed-length solve is singular: solve once with s_f free from just below the
    // shortest solved length (or, if nothing solved, from each grid length in turn).
    let mut fold: Option<Candidate> = None;
    if grid[0].is_none() {
        let first_ok = grid.iter().position(Option::is_some);
        let tries: Vec<usize> = match first_ok {
            Some(k) => vec![k.saturating_sub(1)],
            None => (0..m).collect(),
        };
        for i in tries {
            let sf = grid_sf(i);
            if let Some((bc, s)) = prob.solve_free(prob.fit_bc(sf, &profile), sf, lo, hi) {
                let (cost, max_k) = (
                    prob.cost(bc[0], bc[1], s),
                    prob.max_abs_curvature(bc[0], bc[1], s),
                );
                fold = Some((s, bc, cost, max_k));
                break;
            }
        }
    }
    let limit = prob.kappa_limit;
    let feasible = |c: &Candidate| c.3 <= limit;
    let best_idx = grid
        .iter()
        .enumerate()
        .filter_map(|(i, c)| c.filter(feasible).map(|c| (i, c.2)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(i, _)| i);
    let fold = fold.filter(feasible);
    let Some(best_idx) = best_idx.or(fold.map(|_| usize::MAX)) else {
        let least_k = grid
            .iter()
            .flatten()
            .chain(fold.iter())
            .map(|c| c.3)
            .fold(f64::INFINITY, f64::min);
        return Err(if least_k.is_finite() {
            PlanError::curvature(PlannerKind::Spiral, least_k / prob.scale_m, &req.truck)
        } else {
            PlanError::Unreachable {
                planner: PlannerKind::Spiral,
                reason: format!(
                    "no quartic spiral of normalised length {lo:.3}–{hi:.3} reaches the goal"
                ),
            }
        });
    };
    // usize::MAX marks "only the fold solution is feasible": nothing to refine.
    let mut best = grid.get(best_idx).copied().flatten();
    if best_idx != usize::MAX {
        let seed = grid[best_idx].map(|c| c.1).unwrap_or([0.0, 0.0]);
        let (a, b) = (
            grid_sf(best_idx.saturating_sub(1)),
            grid_sf((best_idx + 1).min(m - 1)),
        );
        let mut warm = seed;
        brent_min(
            |sf| match solve(sf, &[warm]) {
                Some(c) if feasible(&c) => {
                    warm = c.1;
                    if best.is_none_or(|b| c.2 < b.2) {
                        best = Some(c);
                    }
                    c.2
                }
                _ => f64::INFINITY,
            },
            a,
            b,
            1e-5 * (hi - lo),
        );
    }
    if let Some(f) = fold
        && best.is_none_or(|b| f.2 < b.2)
    {
        best = Some(f);
    }
    let Some((sf, [bb, cc], cost, max_k)) = best else {
        unreachable!("best_idx points at a solved grid entry");
    };
    let params = prob.params(bb, cc, sf);
    let path = sample(&params, &req.start, &req.goal, cfg.sample_spacing_m);
    Ok(SpiralPlan {
        params,
        cost,
        max_abs_curvature_per_m: max_k / prob.scale_m,
        path,
        newton_solves,
    })
}

/// Dense world-frame samples of a normalised spiral, ≤ `spacing_m` apart.
///
/// x and y advance by the Euler–Maclaurin-corrected trapezoid
/// ∫f ≈ h/2 (f₀ + f₁) + h²/12 (f′₀ − f′₁), with f = cos θ, f′ = −κ sin θ (and likewise
/// for sin θ): O(h⁵) per step like Simpson, but one sin_cos per sample.
pub fn sample(p: &SpiralParams, start: &Pose2, goal: &Pose2, spacing_m: f64) -> Path {
    let r = p.scale_m;
    let sign = if p.mirrored { -1.0 } else { 1.0 };
    let n = ((p.sf * r / spacing_m).ceil() as usize).max(1);
    let h = p.sf / n as f64;
    let (mut x, mut y) = (0.0, 0.0);
    let mut samples = Vec::with_capacity(n + 1);
    let mut prev: Option<(f64, f64, f64)> = None; // (sin θ, cos θ, κ) at the last sample
    for i in 0..=n {
        let s = h * i as f64;
        let theta = p.heading(s);
        let k = p.curvature(s);
        let (sn, cs) = theta.sin_cos();
        if let Some((s0, c0, k0)) = prev {
            x += h / 2.0 * (c0 + cs) + h * h / 12.0 * (-k0 * s0 + k * sn);
            y += h / 2.0 * (s0 + sn) + h * h / 12.0 * (k0 * c0 - k * cs);
        }
        prev = Some((sn, cs, k));
        let local = Pose2::new(r * x, sign * r * y, 0.0);
        let world = start.to_world(&local);
        samples.push(PathSample {
            s_m: r * s,
            x_m: world.x_m,
            y_m: world.y_m,
            // Unwrapped heading: the spiral's θ(s) is continuous by construction.
            heading_rad: start.heading_rad + sign * theta,
            curvature_per_m: sign * k / r,
        });
    }
    if let Some(last) = samples.last_mut() {
        last.heading_rad += wrap_angle(goal.heading_rad - last.heading_rad);
    }
    Path { samples }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closed_form_d_e_meet_end_conditions() {
        let prob = SpiralProblem {
            a: 0.6,
            x_f: 0.9,
            y_f: 0.3,
            theta_f: 0.4,
            kappa_f: 0.2,
            kappa_limit: 6.0,
            scale_m: 6.0,
            mirrored: false,
        };
        let p = prob.params(3.0, -7.0, 1.2);
        assert!((p.curvature(1.2) - 0.2).abs() < 1e-12);
        assert!((p.heading(1.2) - 0.4).abs() < 1e-12);
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        let prob = SpiralProblem {
            a: 0.6,
            x_f: 0.95,
            y_f: 0.3,
            theta_f: 0.4,
            kappa_f: 0.0,
            kappa_limit: 6.0,
            scale_m: 6.0,
            mirrored: false,
        };
        let (b, c, sf) = (2.0, -5.0, 1.1);
        let (_, j) = prob.endpoint_and_jacobian(b, c, sf, true);
        let h = 1e-6;
        let (pb, _) = prob.endpoint_and_jacobian(b + h, c, sf, true);
        let (mb, _) = prob.endpoint_and_jacobian(b - h, c, sf, true);
        let (pc, _) = prob.endpoint_and_jacobian(b, c + h, sf, true);
        let (mc, _) = prob.endpoint_and_jacobian(b, c - h, sf, true);
        for k in 0..2 {
            assert!((j[k][0] - (pb[k] - mb[k]) / (2.0 * h)).abs() < 1e-7);
            assert!((j[k][1] - (pc[k] - mc[k]) / (2.0 * h)).abs() < 1e-7);
        }
    }
}
