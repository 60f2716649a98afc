//! rerun recording of a trial: a y-up map, the verdict, plots and the event log, on the `sim_time` timeline.
//!
//! Everything goes through rerun's public SDK. A file is recorded into a memory sink and
//! encoded by rerun when the trial ends, on the writer thread the MCAP sink uses too
//! (`crate::writer`), which reports write errors with the file's name.

mod columns;
mod layout;
mod recorder;
mod scene;
mod signals;

use std::fs::File;
use std::io::{BufWriter, Write as _};
use std::path::PathBuf;
use std::sync::mpsc::Receiver;

use crate::LogError;
use crate::writer::{WriterThread, with_causes};
use columns::Columns;

/// Where the recording goes.
#[derive(Debug, Clone, PartialEq)]
pub enum RerunTarget {
    /// An .rrd file.
    File(PathBuf),
    /// Spawn a local viewer (the `rerun` executable must be on PATH).
    Spawn,
    /// A running viewer at host:port (its gRPC proxy).
    Connect(String),
}

/// How long a live viewer may take to accept the recording's last data.
const VIEWER_TIMEOUT: std::time::Duration = std::time::Duration::from_secs(5);
/// Buffered per-step data is sent as columns every this many steps and at the end: one
/// `send_columns` per entity instead of one `log` per entity and step, since rerun's cost
/// is per chunk. Files and memory get a minute of simulated time per chunk; a live viewer
/// gets 0.1 s, so it follows the truck smoothly.
const SEND_EVERY_FILE: usize = 6000;
const SEND_EVERY_LIVE: usize = 10;

/// Where the stream's messages end up, and how closing it finishes them.
enum Sink {
    /// Kept in memory and encoded to the file by the writer thread at the end.
    File {
        storage: rerun::sink::MemorySinkStorage,
        writer: WriterThread<rerun::sink::MemorySinkStorage>,
    },
    /// Kept in memory for the caller ([`RerunRecorder::in_memory`]).
    Memory,
    /// A viewer: closing flushes with a deadline, on a thread of its own.
    Live,
}

/// Where a live recording is in its closing.
enum Close {
    Open,
    /// The trial's outcome is logged: a thread flushes the stream and closes it.
    Closing(std::sync::mpsc::Receiver<Option<String>>),
    /// Closed; later calls log nothing.
    Closed,
}

/// Streams one trial to rerun.
pub struct RerunRecorder {
    rec: rerun::RecordingStream,
    sink: Sink,
    send_every: usize,
    /// The scenario's limits (from its scene): drawn on the plots (lateral and heading at
    /// entry, contact force) and the verdict's table of the pick's criteria.
    tolerances: Option<forkbench_trial::Limits>,
    /// Fork length and the pallet's half width: where the tips reach the face plane
    /// (the judged entry), and the approach window the entry plots cover.
    entry_geometry: [f64; 2],
    /// When and where (fork root) the tips first reached the face.
    entry_at: Option<(f64, [f64; 2])>,
    /// Plans on screen, the last one the one being driven.
    plans: u32,
    /// The event log so far, for the verdict document.
    events: Vec<String>,
    /// Rack and wall outlines, redrawn unclipped when a mission's map widens the frame.
    obstacle_outlines: Vec<[[f64; 2]; 5]>,
    cols: Columns,
    signal_cols: signals::SignalColumns,
    error: Option<String>,
    close: Close,
}

impl std::fmt::Debug for RerunRecorder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "RerunRecorder({} steps)", self.cols.steps)
    }
}

/// Why the blueprint could not be built (kept with the cache, so each file reports it).
#[derive(Debug, thiserror::Error)]
enum BlueprintError {
    #[error(transparent)]
    Stream(#[from] rerun::RecordingStreamError),
    #[error(transparent)]
    Flush(#[from] rerun::sink::SinkFlushError),
}

/// The blueprint's messages for a focus, each built once per process: building them
/// spins up a whole in-memory recording stream, which cost as much as a short trial when
/// done per file.
fn blueprint_msgs(focus: layout::Focus) -> Result<&'static [rerun::log::LogMsg], LogError> {
    use rerun::log::LogMsg;
    type Built = std::sync::OnceLock<Result<Vec<LogMsg>, BlueprintError>>;
    static MSGS: [Built; 3] = [Built::new(), Built::new(), Built::new()];
    let k = layout::Focus::ALL
        .iter()
        .position(|f| *f == focus)
        .unwrap_or(0);
    MSGS[k]
        .get_or_init(|| {
            let (rec, storage) = rerun::RecordingStreamBuilder::new(APP).memory()?;
            layout::blueprint(focus).send(
                &rec,
                rerun::blueprint::BlueprintActivation {
                    make_active: true,
                    make_default: true,
                },
            )?;
            rec.flush_blocking()?;
            // Keep only the blueprint store and its activation, not the carrier recording.
            Ok(storage
                .take()
                .into_iter()
                .filter(|m| match m {
                    LogMsg::BlueprintActivationCommand(_) => true,
                    m => m.store_id().kind() == rerun::StoreKind::Blueprint,
                })
                .collect())
        })
        .as_deref()
        .map_err(|e| LogError::Rerun(format!("building the blueprint: {e}")))
}

/// The application every recording belongs to (the viewer groups recordings by it).
const APP: &str = "forkbench";

/// The writer thread of an .rrd file: rerun encodes what the memory sink holds, and the
/// bytes go to the file.
fn write_rrd(file: File, rx: Receiver<rerun::sink::MemorySinkStorage>) -> Option<String> {
    let mut out = BufWriter::new(file);
    for storage in rx {
        let bytes = match storage.drain_as_bytes() {
            Ok(b) => b,
            Err(e) => return Some(format!("encoding the recording: {}", with_causes(&e))),
        };
        if let Err(e) = out.write_all(&bytes) {
            return Some(with_causes(&e));
        }
    }
    out.flush().err().map(|e| with_causes(&e))
}

impl RerunRecorder {
    pub fn new(target: &RerunTarget) -> Result<Self, LogError> {
        let rerun_err = |e: rerun::RecordingStreamError| LogError::Rerun(e.to_string());
        // The recording's properties go out once, with its name, when the scene is known.
        let builder = rerun::RecordingStreamBuilder::new(APP).send_properties(false);
        let (rec, sink) = match target {
            RerunTarget::File(p) => {
                let (rec, storage) = builder.memory().map_err(rerun_err)?;
                let writer = WriterThread::spawn(
                    p,
                    "rrd-writer",
                    "the .rrd writer thread",
                    1,
                    Box::new(write_rrd),
                )?;
                (rec, Sink::File { storage, writer })
            }
            RerunTarget::Spawn => (builder.spawn().map_err(rerun_err)?, Sink::Live),
            RerunTarget::Connect(addr) => (connect(builder, addr)?, Sink::Live),
        };
        Self::on(rec, sink)
    }

    /// A recorder whose messages stay in memory, for reading back (tests, tools).
    pub fn in_memory() -> Result<(Self, rerun::sink::MemorySinkStorage), LogError> {
        let (rec, storage) = rerun::RecordingStreamBuilder::new(APP)
            .send_properties(false)
            .memory()
            .map_err(|e| LogError::Rerun(e.to_string()))?;
        let me = Self::on(rec, Sink::Memory)?;
        Ok((me, storage))
    }

    fn on(rec: rerun::RecordingStream, sink: Sink) -> Result<Self, LogError> {
        // `sim_time` is the recording's only timeline: a wall-clock `log_time` on some
        // entities would only confuse.
        rec.set_log_time_enabled(false);
        for msg in blueprint_msgs(layout::Focus::Lateral)? {
            rec.record_msg(msg.clone());
        }
        let send_every = match sink {
            Sink::File { .. } | Sink::Memory => SEND_EVERY_FILE,
            Sink::Live => SEND_EVERY_LIVE,
        };
        Ok(Self {
            rec,
            sink,
            send_every,
            tolerances: None,
            entry_geometry: [0.0; 2],
            entry_at: None,
            plans: 0,
            events: Vec::new(),
            obstacle_outlines: Vec::new(),
            cols: Columns::default(),
            signal_cols: Default::default(),
            error: None,
            close: Close::Open,
        })
    }

    fn at(&self, t_s: f64) {
        self.rec.set_duration_secs("sim_time", t_s);
    }

    fn note<T, E: std::fmt::Display>(&mut self, r: Result<T, E>) {
        if let Err(e) = r {
            self.error.get_or_insert(e.to_string());
        }
    }

    /// Sends what is buffered and starts closing: a file is handed to its writer thread, a
    /// viewer is flushed on a thread of its own; later calls log nothing.
    fn close_async(&mut self) {
        if !matches!(self.close, Close::Open) {
            return;
        }
        self.close = Close::Closed;
        self.send_buffered();
        self.send_leftover_first_rows();
        let rec = std::mem::replace(&mut self.rec, rerun::RecordingStream::disabled());
        match &mut self.sink {
            Sink::File { storage, writer } => {
                // The storage holds the stream: the writer thread encodes and drops it.
                writer.send(storage.clone());
                writer.close();
            }
            Sink::Memory => {
                let r = rec.flush_blocking();
                self.note(r);
            }
            Sink::Live => self.close = close_live(rec),
        }
    }

    /// Sends what is buffered and closes the recording (the .rrd is complete when this
    /// returns); returns the first logging or writing error, if any.
    pub fn finish(&mut self) -> Result<(), LogError> {
        self.close_async();
        if let Close::Closing(rx) = std::mem::replace(&mut self.close, Close::Closed) {
            use std::sync::mpsc::RecvTimeoutError;
            // Twice the flush's own timeout: dropping the stream may wait too.
            match rx.recv_timeout(2 * VIEWER_TIMEOUT) {
                Ok(Some(e)) => self.note::<(), _>(Err(e)),
                Ok(None) => {}
                Err(RecvTimeoutError::Timeout) => self.note::<(), _>(Err(format!(
                    "the viewer did not take the recording within {} s (is it a rerun viewer?)",
                    2 * VIEWER_TIMEOUT.as_secs()
                ))),
                Err(RecvTimeoutError::Disconnected) => {
                    self.note::<(), _>(Err("the rerun closing thread panicked"))
                }
            }
        }
        let written = match &mut self.sink {
            Sink::File { writer, .. } => writer.finish(),
            Sink::Memory | Sink::Live => Ok(()),
        };
        match self.error.take() {
            Some(e) => Err(LogError::Rerun(e)),
            None => written,
        }
    }
}

/// A stream to the viewer at `addr`, failing now, clearly, if nothing listens there (the
/// gRPC client would otherwise retry silently in the background).
fn connect(
    builder: rerun::RecordingStreamBuilder,
    addr: &str,
) -> Result<rerun::RecordingStream, LogError> {
    let sock: std::net::SocketAddr = addr
        .parse()
        .map_err(|e| LogError::Rerun(format!("connect {addr:?}: expected host:port ({e})")))?;
    std::net::TcpStream::connect_timeout(&sock, std::time::Duration::from_secs(2))
        .map_err(|e| LogError::Rerun(format!("no rerun viewer reachable at {addr}: {e}")))?;
    builder
        .connect_grpc_opts(format!("rerun+http://{addr}/proxy"))
        .map_err(|e| LogError::Rerun(e.to_string()))
}

/// Flushes a viewer's stream with a deadline and closes it, on a thread of its own, so a
/// port that accepts TCP but is no viewer cannot hang the run.
fn close_live(rec: rerun::RecordingStream) -> Close {
    let (tx, rx) = std::sync::mpsc::channel();
    let closing = std::thread::Builder::new()
        .name("rerun-close".into())
        .spawn(move || {
            let r = rec
                .flush_with_timeout(VIEWER_TIMEOUT)
                .err()
                .map(|e| e.to_string());
            drop(rec);
            let _ = tx.send(r);
        });
    match closing {
        Ok(_) => Close::Closing(rx),
        Err(_) => Close::Closed,
    }
}

impl Drop for RerunRecorder {
    fn drop(&mut self) {
        let _ = self.finish();
    }
}
