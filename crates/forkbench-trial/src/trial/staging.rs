//! The pick as a docking server runs it when the first look finds no pallet: drive (Hybrid-A*, forwards and backwards) to a staging pose before the prior face, and look there again, waiting or backing away between looks, before giving up.

use forkbench_core::Pose2;
use forkbench_core::geometry::Obstacle;
use forkbench_geom::Obstacles;
use forkbench_nav::{GlobalPlannerKind, NavMap, OccupancyGrid};
use forkbench_track::SegmentFollower;

use super::mission::DriveStats;
use super::state::Trial;
use crate::outcome::Failure;
use crate::phase::Failed;
use crate::recorder::{Level, Recorder};
use crate::scenario::mission::{GlobalFile, MissionSpec, Waypoint, mission_tracker};
use crate::scenario::{BetweenLooks, WhenNotSeen};
use crate::stage_error::StageError;

/// Cell of the staging leg's map.
const RESOLUTION_M: f64 = 0.1;
/// Floor around the start and the staging pose the leg may use on an open floor.
const ROOM_M: f64 = 8.0;
/// The pallet is planned round grown by this (its placement is uncertain).
const PALLET_GROWTH_M: f64 = 0.2;

impl Trial<'_> {
    /// When the first look found nothing: the scenario's policy. `Ok` with the pallet
    /// found (the truck at the staging pose, the estimate and first fix taken there).
    pub(super) async fn stage_and_look<R: Recorder + ?Sized>(
        &mut self,
        rec: &mut R,
    ) -> Result<(), Failed> {
        let pick = self.scn.pick.clone();
        match pick.when_not_seen {
            WhenNotSeen::Fail => {
                return Err(Failed::new(
                    Failure::PalletNotFound,
                    "the pallet sensing found no pallet from the start pose ([pick] when_not_seen = \"fail\")",
                ));
            }
            WhenNotSeen::Prior => {
                rec.event(
                    self.world.sim.time_s(),
                    Level::Warn,
                    "no pallet seen from the start: planning on the prior, looking at every frame",
                );
                self.aim_at_prior();
                return Ok(());
            }
            WhenNotSeen::Stage => {}
        }
        let staging =
            self.world
                .pallet_nominal
                .to_world(&Pose2::new(-pick.staging_distance_m, 0.0, 0.0));
        rec.event(
            self.world.sim.time_s(),
            Level::Warn,
            &format!(
                "no pallet seen from the start: staging at ({:.2}, {:.2}) m, {:.1}°, {:.1} m before the expected face",
                staging.x_m,
                staging.y_m,
                staging.heading_rad.to_degrees(),
                pick.staging_distance_m
            ),
        );
        self.enter(super::link::Stage::Staging);
        self.staging_leg(staging, rec)
            .await
            .map_err(|why| Failed::new(Failure::StagingUnreachable, why))?;
        let truth = self.world.sim.pallet_pose();
        for look in 1..=pick.looks {
            if look > 1 {
                self.between_looks(pick.between_looks, &pick, rec).await?;
            }
            let missed = self.verdict.out.estimates_missed;
            self.first_fix_and_estimate(&truth, rec)?;
            let found = self.verdict.out.estimates_missed == missed;
            rec.event(
                self.world.sim.time_s(),
                if found { Level::Info } else { Level::Warn },
                &format!(
                    "look {look} of {} from the staging pose: {}",
                    pick.looks,
                    if found { "pallet found" } else { "no pallet" }
                ),
            );
            if found {
                return Ok(());
            }
        }
        Err(Failed::new(
            Failure::PalletNotFound,
            format!(
                "no pallet from the start pose, nor in {} looks from the staging pose {:.1} m before the expected face",
                pick.looks, pick.staging_distance_m
            ),
        ))
    }

    /// Drives to `staging` as a mission leg planned by Hybrid-A*, round the racks, the
    /// walls and the pallet where it should stand. Err: why it was not reached.
    async fn staging_leg<R: Recorder + ?Sized>(
        &mut self,
        staging: Pose2,
        rec: &mut R,
    ) -> Result<(), String> {
        let here = self.world.sim.fork_root_pose();
        let map = self
            .staging_map(&here, &staging)
            .map_err(|e| e.to_string())?;
        let m = self.staging_mission(here);
        let to = Waypoint {
            name: "staging".into(),
            pose: staging,
        };
        let i = self.verdict.out.legs.len();
        let leg = self.leg(&map, &m, (i, &m.start, &to), rec).await;
        let (ok, why) = self.record_leg(leg, rec);
        if ok {
            Ok(())
        } else {
            Err(format!(
                "the staging pose was not reached: {}",
                why.unwrap_or_default()
            ))
        }
    }

    /// The world's racks and walls and the pallet (grown), on a floor that spans them,
    /// the truck and the staging pose with room to manoeuvre.
    fn staging_map(&self, here: &Pose2, staging: &Pose2) -> Result<NavMap, StageError> {
        let p = &self.scn.pallet;
        let mut obstacles = self.world.obstacles.clone();
        obstacles.push(Obstacle {
            centre: self
                .world
                .pallet_nominal
                .to_world(&Pose2::new(p.depth_m / 2.0, 0.0, 0.0)),
            length_m: p.depth_m + 2.0 * PALLET_GROWTH_M,
            width_m: p.width_m + 2.0 * PALLET_GROWTH_M,
        });
        let mut extra = Vec::new();
        for c in [here, staging] {
            for (dx, dy) in [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)] {
                extra.push([c.x_m + dx * ROOM_M, c.y_m + dy * ROOM_M]);
            }
        }
        let grid = OccupancyGrid::from_obstacles(&obstacles, &extra, RESOLUTION_M, 0.0)?;
        let mut shapes = Obstacles::new();
        for o in &obstacles {
            shapes.add_rect(&o.centre, o.length_m, o.width_m);
        }
        Ok(NavMap::new(grid, shapes))
    }

    /// The leg's settings: the mission's tracker and Hybrid-A* settings where the scenario
    /// has a mission, the defaults otherwise; Hybrid-A* always (the truck may face away).
    fn staging_mission(&self, here: Pose2) -> MissionSpec {
        let (global, tracker) = match &self.scn.mission {
            Some(m) => (m.global.clone(), m.tracker.clone()),
            None => (GlobalFile::default(), mission_tracker()),
        };
        MissionSpec {
            start: Waypoint {
                name: "pick start".into(),
                pose: here,
            },
            via: vec![],
            backout_m: 0.0,
            arrive_tolerance_m: 0.5,
            arrive_tolerance_rad: 15f64.to_radians(),
            leg_timeout_s: 180.0,
            global: GlobalFile {
                planner: GlobalPlannerKind::HybridAstar,
                approach_m: 1.0,
                ..global
            },
            tracker,
        }
    }

    /// Between two looks: stand `retry_wait_s`, or back `retry_step_m` straight away
    /// from the pallet.
    async fn between_looks<R: Recorder + ?Sized>(
        &mut self,
        how: BetweenLooks,
        pick: &crate::scenario::PickFile,
        rec: &mut R,
    ) -> Result<(), StageError> {
        let here = self.world.sim.fork_root_pose();
        let m = self.staging_mission(here);
        let mut stats = DriveStats::default();
        let result = match how {
            BetweenLooks::Wait => {
                let until_s = self.world.sim.time_s() + pick.retry_wait_s;
                let stand = |input: &forkbench_track::TrackerInput| forkbench_track::Command {
                    speed_mps: 0.0,
                    steer_rad: input.steer_rad,
                    lookahead_point: [input.pose.x_m, input.pose.y_m],
                    cross_track_m: 0.0,
                    remaining_m: 0.0,
                    path_curvature_per_m: 0.0,
                    done: input.t_s >= until_s,
                };
                self.drive_with(stand, &m, &mut stats, rec).await
            }
            BetweenLooks::Move => {
                let back = here.to_world(&Pose2::new(-pick.retry_step_m, 0.0, 0.0));
                let seg = forkbench_core::Path::straight(&back, pick.retry_step_m, 0.02)
                    .driven_backwards();
                let mut f = SegmentFollower::new(vec![seg], m.tracker.clone(), &self.scn.truck);
                self.drive_with(|input| f.command(input), &m, &mut stats, rec)
                    .await
            }
        };
        result.map_err(|e| StageError::Leg {
            number: self.verdict.out.legs.len(),
            name: "between looks".into(),
            detail: e.to_string(),
        })?;
        Ok(())
    }
}
