//! The braking distance measured in the physics: the truck brought to a speed on an open floor, then commanded to stop, empty or carrying its rated load.

use forkbench_core::{ForkliftSpec, PalletSpec, Pose2};
use forkbench_sim::{Sim, SimConfig};
use serde::Serialize;

use crate::SafetyError;
use crate::sizing::Load;

/// Below this speed the truck counts as stopped.
pub const STOPPED_MPS: f64 = 0.005;

/// Longest simulated time allowed to reach the speed, and again to stop.
const PHASE_LIMIT_S: f64 = 60.0;

/// How long the speed must hold within 1 % of the target before braking begins.
const STEADY_S: f64 = 0.5;

/// One braking run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Braking {
    pub speed_mps: f64,
    pub load: Load,
    /// The mass braked: the truck, and the pallet with its payload when loaded.
    pub mass_kg: f64,
    /// From the stop command to standstill.
    pub distance_m: f64,
    pub time_s: f64,
}

/// Brakes the truck from `speed_mps` on the floor `sim` describes and measures how far it
/// travels. `Load::Rated` carries `pallet` with the payload that makes it the truck's
/// rated capacity.
pub fn braking_distance(
    truck: &ForkliftSpec,
    sim_cfg: &SimConfig,
    pallet: &PalletSpec,
    speed_mps: f64,
    load: Load,
) -> Result<Braking, SafetyError> {
    if !(speed_mps.is_finite() && speed_mps > 0.0 && speed_mps <= truck.max_speed_mps * 2.0) {
        return Err(SafetyError::Speed { speed_mps });
    }
    let mut sim = open_floor(truck, sim_cfg, pallet, load)?;
    let mass_kg = truck.mass_kg
        + match load {
            Load::Empty => 0.0,
            Load::Rated => truck.rated_capacity_kg,
        };
    reach(&mut sim, speed_mps)?;
    let (start, t0) = (sim.fork_root_pose(), sim.time_s());
    while sim.speed_mps().abs() >= STOPPED_MPS {
        if sim.time_s() - t0 > PHASE_LIMIT_S {
            return Err(SafetyError::NotStopped {
                speed_mps,
                limit_s: PHASE_LIMIT_S,
            });
        }
        sim.step(0.0, 0.0);
    }
    Ok(Braking {
        speed_mps,
        load,
        mass_kg,
        distance_m: start.distance_to(&sim.fork_root_pose()),
        time_s: sim.time_s() - t0,
    })
}

/// A world with nothing but the truck and its pallet: on the forks (lifted, its payload
/// making up the rated capacity) or standing far behind.
fn open_floor(
    truck: &ForkliftSpec,
    sim_cfg: &SimConfig,
    pallet: &PalletSpec,
    load: Load,
) -> Result<Sim, SafetyError> {
    let start = Pose2::new(0.0, 0.0, 0.0);
    let mut spec = pallet.clone();
    let at = match load {
        Load::Empty => Pose2::new(-100.0, 0.0, 0.0),
        Load::Rated => {
            spec.payload_kg = (truck.rated_capacity_kg - spec.mass_kg).max(0.0);
            // The face just ahead of the fork root: the forks run through the pockets.
            Pose2::new(0.02, 0.0, 0.0)
        }
    };
    let mut sim = Sim::new(truck, &start, &spec, &at, &[], sim_cfg)?;
    if load == Load::Rated {
        sim.lift()?;
    }
    Ok(sim)
}

/// Drives straight until the speed holds at `speed_mps`.
fn reach(sim: &mut Sim, speed_mps: f64) -> Result<(), SafetyError> {
    let mut steady_s = 0.0;
    while steady_s < STEADY_S {
        if sim.time_s() > PHASE_LIMIT_S {
            return Err(SafetyError::NotReached {
                speed_mps,
                limit_s: PHASE_LIMIT_S,
            });
        }
        sim.step(speed_mps, 0.0);
        let near = (sim.speed_mps() - speed_mps).abs() <= 0.01 * speed_mps;
        steady_s = if near { steady_s + sim.dt_s() } else { 0.0 };
    }
    Ok(())
}
