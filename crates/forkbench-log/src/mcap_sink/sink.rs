//! The MCAP writer thread: serialises what the recorder hands over and writes the file.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::sync::mpsc::{Receiver, SyncSender};

use forkbench_core::Pose2;
use forkbench_trial::StepRecord;
use serde::Serialize;

use super::messages::*;
use super::schemas::CHANNELS;
use crate::writer::with_causes;

/// A pallet (or its estimate) moving less than this since its last transform is not
/// re-sent: it is pushed only on contact, so most trials send one transform each.
pub(super) const PALLET_MOVE_M: f64 = 5e-4;
pub(super) const PALLET_TURN_RAD: f64 = 1e-4;

/// A message, serialised by the writer thread into its buffer.
pub(super) type JsonMsg = Box<dyn FnOnce(&mut Vec<u8>) -> serde_json::Result<()> + Send>;

/// A message for the file, in the order the trial made it.
pub(super) enum Item {
    Json {
        topic: std::borrow::Cow<'static, str>,
        t_s: f64,
        msg: JsonMsg,
    },
    Step(StepRecord),
    /// A scalar signal's value (`forkbench.Scalar`): per step, so no closure and no
    /// topic string of its own.
    Scalar {
        topic: std::sync::Arc<str>,
        t_s: f64,
        value: f64,
    },
}

/// `forkbench.Scalar`: one value of a signal's series.
#[derive(Serialize)]
pub(super) struct ScalarMsg {
    pub(super) t_s: f64,
    pub(super) value: f64,
}

/// Work for the writer thread.
pub(super) enum Cmd {
    /// Messages handed over together, so the threads do not wake each other per step.
    Batch(Vec<Item>),
    /// A channel first used after the file was opened (a signal's own topic).
    Channel {
        topic: String,
        schema_name: &'static str,
        schema: &'static str,
    },
    /// Flush the current chunk and acknowledge.
    Flush(SyncSender<Option<String>>),
    /// Stop without finishing the file, as a crash would.
    Abandon,
}

/// The writer thread's state.
pub(super) struct Sink {
    pub(super) writer: mcap::Writer<BufWriter<File>>,
    pub(super) channels: BTreeMap<String, u16>,
    /// Schema ids by name.
    pub(super) schemas: BTreeMap<&'static str, u16>,
    pub(super) sequence: u32,
    /// Last transforms sent for the pallet and its estimate.
    pub(super) pallet_sent: Option<Pose2>,
    pub(super) estimate_sent: Option<Pose2>,
    pub(super) buf: Vec<u8>,
    pub(super) error: Option<String>,
}

pub(super) fn moved(last: Option<Pose2>, now: &Pose2) -> bool {
    last.is_none_or(|l| {
        (l.x_m - now.x_m).hypot(l.y_m - now.y_m) > PALLET_MOVE_M
            || (l.heading_rad - now.heading_rad).abs() > PALLET_TURN_RAD
    })
}

impl Sink {
    /// Starts the MCAP file in `file`: header, schemas, channels and the metadata record.
    pub(super) fn open(
        file: File,
        metadata: BTreeMap<String, String>,
    ) -> Result<Self, mcap::McapError> {
        // Small chunks: a crash loses at most the chunk being written. LZ4 on this thread
        // only (no compressor threads, which would take the trial's core): on the field
        // test it costs 8.7 M instructions less per trial than zstd level 1 (49.5 vs
        // 58.2 M over the plain trial, callgrind), for files 1.5× larger (422 vs 276 KB).
        let mut writer = mcap::WriteOptions::new()
            .chunk_size(Some(64 * 1024))
            .compression(Some(mcap::Compression::Lz4))
            .compression_level(1)
            .compression_threads(0)
            .create(BufWriter::new(file))?;
        writer.write_metadata(&mcap::records::Metadata {
            name: "forkbench".into(),
            metadata,
        })?;
        let mut me = Self {
            writer,
            channels: BTreeMap::new(),
            schemas: BTreeMap::new(),
            sequence: 0,
            pallet_sent: None,
            estimate_sent: None,
            buf: Vec::with_capacity(1024),
            error: None,
        };
        for (topic, name, schema) in CHANNELS {
            me.add_channel(topic, name, schema)?;
        }
        Ok(me)
    }

    /// Registers `topic` with its schema (once per schema name).
    fn add_channel(
        &mut self,
        topic: &str,
        schema_name: &'static str,
        schema: &'static str,
    ) -> Result<(), mcap::McapError> {
        let sid = match self.schemas.get(schema_name) {
            Some(id) => *id,
            None => {
                let id = self
                    .writer
                    .add_schema(schema_name, "jsonschema", schema.as_bytes())?;
                self.schemas.insert(schema_name, id);
                id
            }
        };
        let cid = self
            .writer
            .add_channel(sid, topic, "json", &BTreeMap::new())?;
        self.channels.insert(topic.to_owned(), cid);
        Ok(())
    }

    /// Runs the writer thread's commands, then finishes the file; returns the first error.
    pub(super) fn run(mut self, rx: Receiver<Cmd>) -> Option<String> {
        for cmd in rx {
            match cmd {
                Cmd::Batch(items) => {
                    for item in items {
                        match item {
                            Item::Json { topic, t_s, msg } => self.write_json(&topic, t_s, msg),
                            Item::Step(s) => self.step(&s),
                            Item::Scalar { topic, t_s, value } => {
                                self.write(&topic, t_s, &ScalarMsg { t_s, value })
                            }
                        }
                    }
                }
                Cmd::Channel {
                    topic,
                    schema_name,
                    schema,
                } => {
                    if let Err(e) = self.add_channel(&topic, schema_name, schema) {
                        self.error.get_or_insert(with_causes(&e));
                    }
                }
                Cmd::Flush(ack) => {
                    let r = self.writer.flush().err().map(|e| with_causes(&e));
                    let _ = ack.send(r);
                }
                Cmd::Abandon => {
                    std::mem::forget(self);
                    return None;
                }
            }
        }
        if let Err(e) = self.writer.finish() {
            self.error.get_or_insert(with_causes(&e));
        }
        self.error
    }
}

impl Sink {
    pub(super) fn write(&mut self, topic: &str, t_s: f64, msg: &impl Serialize) {
        self.write_json(topic, t_s, |buf| serde_json::to_writer(buf, msg));
    }

    /// Serialises a message with `to_json` into the reused buffer and writes it.
    pub(super) fn write_json(
        &mut self,
        topic: &str,
        t_s: f64,
        to_json: impl FnOnce(&mut Vec<u8>) -> serde_json::Result<()>,
    ) {
        let mut buf = std::mem::take(&mut self.buf);
        buf.clear();
        match to_json(&mut buf) {
            Ok(()) => self.write_bytes(topic, t_s, &buf),
            Err(e) => {
                self.error.get_or_insert(e.to_string());
            }
        }
        self.buf = buf;
    }

    pub(super) fn write_bytes(&mut self, topic: &str, t_s: f64, data: &[u8]) {
        let Some(&channel_id) = self.channels.get(topic) else {
            return;
        };
        self.sequence += 1;
        let header = mcap::records::MessageHeader {
            channel_id,
            sequence: self.sequence,
            log_time: ns(t_s),
            publish_time: ns(t_s),
        };
        if let Err(e) = self.writer.write_to_known_channel(&header, data) {
            self.error.get_or_insert(with_causes(&e));
        }
    }

    pub(super) fn transform(&mut self, t_s: f64, child: &'static str, p: &Pose2) {
        self.write("/tf", t_s, &FrameTransform::world(t_s, child, p));
    }

    pub(super) fn step(&mut self, s: &StepRecord) {
        let t = s.t_s;
        self.transform(t, "fork_root", &s.truth);
        if moved(self.pallet_sent, &s.pallet) {
            self.transform(t, "pallet", &s.pallet);
            self.pallet_sent = Some(s.pallet);
        }
        if moved(self.estimate_sent, &s.pallet_estimate) {
            self.transform(t, "pallet_estimate", &s.pallet_estimate);
            self.estimate_sent = Some(s.pallet_estimate);
        }
        // True and measured poses side by side at each NAV350 fix (the true pose at the
        // full rate is /tf and the telemetry's `truth`).
        if let Some(f) = &s.fix {
            self.write("/truck/pose_measured", t, &PoseInFrame::world(t, f));
            self.write("/truck/pose_true", t, &PoseInFrame::world(t, &s.truth));
        }
        let telemetry = Telemetry {
            t_s: t,
            truth: xyh(&s.truth),
            estimate: xyh(&s.estimate),
            pallet: xyh(&s.pallet),
            pallet_estimate: xyh(&s.pallet_estimate),
            steer_cmd_rad: s.steer_cmd_rad as f32,
            steer_rad: s.steer_rad as f32,
            speed_cmd_mps: s.speed_cmd_mps as f32,
            speed_mps: s.speed_mps as f32,
            lookahead_m: s.lookahead.map(|v| v as f32),
            cross_track_m: s.cross_track_m as f32,
            path_curvature_per_m: s.path_curvature_per_m as f32,
            contact_force_n: s.contact_force_n as f32,
        };
        self.write("/forkbench/telemetry", t, &telemetry);
    }
}
