//! Recordings are read back: MCAP with the mcap crate, and with `--features rerun` rerun's messages with its public SDK (CI checks the .rrd files with `rerun rrd verify` and rerun's Python reader).

// The .rrd sink's tests: the rerun feature is opt-in (CI runs them with it).
#[cfg(feature = "rerun")]
#[path = "recordings/rrd.rs"]
mod rrd;

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use forkbench_log::McapRecorder;
use forkbench_trial::{Recorder, Scenario, TrialOptions, run_trial_recorded};

fn field_test() -> Scenario {
    Scenario::load(Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenarios/field-test.toml"
    )))
    .and_then(|s| s.with_pallet_sensing("gaussian"))
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
    let mut world_ids = BTreeSet::new();
    let mut logs = Vec::new();
    for m in mcap::MessageStream::new(&bytes).expect("valid mcap") {
        let m = m.expect("message");
        assert!(
            m.log_time >= last_time,
            "log time goes back at {}",
            m.channel.topic
        );
        // Simulated time 0 is the documented epoch, not 1970.
        let epoch_ns = forkbench_log::mcap_sink::SIM_EPOCH_UNIX_S * 1_000_000_000;
        assert!(m.log_time >= epoch_ns && m.log_time < epoch_ns + 700_000_000_000);
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
        if m.channel.topic == "/world" {
            for e in v["entities"].as_array().expect("entities") {
                world_ids.insert(e["id"].as_str().expect("id").to_owned());
            }
        }
        if m.channel.topic == "/log" {
            logs.push(v["message"].as_str().expect("message").to_owned());
        }
        if m.channel.topic == "/forkbench/outcome" {
            outcome_msg = Some(v);
        }
    }
    // The drive, the look-ahead point and the markers are drawn in the world.
    for id in [
        "trajectory/0",
        "trajectory/1",
        "lookahead",
        "start",
        "goal",
        "pallet_initial",
        "plan/0",
    ] {
        assert!(world_ids.contains(id), "no {id} in /world: {world_ids:?}");
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
        last_time - forkbench_log::mcap_sink::SIM_EPOCH_UNIX_S * 1_000_000_000,
        (out.sim_time_s * 1e9).round() as u64,
        "log time is simulation time from the epoch"
    );
    // The verdict in /log and in forkbench.Outcome, beside the judged outcome's fields.
    let mut outcome_msg = outcome_msg.expect("outcome");
    let verdict = outcome_msg["verdict"].as_str().expect("verdict").to_owned();
    let word = if out.success { "SUCCESS" } else { "FAILED" };
    assert!(verdict.starts_with(word), "{verdict}");
    if let Some(d) = &out.failure_detail {
        assert!(verdict.contains(d.as_str()), "{verdict}");
    }
    assert_eq!(
        logs.last(),
        Some(&format!("outcome: {verdict}")),
        "{logs:?}"
    );
    outcome_msg
        .as_object_mut()
        .expect("object")
        .remove("verdict");
    assert_eq!(outcome_msg, serde_json::to_value(&out).expect("serialises"));

    let summary = mcap::Summary::read(&bytes)
        .expect("readable")
        .expect("indexed file has a summary");
    assert!(!summary.chunk_indexes.is_empty(), "chunked");
    assert_eq!(summary.metadata_indexes.len(), 1);
}

/// A replan deletes the superseded plan's entity before drawing the new one.
#[test]
fn mcap_deletes_a_superseded_plan() {
    let scn = field_test();
    let path = tmp("replan.mcap");
    let mut rec = McapRecorder::create(&path, BTreeMap::new()).expect("opens");
    let replan = TrialOptions {
        replan: Some(true),
        ..opts()
    };
    let out = run_trial_recorded(&scn, &scn.cases[0], &replan, &mut rec);
    rec.finish().expect("finishes");
    assert!(out.replans >= 1, "the field test replans: {out:?}");
    let bytes = std::fs::read(&path).expect("written");
    let (mut deleted, mut drawn) = (Vec::new(), Vec::new());
    for m in mcap::MessageStream::new(&bytes).expect("valid mcap") {
        let m = m.expect("message");
        if m.channel.topic != "/world" {
            continue;
        }
        let v: serde_json::Value = serde_json::from_slice(&m.data).expect("JSON");
        for d in v["deletions"].as_array().expect("deletions") {
            deleted.push(d["id"].as_str().expect("id").to_owned());
        }
        for e in v["entities"].as_array().expect("entities") {
            let id = e["id"].as_str().expect("id");
            if id.starts_with("plan/") {
                drawn.push(id.to_owned());
            }
        }
    }
    let n = out.replans as usize;
    let want_drawn: Vec<String> = (0..=n).map(|i| format!("plan/{i}")).collect();
    let want_deleted: Vec<String> = (0..n).map(|i| format!("plan/{i}")).collect();
    assert_eq!(drawn, want_drawn);
    assert_eq!(deleted, want_deleted);
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
    // No summary, no footer: as if the process died. The target is untouched; what was
    // written is in the temporary file beside it.
    let partial = rec.abandon().expect("a partial file");
    assert!(!path.exists(), "a crashed recording appeared at its path");
    assert_eq!(partial.parent(), path.parent());
    let bytes = std::fs::read(&partial).expect("written");
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

/// The version the metadata names is the rerun SDK actually locked.
#[test]
fn rerun_version_matches_the_lock_file() {
    let lock = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../Cargo.lock"))
        .expect("Cargo.lock");
    let want = format!(
        "name = \"rerun\"\nversion = \"{}\"",
        forkbench_log::RERUN_VERSION
    );
    assert!(lock.contains(&want), "Cargo.lock has no {want}");
    let meta = forkbench_log::mcap_metadata(["s", "c", "p", "t"], 7, "9.9.9");
    assert_eq!(meta["rerun_version"], forkbench_log::RERUN_VERSION);
    assert_eq!(meta["seed"], "7");
}
