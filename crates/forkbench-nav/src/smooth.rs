//! From a route's polyline to a drivable path: shortcuts, a symmetric clothoid pair at each corner (curvature-continuous, |κ| ≤ κ_max), and the swept footprint checked along the result.

use forkbench_core::units::wrap_angle;
use forkbench_core::{Path, PathSample, Pose2};
use forkbench_geom::{Footprint, Obstacles};

use crate::space::FreeSpace;

/// Smoothing settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SmoothParams {
    /// The truck's limit, κ_max = tan(α_max) / L.
    pub max_curvature_per_m: f64,
    /// Corners are first tried at this fraction of κ_max (margin for the tracker), and at
    /// κ_max itself where the legs are too short or the gentler corner strikes something.
    pub preferred_fraction: f64,
    /// Spacing of the output samples.
    pub spacing_m: f64,
    /// Arc length between footprint checks along the result.
    pub check_step_m: f64,
    /// Clearances are measured up to this distance.
    pub clearance_cap_m: f64,
}

impl SmoothParams {
    pub fn for_curvature(max_curvature_per_m: f64) -> Self {
        Self {
            max_curvature_per_m,
            preferred_fraction: 0.8,
            spacing_m: 0.02,
            check_step_m: 0.05,
            clearance_cap_m: 2.0,
        }
    }
}

/// No curvature-limited path follows the polyline.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SmoothError {
    #[error(
        "the corner at ({x:.2}, {y:.2}) m turns {turn_deg:.0}°: at κ ≤ {kappa:.3} 1/m it needs {needed_m:.2} m of straight on each side, but the leg {side} is {available_m:.2} m long"
    )]
    CornerTooTight {
        /// The corner's index among the interior vertices.
        corner: usize,
        x: f64,
        y: f64,
        turn_deg: f64,
        kappa: f64,
        needed_m: f64,
        available_m: f64,
        side: &'static str,
    },
    #[error("the polyline needs at least two distinct points")]
    Degenerate,
}

/// Where the swept footprint first strikes an obstacle.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct SweptHit {
    pub s_m: f64,
    pub x_m: f64,
    pub y_m: f64,
    /// Index of the obstacle struck.
    pub obstacle: usize,
}

/// A smoothed path and what its swept footprint touches.
#[derive(Debug, Clone, PartialEq)]
pub struct Smoothed {
    /// The polyline after shortcuts.
    pub polyline: Vec<[f64; 2]>,
    pub path: Path,
    /// The first strike of the chassis or forks, if any (the path is still given).
    pub hit: Option<SweptHit>,
    /// Smallest distance from the footprint to an obstacle along the path (capped).
    pub min_clearance_m: f64,
    pub max_curvature_per_m: f64,
}

impl Smoothed {
    pub fn clear(&self) -> bool {
        self.hit.is_none()
    }
}

/// Greedy shortcuts: from each kept vertex, jump to the farthest later vertex in free
/// view. `anchors` (indices) are never skipped (the heading lead-in and lead-out).
pub fn shortcut<S: FreeSpace + ?Sized>(
    space: &S,
    points: &[[f64; 2]],
    anchors: &[usize],
) -> Vec<[f64; 2]> {
    let Some(&first) = points.first() else {
        return Vec::new();
    };
    let mut out = vec![first];
    let mut i = 0;
    while i + 1 < points.len() {
        let limit = anchors
            .iter()
            .copied()
            .filter(|&a| a > i)
            .min()
            .unwrap_or(points.len() - 1);
        let j = (i + 1..=limit)
            .rev()
            .find(|&j| j == i + 1 || space.segment_free(points[i], points[j]))
            .unwrap_or(i + 1);
        out.push(points[j]);
        i = j;
    }
    out
}

/// One corner: where its clothoids start and end, and their shape.
#[derive(Debug, Clone, Copy)]
struct Corner {
    vertex: [f64; 2],
    heading_in: f64,
    turn_rad: f64,
    kappa: f64,
    /// Distance from the vertex to the first clothoid's start (and from the vertex to the
    /// second's end).
    tangent_m: f64,
}

impl Corner {
    fn new(vertex: [f64; 2], heading_in: f64, heading_out: f64, kappa: f64) -> Self {
        let turn_rad = wrap_angle(heading_out - heading_in);
        let (x, y) = clothoid_end(turn_rad.abs() / kappa, kappa, 1e-3);
        Self {
            vertex,
            heading_in,
            turn_rad,
            kappa,
            tangent_m: x + y * (turn_rad.abs() / 2.0).tan(),
        }
    }

    fn clothoid_len_m(&self) -> f64 {
        self.turn_rad.abs() / self.kappa
    }
}

/// End point of a clothoid from curvature 0 to `kappa` over `len_m`, in its start frame.
fn clothoid_end(len_m: f64, kappa: f64, step_m: f64) -> (f64, f64) {
    let n = (len_m / step_m).ceil().max(1.0) as usize;
    let h = len_m / n as f64;
    let (mut x, mut y) = (0.0, 0.0);
    for i in 0..n {
        let s = (i as f64 + 0.5) * h;
        let th = kappa * s * s / (2.0 * len_m);
        x += h * th.cos();
        y += h * th.sin();
    }
    (x, y)
}

fn heading(a: [f64; 2], b: [f64; 2]) -> f64 {
    (b[1] - a[1]).atan2(b[0] - a[0])
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (b[0] - a[0]).hypot(b[1] - a[1])
}

/// Corners at each interior vertex, with per-vertex curvature `kappa[i - 1]`; checks that
/// neighbouring corners fit on the leg between them.
fn corners(pts: &[[f64; 2]], kappa: &[f64]) -> Result<Vec<Corner>, SmoothError> {
    let mut out: Vec<Corner> = Vec::new();
    for i in 1..pts.len() - 1 {
        let (hi, ho) = (heading(pts[i - 1], pts[i]), heading(pts[i], pts[i + 1]));
        out.push(Corner::new(pts[i], hi, ho, kappa[i - 1]));
    }
    for (k, leg) in pts.windows(2).enumerate() {
        let before = k
            .checked_sub(1)
            .and_then(|c| out.get(c))
            .map_or(0.0, |c| c.tangent_m);
        let after = out.get(k).map_or(0.0, |c| c.tangent_m);
        let available_m = dist(leg[0], leg[1]);
        if before + after > available_m + 1e-9 {
            let (corner, side) = if after >= before {
                (k, "before it")
            } else {
                (k - 1, "after it")
            };
            let c = out[corner];
            return Err(SmoothError::CornerTooTight {
                corner,
                x: c.vertex[0],
                y: c.vertex[1],
                turn_deg: c.turn_rad.abs().to_degrees(),
                kappa: c.kappa,
                needed_m: c.tangent_m,
                available_m: available_m - (before + after - c.tangent_m),
                side,
            });
        }
    }
    Ok(out)
}

/// The samples of a polyline with its corners rounded, every `spacing_m`.
fn sample(pts: &[[f64; 2]], corners: &[Corner], spacing_m: f64) -> Path {
    let mut w = Walker::new(pts[0], heading(pts[0], pts[1]), spacing_m);
    for c in corners {
        let (s, co) = c.heading_in.sin_cos();
        let entry = [
            c.vertex[0] - c.tangent_m * co,
            c.vertex[1] - c.tangent_m * s,
        ];
        w.straight_to(entry);
        let len = c.clothoid_len_m();
        let sign = c.turn_rad.signum();
        w.curve(len, |u| sign * c.kappa * u / len);
        w.curve(len, |u| sign * c.kappa * (1.0 - u / len));
        let out = c.heading_in + c.turn_rad;
        let exit = [
            c.vertex[0] + c.tangent_m * out.cos(),
            c.vertex[1] + c.tangent_m * out.sin(),
        ];
        // Snap the integration's sub-millimetre drift so it does not build up.
        w.pos = exit;
        w.heading = out;
    }
    w.straight_to(pts[pts.len() - 1]);
    w.finish()
}

/// Integrates curvature along arc length and emits samples at a fixed spacing.
struct Walker {
    pos: [f64; 2],
    heading: f64,
    s: f64,
    kappa: f64,
    next_emit: f64,
    spacing: f64,
    out: Vec<PathSample>,
}

impl Walker {
    fn new(pos: [f64; 2], heading: f64, spacing: f64) -> Self {
        let mut w = Self {
            pos,
            heading,
            s: 0.0,
            kappa: 0.0,
            next_emit: 0.0,
            spacing,
            out: Vec::new(),
        };
        w.emit();
        w
    }

    fn emit(&mut self) {
        self.out.push(PathSample {
            s_m: self.s,
            x_m: self.pos[0],
            y_m: self.pos[1],
            heading_rad: self.heading,
            curvature_per_m: self.kappa,
        });
        self.next_emit = self.s + self.spacing;
    }

    fn straight_to(&mut self, to: [f64; 2]) {
        let len = dist(self.pos, to);
        self.curve(len, |_| 0.0);
    }

    /// Advances `len` with curvature `k(u)` at distance `u` into the piece.
    fn curve(&mut self, len: f64, k: impl Fn(f64) -> f64) {
        let h = 1e-3_f64.min(self.spacing);
        let n = (len / h).ceil() as usize;
        for i in 0..n {
            let step = h.min(len - i as f64 * h);
            let u = i as f64 * h;
            let mid = self.heading + 0.5 * step * k(u + step / 2.0);
            self.pos = [
                self.pos[0] + step * mid.cos(),
                self.pos[1] + step * mid.sin(),
            ];
            self.heading += step * k(u + step / 2.0);
            self.s += step;
            self.kappa = k(u + step);
            if self.s >= self.next_emit - 1e-9 {
                self.emit();
            }
        }
    }

    fn finish(mut self) -> Path {
        if self.out.last().is_some_and(|p| p.s_m < self.s - 1e-9) {
            self.emit();
        }
        for p in &mut self.out {
            p.heading_rad = wrap_angle(p.heading_rad);
        }
        Path::new(self.out)
    }
}

/// The first obstacle the truck's parts strike along `path`, checked every `step_m`.
pub fn first_strike(
    obstacles: &Obstacles,
    parts: &[Footprint],
    path: &Path,
    step_m: f64,
) -> Option<SweptHit> {
    parts
        .iter()
        .filter_map(|fp| obstacles.first_hit_along(fp, path, step_m))
        .min_by(|a, b| a.s_m.total_cmp(&b.s_m))
        .and_then(|h| {
            let at = path.samples.iter().find(|p| p.s_m >= h.s_m)?;
            Some(SweptHit {
                s_m: h.s_m,
                x_m: at.x_m,
                y_m: at.y_m,
                obstacle: h.obstacle,
            })
        })
}

/// Smallest clearance of the truck's parts along `path`, checked every `step_m`.
pub fn min_clearance(
    obstacles: &Obstacles,
    parts: &[Footprint],
    path: &Path,
    step_m: f64,
    cap_m: f64,
) -> f64 {
    let mut best = cap_m;
    let mut next = f64::NEG_INFINITY;
    for p in &path.samples {
        if p.s_m < next {
            continue;
        }
        next = p.s_m + step_m;
        for fp in parts {
            best = best.min(obstacles.clearance(fp, &p.pose(), best));
        }
    }
    best
}

/// Smooths `polyline` (already shortcut) into a curvature-continuous path and checks its
/// swept footprint `parts`. A corner that strikes an obstacle is retried at κ_max (it then
/// cuts less of the corner) before the strike is reported. The clearance reported is that
/// of `clearance_parts` (the truck itself, where `parts` are grown by a margin).
pub fn smooth(
    polyline: &[[f64; 2]],
    obstacles: &Obstacles,
    (parts, clearance_parts): (&[Footprint], &[Footprint]),
    p: &SmoothParams,
) -> Result<Smoothed, SmoothError> {
    let pts: Vec<[f64; 2]> = dedup(polyline);
    if pts.len() < 2 {
        return Err(SmoothError::Degenerate);
    }
    let k_max = p.max_curvature_per_m;
    let mut kappa = vec![k_max * p.preferred_fraction; pts.len().saturating_sub(2)];
    let mut cs = fitted_corners(&pts, &mut kappa, k_max)?;
    loop {
        let path = sample(&pts, &cs, p.spacing_m);
        let hit = first_strike(obstacles, parts, &path, p.check_step_m);
        let retry = hit
            .and_then(|h| corner_at(&pts, &cs, h.s_m))
            .filter(|&i| kappa[i] < k_max);
        if let Some(i) = retry {
            kappa[i] = k_max;
            cs = fitted_corners(&pts, &mut kappa, k_max)?;
            continue;
        }
        let min_clearance_m = if hit.is_some() {
            0.0
        } else {
            min_clearance(
                obstacles,
                clearance_parts,
                &path,
                p.check_step_m * 2.0,
                p.clearance_cap_m,
            )
        };
        let max_curvature_per_m = path
            .samples
            .iter()
            .map(|s| s.curvature_per_m.abs())
            .fold(0.0, f64::max);
        return Ok(Smoothed {
            polyline: pts,
            path,
            hit,
            min_clearance_m,
            max_curvature_per_m,
        });
    }
}

/// Corners at the given curvatures, each corner that does not fit its legs raised to
/// `k_max` (tighter, shorter) until all fit or one at `k_max` still does not.
fn fitted_corners(
    pts: &[[f64; 2]],
    kappa: &mut [f64],
    k_max: f64,
) -> Result<Vec<Corner>, SmoothError> {
    loop {
        match corners(pts, kappa) {
            Err(SmoothError::CornerTooTight { corner, .. }) if kappa[corner] < k_max => {
                kappa[corner] = k_max;
            }
            other => return other,
        }
    }
}

/// The corner nearest arc length `s_m` (measured on the polyline, which is only a little
/// longer than the smoothed path).
fn corner_at(pts: &[[f64; 2]], cs: &[Corner], s_m: f64) -> Option<usize> {
    let mut s = 0.0;
    let mut best: Option<(usize, f64)> = None;
    for i in 0..cs.len() {
        s += dist(pts[i], pts[i + 1]);
        let d = (s - s_m).abs();
        if best.is_none_or(|(_, bd)| d < bd) {
            best = Some((i, d));
        }
    }
    best.map(|(i, _)| i)
}

fn dedup(points: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let mut out: Vec<[f64; 2]> = Vec::new();
    for &p in points {
        if out.last().is_none_or(|&q| dist(p, q) > 1e-6) {
            out.push(p);
        }
    }
    out
}

/// The lead-in and lead-out points that fix the start and goal headings: `lead_m[0]`
/// ahead of the start and `lead_m[1]` behind the goal.
pub fn lead_points(
    start: &Pose2,
    goal: &Pose2,
    [lead_in, lead_out]: [f64; 2],
) -> ([f64; 2], [f64; 2]) {
    let (ss, sc) = start.heading_rad.sin_cos();
    let (gs, gc) = goal.heading_rad.sin_cos();
    (
        [start.x_m + lead_in * sc, start.y_m + lead_in * ss],
        [goal.x_m - lead_out * gc, goal.y_m - lead_out * gs],
    )
}
