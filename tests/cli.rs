//! End-to-end tests of the `forkbench` binary and of the data files under scenarios/ and worlds/.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn forkbench(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_forkbench"))
        .args(args)
        .output()
        .expect("binary runs")
}

fn stdout_json(out: &Output) -> serde_json::Value {
    assert!(
        out.status.success(),
        "stderr: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("one JSON object")
}

fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("forkbench-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir.join(name)
}

#[test]
fn plan_bspline_json_has_every_field_and_an_exact_endpoint() {
    let v = stdout_json(&forkbench(&[
        "plan",
        "bspline",
        "--start",
        "0,0,90",
        "--goal",
        "1.5,6.5,105",
        "--json",
    ]));
    for key in [
        "planner",
        "start",
        "goal",
        "params",
        "cost",
        "max_curvature_per_m",
        "max_steer_rad",
        "length_m",
        "endpoint_error_m",
        "solve_time_us",
        "samples",
    ] {
        assert!(v.get(key).is_some(), "missing {key}");
    }
    assert_eq!(v["planner"], "bspline");
    assert!(v["params"]["l1_m"].as_f64().expect("l1") >= 1.5);
    assert!(v["params"]["l2_m"].as_f64().expect("l2") >= 1.5);
    assert!(v["endpoint_error_m"].as_f64().expect("err") < 1e-9);
    // Scenario 18 of the paper: max steering 0.5255 rad.
    assert!((v["max_steer_rad"].as_f64().expect("steer") - 0.5255).abs() < 5e-4);
    let samples = v["samples"].as_array().expect("samples");
    let mut prev: Option<(f64, f64, f64)> = None;
    for s in samples {
        let (sm, x, y) = (
            s["s_m"].as_f64().expect("s"),
            s["x_m"].as_f64().expect("x"),
            s["y_m"].as_f64().expect("y"),
        );
        assert!(s["heading_rad"].is_f64() && s["curvature_per_m"].is_f64());
        if let Some((ps, px, py)) = prev {
            assert!(sm > ps && sm - ps <= 0.01 + 1e-9, "arc spacing {}", sm - ps);
            assert!((x - px).hypot(y - py) <= 0.01 + 1e-9);
        }
        prev = Some((sm, x, y));
    }
    let last = samples.last().expect("non-empty");
    assert!((last["x_m"].as_f64().expect("x") - 1.5).abs() < 1e-9);
    assert!((last["y_m"].as_f64().expect("y") - 6.5).abs() < 1e-9);
}

#[test]
fn plan_spiral_json_reports_normalised_params() {
    let v = stdout_json(&forkbench(&[
        "plan",
        "spiral",
        "--start",
        "1,2,30",
        "--goal",
        "6,-1,-20",
        "--start-curvature",
        "-0.2",
        "--json",
    ]));
    assert_eq!(v["planner"], "spiral");
    for key in ["a", "b", "c", "d", "e", "sf", "scale_m", "mirrored"] {
        assert!(v["params"].get(key).is_some(), "missing params.{key}");
    }
    assert_eq!(v["params"]["mirrored"], true);
    assert!(v["endpoint_error_m"].as_f64().expect("err") <= 1e-3);
    assert!(v["cost"].as_f64().expect("cost") > 0.0);
    let first = &v["samples"][0];
    assert!((first["curvature_per_m"].as_f64().expect("k0") + 0.2).abs() < 1e-12);
}

#[test]
fn infeasible_goal_fails_with_the_limit_named() {
    let out = forkbench(&["plan", "bspline", "--start", "0,0,0", "--goal", "1,3,0"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("κ_max 1.0630 m⁻¹") && err.contains("needs max |κ|"),
        "{err}"
    );
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn malformed_pose_is_a_usage_error() {
    let out = forkbench(&["plan", "spiral", "--start", "0,0", "--goal", "6,1,0"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("x_m,y_m,heading_deg"), "{err}");
    let out = forkbench(&["plan", "spiral", "--start", "0,0,abc", "--goal", "6,1,0"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("heading_deg"));
}

#[test]
fn reproduce_both_tables_as_json() {
    let b = stdout_json(&forkbench(&["reproduce", "bspline", "--json"]));
    let rows = b["rows"].as_array().expect("rows");
    assert_eq!(rows.len(), 18);
    for r in rows {
        let ours = r["max_curvature_per_m"].as_f64().expect("ours");
        let paper = r["paper_max_curvature_per_m"].as_f64().expect("paper");
        assert!(ours <= paper * (1.0 + 1e-9), "{r}");
    }
    let s = stdout_json(&forkbench(&["reproduce", "spiral", "--json"]));
    let rows = s["rows"].as_array().expect("rows");
    assert_eq!(rows.len(), 23);
    for r in rows {
        assert!(r["endpoint_error_m"].as_f64().expect("err") <= 1e-3, "{r}");
        assert!(r["paper_cost"].as_f64().expect("paper cost") > 0.0);
    }
}

#[test]
fn reproduce_markdown_has_a_row_per_scenario() {
    let out = forkbench(&["reproduce", "spiral"]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        text.lines()
            .filter(|l| l.starts_with("| ") && !l.starts_with("| #"))
            .count(),
        23
    );
    assert!(
        text.contains("paper's path ends"),
        "explains the rows where our cost is higher"
    );
}

#[test]
fn plots_are_written_as_png_and_svg() {
    let png = tmp("plan.png");
    let out = forkbench(&[
        "plan",
        "bspline",
        "--start",
        "0,0,90",
        "--goal",
        "1,6.5,95",
        "--plot",
        png.to_str().expect("utf8"),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let bytes = std::fs::read(&png).expect("png written");
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    let svg = tmp("table.svg");
    let out = forkbench(&["reproduce", "spiral", "--plot", svg.to_str().expect("utf8")]);
    assert!(out.status.success());
    let text = std::fs::read_to_string(&svg).expect("svg written");
    assert!(text.contains("<svg") && text.contains("polyline"));
    let out = forkbench(&[
        "plan", "bspline", "--start", "0,0,90", "--goal", "1,6.5,95", "--plot", "x.gif",
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains(".svg or .png"));
}

#[test]
fn bad_table_file_error_names_file_and_line() {
    let bad = tmp("bad-table.toml");
    std::fs::write(&bad, "paper = \"x\"\nstart_mm_deg = [0.0, 0.0, 90.0]\npick_distance_mm = 6500.0\n\n[[case]]\nname = \"1\"\nlateral_offset_mm = \"wide\"\n").expect("write");
    let out = forkbench(&[
        "reproduce",
        "bspline",
        "--table",
        bad.to_str().expect("utf8"),
    ]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("bad-table.toml")
            && err.contains("line 7")
            && err.contains("lateral_offset_mm"),
        "{err}"
    );
}

#[test]
fn bad_truck_file_error_names_the_field() {
    let bad = tmp("truck.toml");
    std::fs::write(&bad, "wheelbase_m = -1.0\n").expect("write");
    let out = forkbench(&[
        "plan",
        "bspline",
        "--start",
        "0,0,90",
        "--goal",
        "1,6.5,95",
        "--truck",
        bad.to_str().expect("utf8"),
    ]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("truck.toml") && err.contains("wheelbase_m"),
        "{err}"
    );
}

/// Every committed data file parses, so none goes stale.
#[test]
fn every_committed_data_file_loads() {
    let toml_files = |dir: &str| -> Vec<PathBuf> {
        let mut v: Vec<PathBuf> = std::fs::read_dir(repo_root().join(dir))
            .expect("dir exists")
            .map(|e| e.expect("entry").path())
            .filter(|p| p.extension().and_then(|e| e.to_str()) == Some("toml"))
            .collect();
        v.sort();
        v
    };
    let (mut tables, mut scenarios, mut worlds) = (0, 0, 0);
    for path in toml_files("scenarios/reference") {
        let text = std::fs::read_to_string(&path).expect("readable");
        let name = path.display().to_string();
        if path
            .file_name()
            .and_then(|f| f.to_str())
            .is_some_and(|f| f.starts_with("bspline-"))
        {
            forkbench_plan::reproduce::BsplineTable::parse(&text, &name)
                .expect("valid B-spline table");
        } else {
            forkbench_plan::reproduce::SpiralTable::parse(&text, &name)
                .expect("valid spiral table");
        }
        tables += 1;
    }
    for path in toml_files("scenarios") {
        let s = forkbench_trial::Scenario::load(&path).unwrap_or_else(|e| panic!("{e}"));
        assert!(!s.cases.is_empty());
        scenarios += 1;
    }
    for path in toml_files("worlds") {
        forkbench_trial::World::load(&path).unwrap_or_else(|e| panic!("{e}"));
        worlds += 1;
    }
    assert!(
        tables >= 2 && scenarios >= 4 && worlds >= 2,
        "{tables} tables, {scenarios} scenarios, {worlds} worlds"
    );
}

#[test]
fn trial_json_reports_the_outcome_in_si_units() {
    let scn = repo_root().join("scenarios/field-test.toml");
    let v = stdout_json(&forkbench(&[
        "trial",
        scn.to_str().expect("utf8"),
        "--no-noise",
        "--json",
    ]));
    for key in [
        "success",
        "failure",
        "lateral_error_m",
        "heading_error_rad",
        "insertion_depth_m",
        "max_steer_rad",
        "max_contact_force_n",
        "pallet_displacement_m",
        "sim_time_s",
        "wall_time_ms",
    ] {
        assert!(v.get(key).is_some(), "missing {key}");
    }
    assert_eq!(v["success"], true);
    assert!(v["failure"].is_null());
    assert!(v["insertion_depth_m"].as_f64().expect("depth") > 1.0);
}

#[test]
fn failed_pick_exits_3_and_names_the_criterion() {
    let scn = repo_root().join("scenarios/field-test.toml");
    let out = forkbench(&["trial", scn.to_str().expect("utf8"), "--seed", "3"]);
    // Seed 3 with full pallet-estimate noise and no replanning; whichever way it ends,
    // the exit status must match the verdict.
    let text = String::from_utf8_lossy(&out.stdout);
    if text.contains("SUCCESS") {
        assert_eq!(out.status.code(), Some(0));
    } else {
        assert_eq!(out.status.code(), Some(3), "{text}");
        assert!(text.contains("FAILED: "), "{text}");
    }
    let bad = tmp("bias.toml");
    std::fs::write(
        &bad,
        "name = \"bias\"\nplanner = \"spiral\"\nestimate_bias = { x_m = 0.0, y_m = 0.27, heading_deg = 0.0 }\nstart = { x_m = 0.0, y_m = 0.0, heading_deg = 0.0 }\npallet = { x_m = 8.5, y_m = 0.5, heading_deg = 0.0 }\n",
    )
    .expect("write");
    let out = forkbench(&["trial", bad.to_str().expect("utf8"), "--no-noise"]);
    assert_eq!(out.status.code(), Some(3));
    assert!(String::from_utf8_lossy(&out.stdout).contains("FAILED: contact_force"));
    // A batch of that biased pick below its JUnit floor: the run worked, the result is a
    // failure (3), and the outputs are written.
    let dir = tmp("below-floor");
    let junit = tmp("below-floor.xml");
    let out = forkbench(&[
        "batch",
        bad.to_str().expect("utf8"),
        "--trials",
        "2",
        "--pallet-noise-scale",
        "0",
        "--out",
        dir.to_str().expect("utf8"),
        "--junit",
        junit.to_str().expect("utf8"),
        "--floor",
        "0.5",
    ]);
    assert_eq!(
        out.status.code(),
        Some(3),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let xml = std::fs::read_to_string(&junit).expect("junit");
    assert!(xml.contains("below the floor 50.0 %"), "{xml}");
}

#[test]
fn trial_input_errors_are_clear() {
    let scn = repo_root().join("scenarios/bspline-table2.toml");
    let out = forkbench(&["trial", scn.to_str().expect("utf8")]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("cases; name one (`--case`"));
    let out = forkbench(&["trial", scn.to_str().expect("utf8"), "--case", "42"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no case named \"42\""));
    let out = forkbench(&["trial", "does-not-exist.toml"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("does-not-exist.toml"));
}

#[test]
fn batch_writes_results_and_regress_gates_them() {
    let scn = repo_root().join("scenarios/field-test.toml");
    let scn = scn.to_str().expect("utf8");
    let out_dir = tmp("batch");
    let _ = std::fs::remove_dir_all(&out_dir);
    let dir = out_dir.to_str().expect("utf8");
    let junit = tmp("batch-junit.xml");
    let out = forkbench(&[
        "batch",
        scn,
        "--trials",
        "4",
        "--pallet-noise-scale",
        "0",
        "--pallet-sensing",
        "gaussian",
        "--out",
        dir,
        "--csv",
        "--report",
        "--junit",
        junit.to_str().expect("utf8"),
        "--floor",
        "0.9",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        String::from_utf8_lossy(&out.stdout)
            .contains("| field-test | bspline | pure_pursuit | plan once | 4 | 4 | 100.0 % |")
    );
    for f in [
        "trials.jsonl",
        "summary.json",
        "summary.md",
        "trials.csv",
        "report.html",
    ] {
        assert!(out_dir.join(f).exists(), "{f}");
    }
    // CSV: a header with SI-unit columns and one row per trial.
    let csv = std::fs::read_to_string(out_dir.join("trials.csv")).expect("csv");
    assert!(
        csv.starts_with("scenario,case,planner,tracker,trial,seed,"),
        "{csv}"
    );
    assert!(
        csv.lines()
            .next()
            .is_some_and(|h| h.contains("lateral_error_m"))
    );
    assert_eq!(csv.lines().count(), 5);
    // JUnit: one passing case (100 % ≥ the 90 % floor) and the provenance as properties.
    let xml = std::fs::read_to_string(&junit).expect("junit");
    assert!(xml.contains("tests=\"1\" failures=\"0\""), "{xml}");
    assert!(
        xml.contains("<property name=\"seed\" value=\"1\"/>"),
        "{xml}"
    );
    // Provenance: the summary says what ran, where and when.
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out_dir.join("summary.json")).expect("s"))
            .expect("json");
    let p = &summary["provenance"];
    for k in [
        "forkbench_version",
        "host",
        "cpu_model",
        "started_at",
        "finished_at",
        "arguments",
    ] {
        assert!(!p[k].is_null(), "provenance.{k}: {p}");
    }
    assert_eq!(p["manifest"]["scenarios"][0]["name"], "field-test");
    let base = tmp("base.json");
    assert!(
        forkbench(&["baseline", dir, "--out", base.to_str().expect("utf8")])
            .status
            .success()
    );
    let ok = forkbench(&["regress", "--baseline", base.to_str().expect("utf8"), dir]);
    assert_eq!(
        ok.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&ok.stdout)
    );
    // A tighter tolerance is not a regression: regress says the settings differ.
    let tight = tmp("tight.toml");
    let text = std::fs::read_to_string(repo_root().join("scenarios/field-test.toml")).expect("r");
    std::fs::write(&tight, text + "\n[tolerances]\nlateral_m = 0.05\n").expect("write");
    let tight_dir = tmp("tight-batch");
    let _ = std::fs::remove_dir_all(&tight_dir);
    let td = tight_dir.to_str().expect("utf8");
    let args = [
        "batch",
        tight.to_str().expect("utf8"),
        "--trials",
        "4",
        "--out",
        td,
    ];
    assert!(forkbench(&args).status.success());
    let warned = forkbench(&["regress", "--baseline", base.to_str().expect("utf8"), td]);
    let err = String::from_utf8_lossy(&warned.stderr);
    assert!(
        err.contains("note: changed since the baseline's batch (still paired by seed): field-test: tolerances.lateral_m"),
        "{err}"
    );
    // A baseline claiming 100 of 100 against 4 of 4 is no drop; one claiming a row that
    // was never run is a failure.
    std::fs::write(&base, r#"{"description":"x","rows":[{"scenario":"gone","planner":"spiral","trials":10,"successes":9}]}"#).expect("write");
    let missing = forkbench(&["regress", "--baseline", base.to_str().expect("utf8"), dir]);
    assert_eq!(missing.status.code(), Some(3));
    assert!(String::from_utf8_lossy(&missing.stdout).contains("missing"));
}

#[test]
fn batch_input_errors_are_clear() {
    let scn = repo_root().join("scenarios/field-test.toml");
    let scn = scn.to_str().expect("utf8");
    let cases: [(&[&str], &str); 6] = [
        (&["--shard", "2/2"], "index must be below the count"),
        (&["--shard", "one/2"], "is not a whole number"),
        (&["--trials", "0"], "trials: must be at least 1"),
        (&["--sweep", "nav_noise=1,2"], "unknown knob"),
        (&["--sweep", "pallet_noise=1,x"], "\"x\" is not a number"),
        (
            &["--pallet-noise-scale", "-1"],
            "pallet_noise_scale`: -1 must be a number from 0 to 100",
        ),
    ];
    for (extra, message) in cases {
        let mut args = vec!["batch", scn, "--out", "/nonexistent-dir-never-written"];
        args.extend_from_slice(extra);
        let out = forkbench(&args);
        assert_eq!(out.status.code(), Some(1), "{extra:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(message), "{extra:?}: {err}");
    }
    // Planner names resolve at run time (a scenario's own or a registered kind): an
    // unknown one is refused before any trial, naming the known kinds.
    let out = forkbench(&[
        "batch",
        scn,
        "--planner",
        "rrt",
        "--out",
        "/nonexistent-dir-never-written",
    ]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("unknown planner \"rrt\" (known: bspline, external, spiral)"),
        "{err}"
    );
    let bad = tmp("bad-baseline.json");
    std::fs::write(&bad, "{ not json").expect("write");
    let out = forkbench(&["regress", "--baseline", bad.to_str().expect("utf8"), "."]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("bad-baseline.json"));
}

#[test]
fn trial_records_rrd_and_mcap_and_refuses_to_overwrite() {
    let scn = repo_root().join("scenarios/field-test.toml");
    let scn = scn.to_str().expect("utf8");
    let (rrd, mcap) = (tmp("rec.rrd"), tmp("rec.mcap"));
    let _ = (std::fs::remove_file(&rrd), std::fs::remove_file(&mcap));
    let (r, m) = (rrd.to_str().expect("utf8"), mcap.to_str().expect("utf8"));
    let out = forkbench(&["trial", scn, "--no-noise", "--rrd", r, "--mcap", m]);
    if cfg!(feature = "rerun") {
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(std::fs::metadata(&rrd).expect("rrd").len() > 10_000);
    } else {
        // The default build has no rerun: refused before anything is opened or run.
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{err}");
        assert!(
            err.contains("--rrd needs rerun") && err.contains("--features rerun"),
            "{err}"
        );
        assert!(out.stdout.is_empty() && !rrd.exists() && !mcap.exists());
        assert!(
            forkbench(&["trial", scn, "--no-noise", "--mcap", m])
                .status
                .success()
        );
    }
    assert_eq!(&std::fs::read(&mcap).expect("mcap")[..8], b"\x89MCAP0\r\n");
    let again = forkbench(&["trial", scn, "--no-noise", "--mcap", m]);
    assert_eq!(again.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&again.stderr).contains("exists (overwriting it needs force"));
    assert!(
        forkbench(&["trial", scn, "--no-noise", "--mcap", m, "--force"])
            .status
            .success()
    );
}

#[test]
fn an_unreachable_viewer_is_reported_and_the_trial_still_runs() {
    let scn = repo_root().join("scenarios/field-test.toml");
    let out = forkbench(&[
        "trial",
        scn.to_str().expect("utf8"),
        "--no-noise",
        "--connect",
        "127.0.0.1:9",
    ]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    if cfg!(feature = "rerun") {
        assert!(
            err.contains("no rerun viewer reachable at 127.0.0.1:9"),
            "{err}"
        );
        assert!(String::from_utf8_lossy(&out.stdout).contains("outcome              SUCCESS"));
    } else {
        assert!(err.contains("--connect needs rerun"), "{err}");
        assert!(out.stdout.is_empty(), "refused before the trial runs");
    }
}

#[test]
fn batch_records_failures_and_replay_reproduces_a_trial() {
    let scn = repo_root().join("scenarios/field-test.toml");
    let dir = tmp("recbatch");
    let _ = std::fs::remove_dir_all(&dir);
    let d = dir.to_str().expect("utf8");
    let out = forkbench(&[
        "batch",
        scn.to_str().expect("utf8"),
        // Both modes, so the field test (one failure in 20 a mode) fails twice.
        "--trials",
        "20",
        "--modes",
        "both",
        "--out",
        d,
        "--max-recordings",
        "2",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let files = crate::common::names_in(&dir.join("recordings"));
    // Both formats with rerun built in, the MCAP alone without.
    let count = |ext: &str| files.iter().filter(|f| f.ends_with(ext)).count();
    let rrds = if cfg!(feature = "rerun") { 2 } else { 0 };
    assert_eq!((count(".rrd"), count(".mcap")), (rrds, 2), "{files:?}");
    assert!(
        files
            .iter()
            .all(|f| f.starts_with("field-test-default-bspline-pure_pursuit-seed")),
        "{files:?}"
    );
    let jsonl = dir.join("trials.jsonl");
    let (flag, rrd) = match cfg!(feature = "rerun") {
        true => ("--rrd", tmp("replayed.rrd")),
        false => ("--mcap", tmp("replayed.mcap")),
    };
    let _ = std::fs::remove_file(&rrd);
    let out = forkbench(&[
        "replay",
        jsonl.to_str().expect("utf8"),
        "--line",
        "3",
        "--scenario",
        scn.to_str().expect("utf8"),
        flag,
        rrd.to_str().expect("utf8"),
    ]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("identical to the recorded outcome"),
        "{text}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(rrd.exists());
}

#[test]
fn corridor_sweep_json_and_g_plot() {
    let v = stdout_json(&forkbench(&[
        "corridor",
        "--sweep-angles",
        "30:90:30",
        "--resolution",
        "0.02",
        "--json",
    ]));
    assert_eq!(v["vehicle"]["length_m"], 0.56);
    assert_eq!(v["resolution_m"], 0.02);
    let rows = v["rows"].as_array().expect("rows");
    // 3 angles × the 4 AMV modes, each with a width, none with a G area (no --width).
    assert_eq!(rows.len(), 12);
    for r in rows {
        assert!(
            r["min_width_m"]
                .as_f64()
                .is_some_and(|w| w > 0.40 && w < 0.75),
            "{r}"
        );
        assert!(
            r.get("g_area_m2").is_none_or(serde_json::Value::is_null),
            "{r}"
        );
    }
    let at = |deg: f64, mode: &str| {
        rows.iter()
            .find(|r| r["angle_deg"] == deg && r["mode"] == mode)
            .and_then(|r| r["min_width_m"].as_f64())
            .expect("row")
    };
    for deg in [30.0, 60.0, 90.0] {
        assert!(at(deg, "oblique") > at(deg, "spin") && at(deg, "spin") > at(deg, "curve"));
    }
    let svg = tmp("g.svg");
    let out = forkbench(&[
        "corridor",
        "--width",
        "0.6",
        "--angle",
        "90",
        "--resolution",
        "0.02",
        "--plot",
        svg.to_str().expect("utf-8"),
        "--json",
    ]);
    let v = stdout_json(&out);
    let g = |mode: &str| {
        v["rows"]
            .as_array()
            .and_then(|r| r.iter().find(|r| r["mode"] == mode))
            .and_then(|r| r["g_area_m2"].as_f64())
            .expect("G area")
    };
    assert!(g("curve") > g("spin") && g("spin") > g("oblique"));
    let text = std::fs::read_to_string(&svg).expect("plot written");
    assert!(
        text.starts_with("<svg") || text.starts_with("<?xml"),
        "{}",
        &text[..40]
    );
}

#[test]
fn corridor_input_errors_are_clear() {
    for (args, needle) in [
        (vec!["--vehicle", "0x0.4"], "length_m"),
        (vec!["--vehicle", "0.56x-1"], "width_m"),
        (vec!["--vehicle", "big"], "LENGTHxWIDTH"),
        (vec!["--angle", "200"], "angle_deg"),
        (vec!["--angle", "-5"], "angle_deg"),
        (vec!["--sweep-angles", "90:30:10"], "B ≥ A"),
        (vec!["--sweep-angles", "0:90"], "A:B:STEP"),
        (vec!["--width", "0.3"], "width_m"),
        (vec!["--resolution", "0"], "resolution"),
        (vec!["--truck", "--width", "1.0"], "width_m"),
        (vec!["--junction", "t", "--angle", "60"], "T junction"),
        (vec!["--junction", "y"], "--junction"),
    ] {
        let mut a = vec!["corridor"];
        a.extend(&args);
        let out = forkbench(&a);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?} succeeded");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
    }
}

/// Issue 21, defect 11: a scenario or case name cannot steer where recordings go, nor
/// make the batch fail after its trials ran.
#[test]
fn names_cannot_steer_recording_paths() {
    let base = tmp("names");
    let _ = std::fs::remove_dir_all(&base);
    let out = base.join("a/b/out");
    std::fs::create_dir_all(&out).expect("dir");
    let text = std::fs::read_to_string(repo_root().join("scenarios/field-test.toml"))
        .expect("readable")
        .replace("name = \"field-test\"", "name = \"../../escaped/x\"");
    let scn = base.join("hostile.toml");
    std::fs::write(&scn, text).expect("write");
    let run = forkbench(&[
        "batch",
        scn.to_str().expect("utf8"),
        "--trials",
        "2",
        "--record",
        "all",
        "--out",
        out.to_str().expect("utf8"),
    ]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(!base.join("a/b/escaped").exists() && !base.join("a/escaped").exists());
    let files: Vec<_> = std::fs::read_dir(out.join("recordings"))
        .expect("recordings inside OUT")
        .map(|e| e.expect("entry").file_name().into_string().expect("utf8"))
        .collect();
    // Two trials, each an MCAP and, with rerun built in, an .rrd.
    let per_trial = if cfg!(feature = "rerun") { 2 } else { 1 };
    assert_eq!(files.len(), 2 * per_trial, "{files:?}");
    assert!(
        files.iter().all(|f| f.starts_with("______escaped_x-")),
        "{files:?}"
    );
}

/// Issue 21, defects 12 and 13: one path for both formats is refused; a world that is a
/// device or a huge file is refused after a bounded read; a directory is not a file.
#[test]
fn one_path_for_two_formats_and_unbounded_inputs_are_refused() {
    let scn = repo_root().join("scenarios/field-test.toml");
    let scn = scn.to_str().expect("utf8");
    let same = tmp("same.out");
    let s = same.to_str().expect("utf8");
    let out = forkbench(&[
        "trial",
        scn,
        "--no-noise",
        "--mcap",
        s,
        "--actuator-log",
        s,
        "--force",
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        String::from_utf8_lossy(&out.stderr)
            .contains("given to two of --rrd, --mcap, --ros2 and --actuator-log")
    );
    let dir = std::env::temp_dir();
    let out = forkbench(&[
        "trial",
        scn,
        "--no-noise",
        "--mcap",
        dir.to_str().expect("utf8"),
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("is a directory"));
    let text = std::fs::read_to_string(scn).expect("readable");
    let zero = tmp("zero-world.toml");
    std::fs::write(&zero, format!("world = \"/dev/zero\"\n{text}")).expect("write");
    let t0 = std::time::Instant::now();
    let out = forkbench(&["trial", zero.to_str().expect("utf8"), "--no-noise"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("/dev/zero") && err.contains("not a regular file"),
        "{err}"
    );
    assert!(t0.elapsed().as_secs() < 20);
    // A deeply nested value's parse error is bounded, not the whole input echoed back.
    let deep = tmp("deep.toml");
    std::fs::write(&deep, format!("x = {}", "[".repeat(200_000))).expect("write");
    let out = forkbench(&["trial", deep.to_str().expect("utf8"), "--no-noise"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(out.stderr.len() < 10_000, "{} bytes", out.stderr.len());
}

/// Issue 21, defect 8: [sim] and [replan] settings are checked at load (bad input, exit
/// 1, naming the field), not when a simulator starts.
#[test]
fn sim_and_replan_settings_are_checked_at_load() {
    let text =
        std::fs::read_to_string(repo_root().join("scenarios/field-test.toml")).expect("readable");
    for (extra, field) in [
        ("[sim]\ndt_s = 0\n", "sim.dt_s"),
        ("[sim]\ndt_s = 1e-9\n", "sim.dt_s"),
        (
            "[replan]\nposition_threshold_m = nan\n",
            "replan.position_threshold_m",
        ),
        (
            "[replan]\nheading_threshold_deg = -1\n",
            "replan.heading_threshold_deg",
        ),
        (
            "[replan]\nposition_threshold_m = inf\n",
            "replan.position_threshold_m",
        ),
    ] {
        let f = tmp(&format!("bad-{}.toml", field.replace('.', "-")));
        std::fs::write(&f, format!("{text}\n{extra}")).expect("write");
        let t0 = std::time::Instant::now();
        let out = forkbench(&["trial", f.to_str().expect("utf8"), "--no-noise"]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{extra}: {err}");
        assert!(err.contains(field), "{extra}: {err}");
        assert!(t0.elapsed().as_secs() < 20, "{extra}");
    }
}

/// Issue 21, defect 9: a port that accepts TCP but is no rerun viewer no longer hangs
/// the run; the outcome is printed and the exit is non-zero.
#[test]
#[cfg_attr(
    not(feature = "rerun"),
    ignore = "a viewer needs rerun: --features rerun"
)]
fn a_silent_viewer_port_times_out() {
    let listener = std::net::TcpListener::bind("127.0.0.1:0").expect("bind");
    let addr = listener.local_addr().expect("addr").to_string();
    std::thread::spawn(move || {
        let mut held = Vec::new();
        for c in listener.incoming().flatten() {
            held.push(c); // accept and never answer
        }
    });
    let scn = repo_root().join("scenarios/field-test.toml");
    let t0 = std::time::Instant::now();
    let out = forkbench(&[
        "trial",
        scn.to_str().expect("utf8"),
        "--no-noise",
        "--connect",
        &addr,
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stdout).contains("outcome"));
    assert!(String::from_utf8_lossy(&out.stderr).contains("did not take the recording"));
    assert!(t0.elapsed().as_secs() < 60, "{:?}", t0.elapsed());
}

/// Issue 21, defect 10: a goal that needs reversing is refused as unreachable (the
/// B-spline folded back into a cusp and reported max |κ| = 0).
#[test]
fn a_goal_behind_the_truck_is_unreachable_for_the_bspline() {
    let out = forkbench(&["plan", "bspline", "--start", "0,0,90", "--goal", "0,-5,90"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("reverses direction") && err.contains("cusp"),
        "{err}"
    );
}

/// Issue 21, defect 7 (planning and scenario part): huge finite inputs are refused with
/// the limit named, at once, instead of exhausting memory or hanging.
#[test]
fn huge_finite_inputs_are_refused_with_the_limit_named() {
    for goal in ["1e9,0,0", "1e20,0,0", "500,0,0"] {
        let t0 = std::time::Instant::now();
        let out = forkbench(&["plan", "spiral", "--start", "0,0,0", "--goal", goal]);
        assert_eq!(out.status.code(), Some(1), "{goal}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains("invalid goal") && err.contains(" m"),
            "{goal}: {err}"
        );
        assert!(t0.elapsed().as_secs() < 10, "{goal}");
    }
    let cfg = tmp("tiny-spacing.toml");
    std::fs::write(&cfg, "[bspline]\nsample_spacing_m = 1e-9\n").expect("write");
    let out = forkbench(&[
        "plan",
        "bspline",
        "--start",
        "0,0,90",
        "--goal",
        "1.5,6.5,105",
        "--config",
        cfg.to_str().expect("utf8"),
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("sample_spacing_m"));
    let text = std::fs::read_to_string(repo_root().join("scenarios/field-test.toml"))
        .expect("readable")
        .replace("pallet = { x_m = 1.832533", "pallet = { x_m = 1e9");
    let far = tmp("far-pallet.toml");
    std::fs::write(&far, text).expect("write");
    let out = forkbench(&["trial", far.to_str().expect("utf8"), "--no-noise"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("pallet.x_m") && err.contains("10 km"), "{err}");
    let out = forkbench(&[
        "batch",
        "--trials",
        "1",
        "--jobs",
        "100000",
        "--out",
        tmp("jobs").to_str().expect("utf8"),
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("at most 256"));
}

/// Issue 21, defect 7 (corridor part): a search that would need more than 1e7 states is
/// refused before it allocates (`--width 3` ran minutes at GBs, `1e6` aborted, `1e308`
/// printed zero areas).
#[test]
fn corridor_work_is_bounded() {
    for w in ["3", "1e6", "1e308"] {
        let t0 = std::time::Instant::now();
        let out = forkbench(&["corridor", "--width", w, "--angle", "90"]);
        assert_eq!(out.status.code(), Some(1), "width {w}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains("width_m") && err.contains("search states"),
            "{w}: {err}"
        );
        assert!(t0.elapsed().as_secs() < 5, "{w}");
    }
}

/// Issue 21, message polish: the reason once, the scenario's world field named, --out
/// that is a file, replay --line 0, and no "NaN m" when planning failed.
#[test]
fn error_messages_are_polished() {
    let out = forkbench(&["trial", "does-not-exist.toml"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.matches("os error 2").count(), 1, "{err}");
    let text =
        std::fs::read_to_string(repo_root().join("scenarios/field-test.toml")).expect("readable");
    let f = tmp("missing-world.toml");
    std::fs::write(&f, format!("world = \"no-such-world.toml\"\n{text}")).expect("write");
    let out = forkbench(&["trial", f.to_str().expect("utf8")]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("missing-world.toml") && err.contains("`world`"),
        "{err}"
    );
    let file = tmp("out-is-a-file");
    std::fs::write(&file, "x").expect("write");
    let out = forkbench(&[
        "batch",
        "--trials",
        "1",
        "--out",
        file.to_str().expect("utf8"),
    ]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("is not a directory"));
    let lines = tmp("lines.jsonl");
    std::fs::write(&lines, "{}\n").expect("write");
    let out = forkbench(&["replay", lines.to_str().expect("utf8"), "--line", "0"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("numbered from 1"));
    // The Gaussian model "sees" a pallet behind the truck, so the planner is what refuses.
    let behind = text
        .replace(
            "pallet = { x_m = 1.832533, y_m = 14.917769",
            "pallet = { x_m = 0.505353, y_m = 1.0",
        )
        .replace("kind = \"tim561+kinect2\"", "kind = \"gaussian\"");
    let f = tmp("pallet-behind.toml");
    std::fs::write(&f, behind).expect("write");
    let out = forkbench(&["trial", f.to_str().expect("utf8"), "--no-noise"]);
    assert_eq!(
        out.status.code(),
        Some(3),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let shown = String::from_utf8_lossy(&out.stdout);
    assert!(
        !shown.contains("NaN") && shown.contains("plan_failed"),
        "{shown}"
    );
}

/// `replay` of a mission trial and of a replanning trial from a batch reproduces them
/// (the legs' planning wall times used to make every mission replay "DIFFERS").
#[test]
fn replay_reproduces_mission_and_replanning_trials_from_a_batch() {
    let scn = repo_root().join("scenarios/warehouse-mission.toml");
    let dir = tmp("replay-batch");
    let _ = std::fs::remove_dir_all(&dir);
    let d = dir.to_str().expect("utf8");
    let args = [
        "batch",
        scn.to_str().expect("utf8"),
        "--trials",
        "1",
        "--modes",
        "both",
    ];
    let out = forkbench(&[&args[..], &["--record", "none", "--out", d]].concat());
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let file = dir.join("trials.jsonl");
    let text = std::fs::read_to_string(&file).expect("records");
    assert!(text.contains("\"replan\":true") && text.contains("\"legs\""));
    for line in ["1", "2"] {
        let out = forkbench(&["replay", file.to_str().expect("utf8"), "--line", line]);
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(
            matches!(out.status.code(), Some(0 | 3))
                && stdout.contains("identical to the recorded outcome"),
            "line {line}: {stdout}{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
}

/// Contradictory truck–pallet geometry is refused at load, naming the field the user set
/// (before, fork spacing failed at the end of the trial and a short fork named a field the
/// user never set).
#[test]
fn contradictory_fork_geometry_is_refused_at_load() {
    let base =
        std::fs::read_to_string(repo_root().join("scenarios/field-test.toml")).expect("read");
    for (setting, field, says) in [
        (
            "fork_spacing_m = 1.5",
            "truck.fork_spacing_m",
            "within 0.280..0.790 m",
        ),
        (
            "fork_length_m = 0.5",
            "truck.fork_length_m",
            "insertion_depth_m = 1 m (the default)",
        ),
    ] {
        let f = tmp(&format!("geometry-{}.toml", &setting[..8]));
        std::fs::write(&f, format!("{base}\n[truck]\n{setting}\n")).expect("write");
        let out = forkbench(&["trial", f.to_str().expect("utf8")]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{err}");
        assert!(
            err.contains(field) && err.contains(says),
            "{setting}: {err}"
        );
    }
}

/// Refactoring must not move results: the first two trials of every row of the README's
/// main job (same batch seed, so the same trial seeds) end exactly as the committed
/// baseline recorded them, success and failure criterion alike.
#[test]
fn outcomes_at_fixed_seeds_match_the_committed_baseline() {
    let out_dir = tmp("baseline-replay");
    let out = forkbench(&[
        "batch",
        "--trials",
        "2",
        "--out",
        out_dir.to_str().expect("utf-8"),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let base: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(repo_root().join("scenarios/baselines/default.json"))
            .expect("baseline"),
    )
    .expect("JSON");
    let key = |r: &serde_json::Value| {
        ["scenario", "case", "planner", "tracker", "replan", "trial"].map(|k| r[k].to_string())
    };
    let recorded: std::collections::BTreeMap<_, _> = base["trials"]
        .as_array()
        .expect("per-trial results")
        .iter()
        .map(|r| (key(r), r))
        .collect();
    let text = std::fs::read_to_string(out_dir.join("trials.jsonl")).expect("records");
    let mut compared = 0;
    for line in text.lines() {
        let r: serde_json::Value = serde_json::from_str(line).expect("a record");
        let want = recorded
            .get(&key(&r))
            .unwrap_or_else(|| panic!("not in the baseline: {r}"));
        for k in ["seed", "success", "failure"] {
            assert_eq!(r[k], want[k], "{k} of {:?}", key(&r));
        }
        compared += 1;
    }
    assert!(compared >= 170, "{compared} trials compared");
}

/// `scan`: one TiM561 scan from the field test's start, as JSON; with ideal rays the
/// detector's estimate lies within half a beam step of the truth; an unknown sensor is
/// refused naming the known ones.
#[test]
fn scan_reports_beams_truth_and_estimate() {
    let scn = repo_root().join("scenarios/field-test.toml");
    let scn = scn.to_str().expect("utf8");
    let v = stdout_json(&forkbench(&["scan", scn, "--no-noise", "--json"]));
    let beams = v["beams"].as_array().expect("beams");
    assert_eq!(beams.len(), 819);
    assert!(beams.iter().any(|b| b["range_m"].is_null()));
    assert!(
        beams
            .iter()
            .any(|b| b["range_m"].as_f64().is_some_and(|r| r > 8.0))
    );
    assert_eq!(v["sensor"], "tim561");
    assert_eq!(v["detector"], "pockets");
    // --at is bounded, and the truck may not stand in the pallet.
    for (at, want) in [
        ("1e300,0,0", "within ±10000 m"),
        ("1.7,15.4,102.8", "in the pallet"),
    ] {
        let out = forkbench(&["scan", scn, "--at", at]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && err.contains(want), "{at}: {err}");
    }
    // The scenario's own detector looks: the RANSAC example's external one.
    let ransac = repo_root().join("examples/detectors/ransac-near-pick.toml");
    let r = stdout_json(&forkbench(&[
        "scan",
        ransac.to_str().expect("utf8"),
        "--no-noise",
        "--json",
    ]));
    assert_ne!(r["detector"], "pockets", "{}", r["detector"]);
    assert!(
        r["estimate"].is_object(),
        "the RANSAC detector found it: {}",
        r["estimate"]
    );
    let (t, e) = (&v["truth"], &v["estimate"]);
    let d = (e["x_m"].as_f64().expect("x") - t["x_m"].as_f64().expect("x"))
        .hypot(e["y_m"].as_f64().expect("y") - t["y_m"].as_f64().expect("y"));
    // Half a 0.33° step at the pallet's 8.4 m.
    assert!(
        d < 0.5 * 8.4 * 0.33f64.to_radians(),
        "{d} m off: {e} vs {t}"
    );
    let png = tmp("scan.png");
    let out = forkbench(&[
        "scan",
        scn,
        "--at",
        "2.719,11.018,102.8",
        "--plot",
        png.to_str().expect("utf8"),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains("3 stringers"));
    assert!(std::fs::metadata(&png).expect("plot").len() > 10_000);
    let out = forkbench(&["scan", scn, "--sensor", "kinect"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("known: tim561"));
}

/// `check`: a scenario's resolved components and fork fit, as text and JSON; a truck whose
/// forks miss the pockets is refused naming the field, and the reflector flags name an
/// unknown reflector.
#[test]
fn check_prints_the_resolved_scenario_and_refuses_bad_geometry() {
    let root = repo_root();
    let mission = root.join("scenarios/warehouse-mission.toml");
    let out = forkbench(&["check", mission.to_str().expect("utf-8")]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("localiser nav350") && text.contains("36 reflectors"),
        "{text}"
    );
    assert!(text.contains("pockets allow 0.280..0.790 m: ok"), "{text}");
    let out = forkbench(&["check", mission.to_str().expect("utf-8"), "--json"]);
    let v = stdout_json(&out);
    assert_eq!(v["fork_fit"]["fork_spacing_m"], 0.535);
    assert_eq!(v["scenario"]["localizer"]["kind"], "nav350");
    let bad = tmp("check-wide-forks.toml");
    let field = std::fs::read_to_string(root.join("scenarios/field-test.toml")).expect("reads");
    std::fs::write(&bad, field + "\n[truck]\nfork_spacing_m = 1.5\n").expect("writes");
    let out = forkbench(&["check", bad.to_str().expect("utf-8")]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("truck.fork_spacing_m") && err.contains("0.280..0.790"),
        "{err}"
    );
    let out = forkbench(&[
        "mission",
        mission.to_str().expect("utf-8"),
        "--missing-reflectors",
        "west-3,nope",
    ]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("sensors.localizer.missing_reflectors") && err.contains("\"nope\""),
        "{err}"
    );
}
