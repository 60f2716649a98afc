//! Mission legs inside the cycle: `carry` (the load on the forks, to where a place begins) and `return` (back to a station, the charging station by default), planned and driven as mission legs.

use forkbench_core::{Pose2, SettingsError};
use serde::{Deserialize, Serialize};

use super::{Context, Failed, Phase, PhaseHost, PhaseRun, settings};
use crate::outcome::Failure;
use crate::pose_deg::{MAX_WORLD_EXTENT_M, PoseDeg};
use crate::recorder::Recorder;

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

/// A resolved leg phase: where it goes (a name, and the fork root's pose there).
#[derive(Debug)]
struct Leg {
    to: (String, Pose2),
}

/// A `carry`: the destination is required.
pub(super) fn build_carry(
    table: &toml::Table,
    cx: &dyn Context,
) -> Result<Box<dyn Phase>, SettingsError> {
    build(table, cx, None)
}

/// A `return`: by default to the mission's start (the charging station).
pub(super) fn build_return(
    table: &toml::Table,
    cx: &dyn Context,
) -> Result<Box<dyn Phase>, SettingsError> {
    build(table, cx, cx.mission_start())
}

fn build(
    table: &toml::Table,
    cx: &dyn Context,
    default: Option<(String, Pose2)>,
) -> Result<Box<dyn Phase>, SettingsError> {
    let cfg: LegFile = settings(table)?;
    cx.mission_start().ok_or_else(|| SettingsError {
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
            let limit = MAX_WORLD_EXTENT_M;
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
            (format!("({:.1}, {:.1})", p.x_m, p.y_m), pose)
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
        to.1.heading_rad = h.to_radians();
    }
    Ok(Box::new(Leg { to }))
}

/// The world's station `name`, named.
fn station(cx: &dyn Context, name: &str) -> Result<(String, Pose2), SettingsError> {
    let pose = cx.station_pose(name).ok_or_else(|| {
        let known = cx.station_names();
        SettingsError::field(
            "to",
            format!("no station {name:?} in the world (it has {known:?})"),
        )
    })?;
    Ok((name.to_owned(), pose))
}

impl Phase for Leg {
    fn run<'t>(&'t self, t: &'t mut dyn PhaseHost, rec: &'t mut dyn Recorder) -> PhaseRun<'t> {
        Box::pin(async move {
            let (name, pose) = (&self.to.0, self.to.1);
            let leg = t.drive_leg((name, pose), rec).await?;
            t.record_measure("planned_length_m", leg.planned_length_m);
            t.record_measure("final_position_error_m", leg.final_position_error_m);
            t.record_measure("cross_track_max_m", leg.cross_track_max_m);
            if leg.success {
                Ok(())
            } else {
                Err(Failed::new(
                    Failure::LegFailed,
                    format!("to {name}: {}", leg.failure_detail.unwrap_or_default()),
                ))
            }
        })
    }
}
