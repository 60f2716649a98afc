//! What a batch is checked for before any trial runs: its own arguments, unique scenario names, resolvable components, and the gate's power.

use crate::{BatchError, BatchSpec, DEFAULT_ALPHA, MAX_JOBS, paired_trials_needed};

/// A trial record's size in memory and on disk, generously (a record with stages, people
/// and a failure's details).
const RECORD_BYTES: u64 = 2048;
/// The records one batch process may hold.
const MAX_RECORD_BYTES: u64 = 4 << 30;

impl BatchSpec {
    /// The batch's own arguments: trials, shard, worker threads and unique names.
    pub fn check(&self, jobs: usize) -> Result<(), BatchError> {
        if self.trials == 0 {
            return Err(BatchError::Setting("trials: must be at least 1".into()));
        }
        self.overrides
            .validate()
            .map_err(|e| BatchError::Setting(e.to_string()))?;
        if self.shard.1 == 0 || self.shard.0 >= self.shard.1 {
            return Err(BatchError::Setting(format!(
                "shard {}/{}: the index must be below the shard count",
                self.shard.0, self.shard.1
            )));
        }
        if !(1..=MAX_JOBS).contains(&jobs) {
            return Err(BatchError::Setting(format!(
                "jobs {jobs}: at least 1 and at most {MAX_JOBS} worker threads"
            )));
        }
        self.check_bytes()?;
        self.check_names()?;
        self.check_components()
    }

    /// Refuses a batch (or its shard) whose records could not be held: every record is
    /// kept for the summary and written to `trials.jsonl`, so the trial count is bounded by
    /// the bytes its records take, before anything is allocated for them.
    fn check_bytes(&self) -> Result<(), BatchError> {
        let total: u64 = self
            .row_sizes()
            .iter()
            .fold(0u64, |a, (_, n)| a.saturating_add(*n));
        let mine = total.div_ceil(self.shard.1.max(1));
        let bytes = mine.saturating_mul(RECORD_BYTES);
        if bytes <= MAX_RECORD_BYTES {
            return Ok(());
        }
        Err(BatchError::Setting(format!(
            "trials: this batch{} would run {mine} trials, about {:.1} GB of records held in \
             memory and written; at most {} trials ({:.1} GB) per process: lower --trials or \
             split it with --shard I/N",
            if self.shard.1 > 1 { "'s shard" } else { "" },
            bytes as f64 / 1e9,
            MAX_RECORD_BYTES / RECORD_BYTES,
            MAX_RECORD_BYTES as f64 / 1e9,
        )))
    }

    /// Refuses a batch too small for the paired gate to see a success-rate drop of `drop`
    /// with 80 % power in every row (at the default α, Holm over the rows).
    pub fn check_power(&self, drop: f64) -> Result<(), BatchError> {
        if !(drop > 0.0 && drop <= 1.0) {
            return Err(BatchError::Setting(format!(
                "min_detectable_drop {drop}: must be a drop in success rate in (0, 1]"
            )));
        }
        let rows = self.row_sizes();
        let need = paired_trials_needed(drop, DEFAULT_ALPHA, rows.len()).ok_or_else(|| {
            BatchError::Setting(format!(
                "min_detectable_drop {drop}: no trial count up to a million is enough"
            ))
        })?;
        let short: Vec<String> = rows
            .iter()
            .filter(|(_, n)| *n < need)
            .map(|(name, n)| format!("{name} ({n})"))
            .collect();
        if short.is_empty() {
            return Ok(());
        }
        Err(BatchError::Setting(format!(
            "min_detectable_drop {drop}: a paired gate over {} rows (α {DEFAULT_ALPHA} Holm) \
             needs at least {need} trials per row to see that drop with 80 % power (a change \
             that only breaks trials; more when it also fixes some), and these rows have fewer: \
             {}. Raise the trial count.",
            rows.len(),
            short.join(", ")
        )))
    }

    /// Every planner and tracker name must resolve in every scenario, and every override
    /// act on it, before any trial runs.
    fn check_components(&self) -> Result<(), BatchError> {
        for s in &self.scenarios {
            let opts = forkbench_trial::TrialOptions {
                overrides: self.overrides.clone(),
                ..Default::default()
            };
            opts.check_against(s)
                .map_err(|e| BatchError::Setting(e.to_string()))?;
            let (planners, trackers) = self.components_of(s);
            for p in &planners {
                s.component(forkbench_trial::Role::Planner, Some(p))
                    .map_err(|e| BatchError::Setting(e.to_string()))?;
            }
            for t in &trackers {
                s.component(forkbench_trial::Role::Tracker, Some(t))
                    .map_err(|e| BatchError::Setting(e.to_string()))?;
            }
        }
        Ok(())
    }

    /// Scenario names key rows and seeds: two scenarios may not share one.
    fn check_names(&self) -> Result<(), BatchError> {
        for (i, a) in self.scenarios.iter().enumerate() {
            if let Some(b) = self.scenarios[..i].iter().find(|b| b.name == a.name) {
                return Err(BatchError::Setting(format!(
                    "scenario name {:?} is used by both {} and {}: names identify result rows \
                     and seeds, so each scenario in a batch needs its own",
                    a.name, b.file, a.file
                )));
            }
        }
        Ok(())
    }
}
