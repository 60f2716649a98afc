//! The running trial as the host a phase drives: its physics, the scenario's pick planner and tracker, the one drive loop and the mission's legs.

use forkbench_core::{ForkliftSpec, PalletSpec, Path, Pose2};
use forkbench_geom::Footprint;
use forkbench_nav::NavMap;
use forkbench_plan::Plan;
use forkbench_sim::Sim;
use forkbench_track::Command;

use crate::outcome::Failure;
use crate::phase::{DriveRun, Failed, LegRun, PhaseHost, Steer};
use crate::recorder::Recorder;
use crate::scenario::mission::Waypoint;
use crate::stage_error::StageError;
use crate::tolerances::Limits;
use crate::trial::state::Trial;

impl Trial<'_> {
    /// The truth now, as a step criterion sees it.
    pub(super) fn step_view(&self) -> crate::step_criteria::StepView<'_> {
        let sim = &self.world.sim;
        crate::step_criteria::StepView {
            t_s: sim.time_s(),
            truck: &self.scn.truck,
            pallet: &self.scn.pallet,
            fork_root: sim.fork_root_pose(),
            pallet_pose: sim.pallet_pose(),
            collision: self.world.collision,
            load: crate::step_criteria::LoadView::of(sim),
        }
    }

    /// What the running phase recorded with `record_measure`, handed over and cleared.
    pub(super) fn take_phase_measures(&mut self) -> std::collections::BTreeMap<String, f64> {
        std::mem::take(&mut self.verdict.phase_measures)
    }
}

impl<'a> PhaseHost for Trial<'a> {
    fn sim(&self) -> &Sim {
        &self.world.sim
    }

    fn sim_mut(&mut self) -> &mut Sim {
        &mut self.world.sim
    }

    fn truck(&self) -> &ForkliftSpec {
        &self.scn.truck
    }

    fn pallet(&self) -> &PalletSpec {
        &self.scn.pallet
    }

    fn insertion_m(&self) -> f64 {
        self.insertion_m
    }

    fn step_view(&self) -> crate::step_criteria::StepView<'_> {
        Trial::step_view(self)
    }

    fn tolerances(&self) -> &Limits {
        &self.scn.tolerances
    }

    fn record_measure(&mut self, name: &str, value: f64) {
        self.verdict.phase_measures.insert(name.to_owned(), value);
    }

    fn stands(&self) -> bool {
        Trial::stands(self)
    }

    fn drive_under<'s>(
        &'s mut self,
        limit_s: f64,
        rec: &'s mut dyn Recorder,
        command: &'s mut Steer<'_>,
    ) -> DriveRun<'s> {
        Box::pin(self.drive_phase(limit_s, rec, command))
    }

    fn sense(&mut self, rec: &mut dyn Recorder) -> Result<Pose2, StageError> {
        Trial::sense(self, rec).map(|(_, pose)| pose)
    }

    fn plan_to_face(
        &mut self,
        pose: Pose2,
        curvature: f64,
        face: &Pose2,
    ) -> Result<Plan, StageError> {
        self.plan_from(pose, curvature, face)
    }

    fn clash(&self, path: &Path) -> Option<StageError> {
        Trial::clash(self, path)
    }

    fn replans(&self) -> u32 {
        self.verdict.out.replans
    }

    fn follow(&mut self, path: Path) {
        self.tracker.reset(&path, &self.scn.truck);
        self.set_path(path);
    }

    fn tracker_command(&mut self, pose: Pose2) -> Result<Command, StageError> {
        Trial::tracker_command(self, pose)
    }

    fn clearance_m(&self, footprint: &Footprint, at: &Pose2, max_m: f64) -> f64 {
        let (obstacles, _) = &self.world.footprints;
        obstacles.clearance(footprint, at, max_m)
    }

    fn drive_leg<'s>(
        &'s mut self,
        (name, pose): (&'s str, Pose2),
        rec: &'s mut dyn Recorder,
    ) -> LegRun<'s> {
        Box::pin(async move {
            let scn = self.scn;
            let m = scn
                .mission
                .as_ref()
                .ok_or_else(|| Failed::new(Failure::Error, "no [mission]"))?;
            let map = NavMap::shared_from_world(&self.world.obstacles, m.global.resolution_m)
                .map_err(|e| Failed::new(Failure::Error, e.to_string()))?;
            let here = Waypoint {
                name: "here".to_owned(),
                pose: self.world.sim.fork_root_pose(),
            };
            let to = Waypoint {
                name: name.to_owned(),
                pose,
            };
            // Numbered after the mission's legs and the cycle's earlier ones (its seed and
            // recorded route are its own); a leg after the first backs out of where it
            // starts, as from a station.
            let number = m.via.len() + 1 + self.verdict.out.phases.len();
            Ok(self.leg(&map, m, (number, &here, &to), rec).await)
        })
    }
}
