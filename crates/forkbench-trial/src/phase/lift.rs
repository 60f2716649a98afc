//! The lift phase: the pallet rises onto the forks (off the floor, its mass on the truck) while the truck stands.

use forkbench_core::SettingsError;
use serde::{Deserialize, Serialize};

use super::{Context, Failed, Phase, PhaseHost, PhaseRun, criteria, settings, stand_for};
use crate::outcome::Failure;
use crate::recorder::Recorder;

/// `[phase.lift]`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub(super) struct Lift {
    /// Time the mast takes to raise the pallet clear of the floor.
    time_s: f64,
}

impl Default for Lift {
    fn default() -> Self {
        Self { time_s: 2.0 }
    }
}

pub(super) fn build(
    table: &toml::Table,
    _cx: &dyn Context,
) -> Result<Box<dyn Phase>, SettingsError> {
    let lift: Lift = settings(table)?;
    if !(lift.time_s.is_finite() && lift.time_s >= 0.0 && lift.time_s <= 60.0) {
        return Err(SettingsError::field(
            "time_s",
            format!("must lie in 0–60 s (got {})", lift.time_s),
        ));
    }
    Ok(Box::new(lift))
}

impl Phase for Lift {
    fn run<'t>(&'t self, t: &'t mut dyn PhaseHost, rec: &'t mut dyn Recorder) -> PhaseRun<'t> {
        Box::pin(async move {
            t.sim_mut()
                .lift()
                .map_err(|e| Failed::new(Failure::LiftFailed, e.to_string()))?;
            stand_for(t, self.time_s, rec).await?;
            criteria::load_held(t)
        })
    }
}
