//! End-to-end: the warehouse world as a ROS map, and global plans on it (`map`, `plan prm|rrt|rrt-connect`).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn forkbench(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_forkbench"))
        .args(args)
        .output()
        .expect("binary runs")
}

fn json_of(out: &Output) -> serde_json::Value {
    assert!(
        out.status.success(),
        "stderr: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("one JSON object")
}

fn world(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../worlds")
        .join(name)
        .display()
        .to_string()
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("forkbench-nav-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("dir");
    d
}

/// Charging station to the aisle before a far rack bay, as `reproduce prm` plans it.
const START: &str = "3,3,90";
const GOAL: &str = "30.75,10.25,0";

#[test]
fn the_warehouse_becomes_a_ros_map_that_plans_like_the_world() {
    let dir = tmp("map");
    let out = forkbench(&[
        "map",
        &world("warehouse.toml"),
        "--out",
        dir.to_str().expect("utf-8"),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let yaml = dir.join("warehouse.yaml");
    let pgm = std::fs::read(dir.join("warehouse.pgm")).expect("pgm");
    // 40.4 × 26.4 m (walls 0.2 m thick outside the 40 × 26 m floor) plus 1 m of margin
    // at 5 cm: 848 × 568 cells.
    assert!(pgm.starts_with(b"P5\n"), "binary PGM");
    let text = String::from_utf8_lossy(&pgm[..64]).into_owned();
    assert!(text.contains("848 568"), "{text}");
    let plan = |map: &str| {
        json_of(&forkbench(&[
            "plan", "prm", "--map", map, "--start", START, "--goal", GOAL, "--nodes", "500",
            "--seed", "1", "--json",
        ]))
    };
    let (from_world, from_yaml) = (
        plan(&world("warehouse.toml")),
        plan(yaml.to_str().expect("utf-8")),
    );
    for v in [&from_world, &from_yaml] {
        assert_eq!(v["success"], true, "{v}");
        // At least the straight line from start to goal, which crosses rack row 1.
        assert!(
            v["length_m"].as_f64().expect("length") > 27.75f64.hypot(7.25),
            "{v}"
        );
        let t = &v["timing_s"];
        assert!(t["total"].as_f64().expect("total") > 0.0, "{t}");
    }
}

#[test]
fn every_global_planner_finds_the_shelf_and_a_blocked_goal_is_refused() {
    for planner in ["prm", "rrt", "rrt-connect"] {
        let v = json_of(&forkbench(&[
            "plan",
            planner,
            "--map",
            &world("warehouse.toml"),
            "--start",
            START,
            "--goal",
            GOAL,
            "--seed",
            "2",
            "--json",
        ]));
        assert_eq!(v["success"], true, "{planner}: {v}");
        let pts = v["polyline_m"].as_array().expect("polyline");
        assert_eq!(pts[0], serde_json::json!([3.0, 3.0]), "{planner}");
        assert_eq!(
            pts[pts.len() - 1],
            serde_json::json!([30.75, 10.25]),
            "{planner}"
        );
    }
    // The map, roadmap and path drawn, in both formats.
    let dir = tmp("plots");
    for ext in ["png", "svg"] {
        let file = dir.join(format!("prm.{ext}"));
        let out = forkbench(&[
            "plan",
            "prm",
            "--map",
            &world("warehouse.toml"),
            "--start",
            START,
            "--goal",
            GOAL,
            "--plot",
            file.to_str().expect("utf-8"),
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let size = std::fs::metadata(&file).expect("drawn").len();
        assert!(size > 20_000, "{ext}: {size} bytes");
    }
    // Inside the row-2 flue wall (y 12.95..13.05): refused with the reason, exit 1, no panic.
    let out = forkbench(&[
        "plan",
        "prm",
        "--map",
        &world("warehouse.toml"),
        "--start",
        START,
        "--goal",
        "15,13.0,0",
    ]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("goal") && err.contains("inside an obstacle"),
        "{err}"
    );
    let out = forkbench(&["plan", "prm", "--start", START, "--goal", GOAL]);
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("--map"),
        "map required"
    );
}

/// `--first-solution` stops at the first connection, `--runs` plans seed after seed in one
/// process, and every route comes with its simplified form, free and no longer.
#[test]
fn first_solution_prm_runs_seed_after_seed_with_simplified_routes() {
    let out = forkbench(&[
        "plan",
        "prm",
        "--first-solution",
        "--runs",
        "5",
        "--seed",
        "10",
        "--map",
        &world("warehouse.toml"),
        "--start",
        START,
        "--goal",
        GOAL,
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let runs: Vec<serde_json::Value> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).expect("one JSON object per line"))
        .collect();
    assert_eq!(runs.len(), 5);
    for (k, v) in runs.iter().enumerate() {
        assert_eq!(v["seed"], 10 + k as u64);
        assert_eq!(v["success"], true, "{v}");
        assert_eq!(v["first_solution"], true);
        // Stopped well before the 5000-sample cap.
        assert!(v["roadmap_nodes"].as_u64().expect("nodes") < 1000, "{v}");
        let raw = v["length_m"].as_f64().expect("length");
        let short = v["simplified"]["length_m"].as_f64().expect("simplified");
        assert!(short <= raw + 1e-9 && short > 27.0, "{raw} → {short}");
    }
    for bad in [vec!["bspline"], vec!["rrt-connect"]] {
        let mut args = vec!["plan"];
        args.extend(bad);
        args.extend(["--first-solution", "--start", START, "--goal", GOAL]);
        let out = forkbench(&args);
        assert_eq!(out.status.code(), Some(1));
        assert!(String::from_utf8_lossy(&out.stderr).contains("--first-solution is for prm"));
    }
}

#[test]
fn a_footprint_plan_smooths_into_a_drivable_path_with_its_clearance() {
    let v = json_of(&forkbench(&[
        "plan",
        "prm",
        "--map",
        &world("warehouse.toml"),
        "--start",
        START,
        "--goal",
        GOAL,
        "--seed",
        "1",
        "--collision",
        "footprint",
        "--smooth",
        "--json",
    ]));
    assert_eq!(v["success"], true, "{v}");
    assert_eq!(v["collision"], "footprint");
    let s = &v["smoothing"];
    assert_eq!(s["ok"], true, "{s}");
    // The default margin of the footprint model, kept by the true footprint.
    let clearance = v["min_clearance_m"].as_f64().expect("clearance");
    assert!(clearance >= 0.15, "{clearance}");
    let samples = s["samples"].as_array().expect("samples");
    let k_max = forkbench_core::ForkliftSpec::default().max_curvature_per_m();
    for p in samples {
        let k = p[4].as_f64().expect("κ");
        assert!(k.abs() <= k_max + 1e-9, "{k}");
    }
    let last = &samples[samples.len() - 1];
    assert!(
        (last[1].as_f64().expect("x") - 30.75).abs() < 1e-3,
        "{last}"
    );
    let t = &v["timing_s"];
    for stage in ["sampling", "connection", "search", "smoothing", "total"] {
        assert!(t[stage].as_f64().expect(stage) > 0.0, "{stage}: {t}");
    }
}

fn mission_file(dir: &Path, name: &str, edit: impl Fn(String) -> String) -> PathBuf {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/warehouse-mission.toml"),
    )
    .expect("reads");
    let text = text.replace(
        "\"../worlds/warehouse.toml\"",
        &format!("{:?}", world("warehouse.toml")),
    );
    let file = dir.join(name);
    std::fs::write(&file, edit(text)).expect("writes");
    file
}

#[test]
fn mission_reports_each_leg_and_the_pick() {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/warehouse-mission.toml");
    let file = file.to_str().expect("utf-8");
    let out = forkbench(&["mission", file, "--seed", "1", "--json"]);
    let v = json_of(&out);
    let legs = v["legs"].as_array().expect("legs");
    assert_eq!(legs.len(), 2, "{v}");
    for l in legs {
        for key in [
            "planned_length_m",
            "planning_time_s",
            "min_clearance_m",
            "cross_track_mean_m",
            "cross_track_max_m",
            "time_s",
        ] {
            assert!(l[key].as_f64().is_some(), "{key}: {l}");
        }
        assert_eq!(l["smoothing"], "ok");
        assert_eq!(l["collisions"], 0);
    }
    let o = &v["overall"];
    assert_eq!(o["legs_done"], 2, "{o}");
    assert_eq!(o["success"], v["success"]);
    // Text: one row per leg, then the pick as `trial` prints it.
    let out = forkbench(&["mission", file, "--seed", "1"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("charging → sorting") && text.contains("sorting → staging"),
        "{text}"
    );
    assert!(text.contains("outcome "), "{text}");
    // A pick scenario is not a mission.
    let out = forkbench(&["mission", &file.replace("warehouse-mission", "field-test")]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no [mission] table"));
}

#[test]
fn a_mission_batch_records_a_failed_leg_and_goes_on() {
    let dir = tmp("mission-batch");
    // The sorting station moved into rack row 3: the first leg cannot be planned.
    let bad = mission_file(&dir, "blocked.toml", |t| {
        t.replace(
            "via = [\"sorting\"]",
            "via = [{ x_m = 20.0, y_m = 21.5, heading_deg = 90.0 }]",
        )
    });
    let good = mission_file(&dir, "good.toml", |t| {
        t.replace("name = \"warehouse-mission\"", "name = \"good-mission\"")
    });
    let out_dir = dir.join("out");
    let out = forkbench(&[
        "batch",
        bad.to_str().expect("utf-8"),
        good.to_str().expect("utf-8"),
        "--trials",
        "3",
        "--record",
        "none",
        "--out",
        out_dir.to_str().expect("utf-8"),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let lines = std::fs::read_to_string(out_dir.join("trials.jsonl")).expect("records");
    let records: Vec<serde_json::Value> = lines
        .lines()
        .map(|l| serde_json::from_str(l).expect("json"))
        .collect();
    assert_eq!(records.len(), 6);
    let failed: Vec<_> = records
        .iter()
        .filter(|r| r["scenario"] == "warehouse-mission")
        .collect();
    assert_eq!(failed.len(), 3);
    for r in failed {
        assert_eq!(r["failure"], "leg_failed", "{r}");
        assert!(
            r["failure_detail"]
                .as_str()
                .expect("detail")
                .contains("inside an obstacle"),
            "{r}"
        );
    }
    let summary = std::fs::read_to_string(out_dir.join("summary.md")).expect("summary");
    assert!(
        summary.contains("Mission legs") && summary.contains("charging → sorting"),
        "{summary}"
    );
}

/// `plan hybrid-astar`: a manoeuvre out of the sorting station with its segments and
/// cusps in JSON, settings from `--config` acting (forwards only cannot turn round in a
/// dead-end aisle), and the point planners' flags and settings refused by name.
#[test]
fn hybrid_astar_plans_manoeuvres_and_refuses_what_cannot_act() {
    let v = json_of(&forkbench(&[
        "plan",
        "hybrid-astar",
        "--map",
        &world("warehouse.toml"),
        "--start",
        "6.5,21.5,90",
        "--goal",
        "6,9.05,180",
        "--json",
    ]));
    assert_eq!(v["success"], true, "{v}");
    let m = &v["manoeuvre"];
    let segments = m["segments"].as_array().expect("segments");
    assert!(segments.len() >= 2, "{m}");
    assert_eq!(
        segments[0]["reverse"], true,
        "backs out of the station first"
    );
    assert_eq!(
        m["cusps"].as_array().expect("cusps").len(),
        segments.len() - 1
    );
    let dir = tmp("hybrid");
    let turn = [
        "--map",
        &world("turnaround.toml"),
        "--start",
        "11,4,0",
        "--goal",
        "3,4,180",
    ];
    let cfg = dir.join("forward.toml");
    std::fs::write(&cfg, "forward_only = true\nmax_expansions = 5000\n").expect("write");
    let plain = forkbench(&[&["plan", "hybrid-astar"][..], &turn, &["--json"]].concat());
    assert_eq!(json_of(&plain)["success"], true);
    let cfg_arg = cfg.to_str().expect("utf-8");
    let forward =
        forkbench(&[&["plan", "hybrid-astar"][..], &turn, &["--config", cfg_arg]].concat());
    // The search ran and found no path within its budget: a verdict, exit 3.
    assert_eq!(
        forward.status.code(),
        Some(3),
        "forwards only cannot turn round"
    );
    for (args, needle) in [
        (vec!["plan", "hybrid-astar", "--smooth"], "--smooth"),
        (
            vec!["plan", "hybrid-astar", "--collision", "inflate"],
            "--collision inflate",
        ),
        (vec!["plan", "hybrid-astar", "--nodes", "50"], "--nodes"),
        (vec!["plan", "prm", "--config", cfg_arg], "--config"),
    ] {
        let out = forkbench(&[&args[..], &turn].concat());
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            !out.status.success() && err.contains(needle),
            "{args:?}: {err}"
        );
    }
    std::fs::write(&cfg, "reverse_penalty = 0.5\n").expect("write");
    let out = forkbench(&[&["plan", "hybrid-astar"][..], &turn, &["--config", cfg_arg]].concat());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("reverse_penalty") && err.contains("forward.toml"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
