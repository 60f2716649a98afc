//! Mission legs inside the cycle: `carry` (the load on the forks, to where a place begins) and `return` (back to a station, the charging station by default), planned and driven as mission legs.

use forkbench_core::SettingsError;
use forkbench_nav::NavMap;
use serde::{Deserialize, Serialize};

use super::{Context, Phase, PhaseRun, settings};
use crate::outcome::Failure;
use crate::recorder::Recorder;
use crate::scenario::PoseDeg;
use crate::scenario::mission::Waypoint;
use crate::trial::state::Trial;

/// `[phase.carry]` and `[phase.return]`: where the leg goes.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub(super) struct LegFile {
    /// The world's station to drive to (a return's default: the mission's start).
    to: Option<String>,
    /// Or a pose of the fork root to drive to.
    pose: Option<PoseDeg>,
    /// The heading to arrive with (default: the station's or the pose's): a station
    /// whose own heading only a reverse could reach is driven into forward from the
    /// other side.
    heading_deg: Option<f64>,
}

/// A resolved leg phase: where it goes.
#[derive(Debug)]
struct Leg {
    to: Waypoint,
}

/// A `carry`: the destination is required.
pub(super) fn build_carry(
    table: &toml::Table,
    cx: &Context<'_>,
) -> Result<Box<dyn Phase>, SettingsError> {
    build(table, cx, None)
}

/// A `return`: by default to the mission's start (the charging station).
pub(super) fn build_return(
    table: &toml::Table,
    cx: &Context<'_>,
) -> Result<Box<dyn Phase>, SettingsError> {
    let start = cx.mission.map(|m| m.start.clone());
    build(table, cx, start)
}

fn build(
    table: &toml::Table,
    cx: &Context<'_>,
    default: Option<Waypoint>,
) -> Result<Box<dyn Phase>, SettingsError> {
    let cfg: LegFile = settings(table)?;
    cx.mission.ok_or_else(|| SettingsError {
        field: None,
        reason: "needs a [mission] table: its global planner and tracker drive the leg".into(),
    })?;
    let mut to = match (&cfg.to, &cfg.pose) {
        (Some(_), Some(_)) => {
            return Err(SettingsError::field(
                "to",
                "give `to` (a station) or `pose`, not both",
            ));
        }
        (Some(name), None) => station(cx, name)?,
        (None, Some(p)) => {
            let pose = p.to_pose();
            let limit = crate::scenario::MAX_WORLD_EXTENT_M;
            let within = |v: f64, lim: f64| v.is_finite() && v.abs() <= lim;
            if !(within(p.x_m, limit) && within(p.y_m, limit) && within(p.heading_deg, 360.0)) {
                return Err(SettingsError::field(
                    "pose",
                    format!(
                        "must lie within ±{limit} m and ±360° (got x_m {}, y_m {}, heading_deg {})",
                        p.x_m, p.y_m, p.heading_deg
                    ),
                ));
            }
            Waypoint {
                name: format!("({:.1}, {:.1})", p.x_m, p.y_m),
                pose,
            }
        }
        (None, None) => default.ok_or_else(|| {
            SettingsError::field("to", "name where to drive: `to` (a station) or `pose`")
        })?,
    };
    if let Some(h) = cfg.heading_deg {
        if !(h.is_finite() && h.abs() <= 360.0) {
            return Err(SettingsError::field(
                "heading_deg",
                format!("must lie within ±360° (got {h})"),
            ));
        }
        to.pose.heading_rad = h.to_radians();
    }
    Ok(Box::new(Leg { to }))
}

/// The world's station `name` as a waypoint.
fn station(cx: &Context<'_>, name: &str) -> Result<Waypoint, SettingsError> {
    let pose = cx.world.station_pose(name).ok_or_else(|| {
        let known: Vec<_> = cx.world.station.iter().map(|s| s.name.as_str()).collect();
        SettingsError::field(
            "to",
            format!("no station {name:?} in the world (it has {known:?})"),
        )
    })?;
    Ok(Waypoint {
        name: name.to_owned(),
        pose,
    })
}

impl Phase for Leg {
    fn run<'t, 'a: 't>(&'t self, t: &'t mut Trial<'a>, rec: &'t mut dyn Recorder) -> PhaseRun<'t> {
        Box::pin(async move {
            let scn = t.scn;
            let m = scn
                .mission
                .as_ref()
                .ok_or((Failure::Error, "no [mission]".to_owned()))?;
            let map = NavMap::shared_from_world(&t.world.obstacles, m.global.resolution_m)
                .map_err(|e| (Failure::Error, e.to_string()))?;
            let here = Waypoint {
                name: "here".to_owned(),
                pose: t.world.sim.fork_root_pose(),
            };
            // Numbered after the mission's legs and the cycle's earlier ones (its seed and
            // recorded route are its own); a leg after the first backs out of where it
            // starts, as from a station.
            let number = m.via.len() + 1 + t.verdict.out.phases.len();
            let leg = t.leg(&map, m, (number, &here, &self.to), rec).await;
            let measures = [
                ("planned_length_m", leg.planned_length_m),
                ("final_position_error_m", leg.final_position_error_m),
                ("cross_track_max_m", leg.cross_track_max_m),
            ];
            t.verdict
                .phase_measures
                .extend(measures.map(|(k, v)| (k.to_owned(), v)));
            if leg.success {
                Ok(())
            } else {
                Err((
                    Failure::LegFailed,
                    format!(
                        "to {}: {}",
                        self.to.name,
                        leg.failure_detail.unwrap_or_default()
                    ),
                ))
            }
        })
    }
}
