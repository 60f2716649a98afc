//! The normalised two-point problem: closed-form d and e, the endpoint integral and its Jacobian, cost and curvature, first guesses.

use forkbench_core::units::wrap_angle;

use super::SpiralParams;
use crate::PlanRequest;
use crate::numeric::{GaussLegendre, max_abs_on_interval, sin_cos_reduced};

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

/// How finely the endpoint integral is resolved: panels per radian of turning.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Rule {
    /// One panel: cheap, enough to steer Newton while it is far from the solution.
    Coarse,
    /// One panel per ~12 rad (error ~1e-8): enough to rank lengths and branches.
    Search,
    /// One panel per ~6 rad (error ~1e-14): the returned spiral.
    Final,
}

impl Rule {
    /// Newton's stopping tolerance on the normalised endpoint error under this rule.
    pub(super) fn tolerance(self) -> f64 {
        match self {
            Rule::Coarse => 1e-6,
            Rule::Search => 1e-9,
            Rule::Final => 1e-11,
        }
    }
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

    /// End position (x(s_f), y(s_f)) and its Jacobian with respect to (b, c, s_f).
    ///
    /// Composite 12-point Gauss–Legendre: one panel per ~6 rad of turning (its error
    /// scales like (T/24)^24 for a turning T per panel), so
    /// spirals that sweep through large angles are integrated as accurately as gentle ones.
    /// The coarse rule is a single panel. The s_f column is Leibniz's rule:
    /// (cos θ_f, sin θ_f) at the upper limit plus θ's dependence on s_f through d and e.
    pub(super) fn endpoint_and_jacobian(
        &self,
        b: f64,
        c: f64,
        sf: f64,
        rule: Rule,
    ) -> ([f64; 2], [[f64; 3]; 2]) {
        let p = self.params(b, c, sf);
        let gl = GaussLegendre::rule12();
        let panels = self.panels(&p, sf, rule);
        let width = sf / panels as f64;
        let half = width / 2.0;
        let (mut x, mut y) = (0.0, 0.0);
        let mut jac = [[0.0; 3]; 2];
        let (inv_s2, inv_s3) = (1.0 / (sf * sf), 1.0 / sf.powi(3));
        let (dd, de) = self.de_dsf(b, c, sf);
        for k in 0..panels {
            let s0 = width * k as f64;
            // Headings first, then their sines and cosines in one branch-free pass that
            // the compiler vectorises: this loop is the planner's hot spot.
            let mut theta = [0.0; 12];
            for (t, xi) in theta.iter_mut().zip(&gl.nodes) {
                *t = p.heading(s0 + half * (1.0 + xi));
            }
            let mut sc = [(0.0, 0.0); 12];
            if theta.iter().all(|t| t.abs() < 1e5) {
                for (slot, t) in sc.iter_mut().zip(&theta) {
                    *slot = sin_cos_reduced(*t);
                }
            } else {
                for (slot, t) in sc.iter_mut().zip(&theta) {
                    *slot = t.sin_cos();
                }
            }
            for ((xi, wi), &(sin, cos)) in gl.nodes.iter().zip(&gl.weights).zip(&sc) {
                let s = s0 + half * (1.0 + xi);
                let w = half * wi;
                let (s2, s3) = (s * s, s * s * s);
                let (s4, s5) = (s2 * s2, s2 * s3);
                // ∂θ/∂b and ∂θ/∂c through b, c directly and through d(b, c), e(b, c).
                let dtb = s2 / 2.0 - 1.5 * s4 * inv_s2 + s5 * inv_s3;
                let dtc = s3 / 3.0 - (2.0 / 3.0) * s4 / sf + s5 * inv_s2 / 3.0;
                let dts = s4 / 4.0 * dd + s5 / 5.0 * de;
                x += w * cos;
                y += w * sin;
                for (col, dt) in [dtb, dtc, dts].into_iter().enumerate() {
                    jac[0][col] -= w * sin * dt;
                    jac[1][col] += w * cos * dt;
                }
            }
        }
        let (st, ct) = p.heading(sf).sin_cos();
        jac[0][2] += ct;
        jac[1][2] += st;
        ([x, y], jac)
    }

    /// ∂d/∂s_f and ∂e/∂s_f of the closed form at fixed (b, c).
    pub(super) fn de_dsf(&self, b: f64, c: f64, sf: f64) -> (f64, f64) {
        let (a, kf, tf) = (self.a, self.kappa_f, self.theta_f);
        let (s2, s3, s4, s5, s6) = (sf * sf, sf.powi(3), sf.powi(4), sf.powi(5), sf.powi(6));
        let dd =
            12.0 * kf / s4 - 80.0 * tf / s5 + 48.0 * a / s4 + 12.0 * b / s3 + 8.0 * c / (3.0 * s2);
        let de = -20.0 * kf / s5 + 100.0 * tf / s6
            - 60.0 * a / s5
            - 15.0 * b / s4
            - 10.0 * c / (3.0 * s3);
        (dd, de)
    }

    /// Panels the accurate rule needs: total turning ≤ s_f · max|κ|, with max|κ| from a
    /// coarse polynomial sample (no trig, so cheap); coefficient bounds are useless
    /// here, they cancel heavily.
    pub(super) fn panels(&self, p: &SpiralParams, sf: f64, rule: Rule) -> usize {
        let rad_per_panel = match rule {
            Rule::Coarse => return 1,
            Rule::Search => 12.0,
            Rule::Final => 6.0,
        };
        let peak = (0..=16)
            .map(|i| p.curvature(sf * i as f64 / 16.0).abs())
            .fold(0.0, f64::max);
        let turning = 1.25 * sf * peak;
        if turning.is_finite() {
            (turning / rad_per_panel).ceil().clamp(1.0, 12.0) as usize
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
        let (end, _) = self.endpoint_and_jacobian(b, c, sf, Rule::Final);
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
    pub(super) fn bezier_heading_profile(&self, h: f64) -> Vec<(f64, f64)> {
        const N: usize = 32;
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

    /// Heading profile that swings toward the goal's side first, then turns onto the goal
    /// heading: the hook-shaped branch that goals with a heading across their bearing
    /// take (the Bézier fits land on a costlier, loop-like branch there).
    pub(super) fn swing_heading_profile(&self) -> Vec<(f64, f64)> {
        const N: usize = 32;
        let swing = 2.0 * self.y_f.atan2(self.x_f);
        (0..=N)
            .map(|i| {
                let u = i as f64 / N as f64;
                let v = 1.0 - u;
                (
                    u,
                    self.theta_f * u * u * (3.0 - 2.0 * u) + swing * 4.0 * u * v * v,
                )
            })
            .collect()
    }

    /// Least-squares (b, c) whose heading θ(σ s_f) follows a reference profile; θ is
    /// linear in (b, c) once d and e are eliminated, so this is a 2×2 solve.
    pub(super) fn fit_bc(&self, sf: f64, profile: &[(f64, f64)]) -> [f64; 2] {
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
        let (_, j) = prob.endpoint_and_jacobian(b, c, sf, Rule::Final);
        let h = 1e-6;
        let (pb, _) = prob.endpoint_and_jacobian(b + h, c, sf, Rule::Final);
        let (mb, _) = prob.endpoint_and_jacobian(b - h, c, sf, Rule::Final);
        let (pc, _) = prob.endpoint_and_jacobian(b, c + h, sf, Rule::Final);
        let (mc, _) = prob.endpoint_and_jacobian(b, c - h, sf, Rule::Final);
        let (ps, _) = prob.endpoint_and_jacobian(b, c, sf + h, Rule::Final);
        let (ms, _) = prob.endpoint_and_jacobian(b, c, sf - h, Rule::Final);
        for k in 0..2 {
            assert!((j[k][0] - (pb[k] - mb[k]) / (2.0 * h)).abs() < 1e-7);
            assert!((j[k][1] - (pc[k] - mc[k]) / (2.0 * h)).abs() < 1e-7);
            assert!((j[k][2] - (ps[k] - ms[k]) / (2.0 * h)).abs() < 1e-7);
        }
    }
}
