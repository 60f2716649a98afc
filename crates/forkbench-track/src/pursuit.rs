//! Pure pursuit on the fork-root reference point, with fixed or speed-scaled look-ahead and a slow final approach.

use forkbench_core::units::wrap_angle;
use forkbench_core::{ForkliftSpec, Path, PathSample, Pose2, SettingsError};
use serde::{Deserialize, Serialize};

use crate::{Tracker, TrackerInput};

/// Tracker settings (SI units).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TrackerConfig {
    /// Fixed look-ahead distance (the B-spline paper's field test: 0.7 m).
    pub lookahead_m: f64,
    /// When set, look-ahead = gain · speed (l_d = K v), bounded below by `min_lookahead_m`.
    pub lookahead_gain_s: Option<f64>,
    pub min_lookahead_m: f64,
    /// Cruise speed (≤ the truck's max picking speed).
    pub cruise_speed_mps: f64,
    /// Speed for the last `approach_distance_m` before the goal (fork entry).
    pub approach_speed_mps: f64,
    pub approach_distance_m: f64,
    /// Deceleration used to plan the stop at the goal.
    pub decel_mps2: f64,
}

impl Default for TrackerConfig {
    fn default() -> Self {
        Self {
            lookahead_m: 0.7,
            lookahead_gain_s: None,
            min_lookahead_m: 0.3,
            cruise_speed_mps: 0.8,
            approach_speed_mps: 0.3,
            approach_distance_m: 2.0,
            decel_mps2: 0.4,
        }
    }
}

impl TrackerConfig {
    /// The first field that holds an impossible value, with the reason.
    pub fn validate(&self) -> Result<(), SettingsError> {
        let positive = [
            ("lookahead_m", self.lookahead_m),
            ("min_lookahead_m", self.min_lookahead_m),
            ("cruise_speed_mps", self.cruise_speed_mps),
            ("approach_speed_mps", self.approach_speed_mps),
            ("decel_mps2", self.decel_mps2),
        ];
        for (f, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return Err(SettingsError::field(f, "must be a positive finite number"));
            }
        }
        if !(self.approach_distance_m.is_finite() && self.approach_distance_m >= 0.0) {
            return Err(SettingsError::field(
                "approach_distance_m",
                "must be a finite number ≥ 0",
            ));
        }
        if let Some(k) = self.lookahead_gain_s
            && !(k.is_finite() && k > 0.0)
        {
            return Err(SettingsError::field(
                "lookahead_gain_s",
                "must be a positive finite number",
            ));
        }
        forkbench_core::settings::in_ranges(&[
            ("lookahead_m", self.lookahead_m, 0.0, 20.0),
            ("min_lookahead_m", self.min_lookahead_m, 0.0, 20.0),
            ("cruise_speed_mps", self.cruise_speed_mps, 0.0, 10.0),
            ("approach_speed_mps", self.approach_speed_mps, 0.0, 10.0),
            ("approach_distance_m", self.approach_distance_m, 0.0, 100.0),
            ("decel_mps2", self.decel_mps2, 0.0, 50.0),
            (
                "lookahead_gain_s",
                self.lookahead_gain_s.unwrap_or(1.0),
                0.0,
                20.0,
            ),
        ])
    }
}

/// One control output.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Command {
    pub speed_mps: f64,
    /// Equivalent steering angle (positive turns left), already within ±α_max.
    pub steer_rad: f64,
    pub lookahead_point: [f64; 2],
    /// Signed lateral offset of the reference point from the path (left positive).
    pub cross_track_m: f64,
    /// Arc length left to the goal.
    pub remaining_m: f64,
    /// Planned curvature at the closest path sample.
    pub path_curvature_per_m: f64,
    /// The goal is reached: stop.
    pub done: bool,
}

/// Pure pursuit along one path. Progress along the path only moves forward, so a path
/// that passes near itself cannot make the tracker jump.
///
/// The path is planned for the fork root, but pure pursuit's arc geometry holds for the
/// point that moves along its own heading: the front (fixed) axle. So the tracker steers
/// the front axle along the fork-root path shifted back by the root's offset; when the
/// axle is on its path with the path's heading, the fork root is on the planned path.
#[derive(Debug, Clone)]
pub struct PurePursuit {
    path: Path,
    cfg: TrackerConfig,
    idx: usize,
    root_ahead_m: f64,
    /// Straight-line distance summed from the first sample to each: no sample can be
    /// farther from another than the difference, which lets the searches skip samples.
    chord_m: Vec<f64>,
    /// Sine and cosine of the goal heading, asked for every tick.
    goal_sin_cos: (f64, f64),
}

/// Slack on the skip bounds, far above the rounding of the distances it compares.
const SKIP_MARGIN_M: f64 = 1e-9;

impl PurePursuit {
    /// `root_ahead_m`: how far the tracked (fork-root) point sits ahead of the front axle.
    pub fn new(root_path: Path, cfg: TrackerConfig, root_ahead_m: f64) -> Self {
        let mut path = root_path;
        for p in &mut path.samples {
            p.x_m -= root_ahead_m * p.heading_rad.cos();
            p.y_m -= root_ahead_m * p.heading_rad.sin();
            // Backwards, the truck is pursued as if it faced its direction of travel.
            if path.reverse {
                p.heading_rad = wrap_angle(p.heading_rad + std::f64::consts::PI);
            }
        }
        let mut chord_m = Vec::with_capacity(path.samples.len());
        let mut sum = 0.0;
        for (i, p) in path.samples.iter().enumerate() {
            if let Some(q) = i.checked_sub(1).map(|j| &path.samples[j]) {
                sum += (p.x_m - q.x_m).hypot(p.y_m - q.y_m);
            }
            chord_m.push(sum);
        }
        let goal_sin_cos = path
            .samples
            .last()
            .map_or((0.0, 1.0), |g| g.heading_rad.sin_cos());
        Self {
            path,
            cfg,
            idx: 0,
            root_ahead_m,
            chord_m,
            goal_sin_cos,
        }
    }

    /// The first sample in `from..to` past `from` whose summed chord exceeds `reach_m`
    /// (`to` when none does).
    fn first_beyond(&self, from: usize, to: usize, reach_m: f64) -> usize {
        // Galloping: most skips are short, and a bisection of the whole window would
        // cost more than the distances it saves.
        let (mut lo, mut step) = (from + 1, 1);
        while lo + step < to && self.chord_m[lo + step] <= reach_m {
            lo += step;
            step *= 2;
        }
        let hi = (lo + step).min(to);
        lo + self.chord_m[lo..hi].partition_point(|&c| c <= reach_m)
    }

    /// The sample closest to `pose` in the window of 400 samples from the last
    /// progress (the first of equals). A sample within summed chord `c` of one at
    /// distance `d` is at least `d − c` away, so those that cannot beat the best are
    /// skipped; the result is that of the full scan.
    fn closest(&self, pose: &Pose2) -> usize {
        let d2 = |i: usize| {
            let p = &self.path.samples[i];
            (p.x_m - pose.x_m).powi(2) + (p.y_m - pose.y_m).powi(2)
        };
        let window = (self.idx + 400).min(self.path.samples.len());
        let mut best = self.idx;
        let mut best_d2 = d2(best);
        let mut best_d = best_d2.sqrt();
        let mut i = self.idx + 1;
        while i < window {
            let di2 = d2(i);
            if di2 < best_d2 {
                best = i;
                best_d2 = di2;
                best_d = di2.sqrt();
            }
            // No closer than the best: nothing to skip, and no square roots to take.
            if di2 <= best_d2 {
                i += 1;
                continue;
            }
            let slack = di2.sqrt() - best_d - SKIP_MARGIN_M;
            i = if slack > 0.0 {
                self.first_beyond(i, window, self.chord_m[i] + slack)
            } else {
                i + 1
            };
        }
        best
    }

    /// The front-axle path being tracked.
    pub fn axle_path(&self) -> &Path {
        &self.path
    }

    /// A tracker with no path yet: [`Tracker::reset`] gives it one.
    pub fn with_config(cfg: TrackerConfig) -> Self {
        Self::new(Path::default(), cfg, 0.0)
    }

    /// Look-ahead distance at this speed.
    fn lookahead_m(&self, speed_mps: f64) -> f64 {
        match self.cfg.lookahead_gain_s {
            Some(k) => (k * speed_mps.abs()).max(self.cfg.min_lookahead_m),
            None => self.cfg.lookahead_m,
        }
    }

    /// Steering and speed for the (measured or predicted) fork-root pose.
    pub fn command(&mut self, root: &Pose2, speed_mps: f64, truck: &ForkliftSpec) -> Command {
        let ld = self.lookahead_m(speed_mps);
        let Some(g) = self.geometry(root, ld, truck) else {
            return stopped(root);
        };
        let cruise = self.cfg.cruise_speed_mps.min(truck.max_speed_mps);
        let mut speed = cruise;
        if g.remaining_m < self.cfg.approach_distance_m {
            speed = speed.min(self.cfg.approach_speed_mps);
        }
        let drive = DriveAnswer::of(truck, speed_mps);
        g.command(stop_profile(
            speed,
            self.cfg.decel_mps2,
            g.remaining_m,
            drive,
        ))
    }

    /// Where the path is, relative to the truck: closest sample, look-ahead point, the
    /// pursuit arc. `None` without a path.
    pub(crate) fn geometry(
        &mut self,
        root: &Pose2,
        ld: f64,
        truck: &ForkliftSpec,
    ) -> Option<Geometry> {
        let mut axle = root.to_world(&Pose2::new(-self.root_ahead_m, 0.0, 0.0));
        if self.path.reverse {
            axle.heading_rad = wrap_angle(axle.heading_rad + std::f64::consts::PI);
        }
        let pose = &axle;
        let last = self.path.samples.last().copied()?;
        // Closest sample, searched forward from the last progress over a bounded window.
        let best = self.closest(pose);
        self.idx = best;
        let near = self.path.samples[best];
        let (sn, cn) = near.heading_rad.sin_cos();
        let dx = pose.x_m - near.x_m;
        let dy = pose.y_m - near.y_m;
        let cross_track_m = -sn * dx + cn * dy;
        let along = cn * dx + sn * dy;
        // Distance to go, measured along the goal heading at the end so the stop is exact.
        let (gs, gc) = self.goal_sin_cos;
        let to_goal_along_heading = gc * (last.x_m - pose.x_m) + gs * (last.y_m - pose.y_m);
        let remaining_m = if self.path.length_m() - near.s_m < 0.5 {
            to_goal_along_heading
        } else {
            self.path.length_m() - near.s_m - along
        };
        let target = self.lookahead_point(pose, best, ld);
        let vx = target[0] - pose.x_m;
        let vy = target[1] - pose.y_m;
        let dist = vx.hypot(vy).max(1e-6);
        let eta = wrap_angle(vy.atan2(vx) - pose.heading_rad);
        let mut arc_curvature_per_m = 2.0 * eta.sin() / dist;
        // Facing backwards, a left turn of the travel direction is a right turn of the
        // truck's heading per metre of (negative) displacement.
        if self.path.reverse {
            arc_curvature_per_m = -arc_curvature_per_m;
        }
        let steer_rad = truck
            .steer_for_curvature(arc_curvature_per_m)
            .clamp(-truck.max_steer_rad, truck.max_steer_rad);
        Some(Geometry {
            target,
            cross_track_m,
            remaining_m,
            path_curvature_per_m: near.curvature_per_m,
            arc_curvature_per_m,
            steer_rad,
            reverse: self.path.reverse,
        })
    }

    /// Look-ahead point: the first sample from `from` at least `ld` away; past the end, a
    /// point on the goal heading's extension, which keeps the forks aligned with the pocket.
    fn lookahead_point(&self, pose: &Pose2, from: usize, ld: f64) -> [f64; 2] {
        let Some(last) = self.path.samples.last().copied() else {
            return [pose.x_m, pose.y_m];
        };
        let (gs, gc) = self.goal_sin_cos;
        if let Some(p) = self.first_at_least(pose, from, ld) {
            return [p.x_m, p.y_m];
        }
        let ext = ld.max(0.05);
        // Project onto the extension line at distance ld from the pose.
        let px = pose.x_m - last.x_m;
        let py = pose.y_m - last.y_m;
        let t_along = gc * px + gs * py;
        let lat = -gs * px + gc * py;
        let fwd = (ext * ext - lat * lat).max(0.0).sqrt();
        let t = t_along + fwd;
        [last.x_m + gc * t, last.y_m + gs * t]
    }
}

impl PurePursuit {
    /// The first sample from `from` at least `ld` from `pose`. A sample within summed
    /// chord `c` of one at distance `d` is at most `d + c` away, so those that cannot
    /// reach `ld` are skipped; the result is that of the full scan.
    fn first_at_least(&self, pose: &Pose2, from: usize, ld: f64) -> Option<PathSample> {
        let n = self.path.samples.len();
        let mut i = from;
        while i < n {
            let p = self.path.samples[i];
            let d2 = (p.x_m - pose.x_m).powi(2) + (p.y_m - pose.y_m).powi(2);
            if d2 >= ld * ld {
                return Some(p);
            }
            let slack = ld - d2.sqrt() - SKIP_MARGIN_M;
            i = if slack > 0.0 && i + 1 < n {
                self.first_beyond(i, n, self.chord_m[i] + slack)
            } else {
                i + 1
            };
        }
        None
    }
}

/// The pursuit geometry at one tick, before a speed is chosen.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Geometry {
    pub target: [f64; 2],
    pub cross_track_m: f64,
    pub remaining_m: f64,
    pub path_curvature_per_m: f64,
    /// Curvature of the arc through the look-ahead point.
    pub arc_curvature_per_m: f64,
    pub steer_rad: f64,
    /// The path is driven backwards: commands carry negative speeds.
    pub reverse: bool,
}

impl Geometry {
    /// The command at `speed_mps` (zero once the goal is reached).
    pub fn command(&self, speed_mps: f64) -> Command {
        let done = self.remaining_m <= 0.002;
        let sign = if self.reverse { -1.0 } else { 1.0 };
        Command {
            speed_mps: if done { 0.0 } else { sign * speed_mps },
            steer_rad: self.steer_rad,
            lookahead_point: self.target,
            cross_track_m: self.cross_track_m,
            remaining_m: self.remaining_m,
            path_curvature_per_m: self.path_curvature_per_m,
            done,
        }
    }
}

/// How the truck's drive answers a speed command, as a stop needs it: how far it runs on
/// after a zero command at its present speed (its dead time and bus, then its declared
/// speed loop's lag), and the slowest command that moves it (its creep threshold). A
/// truck that declares no speed loop is taken to answer at once, as the first truck did.
#[derive(Debug, Clone, Copy)]
pub(crate) struct DriveAnswer {
    run_on_m: f64,
    creep_mps: f64,
}

impl DriveAnswer {
    pub(crate) fn of(truck: &ForkliftSpec, speed_mps: f64) -> Self {
        let lag_s = truck.drive.time_constant_s.unwrap_or(0.0);
        Self {
            run_on_m: speed_mps.abs() * (truck.drive_delay_s() + lag_s),
            creep_mps: truck.drive.creep_speed_mps,
        }
    }
}

/// Stop at the goal: v ≤ √(2 a d), with a small floor (at least the drive's creep speed)
/// so the last millimetres close; `d` is the distance left less how far the truck runs
/// on, so its command falls to the floor where it will come to rest on the goal.
pub(crate) fn stop_profile(
    speed_mps: f64,
    decel_mps2: f64,
    remaining_m: f64,
    drive: DriveAnswer,
) -> f64 {
    let d = remaining_m - drive.run_on_m;
    speed_mps.min(
        (2.0 * decel_mps2 * d.max(0.0))
            .sqrt()
            .max(0.02)
            .max(drive.creep_mps),
    )
}

/// A moving command at least the drive's creep speed, so it moves the truck.
pub(crate) fn above_creep(speed_mps: f64, truck: &ForkliftSpec) -> f64 {
    let creep = truck.drive.creep_speed_mps;
    if speed_mps != 0.0 && speed_mps.abs() < creep {
        creep.copysign(speed_mps)
    } else {
        speed_mps
    }
}

/// The command without a path: stand still, done.
pub(crate) fn stopped(root: &Pose2) -> Command {
    Command {
        speed_mps: 0.0,
        steer_rad: 0.0,
        lookahead_point: [root.x_m, root.y_m],
        cross_track_m: 0.0,
        remaining_m: 0.0,
        path_curvature_per_m: 0.0,
        done: true,
    }
}

impl Tracker for PurePursuit {
    fn name(&self) -> &str {
        "pure_pursuit"
    }

    fn reset(&mut self, path: &Path, truck: &ForkliftSpec) {
        *self = Self::new(
            path.clone(),
            self.cfg.clone(),
            truck.fork_root_ahead_of_front_axle_m,
        );
    }

    fn command(&mut self, state: &TrackerInput) -> Command {
        PurePursuit::command(self, &state.pose, state.speed_mps, state.truck)
    }
}

#[cfg(test)]
mod tests;
