//! Hybrid-A*: manoeuvres with cusps on maps where a point planner's smoothed route cannot start, and its errors.

use forkbench_core::geometry::Obstacle;
use forkbench_core::units::wrap_angle;
use forkbench_core::{ForkliftSpec, Pose2};
use forkbench_geom::Footprint;
use forkbench_nav::hybrid::{Body, HybridParams, HybridQuery, Manoeuvre, plan_hybrid};
use forkbench_nav::{NavError, NavMap};

fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> Obstacle {
    Obstacle {
        centre: Pose2::new((x0 + x1) / 2.0, (y0 + y1) / 2.0, 0.0),
        length_m: x1 - x0,
        width_m: y1 - y0,
    }
}

/// `obstacles` on a floor spanning `w` × `h` m from the origin (corner posts keep the
/// grid that size).
fn map(w: f64, h: f64, obstacles: &[Obstacle]) -> NavMap {
    let mut all = obstacles.to_vec();
    for (x, y) in [
        (0.0, 0.0),
        (w - 0.05, 0.0),
        (0.0, h - 0.05),
        (w - 0.05, h - 0.05),
    ] {
        all.push(rect(x, y, x + 0.05, y + 0.05));
    }
    NavMap::from_world(&all, 0.05).expect("map")
}

/// 30 × 20 m, two rack rows 22 m long with a 4 m gap at each end.
fn two_rows() -> NavMap {
    map(
        30.0,
        20.0,
        &[rect(4.0, 6.5, 26.0, 8.0), rect(4.0, 12.0, 26.0, 13.5)],
    )
}

fn query(start: Pose2, goal: Pose2) -> HybridQuery {
    HybridQuery {
        start,
        goal,
        truck: ForkliftSpec::default(),
        margin_m: 0.1,
        load: None,
        params: HybridParams::default(),
        approach_m: 0.0,
    }
}

/// Ends at the goal, every pose clear of the map's obstacles (the footprint grown by the
/// margin less the corners' travel between the search's checks), curvature within the
/// fork root's limit.
fn check(m: &NavMap, q: &HybridQuery, plan: &Manoeuvre) {
    let slack = forkbench_nav::hybrid::CORNER_STEP_M;
    let body = Body::of(&q.truck, q.margin_m - slack, q.load);
    let end = plan.poses().last().expect("poses");
    assert!(
        (end.x_m - q.goal.x_m).hypot(end.y_m - q.goal.y_m) < 1e-3,
        "{end:?}"
    );
    assert!(wrap_angle(end.heading_rad - q.goal.heading_rad).abs() < 1e-3);
    let first = plan.poses().next().expect("poses");
    assert!((first.x_m - q.start.x_m).hypot(first.y_m - q.start.y_m) < 1e-9);
    for p in plan.poses() {
        assert!(body.free(&m.obstacles, &p), "strikes at {p:?}");
    }
    let k = forkbench_nav::hybrid::root_max_curvature_per_m(&q.truck) * q.params.curvature_fraction;
    for s in plan.segments.iter().flat_map(|p| &p.samples) {
        assert!(s.curvature_per_m.abs() <= k + 1e-9);
    }
    // Samples are dense: no jump longer than the sample step.
    for seg in &plan.segments {
        for w in seg.samples.windows(2) {
            assert!((w[1].x_m - w[0].x_m).hypot(w[1].y_m - w[0].y_m) < 0.06);
        }
    }
}

#[test]
fn starts_facing_away_from_the_route() {
    let m = two_rows();
    let q = query(
        Pose2::new(2.0, 3.0, 0.0),
        Pose2::new(19.0, 17.0, 90f64.to_radians()),
    );
    let plan = plan_hybrid(&m, &q).expect("plans");
    check(&m, &q, &plan);
    assert!(plan.length_m < 40.0, "{} m", plan.length_m);
}

#[test]
fn turns_round_in_an_aisle_with_cusps() {
    // A 5.5 m aisle between two walls: the truck (4.05 m long, 0.94 m turning radius)
    // cannot turn round forwards.
    let m = map(
        20.0,
        8.0,
        &[rect(0.0, 0.0, 20.0, 1.25), rect(0.0, 6.75, 20.0, 8.0)],
    );
    let q = query(
        Pose2::new(10.0, 4.0, 0.0),
        Pose2::new(10.0, 4.0, std::f64::consts::PI),
    );
    let plan = plan_hybrid(&m, &q).expect("plans");
    check(&m, &q, &plan);
    assert!(!plan.cusps().is_empty(), "turned round without reversing");
    assert!(plan.reverse_m() > 0.0);
    let forward_only = HybridQuery {
        params: HybridParams {
            forward_only: true,
            max_expansions: 20_000,
            ..HybridParams::default()
        },
        ..q
    };
    assert!(plan_hybrid(&m, &forward_only).is_err());
}

#[test]
fn backs_out_of_a_dead_end_bay() {
    // A bay 1.8 m wide and 6 m deep opening south onto an aisle; the truck is in it,
    // forks towards the dead end.
    let m = map(
        20.0,
        14.0,
        &[
            rect(0.0, 8.0, 9.1, 14.0),
            rect(10.9, 8.0, 20.0, 14.0),
            rect(9.1, 13.5, 10.9, 14.0),
        ],
    );
    let q = query(
        Pose2::new(10.0, 11.7, 90f64.to_radians()),
        Pose2::new(16.0, 4.0, 0.0),
    );
    let plan = plan_hybrid(&m, &q).expect("plans");
    check(&m, &q, &plan);
    assert!(plan.segments[0].reverse, "the first move must be backwards");
}

#[test]
fn an_unreachable_goal_is_refused_quickly() {
    // The goal is in a closed room.
    let m = map(
        20.0,
        20.0,
        &[rect(12.0, 12.0, 20.0, 12.3), rect(12.0, 12.0, 12.3, 20.0)],
    );
    let q = query(Pose2::new(4.0, 4.0, 0.0), Pose2::new(16.0, 16.0, 0.0));
    let t0 = std::time::Instant::now();
    let err = plan_hybrid(&m, &q).expect_err("unreachable");
    assert!(matches!(err, NavError::Unreachable(_)), "{err}");
    assert!(t0.elapsed().as_secs_f64() < 2.0);
    // A budget that runs out is its own error.
    let open = map(20.0, 20.0, &[rect(9.0, 2.0, 11.0, 18.0)]);
    let tight = HybridQuery {
        params: HybridParams {
            max_expansions: 3,
            ..HybridParams::default()
        },
        ..query(Pose2::new(4.0, 10.0, 0.0), Pose2::new(16.0, 10.0, 0.0))
    };
    assert!(matches!(
        plan_hybrid(&open, &tight),
        Err(NavError::Budget { .. })
    ));
}

#[test]
fn a_carried_pallet_blocks_a_gap_the_empty_truck_passes() {
    // A 1.5 m gap in a wall: the 1.2 m truck passes; with a 1.6 m-wide load it cannot.
    let m = map(
        20.0,
        12.0,
        &[rect(10.0, 0.0, 10.5, 5.25), rect(10.0, 6.75, 10.5, 12.0)],
    );
    let q = query(Pose2::new(4.0, 6.0, 0.0), Pose2::new(16.0, 6.0, 0.0));
    check(&m, &q, &plan_hybrid(&m, &q).expect("empty truck plans"));
    let loaded = HybridQuery {
        load: Some(Footprint {
            length_m: 1.2,
            width_m: 1.6,
            centre_ahead_m: 0.8,
        }),
        params: HybridParams {
            max_expansions: 20_000,
            ..HybridParams::default()
        },
        ..q
    };
    assert!(plan_hybrid(&m, &loaded).is_err());
}

#[test]
fn settings_out_of_range_are_named() {
    let m = two_rows();
    let mut q = query(Pose2::new(2.0, 3.0, 0.0), Pose2::new(19.0, 17.0, 1.0));
    q.params.cell_m = f64::NAN;
    let err = plan_hybrid(&m, &q).expect_err("refused").to_string();
    assert!(err.contains("cell_m"), "{err}");
}

/// The held-out map of issue #45: PRM with the footprint model and smoothing, from a start
/// facing away from the route, plans a drivable result on every seed (the smoothed route
/// where it can be had, a Hybrid-A* manoeuvre where the lead-in corner is too tight).
#[test]
fn smoothed_prm_from_a_start_facing_away_plans_on_every_seed() {
    use forkbench_nav::{Algorithm, CollisionModel, GlobalQuery, PrmParams, plan_global};
    let m = two_rows();
    let mut fell_back = 0;
    for seed in 1..=20 {
        let q = GlobalQuery {
            start: Pose2::new(2.0, 3.0, 0.0),
            goal: Pose2::new(19.0, 17.0, 90f64.to_radians()),
            algorithm: Algorithm::Prm(PrmParams {
                nodes: 500,
                connect_m: Some(10.0),
                seed,
            }),
            collision: CollisionModel::Footprint,
            inflate_m: 0.0,
            smooth: true,
            lead_m: [2.5, 2.5],
            approach: Vec::new(),
            margin_m: 0.15,
            truck: ForkliftSpec::default(),
            manoeuvre_fallback: Some(HybridParams::default()),
        };
        let plan = plan_global(&m, &q).expect("plans");
        assert!(plan.succeeded(), "seed {seed}: {:?}", plan.fallback);
        if let Some(man) = &plan.manoeuvre {
            fell_back += 1;
            let hq = HybridQuery {
                margin_m: q.margin_m,
                ..query(q.start, q.goal)
            };
            check(&m, &hq, man);
        }
        // Without the fallback the same query reports the failure instead.
        let strict = GlobalQuery {
            manoeuvre_fallback: None,
            ..q
        };
        let plain = plan_global(&m, &strict).expect("plans");
        assert!(plain.manoeuvre.is_none());
        assert_eq!(plain.succeeded(), plan.manoeuvre.is_none());
    }
    assert!(fell_back > 0, "the lead-in corner never needed a manoeuvre");
}

/// Random free start and goal poses (chassis 0.3 m clear, at least 5 m apart, any heading)
/// on the two-row map: Hybrid-A* plans every pair.
#[test]
fn plans_random_free_pose_pairs() {
    let m = two_rows();
    let truck = ForkliftSpec::default();
    let clear = Body::of(&truck, 0.3, None);
    let mut state = 7u64;
    let mut next = move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut pose = || loop {
        let p = Pose2::new(
            next() * 30.0,
            next() * 20.0,
            (next() * 2.0 - 1.0) * std::f64::consts::PI,
        );
        if clear.free(&m.obstacles, &p) && clear.on_map(&p, m.grid.extent()) {
            return p;
        }
    };
    let mut planned = 0;
    for _ in 0..20 {
        let (a, b) = loop {
            let (a, b) = (pose(), pose());
            if (a.x_m - b.x_m).hypot(a.y_m - b.y_m) >= 5.0 {
                break (a, b);
            }
        };
        let q = query(a, b);
        let plan = plan_hybrid(&m, &q).unwrap_or_else(|e| panic!("{a:?} → {b:?}: {e}"));
        check(&m, &q, &plan);
        planned += 1;
    }
    assert_eq!(planned, 20);
}
