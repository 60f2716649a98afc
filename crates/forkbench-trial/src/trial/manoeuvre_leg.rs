//! Mission legs planned by Hybrid-A*: the manoeuvre's first segment driven (the wheel set before moving off, a stop at its end), then a new plan from where the truck stands, until the last segment is driven.

use std::time::Instant;

use forkbench_core::Signal;
use forkbench_nav::NavMap;
use forkbench_nav::hybrid::{HybridQuery, Manoeuvre, plan_hybrid_from_here};
use forkbench_track::SegmentFollower;

use super::mission::{DriveStats, REVERSE, SMOOTHED, path_points};
use super::state::Trial;
use crate::outcome::LegOutcome;
use crate::recorder::Recorder;
use crate::scenario::mission::{MissionSpec, Waypoint};
use crate::stage_error::LegError;

/// Most plans one leg makes (one per cusp reached, and the first).
const MAX_PLANS: u32 = 16;

impl Trial<'_> {
    /// Plans from where the truck stands to `to`, drives the first segment, and again from
    /// the cusp, until a plan's only segment is driven.
    pub(super) async fn manoeuvre_leg<R: Recorder + ?Sized>(
        &mut self,
        map: &NavMap,
        m: &MissionSpec,
        (i, to): (usize, &Waypoint),
        (leg, stats): (&mut LegOutcome, &mut DriveStats),
        rec: &mut R,
    ) -> Result<(), LegError> {
        for round in 0..MAX_PLANS {
            let here = self.sense(rec)?.1;
            let q = HybridQuery {
                start: here,
                goal: to.pose,
                truck: self.scn.truck.clone(),
                margin_m: m.global.margin_m,
                load: self.load(),
                params: m.global.hybrid,
                approach_m: m.global.approach_m,
            };
            let t0 = Instant::now();
            let planned = plan_hybrid_from_here(map, &q);
            leg.planning_time_s += t0.elapsed().as_secs_f64();
            leg.planning_attempts += 1;
            let (plan, _) = planned?;
            if round == 0 {
                leg.smoothing = "hybrid-astar".into();
                leg.planned_length_m = plan.length_m;
                leg.route_length_m = plan.length_m;
            }
            leg.min_clearance_m = leg.min_clearance_m.min(clearance(map, &q, &plan));
            record_manoeuvre(rec, self.world.sim.time_s(), i, &plan);
            let Some(first) = plan.segments.first() else {
                return Ok(());
            };
            if first.reverse {
                leg.reverse_length_m += first.length_m();
            }
            let mut follower =
                SegmentFollower::new(vec![first.clone()], m.tracker.clone(), &self.scn.truck);
            self.drive_with(|input| follower.command(input), m, &mut *stats, rec)
                .await?;
            if plan.segments.len() == 1 {
                return Ok(());
            }
        }
        Err(LegError::TooManyCusps { plans: MAX_PLANS })
    }
}

impl Trial<'_> {
    /// The pallet on the forks, as a footprint ahead of the fork root (`None` unloaded):
    /// a loaded truck plans round it.
    fn load(&self) -> Option<forkbench_geom::Footprint> {
        if !self.world.sim.carrying() {
            return None;
        }
        let at = self
            .world
            .sim
            .fork_root_pose()
            .to_local(&self.world.sim.pallet_pose());
        let pallet = &self.scn.pallet;
        Some(forkbench_geom::Footprint {
            length_m: pallet.depth_m,
            width_m: pallet.width_m,
            centre_ahead_m: at.x_m + pallet.depth_m / 2.0,
        })
    }
}

/// The truck's own footprint's least clearance along the manoeuvre.
fn clearance(map: &NavMap, q: &HybridQuery, plan: &Manoeuvre) -> f64 {
    let parts = forkbench_nav::truck_parts(&q.truck, 0.0);
    plan.segments
        .iter()
        .map(|p| forkbench_nav::smooth::min_clearance(&map.obstacles, &parts, p, 0.05, 1.0))
        .fold(f64::INFINITY, f64::min)
}

/// The plan (blue) and the segment about to be driven (blue forwards, purple backwards).
fn record_manoeuvre<R: Recorder + ?Sized>(rec: &mut R, t_s: f64, leg: usize, plan: &Manoeuvre) {
    let points = plan.polyline();
    rec.signal(
        t_s,
        &format!("nav/route/{leg}"),
        &Signal::Path(&points),
        SMOOTHED,
    );
    if let Some(seg) = plan.segments.first() {
        let style = if seg.reverse { REVERSE } else { SMOOTHED };
        rec.signal(
            t_s,
            &format!("nav/route/{leg}/driving"),
            &Signal::Path(&path_points(seg)),
            style.width(0.09),
        );
    }
}
