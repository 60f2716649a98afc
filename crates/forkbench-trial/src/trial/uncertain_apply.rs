//! A trial's uncertain parameters drawn (or pinned) and applied to what it runs with: the truck, the sensors' latencies, the true pallet and start, the movers.

use std::collections::BTreeMap;

use forkbench_core::Pose2;

use crate::ScenarioError;
use crate::scenario::Scenario;
use crate::scenario::uncertain::{Axis, Target, Values};

/// Where the true pallet and the truck's start lie off the case's, each in its own frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Shift {
    pub pallet: Pose2,
    pub start: Pose2,
}

impl Default for Shift {
    fn default() -> Self {
        let zero = Pose2::new(0.0, 0.0, 0.0);
        Shift {
            pallet: zero,
            start: zero,
        }
    }
}

/// What a trial's uncertain parameters change, by kind.
#[derive(Debug, Clone, Default)]
pub(super) struct Drawn {
    pub values: Values,
    pub shift: Shift,
    /// Truck settings by dotted path.
    pub truck: BTreeMap<String, f64>,
    pub detector_latency_s: Option<f64>,
    pub nav350_latency_s: Option<f64>,
}

/// Draws the scenario's uncertain parameters for a trial seeded `seed` (or takes the
/// `pinned` values), each checked against what it declares.
pub(super) fn draw(scn: &Scenario, seed: u64, pinned: &Values) -> Result<Drawn, ScenarioError> {
    scn.uncertain.check_pinned(pinned)?;
    let mut d = Drawn {
        values: scn.uncertain.values(seed, pinned),
        ..Drawn::default()
    };
    for u in &scn.uncertain.0 {
        let v = d.values[&u.name];
        match &u.target {
            Target::Pallet(a) => set(&mut d.shift.pallet, *a, v),
            Target::Start(a) => set(&mut d.shift.start, *a, v),
            Target::Truck(path) => {
                d.truck.insert((*path).to_owned(), v);
            }
            Target::DetectorLatency => d.detector_latency_s = Some(v),
            Target::Nav350Latency => d.nav350_latency_s = Some(v),
            Target::MoverStart(_) | Target::MoverSpeed(_) => {}
        }
    }
    Ok(d)
}

fn set(p: &mut Pose2, axis: Axis, v: f64) {
    match axis {
        Axis::X => p.x_m = v,
        Axis::Y => p.y_m = v,
        Axis::Heading => p.heading_rad = v.to_radians(),
    }
}

/// The start time and speed a trial's `values` pin for mover `i` (each `None`: as the
/// scenario has it).
pub(super) fn mover_pins(scn: &Scenario, values: &Values, i: usize) -> (Option<f64>, Option<f64>) {
    let mut pins = (None, None);
    for u in &scn.uncertain.0 {
        match u.target {
            Target::MoverStart(j) if j == i => pins.0 = values.get(&u.name).copied(),
            Target::MoverSpeed(j) if j == i => pins.1 = values.get(&u.name).copied(),
            _ => {}
        }
    }
    pins
}
