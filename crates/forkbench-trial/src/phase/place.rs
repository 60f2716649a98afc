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
use crate::step_criteria::{StepCriterion, StepView};

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
                return Err(Failed::new(Failure::Error, "nothing on the forks to place"));
            }
            self.approach(t, rec).await?;
            t.sim_mut().lower();
            stand_for(t, self.cfg.lower_time_s, rec).await?;
            let placed = t.sim().pallet_pose();
            // Measured and judged where the pallet was set down, before the forks pull
            // out of it.
            let mut on_slot = self.on_slot();
            on_slot.observe(&t.step_view());
            Self::measure(t, &placed, &on_slot);
            back_straight(t, (self.cfg.retract_m, 0.5, 30.0), rec).await?;
            criteria::held(&on_slot)?;
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
        let pose = t.sense(rec)?;
        let k0 = t.sim().steer_rad().tan() / truck.wheelbase_m;
        let time = t.sim().time_s();
        let refused = |why: StageError| {
            Failed::new(
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
                let cmd = t.tracker_command(pose)?;
                Ok((!(cmd.done && t.stands())).then_some(cmd))
            })
            .await?;
        if arrived {
            Ok(())
        } else {
            Err(Failed::new(
                Failure::Timeout,
                format!("not stopped at slot {:?} after {timeout_s} s", self.slot),
            ))
        }
    }

    /// The placed pallet against the slot (as `on_slot` measured it), recorded, and the
    /// room left around it.
    fn measure(t: &mut dyn PhaseHost, placed: &Pose2, on_slot: &PlacedOnSlot) {
        let clearance = t.clearance_m(&pallet_footprint(t.pallet()), placed, 1.0);
        if let Some((d, h)) = on_slot.off() {
            t.record_measure("position_error_m", d);
            t.record_measure("heading_error_rad", h);
        }
        t.record_measure("clearance_m", clearance);
    }

    /// The criterion the set-down pallet is judged by: its slot and the place tolerances.
    fn on_slot(&self) -> PlacedOnSlot {
        PlacedOnSlot {
            slot: self.slot.clone(),
            at: self.at,
            limits: (self.cfg.position_m, self.cfg.heading_deg),
            placed: None,
        }
    }
}

/// The pallet set down within the place tolerances of its slot: its distance and heading
/// off the slot, where it was set down.
#[derive(Debug)]
struct PlacedOnSlot {
    slot: String,
    at: Pose2,
    /// Position (m) and heading (°) tolerances.
    limits: (f64, f64),
    placed: Option<Pose2>,
}

impl PlacedOnSlot {
    fn off(&self) -> Option<(f64, f64)> {
        let placed = self.placed?;
        Some((
            placed.distance_to(&self.at),
            wrap_angle(placed.heading_rad - self.at.heading_rad),
        ))
    }
}

impl StepCriterion for PlacedOnSlot {
    fn name(&self) -> &'static str {
        "placement_error"
    }
    fn measure(&self) -> Option<&'static str> {
        None
    }
    fn describe(&self) -> &'static str {
        "how far from its slot, and how turned, the pallet was set down"
    }
    fn observe(&mut self, view: &StepView<'_>) {
        self.placed = Some(view.pallet_pose);
    }
    fn value(&self) -> Option<f64> {
        self.off().map(|(d, _)| d)
    }
    fn broken(&self) -> Option<String> {
        let (d, h) = self.off()?;
        let (position_m, heading_deg) = self.limits;
        (d > position_m || h.abs() > heading_deg.to_radians()).then(|| {
            format!(
                "placed {d:.3} m and {:.2}° off slot {:?} (limits {position_m} m, {heading_deg}°)",
                h.to_degrees(),
                self.slot,
            )
        })
    }
}

#[cfg(test)]
mod placed_tests {
    use super::*;
    use crate::step_criteria::LoadView;
    use forkbench_core::{ForkliftSpec, PalletSpec};

    fn judged_at(pallet_pose: Pose2) -> PlacedOnSlot {
        let (truck, pallet) = (ForkliftSpec::default(), PalletSpec::field_1200());
        let mut c = PlacedOnSlot {
            slot: "drop-1".into(),
            at: Pose2::new(10.0, 5.0, 0.0),
            limits: (0.05, 2.0),
            placed: None,
        };
        c.observe(&StepView {
            t_s: 0.0,
            truck: &truck,
            pallet: &pallet,
            fork_root: Pose2::new(8.0, 5.0, 0.0),
            pallet_pose,
            collision: false,
            load: LoadView::default(),
        });
        c
    }

    #[test]
    fn a_pallet_set_down_off_its_slot_breaks_the_placement_with_both_figures() {
        assert!(judged_at(Pose2::new(10.03, 5.0, 0.01)).broken().is_none());
        let why = judged_at(Pose2::new(10.08, 5.0, 0.0))
            .broken()
            .expect("8 cm off");
        assert_eq!(
            why,
            "placed 0.080 m and 0.00° off slot \"drop-1\" (limits 0.05 m, 2°)"
        );
        assert!(judged_at(Pose2::new(10.0, 5.0, 0.1)).broken().is_some());
        assert_eq!(
            Failure::of_criterion("placement_error"),
            Failure::PlacementError
        );
    }
}
