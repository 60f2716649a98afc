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
const GOAL: &str = "30.75,9.75,0";

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
    // 40.4 × 25.4 m (walls 0.2 m thick outside the 40 × 25 m floor) plus 1 m of margin
    // at 5 cm: 848 × 548 cells.
    assert!(pgm.starts_with(b"P5\n"), "binary PGM");
    let text = String::from_utf8_lossy(&pgm[..64]).into_owned();
    assert!(text.contains("848 548"), "{text}");
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
            v["length_m"].as_f64().expect("length") > 27.75f64.hypot(6.75),
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
            serde_json::json!([30.75, 9.75]),
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
    // Inside the row-2 flue wall: refused with the reason, exit 1, no panic.
    let out = forkbench(&[
        "plan",
        "prm",
        "--map",
        &world("warehouse.toml"),
        "--start",
        START,
        "--goal",
        "15,12.5,0",
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
