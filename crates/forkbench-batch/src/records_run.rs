//! A batch's records in job order, for a caller that wants them in memory (the Python layer): run on a thread pool, or through a batch directory.

use std::collections::HashMap;
use std::path::Path;

use rayon::prelude::*;

use crate::{BatchError, BatchSpec, TrialRecord, read_records, run_batch};

/// Runs `spec` on `jobs` threads and returns its records in [`BatchSpec::jobs`]' order:
/// in memory, or with `out` through that batch directory (written, or resumed, as
/// [`run_batch`] does). The same trials and outcomes either way.
pub fn run_records(
    spec: &BatchSpec,
    jobs: usize,
    out: Option<&Path>,
) -> Result<Vec<TrialRecord>, BatchError> {
    spec.check(jobs)?;
    let todo = spec.jobs();
    let Some(dir) = out else {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(jobs)
            .build()
            .map_err(|e| BatchError::Internal(format!("thread pool: {e}")))?;
        let records = pool.install(|| {
            todo.par_iter()
                .with_max_len(1)
                .map(|j| spec.run_job(j))
                .collect()
        });
        // Pooled external planners live in the workers' thread-locals: end them here too.
        pool.broadcast(|_| forkbench_plan::external::release_pooled());
        return Ok(records);
    };
    run_batch(spec, dir, jobs, &|_| {})?;
    let order: HashMap<_, usize> = todo
        .iter()
        .enumerate()
        .map(|(i, j)| (spec.key(j), i))
        .collect();
    let mut records = read_records(&dir.join("trials.jsonl"))?;
    records.retain(|r| order.contains_key(&r.key()));
    records.sort_by_key(|r| order[&r.key()]);
    Ok(records)
}
