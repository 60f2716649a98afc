//! The field-test trial both recording benches run, and a scratch directory for their files.

use std::path::{Path, PathBuf};

use forkbench_trial::{Scenario, TrialOptions};

/// The field-test scenario and the options (seed 7) of the benchmarked trial.
pub fn field_test() -> (Scenario, TrialOptions) {
    let scn = Scenario::load(Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenarios/field-test.toml"
    )))
    .expect("loads");
    let opts = TrialOptions {
        seed: Some(7),
        ..TrialOptions::default()
    };
    (scn, opts)
}

/// A fresh directory under the system temp dir, per process.
pub fn scratch_dir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("forkbench-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    dir
}
