//! Cubic uniform B-spline pick planner (Lü et al. 2019): six control points, min-max curvature over (L1, L2).

use forkbench_core::{Path, PathSample, Pose2, SettingsError};
use serde::{Deserialize, Serialize};

use crate::numeric::max_abs_on_interval;

mod slp;
use crate::{Plan, PlanError, PlanParams, PlanRequest};

/// Settings of the B-spline planner.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BsplineConfig {
    /// Lower bound of both handle lengths L1, L2 (the paper's empirical 1.5 m).
    pub min_handle_m: f64,
    /// Upper bound of both handle lengths; default: the start–goal distance (longer
    /// handles fold the control polygon back on itself).
    pub max_handle_m: Option<f64>,
    /// Grid points per axis of the global stage.
    pub grid_points: usize,
    /// Largest arc-length spacing of the output samples.
    pub sample_spacing_m: f64,
}

impl Default for BsplineConfig {
    fn default() -> Self {
        Self {
            min_handle_m: 1.5,
            max_handle_m: None,
            grid_points: 8,
            sample_spacing_m: 0.01,
        }
    }
}

/// One cubic segment as a power-basis polynomial P(u) = a u³ + b u² + c u + d.
#[derive(Debug, Clone, Copy)]
struct Segment {
    a: [f64; 2],
    b: [f64; 2],
    c: [f64; 2],
    d: [f64; 2],
}

impl Segment {
    /// Expands 1/6 [u³ u² u 1] G V for four control points V.
    fn from_points(v: [[f64; 2]; 4]) -> Self {
        let comb = |k: [f64; 4]| {
            [
                (k[0] * v[0][0] + k[1] * v[1][0] + k[2] * v[2][0] + k[3] * v[3][0]) / 6.0,
                (k[0] * v[0][1] + k[1] * v[1][1] + k[2] * v[2][1] + k[3] * v[3][1]) / 6.0,
            ]
        };
        Segment {
            a: comb([-1.0, 3.0, -3.0, 1.0]),
            b: comb([3.0, -6.0, 3.0, 0.0]),
            c: comb([-3.0, 0.0, 3.0, 0.0]),
            d: comb([1.0, 4.0, 1.0, 0.0]),
        }
    }

    fn point(&self, u: f64) -> [f64; 2] {
        [
            ((self.a[0] * u + self.b[0]) * u + self.c[0]) * u + self.d[0],
            ((self.a[1] * u + self.b[1]) * u + self.c[1]) * u + self.d[1],
        ]
    }

    fn d1(&self, u: f64) -> [f64; 2] {
        [
            (3.0 * self.a[0] * u + 2.0 * self.b[0]) * u + self.c[0],
            (3.0 * self.a[1] * u + 2.0 * self.b[1]) * u + self.c[1],
        ]
    }

    fn d2(&self, u: f64) -> [f64; 2] {
        [
            6.0 * self.a[0] * u + 2.0 * self.b[0],
            6.0 * self.a[1] * u + 2.0 * self.b[1],
        ]
    }

    /// κ = (x'y'' − y'x'') / |P'|³; infinite at a cusp (zero speed).
    fn curvature(&self, u: f64) -> f64 {
        let p1 = self.d1(u);
        let p2 = self.d2(u);
        let v2 = p1[0] * p1[0] + p1[1] * p1[1];
        if v2 < 1e-24 {
            return f64::INFINITY;
        }
        (p1[0] * p2[1] - p1[1] * p2[0]) / (v2 * v2.sqrt())
    }

    fn speed(&self, u: f64) -> f64 {
        let p = self.d1(u);
        p[0].hypot(p[1])
    }
}

/// The six-point, three-segment curve of the paper.
#[derive(Debug, Clone, Copy)]
pub struct BsplineCurve {
    /// P0, P_start, P1, P2, P_dest, P3.
    pub control_points_m: [[f64; 2]; 6],
    segments: [Segment; 3],
}

impl BsplineCurve {
    /// Control polygon from the start and goal poses and the handle lengths L1, L2.
    pub fn new(start: &Pose2, goal: &Pose2, l1_m: f64, l2_m: f64) -> Self {
        let ts = start.direction();
        let td = goal.direction();
        let s = [start.x_m, start.y_m];
        let d = [goal.x_m, goal.y_m];
        let p = [
            [s[0] - l1_m * ts[0], s[1] - l1_m * ts[1]],
            s,
            [s[0] + l1_m * ts[0], s[1] + l1_m * ts[1]],
            [d[0] - l2_m * td[0], d[1] - l2_m * td[1]],
            d,
            [d[0] + l2_m * td[0], d[1] + l2_m * td[1]],
        ];
        let segments = [
            Segment::from_points([p[0], p[1], p[2], p[3]]),
            Segment::from_points([p[1], p[2], p[3], p[4]]),
            Segment::from_points([p[2], p[3], p[4], p[5]]),
        ];
        Self {
            control_points_m: p,
            segments,
        }
    }

    /// Largest |κ| over the whole curve; `samples`/`refine` trade speed for accuracy.
    fn max_abs_curvature_with(&self, samples: usize, refine: usize) -> f64 {
        self.segments
            .iter()
            .map(|seg| max_abs_on_interval(|u| seg.curvature(u), 0.0, 1.0, samples, refine).1)
            .fold(0.0, f64::max)
    }

    /// Every local peak of |κ| (segment, u, |κ|) within `keep` of the largest.
    fn peaks(&self, samples: usize, keep: f64) -> Vec<(usize, f64, f64)> {
        let mut out = Vec::new();
        for (k, seg) in self.segments.iter().enumerate() {
            let h = 1.0 / samples as f64;
            let v = |i: usize| seg.curvature(i as f64 * h).abs();
            for i in 0..=samples {
                let (prev, here, next) = (
                    if i > 0 { v(i - 1) } else { f64::NEG_INFINITY },
                    v(i),
                    if i < samples {
                        v(i + 1)
                    } else {
                        f64::NEG_INFINITY
                    },
                );
                if here >= prev && here >= next {
                    let lo = i.saturating_sub(1) as f64 * h;
                    let hi = ((i + 1).min(samples)) as f64 * h;
                    let (u, val) = max_abs_on_interval(|u| seg.curvature(u), lo, hi, 4, 6);
                    out.push((k, u, val));
                }
            }
        }
        let top = out.iter().map(|p| p.2).fold(0.0, f64::max);
        out.retain(|p| p.2 >= keep * top || !top.is_finite());
        out
    }

    /// Largest |κ| over the curve, accurate to ~1e-9 relative.
    pub fn max_abs_curvature_per_m(&self) -> f64 {
        self.max_abs_curvature_with(64, 12)
    }

    /// Dense samples no further apart than `spacing_m` along the arc.
    pub fn sample(&self, start: &Pose2, goal: &Pose2, spacing_m: f64) -> Path {
        let mut samples: Vec<PathSample> = Vec::new();
        let mut s_m = 0.0;
        let mut prev_heading = start.heading_rad;
        let mut prev_speed = 0.0;
        for (k, seg) in self.segments.iter().enumerate() {
            // Step in u so that the fastest part of the segment still moves ≤ spacing.
            let vmax = (0..=32)
                .map(|i| seg.speed(i as f64 / 32.0))
                .fold(0.0, f64::max);
            let n = ((vmax * 1.05 / spacing_m).ceil() as usize).max(1);
            let du = 1.0 / n as f64;
            for i in usize::from(k > 0)..=n {
                let u = i as f64 * du;
                let p = seg.point(u);
                let t = seg.d1(u);
                let speed = t[0].hypot(t[1]);
                if i > 0 {
                    // Trapezoid on |P'|: over ≤ 1 cm steps its error is ~1e-9 m.
                    s_m += 0.5 * (prev_speed + speed) * du;
                }
                prev_speed = speed;
                // Continuous (unwrapped) heading so trackers never see a 2π jump.
                let raw = t[1].atan2(t[0]);
                let heading = prev_heading + forkbench_core::units::wrap_angle(raw - prev_heading);
                prev_heading = heading;
                samples.push(PathSample {
                    s_m,
                    x_m: p[0],
                    y_m: p[1],
                    heading_rad: heading,
                    curvature_per_m: seg.curvature(u),
                });
            }
        }
        // The curve interpolates both poses by construction; pin the last sample's
        // heading to the goal's branch so its wrapped value is exact.
        if let Some(last) = samples.last_mut() {
            last.heading_rad = last.heading_rad
                + forkbench_core::units::wrap_angle(goal.heading_rad - last.heading_rad);
        }
        Path::new(samples)
    }
}

/// Result of the B-spline planner.
#[derive(Debug, Clone, PartialEq)]
pub struct BsplinePlan {
    pub l1_m: f64,
    pub l2_m: f64,
    pub control_points_m: [[f64; 2]; 6],
    pub max_abs_curvature_per_m: f64,
    pub path: Path,
    /// Objective evaluations the optimiser used.
    pub evaluations: usize,
}

impl BsplinePlan {
    pub fn into_plan(self) -> Plan {
        Plan {
            planner: "bspline".into(),
            params: PlanParams::Bspline {
                l1_m: self.l1_m,
                l2_m: self.l2_m,
                control_points_m: self.control_points_m,
            },
            cost: self.max_abs_curvature_per_m,
            path: self.path,
            control_polygon_m: Some(self.control_points_m.to_vec()),
        }
    }
}

/// Max |κ| of the curve for given handles (accurate); used to evaluate the paper's (L1, L2).
pub fn max_abs_curvature_for(start: &Pose2, goal: &Pose2, l1_m: f64, l2_m: f64) -> f64 {
    BsplineCurve::new(start, goal, l1_m, l2_m).max_abs_curvature_per_m()
}

impl BsplineConfig {
    pub(crate) fn validate(&self) -> Result<(), SettingsError> {
        let bad = |field, reason: &str| Err(SettingsError::field(field, reason));
        if !(self.min_handle_m.is_finite() && self.min_handle_m > 0.0) {
            return bad("min_handle_m", "must be a positive finite length");
        }
        if let Some(max) = self.max_handle_m
            && !(max.is_finite() && max >= self.min_handle_m)
        {
            return bad("max_handle_m", "must be finite and ≥ min_handle_m");
        }
        if self.grid_points < 3 {
            return bad("grid_points", "must be at least 3");
        }
        if !(self.sample_spacing_m.is_finite()
            && self.sample_spacing_m >= crate::MIN_SAMPLE_SPACING_M)
        {
            return bad("sample_spacing_m", "must be a positive finite length");
        }
        // Work grows with the grid's square; lengths beyond a warehouse are typos.
        if self.grid_points > 1000 {
            return bad("grid_points", "must be at most 1000");
        }
        forkbench_core::settings::in_ranges(&[
            ("min_handle_m", self.min_handle_m, 0.0, 100.0),
            (
                "max_handle_m",
                self.max_handle_m.unwrap_or(1.0),
                0.0,
                1000.0,
            ),
            ("sample_spacing_m", self.sample_spacing_m, 0.0, 1.0),
        ])
    }
}

/// Plans the min-max-curvature B-spline: a grid over the (L1, L2) box finds the basins
/// of the global optimum, sequential linear programming refines the best few.
pub fn plan(req: &PlanRequest, cfg: &BsplineConfig) -> Result<BsplinePlan, PlanError> {
    req.validate()?;
    cfg.validate()?;
    let (start, goal) = (&req.start, &req.goal);
    let lo = cfg.min_handle_m;
    let hi = cfg
        .max_handle_m
        .unwrap_or_else(|| start.distance_to(goal).max(lo + 1.0));
    let mut evaluations = 0usize;
    // Medium accuracy is enough to steer the search; the winner is re-measured exactly.
    let mut objective = |p: [f64; 2]| {
        evaluations += 1;
        BsplineCurve::new(start, goal, p[0], p[1]).max_abs_curvature_with(8, 4)
    };

    let n = cfg.grid_points;
    let step = (hi - lo) / (n - 1) as f64;
    let mut seeds = slp::grid_seeds(&mut objective, lo, step, n);
    seeds.sort_by(|a, b| a.2.total_cmp(&b.2));
    // A second basin is refined only when it is nearly as good as the first.
    if let Some(&(_, _, v0)) = seeds.first() {
        seeds.retain(|s| s.2 <= v0 * 1.25);
    }
    seeds.truncate(3);
    if seeds.is_empty() {
        return Err(PlanError::Unreachable {
            planner: "bspline".into(),
            reason: format!(
                "every control polygon with handles in [{lo:.3}, {hi:.3}] m folds back into a cusp"
            ),
        });
    }
    let mut best = ([f64::NAN; 2], f64::INFINITY);
    for &(i, j, _) in &seeds {
        let (x, fx, used) = slp::slp_minmax(
            start,
            goal,
            [lo + step * i as f64, lo + step * j as f64],
            step,
            lo,
            hi,
        );
        evaluations += used;
        if fx < best.1 {
            best = (x, fx);
        }
    }
    let [l1, l2] = best.0;
    finish(req, cfg, [l1, l2], evaluations)
}

/// Checks the winning curve (no cusp, within the truck's curvature) and samples it.
fn finish(
    req: &PlanRequest,
    cfg: &BsplineConfig,
    [l1, l2]: [f64; 2],
    evaluations: usize,
) -> Result<BsplinePlan, PlanError> {
    let (start, goal) = (&req.start, &req.goal);
    let curve = BsplineCurve::new(start, goal, l1, l2);
    let max_k = curve.max_abs_curvature_per_m();
    if !max_k.is_finite() {
        return Err(PlanError::Unreachable {
            planner: "bspline".into(),
            reason: "the best control polygon still has a cusp".into(),
        });
    }
    // κ ≤ κ_max and arctan(L κ) ≤ α_max are the same bound; check it once.
    if max_k > req.truck.max_curvature_per_m() {
        return Err(PlanError::curvature("bspline", max_k, &req.truck));
    }
    let path = curve.sample(start, goal, cfg.sample_spacing_m);
    if let Some(s_m) = crate::find_cusp(&path, req.truck.max_curvature_per_m()) {
        return Err(PlanError::Unreachable {
            planner: "bspline".into(),
            reason: format!(
                "the path reverses direction (a cusp {s_m:.2} m along it): the goal needs \
                 the truck to back up, which a forward pick path cannot"
            ),
        });
    }
    Ok(BsplinePlan {
        l1_m: l1,
        l2_m: l2,
        control_points_m: curve.control_points_m,
        max_abs_curvature_per_m: max_k,
        path,
        evaluations,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_2;

    fn table2(d_m: f64, theta_deg: f64) -> (Pose2, Pose2) {
        (
            Pose2::new(0.0, 0.0, FRAC_PI_2),
            Pose2::new(d_m, 6.5, FRAC_PI_2 + theta_deg.to_radians()),
        )
    }

    #[test]
    fn curve_interpolates_poses_with_zero_end_curvature() {
        let (s, g) = table2(1.5, 15.0);
        let c = BsplineCurve::new(&s, &g, 1.7, 2.2);
        let p0 = c.segments[0].point(0.0);
        let p1 = c.segments[2].point(1.0);
        assert!((p0[0] - s.x_m).abs() < 1e-12 && (p0[1] - s.y_m).abs() < 1e-12);
        assert!((p1[0] - g.x_m).abs() < 1e-12 && (p1[1] - g.y_m).abs() < 1e-12);
        assert!(c.segments[0].curvature(0.0).abs() < 1e-12);
        assert!(c.segments[2].curvature(1.0).abs() < 1e-12);
        // C2 across the knots.
        for k in 0..2 {
            let (a, b) = (&c.segments[k], &c.segments[k + 1]);
            assert!((a.curvature(1.0) - b.curvature(0.0)).abs() < 1e-12);
        }
    }

    #[test]
    fn plan_beats_or_matches_fine_grid() {
        let (s, g) = table2(1.0, -10.0);
        let plan = plan(&PlanRequest::new(s, g), &BsplineConfig::default()).expect("feasible");
        let mut brute = f64::INFINITY;
        for i in 0..=120 {
            for j in 0..=120 {
                let l1 = 1.5 + 5.0 * i as f64 / 120.0;
                let l2 = 1.5 + 5.0 * j as f64 / 120.0;
                brute = brute.min(BsplineCurve::new(&s, &g, l1, l2).max_abs_curvature_with(24, 20));
            }
        }
        assert!(
            plan.max_abs_curvature_per_m <= brute * (1.0 + 1e-3),
            "{} vs {brute}",
            plan.max_abs_curvature_per_m
        );
    }
}
