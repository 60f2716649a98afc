//! A trial that panics becomes that trial's `error` outcome, so a batch goes on.

use forkbench_trial::outcome::{Failure, TrialOutcome};
use forkbench_trial::scenario::Scenario;

/// Runs `f`, turning a panic into an `error` outcome that carries the message and seed.
pub fn guarded(
    s: &Scenario,
    case: &str,
    names: (&str, &str),
    seed: u64,
    f: impl FnOnce() -> TrialOutcome,
) -> TrialOutcome {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).unwrap_or_else(|panic| {
        let message = panic
            .downcast_ref::<&str>()
            .map(|s| (*s).to_owned())
            .or_else(|| panic.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "panic with a non-text payload".to_owned());
        error_outcome(
            s,
            case,
            names,
            seed,
            format!("trial panicked (seed {seed}): {message}"),
        )
    })
}

fn error_outcome(
    s: &Scenario,
    case: &str,
    names: (&str, &str),
    seed: u64,
    detail: String,
) -> TrialOutcome {
    let mut out = TrialOutcome::blank(&s.name, case, names, seed, s.noise.enabled);
    out.fail(Failure::Error, detail);
    out
}
