//! Recordings are read back: MCAP with the mcap crate, rerun's messages with its public SDK (CI checks the .rrd files with `rerun rrd verify` and rerun's Python reader).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use forkbench_log::{McapRecorder, RerunRecorder, RerunTarget};
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

/// Chunks of a recording kept in memory, by entity path (rerun's public SDK).
fn chunks_by_entity(msgs: Vec<rerun::log::LogMsg>) -> BTreeMap<String, Vec<rerun::log::Chunk>> {
    let mut chunks: BTreeMap<String, Vec<rerun::log::Chunk>> = BTreeMap::new();
    for msg in msgs {
        if let rerun::log::LogMsg::ArrowMsg(store, m) = msg
            && store.kind() == rerun::StoreKind::Recording
        {
            let chunk = rerun::log::Chunk::from_arrow_msg(&m).expect("a chunk");
            chunks
                .entry(chunk.entity_path().to_string())
                .or_default()
                .push(chunk);
        }
    }
    chunks
}

/// Every string of `component` logged to `entity`.
fn strings(
    chunks: &BTreeMap<String, Vec<rerun::log::Chunk>>,
    entity: &str,
    component: rerun::ComponentIdentifier,
) -> Vec<String> {
    chunks
        .get(entity)
        .into_iter()
        .flatten()
        .flat_map(|c| {
            c.iter_slices::<String>(component)
                .flatten()
                .map(|s| s.to_string())
                .collect::<Vec<_>>()
        })
        .collect()
}

/// Rows sent on `sim_time` per entity.
fn temporal_rows(chunks: &BTreeMap<String, Vec<rerun::log::Chunk>>) -> BTreeMap<String, usize> {
    chunks
        .iter()
        .map(|(e, cs)| {
            (
                e.clone(),
                cs.iter()
                    .filter(|c| !c.is_static())
                    .map(|c| c.num_rows())
                    .sum(),
            )
        })
        .collect()
}

/// Runs the field test into a recorder kept in memory; returns its chunks, the blueprint's
/// message count and the outcome.
fn recorded_in_memory(
    opts: &TrialOptions,
    extra: &mut dyn Recorder,
) -> (
    BTreeMap<String, Vec<rerun::log::Chunk>>,
    usize,
    forkbench_trial::TrialOutcome,
) {
    let scn = field_test();
    let (mut rec, storage) = RerunRecorder::in_memory().expect("opens");
    let out = run_trial_recorded(
        &scn,
        &scn.cases[0],
        opts,
        &mut forkbench_trial::Tee(vec![&mut rec, extra]),
    );
    rec.finish().expect("closes");
    let msgs = storage.take();
    let blueprint = msgs
        .iter()
        .filter(|m| m.store_id().kind() == rerun::StoreKind::Blueprint)
        .count();
    (chunks_by_entity(msgs), blueprint, out)
}

#[test]
fn rrd_holds_the_map_plots_verdict_and_the_trials_name() {
    /// Counts the NAV350 fixes the trial reports.
    struct Fixes(usize);
    impl Recorder for Fixes {
        fn step(&mut self, s: &forkbench_trial::StepRecord) {
            self.0 += usize::from(s.fix.is_some());
        }
    }
    let mut fixes = Fixes(0);
    let (chunks, blueprint, out) = recorded_in_memory(&opts(), &mut fixes);
    assert!(blueprint > 10, "a blueprint is sent: {blueprint} messages");
    for e in [
        "/map",
        "/map/initial",
        "/map/world/pallet",
        "/map/truck",
        "/map/plan/0",
        "/map/track/trajectory",
        "/map/track/now",
        "/map/sensors/nav350_fix",
        "/map/sensors/pallet_estimate",
        "/plots/lateral_error",
        "/plots/heading_error",
        "/plots/steering",
        "/plots/speed",
        "/plots/contact_force",
        "/events",
        "/verdict",
    ] {
        assert!(chunks.contains_key(e), "missing {e}: {:?}", chunks.keys());
    }
    // Every step's truck pose, trajectory tail, look-ahead and drive plots (sent as
    // columns), plus the start pose; the entry errors over the approach only.
    let rows = temporal_rows(&chunks);
    let steps = (out.sim_time_s / field_test().sim.dt_s).round() as usize;
    assert_eq!(rows["/map/truck"], steps + 1, "{rows:?}");
    for p in ["/plots/steering", "/plots/contact_force", "/map/track/now"] {
        assert_eq!(rows[p], steps, "{p}: {rows:?}");
    }
    // From the tips 1.5 m before the face through the insertion: not the whole trial.
    let approach = rows["/plots/lateral_error"];
    assert!(
        approach > 10 && approach < steps * 3 / 4,
        "{approach} of {steps} steps"
    );
    // The judged entry: one marker on each entry plot and one on the map.
    for e in [
        "/plots/lateral_error/entry",
        "/plots/heading_error/entry",
        "/map/track/entry",
    ] {
        assert_eq!(rows.get(e), Some(&1), "{e}: {rows:?}");
    }
    // One row (true and measured arrow) per NAV350 fix.
    assert!(fixes.0 > 10, "{} fixes", fixes.0);
    assert_eq!(rows["/map/sensors/nav350_fix"], fixes.0, "{rows:?}");
    // The recording is named after the trial, the verdict names the failed criterion or
    // success, and the series have their names and fixed colours.
    let name = strings(
        &chunks,
        "/__properties",
        rerun::RecordingInfo::descriptor_name().component,
    );
    let want = format!(
        "field-test / {} / {} / {} / seed {}",
        out.case, out.planner, out.tracker, out.seed
    );
    assert!(name.contains(&want), "{name:?} lacks {want}");
    let verdict = strings(
        &chunks,
        "/verdict",
        rerun::TextDocument::descriptor_text().component,
    );
    let last = verdict.last().expect("a verdict");
    match out.failure {
        None => assert!(last.contains("SUCCESS"), "{last}"),
        Some(f) => {
            assert!(last.contains(&format!("FAILED: {}", f.name())), "{last}");
            assert!(
                last.contains(out.failure_detail.as_deref().unwrap_or("?")),
                "{last}"
            );
        }
    }
    let names = strings(
        &chunks,
        "/plots/lateral_error",
        rerun::SeriesLines::descriptor_names().component,
    );
    assert_eq!(names, ["fork root", "+ limit", "− limit"]);
    let colors = rerun::SeriesLines::descriptor_colors().component;
    for plot in ["/plots/lateral_error", "/plots/steering"] {
        assert!(
            chunks[plot]
                .iter()
                .any(|c| c.components().contains_component(colors)),
            "{plot} colours"
        );
    }
}

/// A replan fades the plan driven so far: its colour is logged again, at the replan.
#[test]
fn rrd_fades_a_superseded_plan() {
    let replan = TrialOptions {
        replan: Some(true),
        ..opts()
    };
    let (chunks, _, out) = recorded_in_memory(&replan, &mut forkbench_trial::NoRecorder);
    assert!(out.replans >= 1, "the field test replans: {out:?}");
    let colors = rerun::LineStrips2D::descriptor_colors().component;
    let logged = |e: &str| {
        chunks[e]
            .iter()
            .filter(|c| c.components().contains_component(colors))
            .map(|c| c.num_rows())
            .sum::<usize>()
    };
    assert_eq!(logged("/map/plan/0"), 2, "drawn, then faded");
    let last = format!("/map/plan/{}", out.replans);
    assert_eq!(logged(&last), 1, "the plan being driven is drawn once");
}

/// The .rrd file is rerun's stream (FourCC, and CI's `rerun rrd verify` checks the rest),
/// holds the blueprint and the trial, and two files from one process are complete.
#[test]
fn rrd_files_are_written_whole() {
    let scn = field_test();
    let mut sizes = Vec::new();
    for name in ["a.rrd", "b.rrd"] {
        let path = tmp(name);
        let mut rec = RerunRecorder::new(&RerunTarget::File(path.clone())).expect("opens");
        run_trial_recorded(&scn, &scn.cases[0], &opts(), &mut rec);
        rec.finish().expect("flushes");
        let bytes = std::fs::read(&path).expect("written");
        assert_eq!(&bytes[..4], b"RRF2", "{name}: rerun's stream header");
        sizes.push(bytes.len());
    }
    assert!(sizes.iter().all(|s| *s > 100_000), "{sizes:?}");
    let ratio = sizes[0] as f64 / sizes[1] as f64;
    assert!(
        (0.9..1.1).contains(&ratio),
        "same trial, same size: {sizes:?}"
    );
}

/// A write that fails (a full disk, a file-size limit) reaches the caller as an error
/// naming the file and the reason, for both sinks, and leaves nothing at the path: both
/// write on threads of their own, so the error comes when the recording is finished. The
/// failure is made real in a child of this test with a 64 KiB file-size limit (a device
/// such as `/dev/full` is refused as a recording's target).
#[test]
#[cfg(target_os = "linux")]
fn a_failed_write_is_reported_by_both_sinks() {
    let exe = std::env::current_exe().expect("the test binary");
    let out = std::process::Command::new("bash")
        .arg("-c")
        .arg("trap '' XFSZ; ulimit -f 64; exec \"$0\" --exact write_failure_child --nocapture")
        .arg(&exe)
        .env(
            "FORKBENCH_WRITE_FAILURE_CHILD",
            tmp("write-failure").as_os_str(),
        )
        .output()
        .expect("bash runs");
    let text =
        String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{text}");
    assert!(text.contains("1 passed"), "the child ran no test: {text}");
}

/// The child of [`a_failed_write_is_reported_by_both_sinks`]: runs only there.
#[test]
fn write_failure_child() {
    let Some(dir) = std::env::var_os("FORKBENCH_WRITE_FAILURE_CHILD") else {
        return;
    };
    let dir = std::path::PathBuf::from(dir);
    std::fs::create_dir_all(&dir).expect("dir");
    let scn = field_test();
    let (m, r) = (dir.join("big.mcap"), dir.join("big.rrd"));
    let mut mcap = McapRecorder::create(&m, BTreeMap::new()).expect("opens");
    let mut rrd = RerunRecorder::new(&RerunTarget::File(r.clone())).expect("opens");
    run_trial_recorded(
        &scn,
        &scn.cases[0],
        &opts(),
        &mut forkbench_trial::Tee(vec![&mut mcap, &mut rrd]),
    );
    for (e, path) in [
        (mcap.finish().expect_err("the MCAP does not fit"), &m),
        (rrd.finish().expect_err("the .rrd does not fit"), &r),
    ] {
        let e = e.to_string();
        assert!(e.contains(&path.display().to_string()), "{e}");
        assert!(e.to_lowercase().contains("too large"), "{e}");
        assert!(
            !path.exists(),
            "a failed recording appeared at {}",
            path.display()
        );
    }
    let left: Vec<_> = std::fs::read_dir(&dir).expect("dir").collect();
    assert!(left.is_empty(), "temporary files left: {left:?}");
}

/// Every signal kind, as a component the sinks know nothing about would send it.
fn send_every_kind(rec: &mut dyn Recorder) {
    use forkbench_core::signal::{Grid, Scan};
    use forkbench_core::{Pose2, Signal, Style};
    let scan = Scan {
        sensor: Pose2::new(1.0, 2.0, 0.5),
        angle_min_rad: -0.5,
        angle_step_rad: 0.01,
        range_min_m: 0.05,
        range_max_m: 10.0,
        ranges_m: (0..101)
            .map(|i| if i == 7 { f64::NAN } else { 3.0 })
            .collect(),
    };
    let grid = Grid {
        origin_m: [0.0, 0.0],
        cell_m: 0.5,
        cols: 4,
        rows: 2,
        cells: vec![0, 100, 100, 0, 0, 100, 0, 0],
    };
    let style = Style::rgb(10, 200, 10).width(0.05);
    let pts = [[0.0, 0.0], [1.0, 1.0], [2.0, 0.5]];
    for i in 0..3 {
        let t = 0.1 * f64::from(i);
        rec.signal(
            t,
            "probe/pose",
            &Signal::Pose(Pose2::new(t, 0.0, 0.0)),
            style,
        );
        rec.signal(t, "probe/value_m", &Signal::Scalar(t * 2.0), style);
    }
    rec.signal(0.3, "probe/scan", &Signal::Scan(&scan), style);
    rec.signal(0.3, "probe/grid", &Signal::Grid(&grid), style);
    rec.signal(0.3, "probe/path", &Signal::Path(&pts), style);
    rec.signal(0.3, "probe/points", &Signal::Points(&pts), style);
    rec.signal(
        0.3,
        "probe/segments",
        &Signal::Segments(&[[pts[0], pts[1]]]),
        style,
    );
    rec.signal(
        0.3,
        "probe/boxes",
        &Signal::Boxes(&[[pts[0], pts[1]]]),
        style,
    );
    rec.signal(0.3, "probe/phase", &Signal::Text("lift started"), style);
}

/// A new component records itself through `Recorder::signal` alone: each kind lands in
/// rerun as an entity under `map/` or `signals/`, and in MCAP on the topic its kind maps to.
#[test]
fn every_signal_kind_reaches_both_sinks() {
    let (mut rerun_rec, storage) = RerunRecorder::in_memory().expect("opens");
    send_every_kind(&mut rerun_rec);
    rerun_rec.finish().expect("closes");
    let chunks = chunks_by_entity(storage.take());
    for kind in [
        "pose", "scan", "grid", "path", "points", "segments", "boxes",
    ] {
        let e = format!("/map/probe/{kind}");
        assert!(chunks.contains_key(&e), "missing {e}: {:?}", chunks.keys());
    }
    assert_eq!(temporal_rows(&chunks)["/map/probe/pose"], 3);
    assert_eq!(temporal_rows(&chunks)["/signals/probe/value_m"], 3);
    let log = strings(
        &chunks,
        "/events",
        rerun::TextLog::descriptor_text().component,
    );
    assert!(
        log.iter().any(|l| l == "probe/phase: lift started"),
        "{log:?}"
    );

    let path = tmp("signals.mcap");
    let mut mcap_rec = McapRecorder::create(&path, BTreeMap::new()).expect("opens");
    send_every_kind(&mut mcap_rec);
    mcap_rec.finish().expect("finishes");
    let bytes = std::fs::read(&path).expect("written");
    let mut topics: BTreeMap<String, (String, Vec<serde_json::Value>)> = BTreeMap::new();
    for m in mcap::MessageStream::new(&bytes).expect("valid mcap") {
        let m = m.expect("message");
        let schema = m.channel.schema.as_ref().expect("schema").name.clone();
        let v: serde_json::Value = serde_json::from_slice(&m.data).expect("JSON");
        topics
            .entry(m.channel.topic.clone())
            .or_insert((schema, Vec::new()))
            .1
            .push(v);
    }
    let schema = |t: &str| topics.get(t).map(|(s, _)| s.as_str());
    assert_eq!(schema("/scan/probe/scan"), Some("foxglove.LaserScan"));
    assert_eq!(schema("/grid/probe/grid"), Some("foxglove.Grid"));
    assert_eq!(schema("/pose/probe/pose"), Some("foxglove.PoseInFrame"));
    assert_eq!(schema("/signals/probe/value_m"), Some("forkbench.Scalar"));
    let scan = &topics["/scan/probe/scan"].1[0];
    assert_eq!(scan["ranges"].as_array().map(Vec::len), Some(101));
    assert!(
        scan["ranges"][7].is_null() && scan["ranges"][8] == 3.0,
        "{scan}"
    );
    assert_eq!(topics["/grid/probe/grid"].1[0]["data"], "AGRkAABkAAA=");
    let ids: BTreeSet<String> = topics["/world"]
        .1
        .iter()
        .flat_map(|u| u["entities"].as_array().cloned().unwrap_or_default())
        .filter_map(|e| e["id"].as_str().map(str::to_owned))
        .collect();
    for kind in ["scan", "grid", "path", "points", "segments", "boxes"] {
        assert!(ids.contains(&format!("probe/{kind}")), "{kind}: {ids:?}");
    }
    let log = &topics["/log"].1;
    assert!(
        log.iter()
            .any(|l| l["name"] == "probe/phase" && l["message"] == "lift started"),
        "{log:?}"
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
