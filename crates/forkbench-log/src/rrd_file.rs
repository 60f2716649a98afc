//! An .rrd file sink: rerun's framing and footer, the blueprint encoded once per process, errors kept.
//!
//! rerun's `FileSink` only logs write errors (a full disk would pass silently), so this
//! sink hands the first error back through [`RrdFileSink::error_slot`].
//!
//! It writes the stream as rerun's `Encoder` does (stream header, framed messages, an end
//! message whose footer holds one chunk manifest per store, the stream footer), from
//! rerun's own pieces. It does not use the `Encoder` itself, because on a short trial its
//! per-file and per-chunk costs, all on one thread, took longer than the trial:
//! - the blueprint is the same in every file: it is encoded once per process, with its
//!   manifest, and written right after the stream header, where its byte offsets are the
//!   same in every file (rerun's `Encoder` re-encoded its 15 chunks per file);
//! - messages are encoded (Arrow IPC, LZ4) by the sending thread and by the writer
//!   thread in turn, so the chunks sent at the end of a trial are encoded on both cores.
//!
//! `rerun rrd verify` checks the footer against the chunks (CI runs it on these files).

use std::collections::HashMap;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{Receiver, RecvTimeoutError, SyncSender, sync_channel};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::Duration;

use rerun::StoreId;
use rerun::external::arrow::array::RecordBatch;
use rerun::external::re_build_info::CrateVersion;
use rerun::external::re_log_encoding::{
    Compression, Encodable as _, EncodingOptions, MessageHeader, MessageKind, RRD_FOURCC,
    RawRrdManifest, RrdFooter, RrdManifestBuilder, StreamFooter, StreamHeader, ToTransport,
};
use rerun::log::LogMsg;
use rerun::sink::{LogSink, SinkFlushError};

/// The first error of a sink, readable after the sink is gone.
pub type ErrorSlot = Arc<Mutex<Option<String>>>;

/// A store's chunk manifest, encoded as the footer carries it.
type ManifestProto = <RawRrdManifest as ToTransport>::Output;
type FooterProto = <RrdFooter as ToTransport>::Output;

/// LZ4, as rerun writes files: the stream header says so, and each message records it.
const OPTIONS: EncodingOptions = EncodingOptions::PROTOBUF_COMPRESSED;
const COMPRESSION: Compression = Compression::LZ4;

/// A chunk's manifest entry, before its place in the file is known.
struct ChunkEntry {
    store_id: StoreId,
    batch: RecordBatch,
    uncompressed_bytes: u64,
}

/// Appends `msg`, framed (message header included), to `out`; returns its chunk, if any.
fn frame(msg: &LogMsg, out: &mut Vec<u8>) -> Result<Option<ChunkEntry>, String> {
    let transport = msg.to_transport(COMPRESSION).map_err(|e| e.to_string())?;
    transport.to_rrd_bytes(out).map_err(|e| e.to_string())?;
    Ok(match msg {
        LogMsg::ArrowMsg(store_id, arrow) => Some(ChunkEntry {
            store_id: store_id.clone(),
            batch: arrow.batch.clone(),
            uncompressed_bytes: transport.byte_size_uncompressed(),
        }),
        LogMsg::SetStoreInfo(_) | LogMsg::BlueprintActivationCommand(_) => None,
    })
}

/// Chunk manifests per store, built as rerun's `Encoder` builds them.
#[derive(Default)]
struct Manifests(HashMap<StoreId, RrdManifestBuilder>);

impl Manifests {
    /// Notes a chunk whose framed message starts at byte `offset` and is `framed_len`
    /// bytes long; the manifest points past the message header, at the payload.
    fn add(&mut self, chunk: &ChunkEntry, offset: u64, framed_len: u64) -> Result<(), String> {
        let header = MessageHeader::ENCODED_SIZE_BYTES as u64;
        let batch = re_sorbet::ChunkBatch::try_from(&chunk.batch).map_err(|e| e.to_string())?;
        self.0
            .entry(chunk.store_id.clone())
            .or_default()
            .append(
                &batch,
                re_span::Span {
                    start: offset + header,
                    len: framed_len - header,
                },
                chunk.uncompressed_bytes,
            )
            .map_err(|e| e.to_string())
    }

    fn into_protos(self) -> Result<Vec<ManifestProto>, String> {
        self.0
            .into_iter()
            .map(|(store_id, builder)| {
                builder
                    .build(store_id)
                    .and_then(|m| m.to_transport(()))
                    .map_err(|e| e.to_string())
            })
            .collect()
    }
}

fn stream_header() -> Result<Vec<u8>, String> {
    let mut out = Vec::new();
    StreamHeader {
        fourcc: RRD_FOURCC,
        version: CrateVersion::LOCAL.to_bytes(),
        options: OPTIONS,
    }
    .to_rrd_bytes(&mut out)
    .map_err(|e| e.to_string())?;
    Ok(out)
}

/// The start of every file: stream header and blueprint, encoded once.
pub struct Prefix {
    bytes: Vec<u8>,
    /// The blueprint store's manifest, for its place right after the stream header.
    manifests: Vec<ManifestProto>,
}

impl Prefix {
    /// The stream header followed by `msgs`.
    pub fn encode(msgs: &[LogMsg]) -> Result<Self, String> {
        let mut bytes = stream_header()?;
        let mut manifests = Manifests::default();
        for msg in msgs {
            let start = bytes.len();
            if let Some(chunk) = frame(msg, &mut bytes)? {
                manifests.add(&chunk, start as u64, (bytes.len() - start) as u64)?;
            }
        }
        Ok(Self {
            bytes,
            manifests: manifests.into_protos()?,
        })
    }
}

/// Work for the writer thread.
enum Cmd {
    /// A message the sending thread framed.
    Framed(Vec<u8>, Option<ChunkEntry>),
    /// A message for the writer thread to frame.
    Msg(LogMsg),
    Flush(SyncSender<()>),
}

/// Writes one .rrd file from a thread of its own.
pub struct RrdFileSink {
    /// The file, as errors name it.
    name: String,
    tx: Mutex<Option<SyncSender<Cmd>>>,
    thread: Mutex<Option<JoinHandle<()>>>,
    error: ErrorSlot,
    /// Messages sent so far: every other one is framed by the writer thread.
    sent: AtomicU64,
}

fn keep(slot: &ErrorSlot, path: &str, e: impl std::fmt::Display) {
    if let Ok(mut s) = slot.lock() {
        s.get_or_insert_with(|| format!("{path}: {e}"));
    }
}

/// The writer thread's state.
struct Writer {
    out: BufWriter<File>,
    /// Bytes written so far.
    offset: u64,
    manifests: Manifests,
    prefix: &'static Prefix,
}

impl Writer {
    fn write(&mut self, bytes: &[u8]) -> Result<(), String> {
        self.out.write_all(bytes).map_err(|e| e.to_string())?;
        self.offset += bytes.len() as u64;
        Ok(())
    }

    fn write_framed(&mut self, bytes: &[u8], chunk: Option<&ChunkEntry>) -> Result<(), String> {
        if let Some(c) = chunk {
            self.manifests.add(c, self.offset, bytes.len() as u64)?;
        }
        self.write(bytes)
    }

    fn run(&mut self, cmd: Cmd) -> Result<(), String> {
        match cmd {
            Cmd::Framed(bytes, chunk) => self.write_framed(&bytes, chunk.as_ref()),
            Cmd::Msg(msg) => {
                let mut bytes = Vec::new();
                let chunk = frame(&msg, &mut bytes)?;
                self.write_framed(&bytes, chunk.as_ref())
            }
            Cmd::Flush(ack) => {
                let r = self.out.flush().map_err(|e| e.to_string());
                let _ = ack.send(());
                r
            }
        }
    }

    /// The end message, whose footer holds every store's manifest, then the stream footer
    /// that points at it.
    fn finish(mut self) -> Result<(), String> {
        let mut manifests = std::mem::take(&mut self.manifests).into_protos()?;
        manifests.extend(self.prefix.manifests.iter().cloned());
        let mut footer = Vec::new();
        FooterProto { manifests }
            .to_rrd_bytes(&mut footer)
            .map_err(|e| e.to_string())?;
        let mut header = Vec::new();
        MessageHeader {
            kind: MessageKind::End,
            len: footer.len() as u64,
        }
        .to_rrd_bytes(&mut header)
        .map_err(|e| e.to_string())?;
        self.write(&header)?;
        let footer_offset = self.offset;
        self.write(&footer)?;
        let mut tail = Vec::new();
        StreamFooter::from_rrd_footer_bytes(footer_offset, &footer)
            .to_rrd_bytes(&mut tail)
            .map_err(|e| e.to_string())?;
        self.write(&tail)?;
        self.out.flush().map_err(|e| e.to_string())
    }
}

/// The writer thread: the prefix, every command in order, then the footer. After a
/// failed write the file is cut short and later messages are dropped (no footer).
fn write_all(mut writer: Writer, rx: &Receiver<Cmd>, slot: &ErrorSlot, path: &str) {
    let mut failed = writer.write(&writer.prefix.bytes).err();
    for cmd in rx {
        match cmd {
            Cmd::Flush(ack) if failed.is_some() => {
                let _ = ack.send(());
            }
            _ if failed.is_some() => {}
            cmd => failed = writer.run(cmd).err(),
        }
    }
    if let Some(e) = failed.or_else(|| writer.finish().err()) {
        keep(slot, path, e);
    }
}

impl RrdFileSink {
    /// Creates the file and starts the writer thread, which writes `prefix` first.
    pub fn create(path: &Path, prefix: &'static Prefix) -> Result<Self, String> {
        let name = path.display().to_string();
        let file = File::create(path).map_err(|e| format!("{name}: {e}"))?;
        let writer = Writer {
            out: BufWriter::new(file),
            offset: 0,
            manifests: Manifests::default(),
            prefix,
        };
        let error = ErrorSlot::default();
        // Bounded: a disk slower than the trial holds the trial back instead of the heap.
        let (tx, rx) = sync_channel(1024);
        let slot = error.clone();
        let thread_name = name.clone();
        let thread = std::thread::Builder::new()
            .name("rrd-writer".into())
            .spawn(move || write_all(writer, &rx, &slot, &thread_name))
            .map_err(|e| format!("{name}: {e}"))?;
        Ok(Self {
            name,
            tx: Mutex::new(Some(tx)),
            thread: Mutex::new(Some(thread)),
            error,
            sent: AtomicU64::new(0),
        })
    }

    /// Where the first write error lands (also after the sink is dropped).
    pub fn error_slot(&self) -> ErrorSlot {
        self.error.clone()
    }

    fn command(&self, cmd: Cmd) {
        let sent = match self.tx.lock() {
            Ok(tx) => tx.as_ref().is_some_and(|tx| tx.send(cmd).is_ok()),
            Err(_) => false,
        };
        if !sent {
            keep(&self.error, &self.name, "the writer thread stopped");
        }
    }
}

impl LogSink for RrdFileSink {
    /// Runs on rerun's forwarding thread: it frames every other message itself, while the
    /// writer thread frames the one before (a trial's columns all arrive at its end).
    fn send(&self, msg: LogMsg) {
        if self.sent.fetch_add(1, Ordering::Relaxed) % 2 == 1 {
            return self.command(Cmd::Msg(msg));
        }
        let mut bytes = Vec::new();
        match frame(&msg, &mut bytes) {
            Ok(chunk) => self.command(Cmd::Framed(bytes, chunk)),
            Err(e) => keep(&self.error, &self.name, e),
        }
    }

    fn flush_blocking(&self, timeout: Duration) -> Result<(), SinkFlushError> {
        let (ack, done) = sync_channel(1);
        self.command(Cmd::Flush(ack));
        // A stopped writer thread drops the acknowledgement: its error is in the slot.
        if let Err(RecvTimeoutError::Timeout) = done.recv_timeout(timeout) {
            return Err(SinkFlushError::Timeout);
        }
        match self.error.lock().ok().and_then(|e| e.clone()) {
            Some(e) => Err(SinkFlushError::failed(e)),
            None => Ok(()),
        }
    }

    fn defers_finalization_to_shutdown(&self) -> bool {
        true
    }
}

impl Drop for RrdFileSink {
    fn drop(&mut self) {
        // Closing the channel lets the thread write the footer; wait for it.
        if let Ok(mut tx) = self.tx.lock() {
            tx.take();
        }
        if let Ok(mut t) = self.thread.lock()
            && let Some(t) = t.take()
            && t.join().is_err()
        {
            keep(&self.error, &self.name, "the writer thread panicked");
        }
    }
}
