//! Child processes kept per worker thread between requests, keyed by what started them, so a batch starts one per thread and command rather than one per trial.

use std::cell::RefCell;
use std::collections::HashMap;
use std::path::PathBuf;

use crate::process::{EnvPolicy, Process};

/// What started a pooled process: protocol, command, directory and environment.
pub(crate) type PoolKey = (&'static str, Vec<String>, PathBuf, EnvPolicy);

thread_local! {
    /// Each process with the id its next request gets.
    static POOL: RefCell<HashMap<PoolKey, (Process, u64)>> = RefCell::new(HashMap::new());
}

/// This thread's process for `key`, if one waits in the pool and kept quiet there: one
/// that printed while nobody asked broke the protocol and is retired (its group killed).
pub(crate) fn take_pooled(key: &PoolKey) -> Option<(Process, u64)> {
    let (mut p, id) = POOL.with(|p| p.borrow_mut().remove(key))?;
    (!p.has_idle_output()).then_some((p, id))
}

/// Returns a process that kept to its protocol, with its next request's id.
pub(crate) fn put_back(key: PoolKey, p: Process, next_id: u64) {
    POOL.with(|pool| pool.borrow_mut().insert(key, (p, next_id)));
}

/// Ends this thread's pooled processes (each group killed): called on every worker when a
/// batch ends, so no child outlives it.
pub fn release_pooled() {
    POOL.with(|p| p.borrow_mut().clear());
}
