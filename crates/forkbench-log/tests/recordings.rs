//! Recordings are read back: MCAP with the mcap crate, .rrd with rerun's own decoder.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use forkbench_log::{McapRecorder, RerunRecorder, RerunTarget};
use forkbench_trial::{Recorder, Scenario, TrialOptions, run_trial_recorded};

fn field_test() -> Scenario {
    Scenario::load(Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenarios/field-test.toml"
    )))
    .expect("loads")
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("forkbench-log-{}", std::process::id()));
    std::fs::create_dir_all(&d).expect("dir");
    d.join(name)
}

fn opts() -> TrialOptions {
    TrialOptions {
        seed: Some(3),
        ..TrialOptions::default()
    }
}

#[test]
fn mcap_has_schemas_channels_time_order_and_the_outcome() {
    let scn = field_test();
    let path = tmp("trial.mcap");
    let meta = BTreeMap::from([("scenario".to_owned(), "field-test".to_owned())]);
    let mut rec = McapRecorder::create(&path, meta).expect("opens");
    let out = run_trial_recorded(&scn, &scn.cases[0], &opts(), &mut rec);
    rec.finish().expect("finishes");
    let bytes = std::fs::read(&path).expect("written");

    let mut per_topic: BTreeMap<String, usize> = BTreeMap::new();
    let mut schemas = BTreeSet::new();
    let mut last_time = 0;
    let mut outcome_msg = None;
    let mut frames: BTreeMap<String, usize> = BTreeMap::new();
    let mut locked = BTreeSet::new();
    for m in mcap::MessageStream::new(&bytes).expect("valid mcap") {
        let m = m.expect("message");
        assert!(
            m.log_time >= last_time,
            "log time goes back at {}",
            m.channel.topic
        );
        last_time = m.log_time;
        assert_eq!(m.channel.message_encoding, "json");
        let schema = m.channel.schema.as_ref().expect("schema");
        assert_eq!(schema.encoding, "jsonschema");
        serde_json::from_slice::<serde_json::Value>(&schema.data).expect("schema is JSON");
        schemas.insert(schema.name.clone());
        *per_topic.entry(m.channel.topic.clone()).or_default() += 1;
        let v: serde_json::Value = serde_json::from_slice(&m.data).expect("message is JSON");
        if m.channel.topic == "/tf" {
            *frames
                .entry(v["child_frame_id"].as_str().expect("child").to_owned())
                .or_default() += 1;
        }
        if m.channel.topic == "/truck/scene" {
            for e in v["entities"].as_array().expect("entities") {
                locked.insert((
                    e["frame_id"].as_str().expect("frame").to_owned(),
                    e["frame_locked"].as_bool().expect("flag"),
                ));
            }
        }
        if m.channel.topic == "/forkbench/outcome" {
            outcome_msg = Some(v);
        }
    }
    for s in [
        "foxglove.SceneUpdate",
        "foxglove.FrameTransform",
        "foxglove.PoseInFrame",
        "foxglove.Log",
        "forkbench.Telemetry",
        "forkbench.Plan",
        "forkbench.Outcome",
    ] {
        assert!(schemas.contains(s), "missing schema {s}: {schemas:?}");
    }
    let steps = (out.sim_time_s / scn.sim.dt_s).round() as usize;
    assert_eq!(per_topic["/forkbench/telemetry"], steps);
    // The truck's frame at every step (and at the start); the pallet only when it moves;
    // geometry drawn once in those frames, frame-locked.
    assert_eq!(frames["fork_root"], steps + 1, "{frames:?}");
    assert!(
        frames["pallet"] >= 1 && frames["pallet"] < steps / 10,
        "{frames:?}"
    );
    assert!(frames.contains_key("pallet_estimate"), "{frames:?}");
    for frame in ["fork_root", "pallet", "pallet_estimate"] {
        assert!(locked.contains(&(frame.to_owned(), true)), "{locked:?}");
    }
    assert_eq!(
        per_topic["/truck/pose_true"],
        per_topic["/truck/pose_measured"]
    );
    assert_eq!(per_topic["/forkbench/outcome"], 1);
    // NAV350 at 8 Hz over the trial.
    let fixes = per_topic["/truck/pose_measured"];
    assert!(
        (fixes as f64 - out.sim_time_s * 8.0).abs() <= 2.0,
        "{fixes} fixes in {} s",
        out.sim_time_s
    );
    assert_eq!(
        last_time,
        (out.sim_time_s * 1e9).round() as u64,
        "log time is simulation time"
    );
    assert_eq!(
        outcome_msg.expect("outcome"),
        serde_json::to_value(&out).expect("serialises")
    );

    let summary = mcap::Summary::read(&bytes)
        .expect("readable")
        .expect("indexed file has a summary");
    assert!(!summary.chunk_indexes.is_empty(), "chunked");
    assert_eq!(summary.metadata_indexes.len(), 1);
}

#[test]
fn a_crash_mid_trial_leaves_a_readable_mcap_up_to_the_last_chunk() {
    struct StopAfter<'a> {
        inner: &'a mut McapRecorder,
        steps: usize,
    }
    impl Recorder for StopAfter<'_> {
        fn step(&mut self, s: &forkbench_trial::StepRecord) {
            self.steps += 1;
            if self.steps <= 300 {
                self.inner.step(s);
            }
            if self.steps == 300 {
                self.inner.flush().expect("flush");
            }
        }
    }
    let scn = field_test();
    let path = tmp("crash.mcap");
    let mut rec = McapRecorder::create(&path, BTreeMap::new()).expect("opens");
    run_trial_recorded(
        &scn,
        &scn.cases[0],
        &opts(),
        &mut StopAfter {
            inner: &mut rec,
            steps: 0,
        },
    );
    rec.abandon(); // no summary, no footer: as if the process died
    let bytes = std::fs::read(&path).expect("written");
    let opts = enumset::EnumSet::only(mcap::read::Options::IgnoreEndMagic);
    let mut telemetry = 0;
    for m in mcap::MessageStream::new_with_options(&bytes, opts).expect("header readable") {
        match m {
            Ok(m) if m.channel.topic == "/forkbench/telemetry" => telemetry += 1,
            Ok(_) => {}
            Err(_) => break, // the torn end
        }
    }
    assert_eq!(
        telemetry, 300,
        "every step up to the flushed chunk is readable"
    );
}

#[test]
fn rrd_decodes_with_rerun_and_holds_the_entities() {
    use rerun::external::re_log_encoding::DecoderApp;
    use rerun::external::re_log_types::LogMsg;

    let scn = field_test();
    let path = tmp("trial.rrd");
    /// Counts the NAV350 fixes the trial reports.
    struct Fixes(usize);
    impl Recorder for Fixes {
        fn step(&mut self, s: &forkbench_trial::StepRecord) {
            self.0 += usize::from(s.fix.is_some());
        }
    }
    let mut fixes = Fixes(0);
    let out = {
        let mut rec = RerunRecorder::new(&RerunTarget::File(path.clone())).expect("opens");
        let out = run_trial_recorded(
            &scn,
            &scn.cases[0],
            &opts(),
            &mut forkbench_trial::Tee(vec![&mut rec, &mut fixes]),
        );
        rec.finish().expect("flushes");
        out
    };
    let file = std::io::BufReader::new(std::fs::File::open(&path).expect("written"));
    let (mut arrow, mut apps, mut kinds) = (0, BTreeSet::new(), BTreeSet::new());
    let mut entities = BTreeSet::new();
    let mut rows: BTreeMap<String, usize> = BTreeMap::new();
    let mut chunks: BTreeMap<String, Vec<rerun::log::Chunk>> = BTreeMap::new();
    for msg in DecoderApp::decode_lazy(file) {
        match msg.expect("decodes") {
            LogMsg::SetStoreInfo(info) => {
                apps.insert(info.info.application_id().to_string());
                kinds.insert(format!("{:?}", info.info.store_id.kind()));
            }
            LogMsg::ArrowMsg(_, m) => {
                arrow += 1;
                if let Ok(chunk) = rerun::log::Chunk::from_arrow_msg(&m) {
                    entities.insert(chunk.entity_path().to_string());
                    if !chunk.is_static() {
                        *rows.entry(chunk.entity_path().to_string()).or_default() +=
                            chunk.num_rows();
                    }
                    chunks
                        .entry(chunk.entity_path().to_string())
                        .or_default()
                        .push(chunk);
                }
            }
            LogMsg::BlueprintActivationCommand(_) => {}
        }
    }
    assert!(apps.contains("forkbench"), "{apps:?}");
    assert!(
        kinds.iter().any(|k| k.contains("Blueprint")),
        "a blueprint is stored: {kinds:?}"
    );
    assert!(arrow > 10, "{arrow} arrow messages");
    for e in [
        "/world/pallet",
        "/truck",
        "/plan/path",
        "/plan/path/control_polygon",
        "/track/trajectory",
        "/track/lookahead",
        "/sensors/nav350_fix",
        "/sensors/pallet_estimate",
        "/plots/curvature",
        "/plots/steering",
        "/plots/speed",
        "/plots/lateral_error",
        "/plots/contact_force",
        "/events",
    ] {
        assert!(entities.contains(e), "missing {e}: {entities:?}");
    }
    // Every step's truck pose and plot values (sent as columns), plus the start pose.
    let steps = (out.sim_time_s / scn.sim.dt_s).round() as usize;
    assert_eq!(rows["/truck"], steps + 1, "{rows:?}");
    for p in [
        "/plots/steering",
        "/plots/contact_force",
        "/track/lookahead",
    ] {
        assert_eq!(rows[p], steps, "{p}: {rows:?}");
    }
    // Outlines and series names are sent once, as the first row of their entity's columns
    // (null after it): a latest-at query at the end of the trial still finds them.
    let end = rerun::external::re_chunk_store::LatestAtQuery::new(
        "sim_time".into(),
        rerun::external::re_log_types::TimeInt::new_temporal((out.sim_time_s * 1e9).round() as i64),
    );
    let strips = rerun::LineStrips2D::descriptor_strips().component;
    let names = rerun::SeriesLines::descriptor_names().component;
    for (entity, component) in [
        ("/truck", strips),
        ("/world/pallet", strips),
        ("/sensors/pallet_estimate", strips),
        ("/plots/curvature", names),
        ("/plots/contact_force", names),
    ] {
        let found = chunks[entity]
            .iter()
            .filter_map(|c| c.latest_at(&end, component))
            .count();
        assert_eq!(found, 1, "{entity} {component} at the end of the trial");
    }
    // One row (true and measured arrow) per NAV350 fix.
    assert!(fixes.0 > 10, "{} fixes", fixes.0);
    assert_eq!(rows["/sensors/nav350_fix"], fixes.0, "{rows:?}");
}

/// The .rrd footer (written by forkbench's own sink, from rerun's pieces) is what rerun's
/// reader expects: one manifest per store (recording and blueprint), and every chunk it
/// lists decodes, at the byte span it gives, to the chunk of that id; together they list
/// every chunk of the file. Two files from one process check the blueprint, encoded once,
/// in a second file too.
#[test]
fn rrd_footer_lists_every_chunk_where_it_is() {
    use rerun::external::re_log_encoding::{
        DecoderApp, MessageHeader, RawRrdManifest, StreamHeader,
    };
    use rerun::external::re_log_types::LogMsg;

    let scn = field_test();
    for name in ["footer-a.rrd", "footer-b.rrd"] {
        let path = tmp(name);
        let mut rec = RerunRecorder::new(&RerunTarget::File(path.clone())).expect("opens");
        run_trial_recorded(&scn, &scn.cases[0], &opts(), &mut rec);
        rec.finish().expect("flushes");
        let bytes = std::fs::read(&path).expect("written");
        // The chunks the file holds, in order, by decoding it from the start.
        let chunk_of = |msg: LogMsg| match msg {
            LogMsg::ArrowMsg(store, m) => Some((
                format!("{:?}", store.kind()),
                rerun::log::Chunk::from_arrow_msg(&m).expect("chunk").id(),
            )),
            _ => None,
        };
        let in_file: BTreeSet<_> = DecoderApp::decode_lazy(bytes.as_slice())
            .filter_map(|m| chunk_of(m.expect("decodes")))
            .collect();
        let manifests = RawRrdManifest::from_rrd_bytes(&bytes).expect("footer reads");
        let kinds: BTreeSet<String> = manifests
            .iter()
            .map(|m| format!("{:?}", m.store_id.kind()))
            .collect();
        assert_eq!(kinds.len(), 2, "{name}: one manifest per store: {kinds:?}");
        let header = &bytes[..StreamHeader::ENCODED_SIZE_BYTES];
        let mut listed = BTreeSet::new();
        for m in &manifests {
            let kind = format!("{:?}", m.store_id.kind());
            let ids: Vec<_> = m.col_chunk_id().expect("ids").collect();
            let offsets: Vec<_> = m.col_chunk_byte_offset().expect("offsets").collect();
            let sizes: Vec<_> = m.col_chunk_byte_size().expect("sizes").collect();
            assert_eq!(ids.len(), offsets.len());
            for ((id, offset), size) in ids.iter().zip(offsets).zip(sizes) {
                // The span excludes the message header: decode header + span on its own.
                let start = offset as usize - MessageHeader::ENCODED_SIZE_BYTES;
                let one = [header, &bytes[start..offset as usize + size as usize]].concat();
                let decoded: Vec<_> = DecoderApp::decode_lazy(one.as_slice())
                    .filter_map(|m| chunk_of(m.expect("the span decodes")))
                    .collect();
                assert_eq!(decoded, [(kind.clone(), *id)], "{name}: chunk at {offset}");
                listed.insert((kind.clone(), *id));
            }
        }
        assert_eq!(listed, in_file, "{name}: the footer lists every chunk");
        assert!(listed.len() > 20, "{name}: {} chunks", listed.len());
    }
}

/// A full disk reaches the caller as an error naming the file and the reason, for both
/// sinks (`/dev/full` opens, then every write fails with ENOSPC): both write on threads of
/// their own, so the error comes when the recording is finished.
#[test]
#[cfg(target_os = "linux")]
fn a_full_disk_is_reported_by_both_sinks() {
    let scn = field_test();
    let full = Path::new("/dev/full");
    let mut mcap = McapRecorder::create(full, BTreeMap::new()).expect("opens");
    let mut rrd = RerunRecorder::new(&RerunTarget::File(full.to_path_buf())).expect("opens");
    run_trial_recorded(
        &scn,
        &scn.cases[0],
        &opts(),
        &mut forkbench_trial::Tee(vec![&mut mcap, &mut rrd]),
    );
    for e in [
        mcap.finish().expect_err("the MCAP does not fit"),
        rrd.finish().expect_err("the .rrd does not fit"),
    ] {
        let e = e.to_string();
        assert!(e.contains("/dev/full"), "{e}");
        assert!(e.to_lowercase().contains("no space"), "{e}");
    }
}
