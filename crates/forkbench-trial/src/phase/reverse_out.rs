//! The reverse-out phase: the truck backs straight out along its own axis for a set distance, with or without the pallet.

use forkbench_core::Pose2;
use forkbench_core::SettingsError;
use serde::{Deserialize, Serialize};

use super::{
    Context, Failed, Phase, PhaseHost, PhaseRun, criteria, open_loop, positive_at_most, settings,
};
use crate::outcome::Failure;
use crate::recorder::Recorder;

/// `[phase.reverse_out]`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub(super) struct ReverseOut {
    /// How far the fork root backs out (by the controller's pose).
    distance_m: f64,
    speed_mps: f64,
    /// Time allowed to back out and stand.
    timeout_s: f64,
}

impl Default for ReverseOut {
    fn default() -> Self {
        Self {
            distance_m: 2.0,
            speed_mps: 0.5,
            timeout_s: 30.0,
        }
    }
}

pub(super) fn build(
    table: &toml::Table,
    _cx: &dyn Context,
) -> Result<Box<dyn Phase>, SettingsError> {
    let r: ReverseOut = settings(table)?;
    positive_at_most(&[
        ("distance_m", r.distance_m, 50.0),
        ("speed_mps", r.speed_mps, 3.0),
        ("timeout_s", r.timeout_s, 600.0),
    ])?;
    Ok(Box::new(r))
}

impl Phase for ReverseOut {
    fn run<'t>(&'t self, t: &'t mut dyn PhaseHost, rec: &'t mut dyn Recorder) -> PhaseRun<'t> {
        Box::pin(async move {
            let (pallet0, carrying) = (t.sim().pallet_pose(), t.sim().carrying());
            back_straight(t, (self.distance_m, self.speed_mps, self.timeout_s), rec).await?;
            if carrying {
                criteria::load_held(t)
            } else {
                criteria::pallet_stayed(t, &pallet0)
            }
        })
    }
}

/// Backs the truck straight out (steering centred) until the fork root, by the
/// controller's pose, is `distance_m` back and the truck stands; `timeout` if it is not
/// within `timeout_s`.
pub(super) async fn back_straight(
    t: &mut dyn PhaseHost,
    (distance_m, speed_mps, timeout_s): (f64, f64, f64),
    rec: &mut dyn Recorder,
) -> Result<(), Failed> {
    let mut from: Option<Pose2> = None;
    let mut backed_m = 0.0;
    let finished = t
        .drive_under(timeout_s, rec, &mut |t, pose| {
            let start = *from.get_or_insert(pose);
            backed_m = start.distance_to(&pose);
            let left_m = distance_m - backed_m;
            Ok(if left_m > 0.0 {
                // Slows over the last metres so the truck stands near the distance.
                Some(open_loop(-speed_mps.min(0.05 + 1.5 * left_m), 0.0, &pose))
            } else {
                (!t.stands()).then(|| open_loop(0.0, 0.0, &pose))
            })
        })
        .await?;
    if finished {
        Ok(())
    } else {
        Err(Failed::new(
            Failure::Timeout,
            format!("backed out {backed_m:.2} of {distance_m} m in {timeout_s} s"),
        ))
    }
}
