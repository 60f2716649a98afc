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
}

impl Provenance {
    /// This process's provenance for a batch that ran from `started` until now.
    pub fn collect(manifest: Manifest, jobs: usize, started: SystemTime) -> Self {
        let commit = env!("FORKBENCH_GIT_COMMIT");
        Self {
            forkbench_version: env!("CARGO_PKG_VERSION").to_owned(),
            git_commit: (!commit.is_empty()).then(|| commit.to_owned()),
            host: host_name(),
            cpu_model: cpu_model(),
            cores: std::thread::available_parallelism().map_or(1, usize::from),
            jobs,
            arguments: std::env::args().collect(),
            started_at: rfc3339(started),
            finished_at: rfc3339(SystemTime::now()),
            manifest,
        }
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
