//! One file written on a thread of its own: the recorder hands over work, the thread writes, and the first error names the file.

use std::fs::File;
use std::path::Path;
use std::sync::mpsc::{Receiver, SyncSender, sync_channel};
use std::thread::JoinHandle;

use crate::LogError;

/// What the writer thread runs: it owns the file and the receiving end, and returns its
/// first error (without the path, which [`WriterThread`] adds).
pub(crate) type Run<C> = Box<dyn FnOnce(File, Receiver<C>) -> Option<String> + Send>;

/// A file and the thread that writes it, fed through a bounded channel (which also bounds
/// memory when the disk is slower than the simulation).
pub(crate) struct WriterThread<C: Send + 'static> {
    path: String,
    /// What the thread is called in messages ("the MCAP writer thread").
    what: &'static str,
    tx: Option<SyncSender<C>>,
    thread: Option<JoinHandle<Option<String>>>,
    error: Option<String>,
    /// The file being written beside the path, renamed onto it when all went well.
    partial: Option<forkbench_core::files::Partial>,
}

/// An error and its causes: crates' own messages ("I/O error from writing…") hide the
/// reason ("No space left on device") in their source.
pub(crate) fn with_causes(e: &dyn std::error::Error) -> String {
    let mut text = e.to_string();
    let mut cause = e.source();
    while let Some(c) = cause {
        text.push_str(": ");
        text.push_str(&c.to_string());
        cause = c.source();
    }
    text
}

impl<C: Send + 'static> WriterThread<C> {
    /// Creates the file for `path` (checked beforehand with [`crate::check_writable`]) and
    /// starts `run` on a thread named `name`: only creating the file, the step that fails
    /// on a bad path, holds up the caller. The file appears at `path` when
    /// [`Self::finish`] succeeds; until then (and after a failure) `path` is untouched.
    pub fn spawn(
        path: &Path,
        name: &str,
        what: &'static str,
        bound: usize,
        run: Run<C>,
    ) -> Result<Self, LogError> {
        let p = path.display().to_string();
        let io = |e: &dyn std::error::Error| LogError::Io {
            path: p.clone(),
            message: with_causes(e),
        };
        let (partial, file) = forkbench_core::files::Partial::create(path)?;
        let (tx, rx) = sync_channel::<C>(bound);
        let thread = std::thread::Builder::new()
            .name(name.into())
            .spawn(move || run(file, rx))
            .map_err(|e| io(&e))?;
        Ok(Self {
            path: p,
            what,
            tx: Some(tx),
            thread: Some(thread),
            error: None,
            partial: Some(partial),
        })
    }

    /// Hands `cmd` to the thread; a thread that stopped is noted (its own error, the cause,
    /// replaces the note when it is joined).
    pub fn send(&mut self, cmd: C) {
        if let Some(tx) = &self.tx
            && tx.send(cmd).is_err()
        {
            self.error
                .get_or_insert_with(|| format!("{} stopped", self.what));
        }
    }

    /// Tells the thread that no more work comes: it finishes the file now, while the
    /// caller does other things; [`Self::finish`] then only joins it.
    pub fn close(&mut self) {
        self.tx = None;
    }

    /// Closes, joins the thread and returns the first error, naming the file.
    pub fn finish(&mut self) -> Result<(), LogError> {
        self.close();
        if let Some(t) = self.thread.take() {
            match t.join() {
                Ok(Some(e)) => self.error = Some(e),
                Ok(None) => {}
                Err(_) => {
                    self.error
                        .get_or_insert_with(|| format!("{} panicked", self.what));
                }
            }
        }
        match self.error.take() {
            Some(message) => {
                self.partial = None;
                Err(self.io_error(message))
            }
            None => match self
                .partial
                .take()
                .map(forkbench_core::files::Partial::commit)
            {
                Some(Err(e)) => Err(self.io_error(format!(
                    "moving the written file into place: {}",
                    e.reason()
                ))),
                _ => Ok(()),
            },
        }
    }

    /// An error about this file.
    pub fn io_error(&self, message: String) -> LogError {
        LogError::Io {
            path: self.path.clone(),
            message,
        }
    }

    /// The message for a thread that went away.
    pub fn stopped(&self) -> LogError {
        self.io_error(format!("{} stopped", self.what))
    }

    /// Joins the thread without reporting anything (a simulated crash).
    /// The bytes stay in the temporary file, as a crash leaves them; its path is returned.
    pub fn abandon(&mut self) -> Option<std::path::PathBuf> {
        self.close();
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
        self.partial
            .take()
            .map(forkbench_core::files::Partial::keep)
    }
}

impl<C: Send + 'static> std::fmt::Debug for WriterThread<C> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "WriterThread({})", self.path)
    }
}
