//! Trial seeds: each trial's seed from the batch seed and the trial's identity alone.

/// How trial seeds derive from the batch seed: 1 hashed the planner in, 2 leaves it out.
pub const SEED_SCHEME: u32 = 2;

/// Seed of one trial from its identity alone, so results do not depend on `--jobs`,
/// sharding or order (FNV-1a over the key, finished with SplitMix64). Neither planner nor
/// tracker is part of it: components compared in one batch see the same random draws
/// (common random numbers), so their trials pair one to one.
pub fn trial_seed(batch_seed: u64, scenario: &str, case: &str, trial: u64) -> u64 {
    // Each field followed by 0xff, so no two keys run together into one byte stream.
    let h = forkbench_core::hash::fnv1a(
        (batch_seed.to_le_bytes().into_iter().chain([0xff]))
            .chain(scenario.bytes().chain([0xff]))
            .chain(case.bytes().chain([0xff]))
            .chain(trial.to_le_bytes().into_iter().chain([0xff])),
    );
    let mut z = h.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}
