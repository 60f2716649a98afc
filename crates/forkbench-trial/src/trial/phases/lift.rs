//! The lift phase: the pallet rises onto the forks (off the floor, its mass on the truck) while the truck stands.

use serde::{Deserialize, Serialize};

use super::run::open_loop;
use super::{Context, Failed, Phase, criteria, settings};
use crate::outcome::Failure;
use crate::recorder::Recorder;
use crate::trial::setup::Trial;

/// `[phase.lift]`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
struct Lift {
    /// Time the mast takes to raise the pallet clear of the floor.
    time_s: f64,
}

impl Default for Lift {
    fn default() -> Self {
        Self { time_s: 2.0 }
    }
}

pub(super) fn defaults() -> toml::Value {
    toml::Value::try_from(Lift::default()).unwrap_or(toml::Value::Table(toml::Table::new()))
}

pub(super) fn build(table: &toml::Table, _cx: &Context<'_>) -> Result<Box<dyn Phase>, String> {
    let lift: Lift = settings(table)?;
    if !(lift.time_s.is_finite() && lift.time_s >= 0.0 && lift.time_s <= 60.0) {
        return Err(format!("time_s must lie in 0–60 s (got {})", lift.time_s));
    }
    Ok(Box::new(lift))
}

impl Phase for Lift {
    fn run(&self, t: &mut Trial<'_>, rec: &mut dyn Recorder) -> Result<(), Failed> {
        t.sim
            .lift()
            .map_err(|e| (Failure::LiftFailed, e.to_string()))?;
        let end_s = t.sim.time_s() + self.time_s;
        t.drive_by(self.time_s + 1.0, rec, |t, pose| {
            Ok((t.sim.time_s() < end_s).then(|| open_loop(0.0, t.sim.steer_rad(), &pose)))
        })?;
        criteria::load_held(t)
    }
}
