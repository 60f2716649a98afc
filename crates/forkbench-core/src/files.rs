//! Reading input files safely (regular files only, size-capped) and writing outputs atomically.

use std::io::{Read as _, Write as _};
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};

/// Why an input file could not be read, or an output written. Messages name the file and
/// the reason, never the file's contents.
#[derive(Debug, thiserror::Error)]
pub enum FileError {
    #[error("{path}: {cause}")]
    Io { path: String, cause: std::io::Error },
    #[error("{path}: not a regular file ({kind}); give a file's path")]
    NotRegular { path: String, kind: &'static str },
    #[error("{path}: larger than {max} bytes, the most read for this kind of file")]
    TooLarge { path: String, max: u64 },
    #[error("{path}: not UTF-8 text")]
    NotText { path: String },
    #[error(
        "{path}: exists and is {kind}, which an output would replace; give a file's path, \
         or - for standard output"
    )]
    NotAnOutput { path: String, kind: &'static str },
    #[error("{path}: is {input}, which this command reads; give the output another name")]
    IsInput { path: String, input: String },
}

impl FileError {
    /// The file the error is about.
    pub fn path(&self) -> &str {
        match self {
            Self::Io { path, .. }
            | Self::NotRegular { path, .. }
            | Self::TooLarge { path, .. }
            | Self::NotText { path }
            | Self::NotAnOutput { path, .. }
            | Self::IsInput { path, .. } => path,
        }
    }

    /// The message without the file's name, for a caller that names the file itself.
    pub fn reason(&self) -> String {
        match self {
            Self::Io { cause, .. } => cause.to_string(),
            other => {
                let text = other.to_string();
                let prefix = format!("{}: ", other.path());
                text.strip_prefix(&prefix).unwrap_or(&text).to_owned()
            }
        }
    }
}

fn io_err(path: &Path) -> impl FnOnce(std::io::Error) -> FileError + '_ {
    move |cause| FileError::Io {
        path: path.display().to_string(),
        cause,
    }
}

fn kind_of(t: std::fs::FileType) -> &'static str {
    use std::os::unix::fs::FileTypeExt as _;
    if t.is_dir() {
        "a directory"
    } else if t.is_fifo() {
        "a FIFO"
    } else if t.is_char_device() || t.is_block_device() {
        "a device"
    } else if t.is_socket() {
        "a socket"
    } else if t.is_symlink() {
        "a symbolic link"
    } else {
        "not a file"
    }
}

/// An output may replace a regular file, or create one; what else stands at `path` (a
/// symbolic link, FIFO, device, socket or folder) is refused, never replaced.
pub fn check_output(path: &Path) -> Result<(), FileError> {
    match std::fs::symlink_metadata(path) {
        Ok(m) if !m.file_type().is_file() => Err(FileError::NotAnOutput {
            path: path.display().to_string(),
            kind: kind_of(m.file_type()),
        }),
        _ => Ok(()),
    }
}

/// An output that would replace one of the command's `inputs` is refused: it would
/// destroy what the command reads.
pub fn check_not_input(out: &Path, inputs: &[std::path::PathBuf]) -> Result<(), FileError> {
    let Ok(o) = std::fs::canonicalize(out) else {
        return Ok(());
    };
    match inputs
        .iter()
        .find(|i| std::fs::canonicalize(i).is_ok_and(|c| c == o))
    {
        Some(i) => Err(FileError::IsInput {
            path: out.display().to_string(),
            input: i.display().to_string(),
        }),
        None => Ok(()),
    }
}

/// Whether `path` means standard output (`-`).
pub fn is_stdout(path: &Path) -> bool {
    path.as_os_str() == "-"
}

/// The files in `dir` whose name ends in `.{ext}`, in name order (a rosbag2 directory's
/// parts, which a split bag numbers in order).
pub fn files_with_extension(dir: &Path, ext: &str) -> std::io::Result<Vec<std::path::PathBuf>> {
    let mut files: Vec<std::path::PathBuf> = std::fs::read_dir(dir)?
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == ext))
        .collect();
    files.sort();
    Ok(files)
}

/// Reads at most `max` bytes of `path`, which must be a regular file (a FIFO would block,
/// a device never end).
pub fn read_bytes(path: &Path, max: u64) -> Result<Vec<u8>, FileError> {
    let meta = std::fs::metadata(path).map_err(io_err(path))?;
    if !meta.is_file() {
        return Err(FileError::NotRegular {
            path: path.display().to_string(),
            kind: kind_of(meta.file_type()),
        });
    }
    if meta.len() > max {
        return Err(FileError::TooLarge {
            path: path.display().to_string(),
            max,
        });
    }
    let file = std::fs::File::open(path).map_err(io_err(path))?;
    let mut bytes = Vec::new();
    file.take(max + 1)
        .read_to_end(&mut bytes)
        .map_err(io_err(path))?;
    if bytes.len() as u64 > max {
        return Err(FileError::TooLarge {
            path: path.display().to_string(),
            max,
        });
    }
    Ok(bytes)
}

/// [`read_bytes`] as UTF-8 text.
pub fn read_text(path: &Path, max: u64) -> Result<String, FileError> {
    String::from_utf8(read_bytes(path, max)?).map_err(|_| FileError::NotText {
        path: path.display().to_string(),
    })
}

/// The temporary file beside `path` that becomes it.
fn temporary(path: &Path) -> std::path::PathBuf {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let name = path
        .file_name()
        .map_or_else(|| "output".to_owned(), |n| n.to_string_lossy().into_owned());
    dir.join(format!(
        ".{name}.tmp-{}-{}",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    ))
}

/// A file written as it is computed, that appears at its path only when committed (a
/// temporary file beside it, flushed, renamed), and is removed if never committed.
#[derive(Debug)]
pub struct AtomicWriter {
    path: std::path::PathBuf,
    tmp: std::path::PathBuf,
    file: Option<std::io::BufWriter<std::fs::File>>,
}

impl AtomicWriter {
    pub fn create(path: &Path) -> Result<Self, FileError> {
        check_output(path)?;
        let tmp = temporary(path);
        let file = std::fs::File::create(&tmp).map_err(io_err(path))?;
        Ok(Self {
            path: path.to_owned(),
            tmp,
            file: Some(std::io::BufWriter::new(file)),
        })
    }

    /// Appends `bytes`; an error names the final path.
    pub fn write(&mut self, bytes: &[u8]) -> Result<(), FileError> {
        match self.file.as_mut() {
            Some(f) => f.write_all(bytes).map_err(io_err(&self.path)),
            None => Ok(()),
        }
    }

    /// Flushes to disk and renames the file into place.
    pub fn commit(mut self) -> Result<(), FileError> {
        let Some(f) = self.file.take() else {
            return Ok(());
        };
        let result = f
            .into_inner()
            .map_err(|e| e.into_error())
            .and_then(|f| f.sync_all())
            .and_then(|()| std::fs::rename(&self.tmp, &self.path));
        if result.is_err() {
            let _ = std::fs::remove_file(&self.tmp);
        }
        result.map_err(io_err(&self.path))
    }
}

impl Drop for AtomicWriter {
    fn drop(&mut self) {
        if self.file.take().is_some() {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

/// A file written elsewhere (a writer thread owns the handle) that appears at its path
/// only when committed: a temporary file beside it, renamed into place. Dropped
/// uncommitted, the temporary file is removed and the path left as it was, so a refused
/// or failed run replaces nothing.
#[derive(Debug)]
pub struct Partial {
    path: std::path::PathBuf,
    tmp: Option<std::path::PathBuf>,
}

impl Partial {
    /// The temporary file for `path` (checked with [`check_output`]), and its handle.
    pub fn create(path: &Path) -> Result<(Self, std::fs::File), FileError> {
        check_output(path)?;
        let tmp = temporary(path);
        let file = std::fs::File::create_new(&tmp).map_err(io_err(path))?;
        Ok((
            Self {
                path: path.to_owned(),
                tmp: Some(tmp),
            },
            file,
        ))
    }

    /// Renames the written file into place (its handle closed by the writer first).
    pub fn commit(mut self) -> Result<(), FileError> {
        let Some(tmp) = self.tmp.take() else {
            return Ok(());
        };
        let result = std::fs::rename(&tmp, &self.path);
        if result.is_err() {
            let _ = std::fs::remove_file(&tmp);
        }
        result.map_err(io_err(&self.path))
    }

    /// Leaves the temporary file where it is, as a process that died would, and returns
    /// its path.
    pub fn keep(mut self) -> std::path::PathBuf {
        self.tmp.take().unwrap_or_else(|| self.path.clone())
    }
}

impl Drop for Partial {
    fn drop(&mut self) {
        if let Some(tmp) = self.tmp.take() {
            let _ = std::fs::remove_file(&tmp);
        }
    }
}

/// Writes `bytes` to `path` so that a reader sees the old file or the new one, never a
/// part: a temporary file in the same folder, flushed to disk, then renamed over `path`.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), FileError> {
    if is_stdout(path) {
        let mut out = std::io::stdout().lock();
        return out
            .write_all(bytes)
            .and_then(|()| out.flush())
            .map_err(io_err(path));
    }
    check_output(path)?;
    let tmp = temporary(path);
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if let Err(cause) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(io_err(path)(cause));
    }
    Ok(())
}

/// Whether `a` and `b` name one existing file (through links and relative paths alike):
/// an output that is one of its command's inputs would destroy it.
pub fn same_file(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(x), Ok(y)) => x == y,
        _ => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An output never replaces a link, FIFO, device or folder; a regular file it does.
    #[test]
    fn outputs_replace_only_regular_files() {
        let dir = std::env::temp_dir().join(format!("fb-outputs-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("dir");
        let file = dir.join("out.json");
        write_atomic(&file, b"1").expect("a new file");
        write_atomic(&file, b"2").expect("a regular file replaced");
        let link = dir.join("link.json");
        std::os::unix::fs::symlink(&file, &link).expect("symlink");
        let e = write_atomic(&link, b"3").expect_err("a link").to_string();
        assert!(
            e.contains("a symbolic link") && e.contains("- for standard output"),
            "{e}"
        );
        assert!(
            std::fs::symlink_metadata(&link)
                .expect("kept")
                .file_type()
                .is_symlink()
        );
        assert_eq!(std::fs::read(&file).expect("read"), b"2");
        // A FIFO of its own, not a device of the machine's: a broken check must not cost
        // the machine its /dev/null.
        let fifo = dir.join("fifo");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        assert!(made.is_ok_and(|s| s.success()), "mkfifo");
        for special in [fifo.as_path(), dir.as_path()] {
            assert!(
                write_atomic(special, b"x").is_err(),
                "{}",
                special.display()
            );
            assert!(
                AtomicWriter::create(special).is_err(),
                "{}",
                special.display()
            );
        }
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn special_files_are_refused_and_sizes_capped() {
        let e = read_text(Path::new("/dev/zero"), 1 << 20).expect_err("device");
        assert!(
            e.to_string().contains("not a regular file (a device)"),
            "{e}"
        );
        let e = read_text(Path::new("/tmp"), 1 << 20).expect_err("dir");
        assert!(e.to_string().contains("a directory"), "{e}");
        let dir = std::env::temp_dir().join(format!("fb-files-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("dir");
        let f = dir.join("big.txt");
        write_atomic(&f, &[b'x'; 100]).expect("write");
        assert_eq!(read_text(&f, 100).expect("fits").len(), 100);
        let e = read_text(&f, 99).expect_err("too large");
        assert!(e.to_string().contains("larger than 99 bytes"), "{e}");
        write_atomic(&f, b"new").expect("rewrite");
        assert_eq!(read_text(&f, 99).expect("read"), "new");
        let left: Vec<_> = std::fs::read_dir(&dir).expect("ls").collect();
        assert_eq!(left.len(), 1, "no temporary file left behind");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
