//! A batch's output directory: made new, resumed, or started over, and never one that a batch did not write.

use std::path::Path;

use crate::manifest::{self, Manifest};
use crate::store::remove_if_present;
use crate::{BatchError, BatchSpec, io, provenance};

/// What a batch writes into its directory (besides `recordings/`).
const BATCH_FILES: [&str; 5] = [
    "trials.jsonl",
    "summary.json",
    "summary.md",
    manifest::FILE,
    provenance::RUNS_FILE,
];

/// The files a batch writes into `dir` (besides `recordings/`): what a command reading the
/// batch must not write over.
pub fn batch_files(dir: &Path) -> Vec<std::path::PathBuf> {
    BATCH_FILES.iter().map(|f| dir.join(f)).collect()
}

/// The recordings the batch in `dir` may have written: one name per trial of its
/// `trials.jsonl` (as `batch --record` names them), in either mode, in each format. A
/// file of yours beside them in `recordings/` is not among them.
fn recording_names(dir: &Path) -> std::collections::HashSet<String> {
    let records = crate::store::read_records_torn(&dir.join("trials.jsonl"))
        .map(|(r, _)| r)
        .unwrap_or_default();
    let mut names = std::collections::HashSet::new();
    for r in &records {
        for replan in [false, true] {
            let stem = r.outcome.recording_stem(replan);
            // `ros2.mcap`: a bag as batches wrote it before bags became directories.
            for ext in ["rrd", "mcap", "ros2", "ros2.mcap"] {
                names.insert(format!("{stem}.{ext}"));
            }
        }
    }
    names
}

/// Whether `path` holds only what a batch's `--ros2` bag directory holds (its
/// `metadata.yaml` and MCAP files): a folder with anything else in it is not deleted.
fn is_bag_dir(path: &Path) -> bool {
    use forkbench_core::out_dir::{first_foreign, is_rosbag2_file};
    matches!(first_foreign(path, is_rosbag2_file), Ok(None))
}

impl BatchSpec {
    /// Starts `dir` over for `force_new`, deleting only what a batch wrote: refused where
    /// no manifest says forkbench wrote the directory, and of `recordings/` only the
    /// recordings named for its trials, the folder itself only when that leaves it
    /// empty. No symbolic link is followed.
    fn reset_dir(&self, dir: &Path, want: &Manifest) -> Result<(), BatchError> {
        let ours = Manifest::read(dir).ok().flatten().is_some();
        let rec = dir.join("recordings");
        let present: Vec<&str> = BATCH_FILES
            .iter()
            .copied()
            .filter(|f| dir.join(f).exists())
            .chain(rec.exists().then_some("recordings/"))
            .collect();
        if !ours && !present.is_empty() {
            return Err(BatchError::Directory(format!(
                "{}: force_new starts over only a directory a batch wrote, and this one has no \
                 manifest.json, yet holds {}; nothing was deleted: move them away or choose \
                 another output directory",
                dir.display(),
                present.join(", ")
            )));
        }
        let ours_recorded = recording_names(dir);
        for f in BATCH_FILES {
            remove_if_present(&dir.join(f))?;
        }
        // A `recordings` that is a symbolic link is not descended: what it points at is
        // not the batch's to delete.
        let real_dir = std::fs::symlink_metadata(&rec).is_ok_and(|m| m.file_type().is_dir());
        if real_dir {
            for entry in std::fs::read_dir(&rec).map_err(io(&rec))?.flatten() {
                let path = entry.path();
                let name = entry.file_name().to_string_lossy().into_owned();
                if !ours_recorded.contains(&name) {
                    continue;
                }
                let kind = entry.file_type();
                if kind.as_ref().is_ok_and(std::fs::FileType::is_file) {
                    remove_if_present(&path)?;
                } else if kind.is_ok_and(|t| t.is_dir()) && is_bag_dir(&path) {
                    std::fs::remove_dir_all(&path).map_err(io(&path))?;
                }
            }
            // Left in place when anything else is in it.
            let _ = std::fs::remove_dir(&rec);
        }
        want.write(dir)
    }

    /// Makes `dir` hold this batch: a new directory gets the manifest; an existing one
    /// must have been started with the same settings (or is cleared with `force_new`).
    pub(crate) fn prepare_dir(&self, dir: &Path) -> Result<(), BatchError> {
        let want = Manifest::of(self)?;
        let trials = dir.join("trials.jsonl");
        refuse_foreign_dir(dir)?;
        if self.force_new {
            return self.reset_dir(dir, &want);
        }
        match Manifest::read(dir)? {
            Some(have) => {
                if have.build != want.build {
                    return Err(BatchError::Directory(format!(
                        "{}: its trials were run by {}, and this run is {}: a directory's \
                         results come from one build, so they are not resumed; start over with \
                         `batch --force-new` (`force_new=True` in Python), or choose another \
                         output directory",
                        dir.display(),
                        manifest::build_name(have.build.as_deref()),
                        manifest::build_name(want.build.as_deref()),
                    )));
                }
                let diff = have.differences(&want);
                if !diff.is_empty() {
                    return Err(BatchError::Directory(format!(
                        "{}: holds trials of a different batch ({} differences, directory → \
                         this run: {}); start over with `batch --force-new` \
                         (`force_new=True` in Python), or choose another output directory",
                        dir.display(),
                        diff.len(),
                        diff.iter().take(8).cloned().collect::<Vec<_>>().join("; ")
                    )));
                }
                if have.success_run != want.success_run {
                    // The summary and a later report read the figures from here.
                    let mut have = have;
                    have.success_run = want.success_run;
                    return have.write(dir);
                }
                Ok(())
            }
            None if std::fs::metadata(&trials).is_ok_and(|m| m.len() > 0) => {
                Err(BatchError::Directory(format!(
                    "{}: has trials.jsonl but no manifest.json (written by an older forkbench, or \
                     not by forkbench), so its settings are unknown; move it away or choose \
                     another output directory",
                    dir.display()
                )))
            }
            None => want.write(dir),
        }
    }
}

/// A batch writes only into a new or empty directory, or one with its manifest: a
/// directory that holds anything else (`out="/"`, a home folder) is not a batch's, and
/// neither its files nor the batch's would be safe beside each other.
fn refuse_foreign_dir(dir: &Path) -> Result<(), BatchError> {
    if dir.join(manifest::FILE).is_file() {
        return Ok(());
    }
    let mut others: Vec<String> = std::fs::read_dir(dir)
        .map_err(io(dir))?
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n != ".lock")
        .take(4)
        .collect();
    if others.is_empty() {
        return Ok(());
    }
    others.sort();
    Err(BatchError::Directory(format!(
        "{}: is not empty ({}{}) and has no manifest.json, so no batch wrote it; a batch \
         writes into a new or empty directory, or resumes one it wrote; nothing was written \
         or deleted: choose another output directory",
        dir.display(),
        others
            .iter()
            .map(|n| forkbench_trial::text::visible(n))
            .collect::<Vec<_>>()
            .join(", "),
        if others.len() == 4 { ", …" } else { "" }
    )))
}
