//! Warehouse missions end to end in the physics: legs with reverse segments, the pick at the end, the footprint against Luo's inflation on narrow aisles, and bad mission input.

use std::path::{Path, PathBuf};

use forkbench_core::{ForkliftSpec, PalletSpec, Path as PlanPath, Pose2};
use forkbench_nav::smooth::{SmoothParams, smooth};
use forkbench_sim::{Sim, SimConfig};
use forkbench_track::{PurePursuit, SegmentFollower, Tracker, TrackerConfig, TrackerInput};
use forkbench_trial::{Failure, Scenario, TrialOptions, TrialOutcome, run_trial};

fn data(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}

fn mission() -> Scenario {
    Scenario::load(&data("data/scenarios/warehouse-mission.toml")).expect("loads")
}

fn run(scn: &Scenario, seed: u64) -> TrialOutcome {
    let opts = TrialOptions {
        seed: Some(seed),
        ..TrialOptions::default()
    };
    run_trial(scn, &scn.cases[0], &opts)
}

/// The outcome without its wall times, which differ between runs.
fn comparable(o: &TrialOutcome) -> serde_json::Value {
    serde_json::to_value(o.without_wall_times()).expect("serialises")
}

#[test]
fn the_warehouse_mission_drives_every_leg_backs_out_and_picks() {
    let scn = mission();
    let out = run(&scn, 1);
    assert_eq!(out.legs.len(), 2, "{:?}", out.legs);
    for l in &out.legs {
        assert!(l.success, "leg {}: {:?}", l.name, l.failure_detail);
        assert_eq!(l.collisions, 0, "{}", l.name);
        assert_eq!(l.smoothing, "ok");
        // The margin the footprint keeps, on the true footprint.
        assert!(
            l.min_clearance_m >= 0.15,
            "{}: {}",
            l.name,
            l.min_clearance_m
        );
        assert!(
            l.cross_track_max_m < 0.1,
            "{}: {}",
            l.name,
            l.cross_track_max_m
        );
        assert!(
            l.final_position_error_m < 0.3,
            "{}",
            l.final_position_error_m
        );
        assert!(l.planned_length_m > 10.0 && l.time_s > 15.0, "{l:?}");
    }
    assert_eq!(
        out.legs[0].reverse_length_m, 0.0,
        "the first leg starts parked"
    );
    assert!(
        out.legs[1].reverse_length_m > 1.0,
        "the truck backs out of the sorting station"
    );
    assert!(out.success, "{:?}: {:?}", out.failure, out.failure_detail);
    // The same seed gives the same mission.
    assert_eq!(comparable(&out), comparable(&run(&scn, 1)));
}

#[test]
fn on_narrow_aisles_luos_inflation_strikes_a_rack_and_the_footprint_does_not() {
    let text = std::fs::read_to_string(data("tests/data/narrow-aisle.toml")).expect("reads");
    let file = data("tests/data/narrow-aisle.toml");
    let world = |p: &Path| forkbench_trial::World::load(&file.parent().expect("dir").join(p));
    let inflate = Scenario::parse(&text, "narrow-aisle.toml", world).expect("parses");
    let footprint_text = text
        .replace("collision = \"inflate\"", "collision = \"footprint\"")
        .replace("check_swept = false", "check_swept = true");
    let footprint = Scenario::parse(&footprint_text, "narrow-aisle.toml", world).expect("parses");
    let mut struck = 0;
    for seed in 1..=4 {
        let leg = &run(&inflate, seed).legs[0];
        if leg.collisions > 0 {
            struck += 1;
            let why = leg.failure_detail.as_deref().unwrap_or("");
            assert!(why.contains("struck a rack or wall"), "{why}");
        }
        let leg = &run(&footprint, seed).legs[0];
        assert!(
            leg.success,
            "footprint, seed {seed}: {:?}",
            leg.failure_detail
        );
        assert_eq!(leg.collisions, 0);
        assert!(leg.min_clearance_m >= 0.15, "{}", leg.min_clearance_m);
    }
    assert!(struck >= 2, "inflation struck in {struck} of 4 runs");
}

#[test]
fn a_reverse_path_is_driven_backwards_in_the_physics() {
    let truck = ForkliftSpec::default();
    // A quarter turn driven backwards: the forward track from the backed-out pose to the
    // start, reversed.
    let sm = smooth(
        &[[-3.0, -3.0], [-3.0, 0.0], [0.0, 0.0]],
        &forkbench_geom::Obstacles::new(),
        (&[], &[]),
        &SmoothParams::for_curvature(truck.max_curvature_per_m()),
    )
    .expect("smooths");
    let path: PlanPath = sm.path.driven_backwards();
    assert!(path.reverse);
    let start = path.samples[0].pose();
    let end = path.samples.last().expect("samples").pose();
    assert!(start.distance_to(&Pose2::new(0.0, 0.0, 0.0)) < 1e-6);
    let far = Pose2::new(50.0, 50.0, 0.0);
    let mut sim = Sim::new(
        &truck,
        &start,
        &PalletSpec::field_1200(),
        &far,
        &[],
        &SimConfig::default(),
    )
    .expect("world");
    let mut pp = PurePursuit::with_config(TrackerConfig {
        cruise_speed_mps: 0.5,
        ..TrackerConfig::default()
    });
    pp.reset(&path, &truck);
    let mut min_speed: f64 = 0.0;
    for _ in 0..6000 {
        let cmd = Tracker::command(
            &mut pp,
            &TrackerInput {
                t_s: sim.time_s(),
                pose: sim.fork_root_pose(),
                speed_mps: sim.speed_mps(),
                steer_rad: sim.steer_rad(),
                fix_measured_s: None,
                truck: &truck,
            },
        );
        assert!(cmd.cross_track_m.abs() < 0.1, "{}", cmd.cross_track_m);
        if cmd.done && sim.speed_mps().abs() < 0.01 {
            break;
        }
        sim.step(cmd.speed_mps, cmd.steer_rad);
        min_speed = min_speed.min(sim.speed_mps());
    }
    assert!(min_speed < -0.3, "the truck went backwards: {min_speed}");
    let got = sim.fork_root_pose();
    assert!(got.distance_to(&end) < 0.05, "{got:?} vs {end:?}");
    let heading = forkbench_core::units::wrap_angle(got.heading_rad - end.heading_rad);
    assert!(heading.abs() < 0.05, "{heading}");
}

#[test]
fn bad_mission_input_names_the_file_and_field() {
    let text =
        std::fs::read_to_string(data("data/scenarios/warehouse-mission.toml")).expect("reads");
    let world = |p: &Path| forkbench_trial::World::load(&data("data/scenarios").join(p));
    let cases = [
        (
            "start = \"charging\"",
            "start = \"charger\"",
            "mission.start",
            "no station \"charger\"",
        ),
        (
            "backout_m = 3.0",
            "backout_m = -1.0",
            "mission.backout_m",
            "in (0, 50]",
        ),
        (
            "nodes = 500",
            "nodes = 0",
            "mission.global.nodes",
            "1..100000",
        ),
        (
            "lookahead_m = 0.6\ncruise",
            "lookahead_m = 0.0\ncruise",
            "mission.tracker.lookahead_m",
            "positive",
        ),
        (
            "collision = \"footprint\"",
            "collision = \"sphere\"",
            "collision",
            "unknown variant",
        ),
    ];
    for (from, to, field, reason) in cases {
        assert!(text.contains(from), "{from}");
        let bad = text.replacen(from, to, 1);
        let e = Scenario::parse(&bad, "m.toml", world)
            .expect_err(to)
            .to_string();
        assert!(
            e.contains("m.toml") && e.contains(field) && e.contains(reason),
            "{e}"
        );
    }
}

#[test]
fn a_leg_that_cannot_be_planned_fails_the_trial_and_says_why() {
    let text =
        std::fs::read_to_string(data("data/scenarios/warehouse-mission.toml")).expect("reads");
    // A via point inside a rack row: planning refuses it.
    let bad = text.replace(
        "via = [\"sorting\"]",
        "via = [{ x_m = 20.0, y_m = 4.5, heading_deg = 0.0 }]",
    );
    let world = |p: &Path| forkbench_trial::World::load(&data("data/scenarios").join(p));
    let scn = Scenario::parse(&bad, "m.toml", world).expect("parses");
    let out = run(&scn, 1);
    assert_eq!(out.failure, Some(Failure::LegFailed));
    let why = out.failure_detail.expect("detail");
    assert!(
        why.contains("leg 1") && why.contains("inside an obstacle"),
        "{why}"
    );
    assert!(!out.legs[0].success);
    assert_eq!(out.legs.len(), 1, "the mission stops at the failed leg");
}

#[test]
fn a_ros_map_is_a_world_a_mission_drives_in() {
    // The warehouse as a map file, as a user's SLAM map would come.
    let dir = std::env::temp_dir().join(format!("forkbench-map-world-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let world = forkbench_trial::World::load(&data("data/worlds/warehouse.toml")).expect("world");
    let map = forkbench_nav::NavMap::from_world(&world.obstacles(), 0.05).expect("map");
    let yaml = forkbench_nav::write_map(&map.grid, &dir, "site").expect("written");
    let from_map = forkbench_trial::World::load(&yaml).expect("a map loads as a world");
    assert!(from_map.rack.len() > 10 && from_map.station.is_empty());
    // Places are poses: a map has no named stations or slots.
    let text = format!(
        r#"name = "map-mission"
world = {yaml:?}
planner = "bspline"
start = {{ x_m = 6.0, y_m = 9.05, heading_deg = 180.0 }}
pallet = {{ x_m = 1.4, y_m = 8.75, heading_deg = 180.0 }}

[mission]
start = {{ x_m = 3.0, y_m = 3.0, heading_deg = 90.0 }}
via = [{{ x_m = 6.5, y_m = 21.5, heading_deg = 90.0 }}]
"#
    );
    let scn = Scenario::parse(&text, "map-mission.toml", |p: &Path| {
        forkbench_trial::World::load(p)
    })
    .expect("parses");
    let out = run(&scn, 1);
    assert_eq!(out.legs.len(), 2, "{:?}", out.failure_detail);
    assert!(out.legs.iter().all(|l| l.success), "{:?}", out.legs);
    assert_ne!(out.failure, Some(Failure::LegFailed));
    // A broken map file is an error naming it.
    std::fs::write(dir.join("site.pgm"), b"P5\n1 1\n255\n").expect("truncated");
    let e = forkbench_trial::World::load(&yaml).expect_err("truncated image");
    assert!(e.to_string().contains("site"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Hybrid-A*'s turn in a dead-end aisle, ending in a 2 m straight approach, driven
/// segment by segment (the wheel set before each segment, a stop at each cusp, a replan
/// from where the truck stands) with pure pursuit in the physics: no touch of the racks,
/// and the truck ends within 5 cm and 2° of the manoeuvre's end.
#[test]
fn a_manoeuvre_with_cusps_is_driven_in_the_physics() {
    use forkbench_nav::hybrid::{HybridParams, HybridQuery, plan_hybrid, plan_hybrid_from_here};
    // The first truck's actuators: with the realistic ones, each segment's end lands
    // elsewhere and the plans from there cycle between two cusps (a known limit of the
    // segment follower, stated in docs/truck.md).
    let truck = ForkliftSpec::default().with_actuators(forkbench_core::actuators::Actuators::IDEAL);
    let world = forkbench_trial::World::load(&data("../../worlds/turnaround.toml")).expect("world");
    let map = forkbench_nav::NavMap::from_world(&world.obstacles(), 0.05).expect("map");
    let q = HybridQuery {
        start: Pose2::new(11.0, 4.0, 0.0),
        goal: Pose2::new(3.0, 4.0, std::f64::consts::PI),
        truck: truck.clone(),
        margin_m: 0.15,
        load: None,
        params: HybridParams::default(),
        approach_m: 2.0,
    };
    let plan = plan_hybrid(&map, &q).expect("plans");
    assert!(plan.cusps().len() >= 2, "{} cusps", plan.cusps().len());
    let far = Pose2::new(50.0, 50.0, 0.0);
    let mut sim = Sim::new(
        &truck,
        &q.start,
        &PalletSpec::field_1200(),
        &far,
        &world.obstacles(),
        &SimConfig::default(),
    )
    .expect("world");
    let cfg = TrackerConfig {
        cruise_speed_mps: 0.4,
        lookahead_m: 0.7,
        ..TrackerConfig::default()
    };
    // Replanned from where the truck stands at each cusp, as a truck would.
    let mut segments_driven = 0;
    let mut plan = plan;
    'replan: for _ in 0..10 {
        let mut follower = SegmentFollower::new(plan.segments.clone(), cfg.clone(), &truck);
        for _ in 0..20_000 {
            let cmd = follower.command(&TrackerInput {
                t_s: sim.time_s(),
                pose: sim.fork_root_pose(),
                speed_mps: sim.speed_mps(),
                steer_rad: sim.steer_rad(),
                fix_measured_s: None,
                truck: &truck,
            });
            if cmd.done {
                break 'replan;
            }
            if follower.segment() > 0 {
                segments_driven += 1;
                let from = sim.fork_root_pose();
                plan = plan_hybrid_from_here(
                    &map,
                    &HybridQuery {
                        start: from,
                        ..q.clone()
                    },
                )
                .expect("replans")
                .0;
                continue 'replan;
            }
            sim.step(cmd.speed_mps, cmd.steer_rad);
            assert!(
                !sim.obstacle_contact(),
                "struck a rack at {:?}",
                sim.fork_root_pose()
            );
        }
    }
    assert!(
        segments_driven >= 2,
        "{segments_driven} segments before the last"
    );
    let got = sim.fork_root_pose();
    assert!(got.distance_to(&q.goal) < 0.05, "{got:?} vs {:?}", q.goal);
    let heading = forkbench_core::units::wrap_angle(got.heading_rad - q.goal.heading_rad);
    assert!(heading.abs() < 2f64.to_radians(), "{heading}");
}
