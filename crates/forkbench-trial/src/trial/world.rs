//! The physics world a trial (or a one-off look) starts in: the truck at its start, the pallet where it really stands.

use forkbench_core::Pose2;
use forkbench_sim::Sim;
use rand_chacha::ChaCha8Rng;

use super::streams::{self, stream};
use super::uncertain_apply::Shift;
use crate::scenario::{Case, Scenario};
use crate::stage_error::StageError;

/// The physics world of a trial: the truck at its start (a mission's first place, else the
/// case's start, or `start_at`), the pallet where it really stands (the case's moved by
/// the uncertain parameters' `shift`, then jittered on its own random stream).
pub(super) fn build_world(
    scn: &Scenario,
    truck: &forkbench_core::ForkliftSpec,
    case: &Case,
    (seed, shift): (u64, &Shift),
    start_at: Option<Pose2>,
) -> Result<(Sim, Pose2, Pose2, Vec<forkbench_sim::Obstacle>), StageError> {
    let true_pallet = jitter(
        &case.pallet.to_world(&shift.pallet),
        &scn.pallet_jitter,
        &mut stream(seed, streams::PALLET_JITTER),
    );
    let obstacles = scn.world.obstacles();
    let start = start_at
        .unwrap_or_else(|| scn.mission.as_ref().map_or(case.start, |m| m.start.pose))
        .to_world(&shift.start);
    let sim = Sim::new(
        truck,
        &start,
        &scn.pallet,
        &true_pallet,
        &obstacles,
        &scn.sim,
    )?;
    Ok((sim, start, true_pallet, obstacles))
}

/// The pallet pose moved by a draw of N(0, σ) per axis in its own frame, truncated at 3σ.
pub(super) fn jitter(pallet: &Pose2, sigma: &Pose2, rng: &mut ChaCha8Rng) -> Pose2 {
    if sigma.x_m == 0.0 && sigma.y_m == 0.0 && sigma.heading_rad == 0.0 {
        return *pallet;
    }
    let mut draw = |s: f64| {
        let z: f64 = rand::RngExt::sample(rng, rand_distr::StandardNormal);
        s * z.clamp(-3.0, 3.0)
    };
    let d = Pose2::new(draw(sigma.x_m), draw(sigma.y_m), draw(sigma.heading_rad));
    pallet.to_world(&d)
}
