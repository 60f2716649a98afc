//! The fixed global order of a batch's jobs and a shard's share of them, shared by running a batch and by checking its records against the manifest.

/// What one scenario contributes: its case count and the planners and trackers it runs.
pub(super) struct ScenarioJobs {
    pub cases: usize,
    pub planners: Vec<String>,
    pub trackers: Vec<String>,
}

/// One job's place: scenario and case indices, planner, tracker, mode, trial index.
pub(super) struct JobRef<'a> {
    pub scenario: usize,
    pub case: usize,
    pub planner: &'a str,
    pub tracker: &'a str,
    pub mode: Option<bool>,
    pub trial: u64,
}

/// The replanning modes every case runs with: both, or the batch's override (or none).
pub(super) fn modes(compare_replanning: bool, replan: Option<bool>) -> Vec<Option<bool>> {
    if compare_replanning {
        vec![Some(false), Some(true)]
    } else {
        vec![replan]
    }
}

/// Calls `f` for each job of shard `index` of `count`, in the order scenario × case ×
/// planner × tracker × mode × trial; shard I takes every job whose position is I mod N.
pub(super) fn for_each_job(
    scenarios: &[ScenarioJobs],
    modes: &[Option<bool>],
    trials: u64,
    (index, count): (u64, u64),
    mut f: impl FnMut(JobRef),
) {
    let mut k: u64 = 0;
    for (si, s) in scenarios.iter().enumerate() {
        for ci in 0..s.cases {
            for p in &s.planners {
                for t in &s.trackers {
                    for &mode in modes {
                        for trial in 0..trials {
                            if count > 0 && k % count == index {
                                f(JobRef {
                                    scenario: si,
                                    case: ci,
                                    planner: p,
                                    tracker: t,
                                    mode,
                                    trial,
                                });
                            }
                            k += 1;
                        }
                    }
                }
            }
        }
    }
}
