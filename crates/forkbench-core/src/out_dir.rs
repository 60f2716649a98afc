//! An output that is a directory (a rosbag2 bag): built in a staging folder beside its path and renamed into place whole, replacing only a directory of the same kind.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use crate::files::FileError;

/// Why a directory output cannot be written at its path.
fn refuse(path: &Path, why: &str) -> FileError {
    FileError::Io {
        path: path.display().to_string(),
        cause: std::io::Error::other(why.to_owned()),
    }
}

/// Checks, before a run, that a directory output may be written at `path`: not standard
/// output or a link, absent unless `force`, and then a directory holding only files that
/// `ours` accepts by name (what this output writes), in a folder that exists. Nothing at
/// `path` is touched.
pub fn check_out_dir(path: &Path, force: bool, ours: fn(&str) -> bool) -> Result<(), FileError> {
    if crate::files::is_stdout(path) {
        return Err(refuse(
            path,
            "standard output carries the run's report; give a directory's path",
        ));
    }
    match std::fs::symlink_metadata(path) {
        Ok(meta) if meta.file_type().is_symlink() => {
            return Err(refuse(
                path,
                "is a symbolic link; an output is not written through a link",
            ));
        }
        Ok(meta) if !meta.is_dir() => {
            return Err(refuse(
                path,
                "exists and is not a directory; this output is a directory (give a new name)",
            ));
        }
        Ok(_) if !force => {
            return Err(refuse(
                path,
                "exists; give --force to replace it, or another name",
            ));
        }
        Ok(_) => check_only_ours(path, ours)?,
        Err(_) => {}
    }
    let parent = parent_of(path);
    if !parent.is_dir() {
        return Err(refuse(
            path,
            &format!("directory {} does not exist", parent.display()),
        ));
    }
    // Probe with a staging folder of our own (removed at once), so a read-only place
    // fails now.
    OutDir::create(path).map(drop)
}

/// The files a rosbag2 directory forkbench writes holds (its `metadata.yaml` and MCAP
/// parts): what `--force` or a batch's restart may replace.
pub fn is_rosbag2_file(name: &str) -> bool {
    name == "metadata.yaml" || name.ends_with(".mcap")
}

/// The first entry of the directory at `path` that is not a regular file `ours` accepts
/// by name: something this output did not write. `Ok(None)`: all of it is ours.
pub fn first_foreign(path: &Path, ours: fn(&str) -> bool) -> std::io::Result<Option<String>> {
    for e in std::fs::read_dir(path)?.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if !e.file_type().is_ok_and(|t| t.is_file()) || !ours(&name) {
            return Ok(Some(name));
        }
    }
    Ok(None)
}

/// A directory that `--force` may replace holds only what this output writes; anything
/// else in it is someone's, and is never deleted.
fn check_only_ours(path: &Path, ours: fn(&str) -> bool) -> Result<(), FileError> {
    let foreign = first_foreign(path, ours).map_err(|cause| FileError::Io {
        path: path.display().to_string(),
        cause,
    })?;
    match foreign {
        Some(name) => Err(refuse(
            path,
            &format!(
                "holds {name}, which this output does not write; it replaces only a \
                 directory it wrote (give another name)"
            ),
        )),
        None => Ok(()),
    }
}

fn parent_of(path: &Path) -> &Path {
    path.parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
}

/// A directory being built in a staging folder beside its path; [`Self::commit`] puts it
/// at the path (replacing what stood there), and a drop without it removes the staging
/// folder, leaving the path as it was.
#[derive(Debug)]
pub struct OutDir {
    path: PathBuf,
    staging: Option<PathBuf>,
}

impl OutDir {
    /// Makes the staging folder for `path`.
    pub fn create(path: &Path) -> Result<Self, FileError> {
        static COUNTER: AtomicU64 = AtomicU64::new(0);
        let name = path
            .file_name()
            .map_or_else(|| "output".to_owned(), |n| n.to_string_lossy().into_owned());
        let staging = parent_of(path).join(format!(
            ".{name}.tmp-{}-{}",
            std::process::id(),
            COUNTER.fetch_add(1, Ordering::Relaxed)
        ));
        std::fs::create_dir(&staging).map_err(|cause| FileError::Io {
            path: path.display().to_string(),
            cause,
        })?;
        Ok(Self {
            path: path.to_owned(),
            staging: Some(staging),
        })
    }

    /// Where a file named `name` of the directory is written before the commit.
    pub fn file(&self, name: &str) -> PathBuf {
        self.staging.as_deref().unwrap_or(&self.path).join(name)
    }

    /// Puts the staged directory at its path. A directory already there (checked by
    /// [`check_out_dir`]) is moved aside first and removed after, so a reader sees the old
    /// bag or the new one.
    pub fn commit(mut self) -> Result<(), FileError> {
        let Some(staging) = self.staging.take() else {
            return Ok(());
        };
        let io = |cause| FileError::Io {
            path: self.path.display().to_string(),
            cause,
        };
        let old = self.path.exists().then(|| {
            let mut aside = staging.clone().into_os_string();
            aside.push(".old");
            PathBuf::from(aside)
        });
        if let Some(old) = &old
            && let Err(e) = std::fs::rename(&self.path, old)
        {
            let _ = std::fs::remove_dir_all(&staging);
            return Err(io(e));
        }
        if let Err(e) = std::fs::rename(&staging, &self.path) {
            let _ = std::fs::remove_dir_all(&staging);
            if let Some(old) = &old {
                let _ = std::fs::rename(old, &self.path);
            }
            return Err(io(e));
        }
        if let Some(old) = old {
            // Held only files this output writes (check_out_dir), so all of it is ours.
            let _ = std::fs::remove_dir_all(old);
        }
        Ok(())
    }
}

impl Drop for OutDir {
    fn drop(&mut self) {
        if let Some(staging) = self.staging.take() {
            let _ = std::fs::remove_dir_all(staging);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A directory output appears whole, replaces only a directory of its own kind with
    /// `force`, and a drop without a commit leaves the path as it was.
    #[test]
    fn a_directory_output_replaces_only_its_own_kind() {
        let dir = std::env::temp_dir().join(format!("fb-outdir-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("dir");
        let bag = dir.join("run.ros2");
        check_out_dir(&bag, false, is_rosbag2_file).expect("a new name");
        let out = OutDir::create(&bag).expect("staging");
        std::fs::write(out.file("metadata.yaml"), "1").expect("write");
        assert!(!bag.exists(), "nothing at the path before the commit");
        out.commit().expect("commit");
        assert_eq!(
            std::fs::read_to_string(bag.join("metadata.yaml"))
                .ok()
                .as_deref(),
            Some("1")
        );
        let e = check_out_dir(&bag, false, is_rosbag2_file)
            .expect_err("exists")
            .to_string();
        assert!(e.contains("--force"), "{e}");
        check_out_dir(&bag, true, is_rosbag2_file).expect("ours, with force");
        let out = OutDir::create(&bag).expect("staging");
        std::fs::write(out.file("metadata.yaml"), "2").expect("write");
        drop(out);
        assert_eq!(
            std::fs::read_to_string(bag.join("metadata.yaml"))
                .ok()
                .as_deref(),
            Some("1")
        );
        let out = OutDir::create(&bag).expect("staging");
        std::fs::write(out.file("metadata.yaml"), "3").expect("write");
        out.commit().expect("replace");
        assert_eq!(
            std::fs::read_to_string(bag.join("metadata.yaml"))
                .ok()
                .as_deref(),
            Some("3")
        );
        std::fs::write(bag.join("notes.txt"), "mine").expect("write");
        let e = check_out_dir(&bag, true, is_rosbag2_file)
            .expect_err("not ours")
            .to_string();
        assert!(e.contains("notes.txt"), "{e}");
        let file = dir.join("plain.mcap");
        std::fs::write(&file, "x").expect("write");
        let e = check_out_dir(&file, true, is_rosbag2_file)
            .expect_err("a file")
            .to_string();
        assert!(e.contains("not a directory"), "{e}");
        let leftovers: Vec<_> = std::fs::read_dir(&dir)
            .expect("list")
            .flatten()
            .map(|e| e.file_name())
            .filter(|n| n.to_string_lossy().starts_with('.'))
            .collect();
        assert!(leftovers.is_empty(), "{leftovers:?}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
