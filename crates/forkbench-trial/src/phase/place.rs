//! The place phase: the truck carries the pallet into a drop slot along a pick planner's path, lowers it, and backs the forks out; judged on where the pallet stands against the slot.

use forkbench_core::SettingsError;
use forkbench_core::units::wrap_angle;
use forkbench_core::{Pose2, Signal, Style};
use serde::{Deserialize, Serialize};

use super::reverse_out::back_straight;
use super::{
    Context, Failed, Phase, PhaseHost, PhaseRun, criteria, positive_at_most, settings, stand_for,
};
use crate::footprints::pallet_footprint;
use crate::outcome::Failure;
use crate::recorder::{Level, Recorder};
use crate::stage_error::StageError;

/// The slot's outline in recordings: cyan, so the placed (orange) pallet reads against it.
const SLOT: Style = Style {
    rgba: Some([0, 210, 230, 255]),
    width_m: Some(0.03),
};

/// `[phase.place]`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub(super) struct PlaceFile {
    /// The world's pallet slot to place at (required).
    slot: Option<String>,
    /// How far the placed pallet's face centre may stand from the slot's.
    position_m: f64,
    /// How far its heading may differ from the slot's.
    heading_deg: f64,
    /// How far short of the slot the truck aims the pallet's face, leaving room behind
    /// it for the forks' tips and the truck's overshoot.
    stop_short_m: f64,
    /// Time the mast takes to set the pallet down; the truck stands.
    lower_time_s: f64,
    /// How far the forks back out of the placed pallet.
    retract_m: f64,
    /// Time allowed to drive to the slot and stand.
    timeout_s: f64,
}

impl Default for PlaceFile {
    fn default() -> Self {
        Self {
            slot: None,
            position_m: 0.05,
            heading_deg: 2.0,
            stop_short_m: 0.0,
            lower_time_s: 2.0,
            retract_m: 2.1,
            timeout_s: 120.0,
        }
    }
}

/// A resolved place: the slot's pose and the settings.
#[derive(Debug)]
struct Place {
    slot: String,
    at: Pose2,
    cfg: PlaceFile,
}

pub(super) fn build(
    table: &toml::Table,
    cx: &dyn Context,
) -> Result<Box<dyn Phase>, SettingsError> {
    let cfg: PlaceFile = settings(table)?;
    positive_at_most(&[
        ("position_m", cfg.position_m, 10.0),
        ("heading_deg", cfg.heading_deg, 180.0),
        ("lower_time_s", cfg.lower_time_s, 60.0),
        ("retract_m", cfg.retract_m, 50.0),
        ("timeout_s", cfg.timeout_s, 600.0),
    ])?;
    if !(cfg.stop_short_m.is_finite() && (0.0..=1.0).contains(&cfg.stop_short_m)) {
        return Err(SettingsError::field(
            "stop_short_m",
            format!("must lie in 0–1 m (got {})", cfg.stop_short_m),
        ));
    }
    let slot = cfg
        .slot
        .clone()
        .ok_or_else(|| SettingsError::field("slot", "name the world's pallet slot to place at"))?;
    let at = slot_pose(cx, &slot)?;
    if let Some(what) = cx.pallet_overlaps(&at) {
        return Err(SettingsError::field(
            "slot",
            format!("{slot:?}: a pallet there overlaps {what}"),
        ));
    }
    Ok(Box::new(Place { slot, at, cfg }))
}

/// The pose of the world's slot `name` (its face centre, heading into the rack).
fn slot_pose(cx: &dyn Context, name: &str) -> Result<Pose2, SettingsError> {
    cx.slot_pose(name).ok_or_else(|| {
        let known = cx.slot_names();
        SettingsError::field(
            "slot",
            format!(
                "{name:?}: the world has no such slot (slots: {})",
                known.join(", ")
            ),
        )
    })
}

impl Phase for Place {
    fn run<'t>(&'t self, t: &'t mut dyn PhaseHost, rec: &'t mut dyn Recorder) -> PhaseRun<'t> {
        Box::pin(async move {
            if !t.sim().carrying() {
                return Err((Failure::Error, "nothing on the forks to place".into()));
            }
            self.approach(t, rec).await?;
            t.sim_mut().lower();
            stand_for(t, self.cfg.lower_time_s, rec).await?;
            let placed = t.sim().pallet_pose();
            let off = self.measure(t, &placed);
            back_straight(t, (self.cfg.retract_m, 0.5, 30.0), rec).await?;
            self.placement(off)?;
            criteria::pallet_stayed(t, &placed)
        })
    }
}

impl Place {
    /// Plans to the fork-root pose that sets the carried pallet's face on the slot (as
    /// if picking a pallet standing there) and drives it with the scenario's tracker.
    async fn approach(&self, t: &mut dyn PhaseHost, rec: &mut dyn Recorder) -> Result<(), Failed> {
        let truck = t.truck().clone();
        let root_on_pallet = t.sim().pallet_pose().to_local(&t.sim().fork_root_pose());
        let aim = self
            .at
            .to_world(&Pose2::new(-self.cfg.stop_short_m, 0.0, 0.0));
        let root_goal = aim.to_world(&root_on_pallet);
        // The face a pick would aim at to end with the fork root at `root_goal`.
        let face = root_goal.to_world(&Pose2::new(truck.fork_length_m - t.insertion_m(), 0.0, 0.0));
        let pose = t.sense(rec).map_err(|e| (Failure::Error, e.to_string()))?;
        let k0 = t.sim().steer_rad().tan() / truck.wheelbase_m;
        let time = t.sim().time_s();
        let refused = |why: StageError| {
            (
                Failure::PlanFailed,
                format!("to slot {:?}: {why}", self.slot),
            )
        };
        let plan = t.plan_to_face(pose, k0, &face).map_err(refused)?;
        if let Some(why) = t.clash(&plan.path) {
            return Err(refused(why));
        }
        rec.plan(
            time,
            t.replans() + 1,
            &plan.path,
            plan.control_polygon_m.as_deref(),
        );
        let corners = pallet_footprint(t.pallet()).corners(&self.at);
        let outline: Vec<[f64; 2]> = corners.iter().chain(&corners[..1]).copied().collect();
        rec.signal(time, "place/slot", &Signal::Path(&outline), SLOT);
        rec.event(
            time,
            Level::Info,
            &format!(
                "place plan: {:.3} m to slot {}",
                plan.path.length_m(),
                self.slot
            ),
        );
        t.follow(plan.path);
        let timeout_s = self.cfg.timeout_s;
        let arrived = t
            .drive_under(timeout_s, rec, &mut |t, pose| {
                let cmd = t
                    .tracker_command(pose)
                    .map_err(|e| (Failure::Error, e.to_string()))?;
                Ok((!(cmd.done && t.stands())).then_some(cmd))
            })
            .await?;
        if arrived {
            Ok(())
        } else {
            Err((
                Failure::Timeout,
                format!("not stopped at slot {:?} after {timeout_s} s", self.slot),
            ))
        }
    }

    /// The placed pallet against the slot (recorded, and returned as its distance and
    /// heading off it), and the room left around it.
    fn measure(&self, t: &mut dyn PhaseHost, placed: &Pose2) -> (f64, f64) {
        let clearance = t.clearance_m(&pallet_footprint(t.pallet()), placed, 1.0);
        let off = (
            placed.distance_to(&self.at),
            wrap_angle(placed.heading_rad - self.at.heading_rad),
        );
        t.record_measure("position_error_m", off.0);
        t.record_measure("heading_error_rad", off.1);
        t.record_measure("clearance_m", clearance);
        off
    }

    /// The pallet set down within the place tolerances of its slot (`(d, h)`: its
    /// distance and heading off it).
    fn placement(&self, (d, h): (f64, f64)) -> Result<(), Failed> {
        if d > self.cfg.position_m || h.abs() > self.cfg.heading_deg.to_radians() {
            return Err((
                Failure::PlacementError,
                format!(
                    "placed {d:.3} m and {:.2}° off slot {:?} (limits {} m, {}°)",
                    h.to_degrees(),
                    self.slot,
                    self.cfg.position_m,
                    self.cfg.heading_deg
                ),
            ));
        }
        Ok(())
    }
}
