//! Where and how a batch was run: version, commit, host, CPU, threads, arguments, times, and its manifest.

use std::time::SystemTime;

use serde::{Deserialize, Serialize};

use super::Manifest;

/// Provenance of a batch's results, kept in `summary.json`, baselines and reports.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Provenance {
    pub forkbench_version: String,
    /// The commit forkbench was built from, when built from a git checkout.
    pub git_commit: Option<String>,
    pub host: String,
    pub cpu_model: String,
    /// Cores the machine offers, and worker threads the batch used.
    pub cores: usize,
    pub jobs: usize,
    /// The command line of the process that ran the batch.
    pub arguments: Vec<String>,
    /// UTC, RFC 3339.
    pub started_at: String,
    pub finished_at: String,
    /// Seed, trials, shard, planners, trackers, overrides and every scenario resolved in
    /// full (truck, tracker, sensors, tolerances, cases).
    pub manifest: Manifest,
    /// Every run that wrote trials into the directory, the first one (the original
    /// command) first, then each resume.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub runs: Vec<RunEntry>,
}

/// One invocation of a batch on its directory.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunEntry {
    pub started_at: String,
    /// None when the run was interrupted.
    pub finished_at: Option<String>,
    pub arguments: Vec<String>,
    pub host: String,
    pub jobs: usize,
    /// Trials this run had left to do when it started.
    pub trials_to_run: u64,
}

/// The run log of a batch directory: one JSON line per invocation.
pub(super) const RUNS_FILE: &str = "runs.jsonl";

/// Appends this invocation to `dir`'s run log.
pub(super) fn log_run(
    dir: &std::path::Path,
    jobs: usize,
    trials_to_run: u64,
    started: SystemTime,
) -> Result<(), super::BatchError> {
    use std::io::Write as _;
    let entry = RunEntry {
        started_at: rfc3339(started),
        finished_at: None,
        arguments: std::env::args().collect(),
        host: host_name(),
        jobs,
        trials_to_run,
    };
    let path = dir.join(RUNS_FILE);
    let line =
        serde_json::to_string(&entry).map_err(|e| super::BatchError::Internal(e.to_string()))?;
    std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(&path)
        .and_then(|mut f| writeln!(f, "{line}"))
        .map_err(super::io(&path))
}

/// The run log of `dir` (unreadable lines skipped: it is informative) with this run, the
/// last, marked finished now and written back; a run without a finish was interrupted.
pub(super) fn finish_runs(dir: &std::path::Path) -> Vec<RunEntry> {
    let path = dir.join(RUNS_FILE);
    let text = forkbench_core::files::read_text(&path, 16 << 20).unwrap_or_default();
    let mut runs: Vec<RunEntry> = text
        .lines()
        .filter_map(|l| serde_json::from_str(l).ok())
        .collect();
    if let Some(last) = runs.last_mut() {
        last.finished_at = Some(rfc3339(SystemTime::now()));
    }
    let lines: Vec<String> = runs
        .iter()
        .filter_map(|r| serde_json::to_string(r).ok())
        .collect();
    // Informative only: a failed rewrite leaves the log as it was.
    let _ = forkbench_core::files::write_atomic(&path, (lines.join("\n") + "\n").as_bytes());
    runs
}

impl Provenance {
    /// This process's provenance for a batch that ran from `started` until now.
    pub fn collect(manifest: Manifest, jobs: usize, started: SystemTime) -> Self {
        Self {
            forkbench_version: env!("CARGO_PKG_VERSION").to_owned(),
            git_commit: super::manifest::build_commit(),
            host: host_name(),
            cpu_model: cpu_model(),
            cores: std::thread::available_parallelism().map_or(1, usize::from),
            jobs,
            arguments: std::env::args().collect(),
            started_at: rfc3339(started),
            finished_at: rfc3339(SystemTime::now()),
            manifest,
            runs: Vec::new(),
        }
    }

    /// This provenance over a resumed directory's runs: started and commanded as its
    /// first run, every run listed.
    pub fn with_runs(mut self, runs: Vec<RunEntry>) -> Self {
        if let Some(first) = runs.first() {
            self.started_at = first.started_at.clone();
            self.arguments = first.arguments.clone();
        }
        self.runs = runs;
        self
    }
}

/// UTC time to the second, RFC 3339.
pub fn rfc3339(t: SystemTime) -> String {
    humantime::format_rfc3339_seconds(t).to_string()
}

fn host_name() -> String {
    std::fs::read_to_string("/proc/sys/kernel/hostname")
        .ok()
        .or_else(|| std::env::var("HOSTNAME").ok())
        .map_or_else(|| "unknown".to_owned(), |h| h.trim().to_owned())
}

fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|t| {
            t.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split_once(':'))
                .map(|(_, v)| v.trim().to_owned())
        })
        .unwrap_or_else(|| std::env::consts::ARCH.to_owned())
}

/// Per scenario, where two manifests' resolved settings differ (`scenario: field: a → b`):
/// a baseline made with other tolerances or sensors is not comparable row for row.
pub fn scenario_differences(base: &Manifest, now: &Manifest) -> Vec<String> {
    let mut out = Vec::new();
    for n in &now.scenarios {
        let Some(b) = base.scenarios.iter().find(|b| b.name == n.name) else {
            continue;
        };
        if b.settings_hash == n.settings_hash {
            continue;
        }
        let mut diffs = Vec::new();
        super::manifest::diff_values("", &b.settings, &n.settings, &mut diffs);
        for d in diffs.into_iter().take(8) {
            out.push(format!("{}: {d}", n.name));
        }
    }
    out
}
