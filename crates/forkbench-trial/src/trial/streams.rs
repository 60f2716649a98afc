//! The table of a trial's random streams: each keyed by what it is for, never by the order draws happen in.
//!
//! Every stream is a ChaCha8 generator seeded from the trial's seed (itself
//! `forkbench_batch::trial_seed`: the batch seed, scenario, case and trial index) and a salt
//! naming its purpose, so adding, removing or reordering a component, a sensor or a mover
//! leaves every other stream's draws unchanged, and two planners in one batch see the same
//! world (common random numbers). The numbers are part of the recorded outcomes: changing
//! one changes every trial's draws of that stream.
//!
//! | stream | salt | draws |
//! |---|---|---|
//! | localisation | [`LOCALISATION`] (1) | the localiser's noise (Gaussian σ, or the NAV350's per-reflector range and bearing) |
//! | pallet estimate | [`ESTIMATE`] (2) | the Gaussian pallet estimate; the first scanner model's (`tim561`) per-beam noise |
//! | pallet jitter | [`PALLET_JITTER`] (3) | the true pallet pose drawn around the case's |
//! | `tim561` bias | [`TIM561_BIAS`] (4) | that scanner's systematic range bias |
//! | other scanners | FNV-1a of `name` (bias) and `name/noise` | each scanner model's bias and per-beam noise |
//! | odometry | [`ODOMETRY`] (6) | speed scale and steering offset |
//! | accuracy study | [`ACCURACY`] (7), seed mixed with the draw index | `reproduce detector`'s scans |
//! | movers | FNV-1a of `mover start <copy> <mover>` | each person's or vehicle's start along its route |
//! | mission legs | the seed with `(leg + 1) << 32` xored in | each leg's global planner (PRM, RRT) |
//! | one scan | the seed xored with [`SCAN_ONCE`] | `forkbench scan`'s bias and noise |

use rand::SeedableRng as _;
use rand_chacha::ChaCha8Rng;

/// The localiser's noise.
pub(super) const LOCALISATION: u64 = 1;
/// The Gaussian pallet estimate, and the first scanner model's per-beam noise.
pub(super) const ESTIMATE: u64 = 2;
/// The true pallet pose's jitter.
pub(super) const PALLET_JITTER: u64 = 3;
/// The first scanner model's range bias.
pub(super) const TIM561_BIAS: u64 = 4;
/// Odometry's speed scale and steering offset.
pub(super) const ODOMETRY: u64 = 6;
/// The detector accuracy study's scans.
pub(super) const ACCURACY: u64 = 7;
/// `forkbench scan`'s one scan (xored into the seed, not a salt of [`stream`]).
pub(super) const SCAN_ONCE: u64 = 0x5CA7_5CA7_5CA7_5CA7;

/// The stream `salt` of a trial seeded `seed`.
pub(super) fn stream(seed: u64, salt: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed ^ salt.wrapping_mul(0x9E37_79B9_7F4A_7C15))
}

/// The detector accuracy study's stream for its `draw`-th scan of a study seeded `seed`.
pub fn accuracy_stream(seed: u64, draw: u64) -> ChaCha8Rng {
    stream(seed ^ draw.wrapping_mul(0xA24B_AED4_963E_E407), ACCURACY)
}

/// A mission leg's planner seed: leg `i` (0-based) of a trial seeded `seed`.
pub(super) fn leg_seed(seed: u64, i: usize) -> u64 {
    seed ^ ((i as u64 + 1) << 32)
}
