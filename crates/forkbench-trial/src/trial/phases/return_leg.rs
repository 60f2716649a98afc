//! The return phase: the last leg of the cycle, from where the truck stands back to a station (the charging station), planned and driven as a mission leg.

use forkbench_nav::NavMap;
use serde::{Deserialize, Serialize};

use super::{Context, Failed, Phase, settings};
use crate::outcome::Failure;
use crate::recorder::Recorder;
use crate::scenario::mission::Waypoint;
use crate::trial::setup::Trial;

/// `[phase.return]`.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
struct ReturnFile {
    /// The world's station to drive to (default: the mission's start).
    to: Option<String>,
    /// The heading to arrive with (default: the station's): a station whose own heading
    /// only a reverse could reach is driven into forward from the other side.
    heading_deg: Option<f64>,
}

/// A resolved return: the station to drive to.
#[derive(Debug)]
struct Return {
    to: Waypoint,
}

pub(super) fn defaults() -> toml::Value {
    toml::Value::try_from(ReturnFile::default()).unwrap_or(toml::Value::Table(toml::Table::new()))
}

pub(super) fn build(table: &toml::Table, cx: &Context<'_>) -> Result<Box<dyn Phase>, String> {
    let cfg: ReturnFile = settings(table)?;
    let mission = cx
        .mission
        .ok_or("needs a [mission] table: its global planner and tracker drive the leg")?;
    let mut to = match cfg.to {
        None => mission.start.clone(),
        Some(name) => {
            let s = cx
                .world
                .station
                .iter()
                .find(|s| s.name == name)
                .ok_or_else(|| {
                    let known: Vec<_> = cx.world.station.iter().map(|s| s.name.as_str()).collect();
                    format!("to: no station {name:?} in the world (it has {known:?})")
                })?;
            Waypoint {
                name,
                pose: forkbench_core::Pose2::new(s.x_m, s.y_m, s.heading_deg.to_radians()),
            }
        }
    };
    if let Some(h) = cfg.heading_deg {
        if !(h.is_finite() && h.abs() <= 360.0) {
            return Err(format!("heading_deg must lie within ±360° (got {h})"));
        }
        to.pose.heading_rad = h.to_radians();
    }
    Ok(Box::new(Return { to }))
}

impl Phase for Return {
    fn run(&self, t: &mut Trial<'_>, rec: &mut dyn Recorder) -> Result<(), Failed> {
        let scn = t.scn;
        let m = scn
            .mission
            .as_ref()
            .ok_or((Failure::Error, "no [mission]".to_owned()))?;
        let map = NavMap::shared_from_world(&t.obstacles, m.global.resolution_m)
            .map_err(|e| (Failure::Error, e.to_string()))?;
        let here = Waypoint {
            name: "the drop".to_owned(),
            pose: t.sim.fork_root_pose(),
        };
        // Numbered after the mission's legs (its seed and recorded route are its own); a
        // leg after the first backs out of where it starts, as from a station.
        let leg = t.leg(&map, m, (m.via.len() + 1, &here, &self.to), rec);
        let measures = [
            ("planned_length_m", leg.planned_length_m),
            ("final_position_error_m", leg.final_position_error_m),
            ("cross_track_max_m", leg.cross_track_max_m),
        ];
        t.phase_measures
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
    }
}
