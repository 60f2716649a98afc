//! Plan stage: a request to the planner for the current estimate, the straight entry added, the swept body checked.

use forkbench_core::{Path, Pose2};
use forkbench_plan::{Plan, PlanRequest};

use super::goal_for;
use super::state::Trial;
use crate::outcome::Failure;
use crate::phase::Failed;
use crate::recorder::{Level, Recorder};
use crate::scenario::{ReplanMethod, truck_footprint};
use crate::stage_error::StageError;

/// Arc-length spacing of the footprint checks along a plan (its samples are 1 cm apart):
/// between two checks the fork root moves 2 cm and a body corner a few cm more in a turn,
/// far below the racks' and walls' thickness.
const PATH_CHECK_STEP_M: f64 = 0.02;

/// A replan's path and the control polygon its recording draws.
pub(super) type Replanned = (Path, Option<Vec<[f64; 2]>>);

/// A deformed path has taken the whole correction this far before the pre-entry pose,
/// so the tracker settles on the corrected line before the forks reach the face.
const BLEND_BEFORE_M: f64 = 0.5;
/// The shortest stretch a correction is blended in over.
const BLEND_MIN_M: f64 = 0.5;

impl Trial<'_> {
    /// Follows `path` from now on (the first plan, a replan, a phase's plan).
    pub(super) fn set_path(&mut self, path: forkbench_core::Path) {
        self.path = path;
        self.path_version += 1;
    }

    /// Plans from `pose` (path curvature `curvature`) to the pre-entry pose of `est`. The
    /// planner's curve ends aligned with the pockets, tips just short of the face (the
    /// papers' P_dest); the forks then go in straight to the target depth.
    pub(super) fn plan_from(
        &mut self,
        pose: Pose2,
        curvature: f64,
        est: &Pose2,
    ) -> Result<Plan, StageError> {
        let truck = &self.scn.truck;
        let mut req = PlanRequest::new(pose, goal_for(est, truck, -self.scn.pick.pre_entry_gap_m));
        req.truck = truck.clone();
        req.start_curvature_per_m = curvature;
        req.obstacles = self.world.obstacles.clone();
        req.seed = self.run.seed;
        let stage = forkbench_core::profile::Stage::Plan;
        let mut plan = forkbench_core::profile::timed(stage, || self.planner.plan(&req))?;
        plan.path
            .extend_straight(self.scn.pick.pre_entry_gap_m + self.insertion_m, 0.01);
        Ok(plan)
    }

    /// The path after a new estimate `est`, as the scenario's `[replan] method` says:
    /// the remaining path deformed onto it, or (and where the deformed path would exceed
    /// κ_max or touch a rack) a new plan from the truck's pose and steering. Deforming
    /// keeps the reference the tracker follows continuous and its shape the planner's: a
    /// fresh plan from the truck's own (noisy, swinging) pose over the few metres left
    /// asked the tracker for an S-curve it could not settle before the face.
    /// Returns the path and the control polygon to draw (a plan's, none for a deformed path).
    pub(super) fn replanned(&mut self, pose: &Pose2, est: &Pose2) -> Result<Replanned, StageError> {
        if self.scn.replan.method == ReplanMethod::Deform {
            let from = nearest_s(&self.path, pose);
            let s_end = self.path.length_m()
                - self.scn.pick.pre_entry_gap_m
                - self.insertion_m
                - BLEND_BEFORE_M;
            let path = deformed(
                &self.path,
                from,
                s_end.max(from + BLEND_MIN_M),
                (&self.sense.pallet_est, est),
            );
            let kappa_max = self.scn.truck.max_curvature_per_m();
            let within = path
                .samples
                .iter()
                .all(|p| p.curvature_per_m.abs() <= kappa_max);
            if within && self.clash(&path).is_none() {
                return Ok((path, None));
            }
        }
        let k0 = self.world.sim.steer_rad().tan() / self.scn.truck.wheelbase_m;
        let plan = self.plan_from(*pose, k0, est)?;
        match self.clash(&plan.path) {
            Some(why) => Err(why),
            None => Ok((plan.path, plan.control_polygon_m)),
        }
    }

    /// Why the truck body swept along `path` would hit a rack or wall (the footprint
    /// checker the corridor analysis uses), if it would and paths are validated.
    pub(super) fn clash(&self, path: &Path) -> Option<StageError> {
        if !self.scn.validate_paths {
            return None;
        }
        let (obstacles, labels) = &self.world.footprints;
        let body = truck_footprint(&self.scn.truck);
        obstacles
            .first_hit_along(&body, path, PATH_CHECK_STEP_M)
            .map(|h| StageError::Clash {
                obstacle: labels[h.obstacle].clone(),
                s_m: h.s_m,
            })
    }

    /// The first plan, from the first fix to the first estimate; its path to drive.
    pub(super) fn first_plan<R: Recorder + ?Sized>(&mut self, rec: &mut R) -> Result<Path, Failed> {
        let est = self.sense.pallet_est;
        let t = self.world.sim.time_s();
        let plan = self.plan_from(self.loc.first_fix, 0.0, &est).map_err(|e| {
            rec.event(t, Level::Error, &format!("planning failed: {e}"));
            Failed::stage(Failure::PlanFailed, e)
        })?;
        rec.plan(t, 0, &plan.path, plan.control_polygon_m.as_deref());
        self.verdict.out.path_length_m = plan.path.length_m();
        if let Some(why) = self.clash(&plan.path) {
            let why = why.to_string();
            rec.event(t, Level::Error, &why);
            return Err(Failed::new(Failure::PlanFailed, why));
        }
        rec.event(
            t,
            Level::Info,
            &format!(
                "{} plan: {:.3} m to the pre-entry pose",
                self.run.planner.name,
                plan.path.length_m()
            ),
        );
        Ok(plan.path)
    }
}

/// Arc length of the path sample nearest `pose`.
fn nearest_s(path: &Path, pose: &Pose2) -> f64 {
    path.samples
        .iter()
        .min_by(|a, b| {
            let d = |s: &forkbench_core::PathSample| (s.x_m - pose.x_m).hypot(s.y_m - pose.y_m);
            d(a).total_cmp(&d(b))
        })
        .map_or(0.0, |s| s.s_m)
}

/// The path deformed onto a moved estimate: each sample past `s_from` is moved by the
/// rigid motion that carries the old estimate onto the new one, weighted by a smoothstep
/// from 0 at `s_from` to 1 at `s_end` and beyond; headings and curvatures are recomputed
/// from the moved positions.
fn deformed(path: &Path, s_from: f64, s_end: f64, (old, new): (&Pose2, &Pose2)) -> Path {
    let mut pts: Vec<(f64, f64)> = Vec::with_capacity(path.samples.len());
    for p in &path.samples {
        let t = ((p.s_m - s_from) / (s_end - s_from)).clamp(0.0, 1.0);
        let w = t * t * (3.0 - 2.0 * t);
        let moved = new.to_world(&old.to_local(&p.pose()));
        pts.push((
            p.x_m + w * (moved.x_m - p.x_m),
            p.y_m + w * (moved.y_m - p.y_m),
        ));
    }
    let mut out = path.clone();
    let n = pts.len();
    let mut s_acc = path.samples.first().map_or(0.0, |p| p.s_m);
    let mut prev_h = path.samples.first().map_or(0.0, |p| p.heading_rad);
    for i in 0..n {
        let (a, b) = (pts[i.saturating_sub(1)], pts[(i + 1).min(n - 1)]);
        let raw = (b.1 - a.1).atan2(b.0 - a.0);
        let h = prev_h + forkbench_core::units::wrap_angle(raw - prev_h);
        if i > 0 {
            s_acc += (pts[i].0 - pts[i - 1].0).hypot(pts[i].1 - pts[i - 1].1);
        }
        let smp = &mut out.samples[i];
        if smp.s_m > s_from {
            smp.x_m = pts[i].0;
            smp.y_m = pts[i].1;
            smp.heading_rad = h;
        }
        smp.s_m = s_acc;
        prev_h = smp.heading_rad;
    }
    for i in 1..n {
        let ds = out.samples[i].s_m - out.samples[i - 1].s_m;
        if out.samples[i].s_m > s_from && ds > 0.0 {
            out.samples[i].curvature_per_m =
                (out.samples[i].heading_rad - out.samples[i - 1].heading_rad) / ds;
        }
    }
    out
}
