//! Plan stage: a request to the planner for the current estimate, the straight entry added, the swept body checked.

use forkbench_core::{Path, Pose2};
use forkbench_plan::{Plan, PlanRequest};

use super::error::StageError;
use super::setup::Trial;
use super::{APPROACH_GAP_M, goal_for};
use crate::outcome::Failure;
use crate::recorder::{Level, Recorder};
use crate::scenario::truck_footprint;

/// Arc-length spacing of the footprint checks along a plan (its samples are 1 cm apart):
/// between two checks the fork root moves 2 cm and a body corner a few cm more in a turn,
/// far below the racks' and walls' thickness.
const PATH_CHECK_STEP_M: f64 = 0.02;

impl Trial<'_> {
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
        let mut req = PlanRequest::new(pose, goal_for(est, truck, -APPROACH_GAP_M));
        req.truck = truck.clone();
        req.start_curvature_per_m = curvature;
        req.obstacles = self.obstacles.clone();
        req.seed = self.run.seed;
        let mut plan = self.planner.plan(&req)?;
        plan.path
            .extend_straight(APPROACH_GAP_M + self.insertion_m, 0.01);
        Ok(plan)
    }

    /// Why the truck body swept along `path` would hit a rack or wall (the footprint
    /// checker the corridor analysis uses), if it would and paths are validated.
    pub(super) fn clash(&self, path: &Path) -> Option<StageError> {
        if !self.scn.validate_paths {
            return None;
        }
        let (obstacles, labels) = &self.footprints;
        let body = truck_footprint(&self.scn.truck);
        obstacles
            .first_hit_along(&body, path, PATH_CHECK_STEP_M)
            .map(|h| StageError::Clash {
                obstacle: labels[h.obstacle].clone(),
                s_m: h.s_m,
            })
    }

    /// The first plan, from the first fix to the first estimate; its path to drive.
    pub(super) fn first_plan<R: Recorder + ?Sized>(
        &mut self,
        rec: &mut R,
    ) -> Result<Path, (Failure, String)> {
        let est = self.pallet_est;
        let t = self.sim.time_s();
        let plan = self.plan_from(self.first_fix, 0.0, &est).map_err(|e| {
            rec.event(t, Level::Error, &format!("planning failed: {e}"));
            (Failure::PlanFailed, e.to_string())
        })?;
        rec.plan(t, 0, &plan.path, plan.control_polygon_m.as_deref());
        self.out.path_length_m = plan.path.length_m();
        if let Some(why) = self.clash(&plan.path) {
            let why = why.to_string();
            rec.event(t, Level::Error, &why);
            return Err((Failure::PlanFailed, why));
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
