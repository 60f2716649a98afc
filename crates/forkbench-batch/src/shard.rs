//! Shards: `I/N` from the command line or from a scheduler's environment (Slurm job arrays, Kubernetes Indexed Jobs), and their directories.

use std::path::{Path, PathBuf};

use super::BatchError;

/// Which shard to run: given, or taken from the scheduler.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ShardArg {
    /// `I/N`.
    Given(u64, u64),
    /// `auto`: from `SLURM_ARRAY_TASK_*` or `JOB_COMPLETION_INDEX` (with the count given,
    /// since Kubernetes does not export it).
    Auto { count: Option<u64> },
}

/// Parses `I/N` or `auto`.
pub fn parse_shard(text: &str, count: Option<u64>) -> Result<ShardArg, BatchError> {
    let bad = |why: &str| BatchError::Setting(format!("shard {text:?}: {why}"));
    if text.trim() == "auto" {
        return Ok(ShardArg::Auto { count });
    }
    if count.is_some() {
        return Err(bad(
            "shard_count goes with shard auto; I/N names the count itself",
        ));
    }
    let (i, n) = text
        .split_once('/')
        .ok_or_else(|| bad("expected I/N (e.g. 0/4) or auto"))?;
    let num = |s: &str, what: &str| {
        s.trim()
            .parse::<u64>()
            .map_err(|_| bad(&format!("{what} {s:?} is not a whole number")))
    };
    let (i, n) = (num(i, "index")?, num(n, "count")?);
    if n == 0 || i >= n {
        return Err(bad("the index must be below the count (0 ≤ I < N)"));
    }
    Ok(ShardArg::Given(i, n))
}

fn var(env: &dyn Fn(&str) -> Option<String>, name: &str) -> Result<Option<u64>, BatchError> {
    env(name)
        .map(|v| {
            v.trim().parse::<u64>().map_err(|_| {
                BatchError::Setting(format!("shard auto: {name}={v:?} is not a whole number"))
            })
        })
        .transpose()
}

/// A Slurm array task's shard. With the count given (`shard_count N`), the task ID is
/// the shard index, so one index can be resubmitted alone (`sbatch --array=2`) and keep its
/// place; without it, (ID − MIN) / STEP of SLURM_ARRAY_TASK_COUNT.
fn slurm(
    env: &dyn Fn(&str) -> Option<String>,
    given: Option<u64>,
) -> Result<Option<(u64, u64)>, BatchError> {
    let Some(id) = var(env, "SLURM_ARRAY_TASK_ID")? else {
        return Ok(None);
    };
    let max = var(env, "SLURM_ARRAY_TASK_MAX")?;
    if let Some(n) = given {
        let top = max.unwrap_or(id).max(id);
        if top >= n {
            return Err(BatchError::Setting(format!(
                "shard auto: the array reaches task {top} but shard_count is {n}; number \
                 the tasks 0…{} (--array=0-{})",
                n - 1,
                n - 1
            )));
        }
        return Ok(Some((id, n)));
    }
    let min = var(env, "SLURM_ARRAY_TASK_MIN")?.unwrap_or(0);
    let step = var(env, "SLURM_ARRAY_TASK_STEP")?.unwrap_or(1).max(1);
    let count = var(env, "SLURM_ARRAY_TASK_COUNT")?.ok_or_else(|| {
        BatchError::Setting(
            "shard auto: SLURM_ARRAY_TASK_ID is set but SLURM_ARRAY_TASK_COUNT is not".into(),
        )
    })?;
    if id < min || (id - min) % step != 0 {
        return Err(BatchError::Setting(format!(
            "shard auto: array task {id} is not on the range {min}, {min}+{step}, …"
        )));
    }
    let i = (id - min) / step;
    if i >= count || max.is_some_and(|m| (m - min) / step + 1 != count) {
        return Err(BatchError::Setting(format!(
            "shard auto: array task {id} (min {min}, step {step}, max {max:?}) does not fit \
             SLURM_ARRAY_TASK_COUNT={count}; submit a contiguous range such as --array=0-{}",
            count.saturating_sub(1)
        )));
    }
    Ok(Some((i, count)))
}

/// The shard `arg` names, reading the scheduler's variables through `env` for `auto`.
pub fn resolve_shard(
    arg: ShardArg,
    env: &dyn Fn(&str) -> Option<String>,
) -> Result<(u64, u64), BatchError> {
    let count = match arg {
        ShardArg::Given(i, n) => return Ok((i, n)),
        ShardArg::Auto { count } => count,
    };
    let k8s = var(env, "JOB_COMPLETION_INDEX")?;
    let from_slurm = slurm(env, count)?;
    let from_k8s = match (k8s, count) {
        (Some(_), None) => {
            return Err(BatchError::Setting(
                "shard auto: JOB_COMPLETION_INDEX is set; give the Job's completions as \
                 shard_count N (Kubernetes does not export it)"
                    .into(),
            ));
        }
        (Some(i), Some(n)) if i >= n => {
            return Err(BatchError::Setting(format!(
                "shard auto: JOB_COMPLETION_INDEX={i} is not below shard_count {n}"
            )));
        }
        (Some(i), Some(n)) => Some((i, n)),
        (None, _) => None,
    };
    match (from_slurm, from_k8s) {
        (Some(s), Some(k)) if s != k => Err(BatchError::Setting(format!(
            "shard auto: Slurm says shard {}/{} but JOB_COMPLETION_INDEX says {}/{}",
            s.0, s.1, k.0, k.1
        ))),
        (Some(s), _) => Ok(s),
        (None, Some(k)) => Ok(k),
        (None, None) => Err(BatchError::Setting(
            "shard auto: no scheduler shard in the environment (SLURM_ARRAY_TASK_ID for a \
             Slurm job array, JOB_COMPLETION_INDEX for a Kubernetes Indexed Job)"
                .into(),
        )),
    }
}

/// Where shard `i` of `n` of a batch writes under `out`: `out` itself for an unsharded
/// batch, else `out/shard-<i>-of-<n>`, so every shard can share one (network) directory.
pub fn shard_dir(out: &Path, (i, n): (u64, u64)) -> PathBuf {
    if n <= 1 {
        out.to_path_buf()
    } else {
        out.join(format!("shard-{i}-of-{n}"))
    }
}

/// The batch directories `merge` reads: each argument that holds a manifest, or the
/// `shard-*` directories directly inside one that does not (`merge OUT/`; a merged result
/// written inside OUT is not taken for a shard).
pub fn merge_inputs(args: &[PathBuf]) -> Result<Vec<PathBuf>, BatchError> {
    let mut out = Vec::new();
    for a in args {
        if a.join(super::manifest::FILE).is_file() {
            out.push(a.clone());
            continue;
        }
        let entries = std::fs::read_dir(a).map_err(super::io(a))?;
        let mut found: Vec<PathBuf> = entries
            .filter_map(Result::ok)
            .map(|e| e.path())
            .filter(|p| {
                let name = p.file_name().map(|n| n.to_string_lossy().into_owned());
                name.is_some_and(|n| n.starts_with("shard-"))
                    && p.join(super::manifest::FILE).is_file()
            })
            .collect();
        if found.is_empty() {
            return Err(BatchError::Directory(format!(
                "{}: neither a batch directory nor a directory of shard directories",
                a.display()
            )));
        }
        found.sort();
        out.extend(found);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn env(vars: &[(&str, &str)]) -> impl Fn(&str) -> Option<String> {
        let vars: Vec<(String, String)> = vars
            .iter()
            .map(|(k, v)| ((*k).to_owned(), (*v).to_owned()))
            .collect();
        move |k: &str| vars.iter().find(|(n, _)| n == k).map(|(_, v)| v.clone())
    }

    fn auto(count: Option<u64>, vars: &[(&str, &str)]) -> Result<(u64, u64), BatchError> {
        resolve_shard(ShardArg::Auto { count }, &env(vars))
    }

    #[test]
    fn slurm_arrays_from_zero_or_not_and_with_steps() {
        let s = [
            ("SLURM_ARRAY_TASK_ID", "2"),
            ("SLURM_ARRAY_TASK_COUNT", "4"),
        ];
        assert_eq!(auto(None, &s).expect("ok"), (2, 4));
        let s = [
            ("SLURM_ARRAY_TASK_ID", "7"),
            ("SLURM_ARRAY_TASK_MIN", "5"),
            ("SLURM_ARRAY_TASK_MAX", "8"),
            ("SLURM_ARRAY_TASK_COUNT", "4"),
        ];
        assert_eq!(auto(None, &s).expect("ok"), (2, 4));
        let s = [
            ("SLURM_ARRAY_TASK_ID", "4"),
            ("SLURM_ARRAY_TASK_STEP", "2"),
            ("SLURM_ARRAY_TASK_COUNT", "3"),
            ("SLURM_ARRAY_TASK_MAX", "4"),
        ];
        assert_eq!(auto(None, &s).expect("ok"), (2, 3));
        // --array=1,3,7: not a range, refused.
        let s = [
            ("SLURM_ARRAY_TASK_ID", "7"),
            ("SLURM_ARRAY_TASK_MIN", "1"),
            ("SLURM_ARRAY_TASK_MAX", "7"),
            ("SLURM_ARRAY_TASK_COUNT", "3"),
        ];
        assert!(auto(None, &s).is_err());
    }

    #[test]
    fn kubernetes_needs_the_count_and_disagreements_are_refused() {
        let k = [("JOB_COMPLETION_INDEX", "3")];
        assert_eq!(auto(Some(4), &k).expect("ok"), (3, 4));
        assert!(
            auto(None, &k)
                .expect_err("no count")
                .to_string()
                .contains("shard_count")
        );
        assert!(auto(Some(3), &k).is_err(), "index beyond the count");
        // A resubmitted single index keeps its place when the count is given.
        let again = [
            ("SLURM_ARRAY_TASK_ID", "2"),
            ("SLURM_ARRAY_TASK_MIN", "2"),
            ("SLURM_ARRAY_TASK_MAX", "2"),
            ("SLURM_ARRAY_TASK_COUNT", "1"),
        ];
        assert_eq!(auto(Some(4), &again).expect("ok"), (2, 4));
        let wide = [("SLURM_ARRAY_TASK_ID", "1"), ("SLURM_ARRAY_TASK_MAX", "7")];
        assert!(
            auto(Some(4), &wide)
                .expect_err("too wide")
                .to_string()
                .contains("task 7")
        );
        let both = [
            ("JOB_COMPLETION_INDEX", "1"),
            ("SLURM_ARRAY_TASK_ID", "2"),
            ("SLURM_ARRAY_TASK_COUNT", "4"),
        ];
        let e = auto(Some(4), &both).expect_err("disagree").to_string();
        assert!(
            e.contains("Slurm says shard 2/4 but JOB_COMPLETION_INDEX says 1/4"),
            "{e}"
        );
        let e = auto(None, &[]).expect_err("none").to_string();
        assert!(
            e.contains("SLURM_ARRAY_TASK_ID") && e.contains("JOB_COMPLETION_INDEX"),
            "{e}"
        );
        assert!(parse_shard("2/2", None).is_err() && parse_shard("0/2", Some(2)).is_err());
        assert_eq!(parse_shard("1/3", None).expect("ok"), ShardArg::Given(1, 3));
    }
}
