//! The .rrd sink read back through rerun's public SDK, and both sinks fed alike.

use std::collections::{BTreeMap, BTreeSet};

use forkbench_log::{McapRecorder, RerunRecorder, RerunTarget};
use forkbench_trial::{Recorder, TrialOptions, run_trial_recorded};

use super::{field_test, opts, tmp};

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
        .arg("trap '' XFSZ; ulimit -f 64; exec \"$0\" --exact rrd::write_failure_child --nocapture")
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
