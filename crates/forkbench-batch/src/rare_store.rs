//! An estimate's or a search's directory: the run's settings (`rare.json`), its trials appended to `trials.jsonl` as each stage ends, and a resume that reruns none of them.

use std::fs::{File, OpenOptions};
use std::io::Write as _;
use std::path::{Path, PathBuf};

use serde_json::Value;

use crate::rare::Tried;
use crate::{BatchError, io};

/// The run's settings, beside its trials.
const SETTINGS_FILE: &str = "rare.json";
/// Every trial, in the order it was run, with its point.
pub const TRIALS_FILE: &str = "trials.jsonl";
/// Largest `rare.json` read (a scenario's resolved settings, world included).
const MAX_SETTINGS_BYTES: u64 = 64 << 20;
/// The results a run writes at its end.
const RESULT_FILES: [&str; 2] = ["estimate.json", "falsify.json"];
/// The lock a run holds on its directory while it writes there (a batch's too).
const LOCK_FILE: &str = ".lock";
/// Every file a run writes in its directory.
pub const OUT_FILES: [&str; 5] = [
    SETTINGS_FILE,
    TRIALS_FILE,
    RESULT_FILES[0],
    RESULT_FILES[1],
    LOCK_FILE,
];

/// The trials a directory already holds for this run, and where new ones are appended.
#[derive(Debug)]
pub struct RareStore {
    /// The first trials of this run, from an earlier one that stopped.
    pub(crate) prior: Vec<Tried>,
    /// Where new trials go, once the run has started.
    file: Option<File>,
    dir: PathBuf,
    settings: Value,
    /// Held while the run may write: a second run on the same directory is refused
    /// rather than appending its trials among these.
    _lock: crate::DirLock,
}

impl RareStore {
    /// Opens `dir` for the run `settings` describes. A directory holding this run's
    /// trials resumes them; one with another run's is refused unless `force_new`, which
    /// starts over (deleting only the files a run writes).
    pub fn open(dir: &Path, settings: &Value, force_new: bool) -> Result<Self, BatchError> {
        std::fs::create_dir_all(dir).map_err(io(dir))?;
        let lock = crate::DirLock::take(dir)?;
        let (settings_path, path) = (dir.join(SETTINGS_FILE), dir.join(TRIALS_FILE));
        if std::fs::metadata(&settings_path).is_ok_and(|m| m.len() > MAX_SETTINGS_BYTES) {
            return Err(BatchError::Content(format!(
                "{}: more than {MAX_SETTINGS_BYTES} bytes, not a run's settings",
                settings_path.display()
            )));
        }
        let have =
            match std::fs::read(&settings_path) {
                Ok(b) => Some(serde_json::from_slice::<Value>(&b).map_err(|e| {
                    BatchError::Content(format!("{}: {e}", settings_path.display()))
                })?),
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => None,
                Err(e) => return Err(io(&settings_path)(e)),
            };
        let has_trials = std::fs::metadata(&path).is_ok_and(|m| m.len() > 0);
        let prior = match have {
            _ if force_new => Vec::new(),
            Some(h) if &h == settings => read_prior(&path)?,
            Some(h) => return Err(other_run(dir, &h, settings)),
            None if has_trials => {
                return Err(BatchError::Directory(format!(
                    "{}: has trials.jsonl but no {SETTINGS_FILE} (written by an older \
                     forkbench), so what it ran is unknown; use --force-new or another \
                     directory",
                    dir.display()
                )));
            }
            None => Vec::new(),
        };
        Ok(RareStore {
            prior,
            file: None,
            dir: dir.to_path_buf(),
            settings: settings.clone(),
            _lock: lock,
        })
    }

    /// Makes the directory this run's, at its first trials (so a run refused before it
    /// starts changes nothing): no earlier result beside them, its settings, the
    /// resumed trials rewritten as they parsed (a line torn by a kill gone).
    fn start(&mut self) -> Result<File, BatchError> {
        for name in RESULT_FILES {
            let p = self.dir.join(name);
            match std::fs::remove_file(&p) {
                Err(e) if e.kind() != std::io::ErrorKind::NotFound => return Err(io(&p)(e)),
                _ => {}
            }
        }
        let settings = self.settings.to_string();
        crate::write_atomic(&self.dir.join(SETTINGS_FILE), settings.as_bytes())?;
        let path = self.dir.join(TRIALS_FILE);
        crate::write_atomic(&path, lines(&self.prior)?.as_bytes())?;
        OpenOptions::new()
            .append(true)
            .open(&path)
            .map_err(io(&path))
    }

    /// Trials already done, reused in order.
    pub fn resumed(&self) -> usize {
        self.prior.len()
    }

    /// Appends newly run trials and flushes them, so a kill loses at most a stage.
    pub(crate) fn append(&mut self, new: &[Tried]) -> Result<(), BatchError> {
        if self.file.is_none() {
            self.file = Some(self.start()?);
        }
        let Some(file) = self.file.as_mut() else {
            return Ok(());
        };
        file.write_all(lines(new)?.as_bytes())
            .and_then(|()| file.flush())
            .map_err(io(&self.dir.join(TRIALS_FILE)))
    }
}

/// Trials as JSON lines.
fn lines(trials: &[Tried]) -> Result<String, BatchError> {
    let mut text = String::new();
    for t in trials {
        text += &serde_json::to_string(t).map_err(|e| BatchError::Internal(e.to_string()))?;
        text.push('\n');
    }
    Ok(text)
}

/// The trials of `path`, read as a batch's records are (a torn last line dropped, each
/// record consistent).
fn read_prior(path: &Path) -> Result<Vec<Tried>, BatchError> {
    let (numbered, _) =
        crate::store::read_jsonl(path, |t: &Tried| crate::store::contradiction(&t.record))?;
    Ok(numbered.into_iter().map(|(_, t)| t).collect())
}

/// The refusal of a directory holding another run, naming what differs.
fn other_run(dir: &Path, have: &Value, want: &Value) -> BatchError {
    let mut diff = Vec::new();
    crate::manifest::diff_values("", have, want, &mut diff);
    BatchError::Directory(format!(
        "{}: holds the trials of another run ({} differences, directory → this run: {}); \
         start over with --force-new, or choose another directory",
        dir.display(),
        diff.len(),
        diff.iter().take(6).cloned().collect::<Vec<_>>().join("; ")
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_second_run_on_a_directory_in_use_is_refused() {
        let dir = std::env::temp_dir().join(format!("forkbench-rare-lock-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let settings = serde_json::json!({ "estimate": "ce" });
        let first = RareStore::open(&dir, &settings, false).expect("opens");
        let e = RareStore::open(&dir, &settings, false).expect_err("in use");
        assert!(
            e.to_string()
                .contains("another forkbench process is writing"),
            "{e}"
        );
        drop(first);
        RareStore::open(&dir, &settings, false).expect("free again");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
