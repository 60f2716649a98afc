//! A batch directory's identity: the manifest of what its trials were run with, and the lock that keeps one writer.

use std::collections::HashSet;
use std::fs::File;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use serde_json::Value;

use super::{BatchError, BatchSpec, io};

/// Everything a batch's results depend on. Resuming, merging and reading results check
/// it, so a directory never mixes trials run with different settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    pub forkbench_version: String,
    /// The git commit forkbench was built from (`None` when built outside a checkout):
    /// a directory's trials all come from one build, so resuming with another is refused.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub build: Option<String>,
    pub seed: u64,
    /// How trial seeds derive from `seed` ([`super::SEED_SCHEME`]); manifests written
    /// before the scheme was named used scheme 1.
    #[serde(default = "scheme_one")]
    pub seed_scheme: u32,
    pub trials: u64,
    /// [index, count]; [0, 1] for an unsharded batch or a merge.
    pub shard: [u64; 2],
    /// Planners every case ran with; empty = each scenario's own.
    pub planners: Vec<String>,
    /// Trackers every case ran with; empty = each scenario's own.
    #[serde(default)]
    pub trackers: Vec<String>,
    /// What the run changed of each scenario (noise scales, sensing models, the truck's
    /// actuators), under the options' own names: the one definition
    /// ([`forkbench_trial::trial::Overrides`]), not a copy.
    #[serde(flatten)]
    pub overrides: forkbench_trial::trial::Overrides,
    pub replan: Option<bool>,
    /// Every trial run planning once and replanning.
    #[serde(default)]
    pub compare_replanning: bool,
    /// The confidence and reliability its summary states success runs at: how the
    /// results are read, not how they were run, so a resume may change it.
    #[serde(default)]
    pub success_run: crate::success_run::SuccessTarget,
    pub scenarios: Vec<ScenarioEntry>,
}

/// One scenario as it was resolved (file contents, world, truck, tracker, sensors,
/// tolerances and cases): its identity is its content, not its name or path.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScenarioEntry {
    pub name: String,
    /// Where it was loaded from: informative only, not compared.
    pub file: String,
    /// FNV-1a of `settings` as compact JSON.
    pub settings_hash: String,
    pub settings: Value,
    /// The external components it runs in this batch, each with the content of the files
    /// its command names: an edited script makes a resume refuse, naming the file.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub components: Vec<crate::prints::ComponentPrint>,
}

impl ScenarioEntry {
    /// The entry of `s`: its resolved settings (without the path) and their hash.
    pub fn of(s: &forkbench_trial::Scenario) -> Result<Self, BatchError> {
        let mut settings =
            serde_json::to_value(s).map_err(|e| BatchError::Internal(e.to_string()))?;
        if let Some(map) = settings.as_object_mut() {
            map.remove("file");
        }
        Ok(ScenarioEntry {
            name: s.name.clone(),
            file: s.file.clone(),
            settings_hash: format!(
                "{:016x}",
                forkbench_core::hash::fnv1a(settings.to_string().bytes())
            ),
            settings,
            components: Vec::new(),
        })
    }
}

pub(super) const FILE: &str = "manifest.json";

/// The git commit this forkbench was built from, when it was built from a checkout; with
/// `-changed-` and a fingerprint of the changes when its sources differed from the commit
/// (edited or new files under `crates/` or `scenarios/`, or the workspace's manifest or
/// lock file), so two builds of one commit with different edits are told apart.
pub fn build_commit() -> Option<String> {
    build_of(env!("FORKBENCH_GIT_COMMIT"), env!("FORKBENCH_GIT_CHANGES"))
}

fn build_of(commit: &str, changes: &str) -> Option<String> {
    match (commit, changes) {
        ("", _) => None,
        (c, "") => Some(c.to_owned()),
        (c, f) => Some(format!("{c}{CHANGED}{f}")),
    }
}

/// What separates a commit from the fingerprint of the changes it was built with.
const CHANGED: &str = "-changed-";

/// A build as a message names it.
pub(super) fn build_name(build: Option<&str>) -> String {
    let Some(build) = build else {
        return "a forkbench that recorded no commit (built outside a git checkout, or \
                before batches recorded it)"
            .to_owned();
    };
    // A manifest is a file anyone may edit: cut at a character, shown escaped.
    let cut =
        |s: &str, n: usize| forkbench_trial::text::visible(&s.chars().take(n).collect::<String>());
    match build.split_once(CHANGED) {
        Some((commit, changes)) => format!(
            "the forkbench built from commit {} with changed sources (fingerprint {})",
            cut(commit, 12),
            cut(changes, 16)
        ),
        None => format!("the forkbench built from commit {}", cut(build, 12)),
    }
}

fn scheme_one() -> u32 {
    1
}

impl Manifest {
    /// The manifest of a batch spec.
    pub fn of(spec: &BatchSpec) -> Result<Self, BatchError> {
        let scenarios = spec
            .scenarios
            .iter()
            .map(|s| {
                let mut e = ScenarioEntry::of(s)?;
                e.components = crate::prints::prints_of(s, &spec.planners, &spec.trackers);
                Ok(e)
            })
            .collect::<Result<_, BatchError>>()?;
        Ok(Manifest {
            forkbench_version: env!("CARGO_PKG_VERSION").to_owned(),
            build: build_commit(),
            seed: spec.seed,
            seed_scheme: super::SEED_SCHEME,
            trials: spec.trials,
            shard: [spec.shard.0, spec.shard.1],
            planners: spec.planners.clone(),
            trackers: spec.trackers.clone(),
            overrides: spec.overrides.clone(),
            replan: spec.replan,
            compare_replanning: spec.compare_replanning,
            success_run: spec.success_run,
            scenarios,
        })
    }

    /// The manifest in `dir`, if there is one.
    pub fn read(dir: &Path) -> Result<Option<Self>, BatchError> {
        let path = dir.join(FILE);
        let text = match std::fs::read_to_string(&path) {
            Ok(t) => t,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(e) => return Err(io(&path)(e)),
        };
        serde_json::from_str(&text)
            .map(Some)
            .map_err(|e| BatchError::Record {
                path: path.display().to_string(),
                line: e.line(),
                message: e.to_string(),
            })
    }

    pub fn write(&self, dir: &Path) -> Result<(), BatchError> {
        let path = dir.join(FILE);
        let text =
            serde_json::to_string_pretty(self).map_err(|e| BatchError::Internal(e.to_string()))?;
        super::write_atomic(&path, (text + "\n").as_bytes())
    }

    /// Why this batch's trials are not `other`'s (named `other_name`) at the same keys:
    /// another batch seed, or trial seeds derived by another scheme; `None` when they
    /// are, whatever else changed (a trial's seed depends on nothing else).
    pub fn seed_difference(&self, other: &Manifest, other_name: &str) -> Option<String> {
        let mut why = Vec::new();
        if other.seed != self.seed {
            why.push(format!(
                "batch seed {} ≠ {other_name}'s {}",
                self.seed, other.seed
            ));
        }
        if other.seed_scheme != self.seed_scheme {
            why.push(format!(
                "trial seeds derived by scheme {} ≠ {other_name}'s {}",
                self.seed_scheme, other.seed_scheme
            ));
        }
        (!why.is_empty()).then(|| why.join("; "))
    }

    /// Where two manifests differ, as `field: ours → theirs` lines (paths into the JSON;
    /// scenario files' paths are left out, their content is compared).
    pub fn differences(&self, other: &Manifest) -> Vec<String> {
        let mut out = Vec::new();
        let (a, b) = (self.comparable(), other.comparable());
        diff_values("", &a, &b, &mut out);
        out
    }

    /// Where two manifests differ other than in the shard index: empty for shards of one
    /// batch.
    pub fn batch_differences(&self, other: &Manifest) -> Vec<String> {
        let mut o = other.clone();
        o.shard[0] = self.shard[0];
        self.differences(&o)
    }

    fn comparable(&self) -> Value {
        let mut v = serde_json::to_value(self).unwrap_or(Value::Null);
        if let Some(map) = v.as_object_mut() {
            map.remove("success_run");
        }
        if let Some(list) = v.get_mut("scenarios").and_then(Value::as_array_mut) {
            for s in list {
                if let Some(map) = s.as_object_mut() {
                    map.remove("file");
                    map.remove("settings_hash");
                }
            }
        }
        v
    }

    /// The key of every trial this manifest's batch (this shard of it) runs, in the order
    /// `BatchSpec::jobs` makes them; none when a scenario's settings lack a name this
    /// needs (a manifest written by another version).
    pub fn expected_keys(&self) -> Option<HashSet<super::TrialKey>> {
        let mut scenarios = Vec::new();
        let mut names: Vec<(Vec<String>, bool)> = Vec::new();
        for s in &self.scenarios {
            let v = &s.settings;
            let own = |role: &str| Some(vec![v.get(role)?.get("name")?.as_str()?.to_owned()]);
            let or_own = |list: &Vec<String>, role| {
                (!list.is_empty())
                    .then(|| list.clone())
                    .or_else(|| own(role))
            };
            let cases = v.get("cases")?.as_array()?;
            let case_names = cases
                .iter()
                .map(|c| c.get("name")?.as_str().map(str::to_owned))
                .collect::<Option<Vec<_>>>()?;
            scenarios.push(super::order::ScenarioJobs {
                cases: case_names.len(),
                planners: or_own(&self.planners, "planner")?,
                trackers: or_own(&self.trackers, "tracker")?,
            });
            names.push((case_names, v.get("replan")?.get("enabled")?.as_bool()?));
        }
        let modes = super::order::modes(self.compare_replanning, self.replan);
        let (shard, mut out) = ((self.shard[0], self.shard[1]), HashSet::new());
        super::order::for_each_job(&scenarios, &modes, self.trials, shard, |j| {
            let (cases, own_mode) = &names[j.scenario];
            out.insert((
                self.scenarios[j.scenario].name.clone(),
                cases[j.case].clone(),
                j.planner.to_owned(),
                j.tracker.to_owned(),
                j.mode.unwrap_or(*own_mode),
                j.trial,
            ));
        });
        Some(out)
    }

    /// Trials this manifest's batch (this shard of it) runs.
    pub fn expected_trials(&self) -> u64 {
        let modes = if self.compare_replanning { 2 } else { 1 };
        let components = (self.planners.len().max(1) * self.trackers.len().max(1) * modes) as u64;
        let total: u64 = self
            .scenarios
            .iter()
            .map(|s| {
                let cases = s.settings.get("cases").and_then(Value::as_array);
                cases.map_or(0, |c| c.len() as u64) * components * self.trials
            })
            .sum();
        let [i, n] = self.shard;
        if n == 0 || i >= total {
            return 0;
        }
        (total - i).div_ceil(n)
    }
}

pub(super) fn diff_values(path: &str, a: &Value, b: &Value, out: &mut Vec<String>) {
    match (a, b) {
        (Value::Object(x), Value::Object(y)) => {
            let mut keys: Vec<&String> = x.keys().chain(y.keys()).collect();
            keys.sort();
            keys.dedup();
            for k in keys {
                let p = if path.is_empty() {
                    k.clone()
                } else {
                    format!("{path}.{k}")
                };
                diff_values(
                    &p,
                    x.get(k).unwrap_or(&Value::Null),
                    y.get(k).unwrap_or(&Value::Null),
                    out,
                );
            }
        }
        (Value::Array(x), Value::Array(y)) if x.len() == y.len() => {
            for (i, (u, v)) in x.iter().zip(y).enumerate() {
                diff_values(&format!("{path}[{i}]"), u, v, out);
            }
        }
        _ if a != b => out.push(format!("{path}: {} → {}", short(a), short(b))),
        _ => {}
    }
}

fn short(v: &Value) -> String {
    let s = v.to_string();
    if s.chars().count() > 60 {
        format!("{}…", s.chars().take(60).collect::<String>())
    } else {
        s
    }
}

/// An exclusive lock on a batch directory, held while a batch or merge writes it.
#[derive(Debug)]
pub struct DirLock {
    _file: File,
    pub path: PathBuf,
}

impl DirLock {
    /// Takes the lock on `dir` (creating `dir/.lock`), or names the directory another
    /// process is writing.
    pub fn take(dir: &Path) -> Result<Self, BatchError> {
        let path = dir.join(".lock");
        let file = File::create(&path).map_err(io(&path))?;
        match file.try_lock() {
            Ok(()) => Ok(DirLock { _file: file, path }),
            Err(std::fs::TryLockError::WouldBlock) => Err(BatchError::Directory(format!(
                "{}: another forkbench process is writing this directory (lock held on {}); \
                 wait for it to finish or choose another --out",
                dir.display(),
                path.display()
            ))),
            Err(std::fs::TryLockError::Error(e)) => Err(io(&path)(e)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_build_from_changed_sources_is_named_apart_from_its_commit() {
        let commit = "0123456789abcdef0123456789abcdef01234567";
        assert_eq!(build_of("", "ffff"), None);
        assert_eq!(build_of(commit, "").as_deref(), Some(commit));
        let changed = build_of(commit, "00c0ffee00c0ffee").expect("a build");
        assert_ne!(Some(changed.clone()), build_of(commit, ""));
        assert_ne!(Some(changed.clone()), build_of(commit, "11c0ffee00c0ffee"));
        assert_eq!(
            build_name(Some(&changed)),
            "the forkbench built from commit 0123456789ab with changed sources (fingerprint \
             00c0ffee00c0ffee)"
        );
        assert_eq!(
            build_name(Some(commit)),
            "the forkbench built from commit 0123456789ab"
        );
        assert!(build_name(None).contains("recorded no commit"));
    }
}

#[cfg(test)]
mod flatten_tests {
    use super::*;

    fn manifest() -> Manifest {
        Manifest {
            forkbench_version: "0".into(),
            build: None,
            seed: 1,
            seed_scheme: 2,
            trials: 3,
            shard: [0, 1],
            planners: vec![],
            trackers: vec![],
            overrides: forkbench_trial::trial::Overrides {
                pallet_noise_scale: Some(0.5),
                truck_preset: Some("realistic".into()),
                ..Default::default()
            },
            replan: None,
            compare_replanning: false,
            success_run: Default::default(),
            scenarios: vec![],
        }
    }

    /// The run's options sit in the manifest under their own names, as before they were
    /// one type; an unknown key is still refused, and a manifest that wrote a missing
    /// scale as null still reads.
    #[test]
    fn the_options_are_the_manifests_own_keys_and_unknown_keys_are_refused() {
        let m = manifest();
        let text = serde_json::to_string(&m).expect("writes");
        assert!(text.contains(r#""pallet_noise_scale":0.5"#), "{text}");
        assert!(text.contains(r#""truck_preset":"realistic""#), "{text}");
        assert!(!text.contains("overrides"), "{text}");
        assert_eq!(serde_json::from_str::<Manifest>(&text).expect("reads"), m);
        let old = text.replace(
            r#""pallet_noise_scale":0.5"#,
            r#""pallet_noise_scale":null"#,
        );
        let back: Manifest = serde_json::from_str(&old).expect("an older manifest reads");
        assert_eq!(back.overrides.pallet_noise_scale, None);
        let extra = text.replacen('{', r#"{"pallet_noise":2.0,"#, 1);
        let e = serde_json::from_str::<Manifest>(&extra).expect_err("an unknown key");
        assert!(e.to_string().contains("pallet_noise"), "{e}");
    }
}
