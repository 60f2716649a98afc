//! Where an external component runs: the directory of the file that names it.

use std::path::{Path as FsPath, PathBuf};

/// Where a planner defined in `file` runs: that file's directory.
pub fn dir_of(file: &FsPath) -> PathBuf {
    file.parent()
        .filter(|p| !p.as_os_str().is_empty())
        .map_or_else(|| PathBuf::from("."), FsPath::to_path_buf)
}
