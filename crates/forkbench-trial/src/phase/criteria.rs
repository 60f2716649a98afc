//! The criteria of the phases after the pick, each once: what it measures and its limit.

use forkbench_core::Pose2;
use forkbench_core::units::wrap_angle;

use forkbench_sim::Sim;

use super::{Failed, PhaseHost};
use crate::outcome::Failure;

/// The carried load stayed on the forks: the truck never accelerated it harder than its
/// friction on them holds (μ g).
pub fn load_held(sim: &Sim) -> Result<(), Failed> {
    if sim.load_shifted() {
        let limit = sim.load_grip_mps2();
        return Err((
            Failure::LoadShifted,
            format!(
                "the load was accelerated at {:.2} m/s² (its friction on the forks holds {limit:.2} m/s²)",
                sim.peak_load_accel_mps2()
            ),
        ));
    }
    Ok(())
}

/// A pallet left standing stayed where it stood (the forks did not drag it) within the
/// pick's displacement and rotation limits.
pub(super) fn pallet_stayed(host: &dyn PhaseHost, from: &Pose2) -> Result<(), Failed> {
    let now = host.sim().pallet_pose();
    let (moved, turned) = (
        now.distance_to(from),
        wrap_angle(now.heading_rad - from.heading_rad),
    );
    let tol = host.tolerances();
    if moved > tol.pallet_displacement_m || turned.abs() > tol.pallet_rotation_rad {
        return Err((
            Failure::PalletDisplaced,
            format!(
                "the forks dragged the pallet {moved:.3} m and turned it {:.2}° (limits {} m, {}°)",
                turned.to_degrees(),
                tol.pallet_displacement_m,
                tol.pallet_rotation_deg()
            ),
        ));
    }
    Ok(())
}
