//! The footprint collision model and the smoothing of routes into drivable paths.

use forkbench_core::geometry::Obstacle;
use forkbench_core::{ForkliftSpec, Pose2};
use forkbench_geom::Obstacles;
use forkbench_nav::smooth::{SmoothParams, shortcut, smooth};
use forkbench_nav::{
    Algorithm, CollisionModel, FootprintSpace, FreeSpace, GlobalQuery, NavMap, OccupancyGrid,
    PrmParams, SmoothError, blocked_rects, plan_global, truck_parts,
};

fn params() -> SmoothParams {
    SmoothParams::for_curvature(ForkliftSpec::default().max_curvature_per_m())
}

fn rect(x: f64, y: f64, length_m: f64, width_m: f64) -> Obstacle {
    Obstacle {
        centre: Pose2::new(x, y, 0.0),
        length_m,
        width_m,
    }
}

/// A 30 × 20 m room with walls and one block in the middle.
fn room() -> NavMap {
    NavMap::from_world(
        &[
            rect(15.0, -0.1, 30.4, 0.2),
            rect(15.0, 20.1, 30.4, 0.2),
            rect(-0.1, 10.0, 0.2, 20.0),
            rect(30.1, 10.0, 0.2, 20.0),
            rect(15.0, 10.0, 6.0, 8.0),
        ],
        0.05,
    )
    .expect("map")
}

#[test]
fn smoothed_corners_keep_the_curvature_limit_and_are_continuous() {
    let p = params();
    let poly = [[0.0, 0.0], [10.0, 0.0], [10.0, 8.0], [3.0, 12.0]];
    let s = smooth(&poly, &Obstacles::new(), (&[], &[]), &p).expect("smooths");
    let k_max = p.max_curvature_per_m;
    assert!(
        s.max_curvature_per_m <= k_max + 1e-9,
        "{}",
        s.max_curvature_per_m
    );
    // Curvature changes by at most the clothoid's sharpness over one sample: no jumps.
    let samples = &s.path.samples;
    for w in samples.windows(2) {
        let dk = (w[1].curvature_per_m - w[0].curvature_per_m).abs();
        assert!(dk < 0.05, "curvature jumps by {dk} at s = {}", w[0].s_m);
        let ds = w[1].s_m - w[0].s_m;
        // Samples fall on the 1 mm integration steps, so a spacing may run over by one.
        assert!(ds > 0.0 && ds <= p.spacing_m + 1e-3 + 1e-9, "{ds}");
        let gap = (w[1].x_m - w[0].x_m).hypot(w[1].y_m - w[0].y_m);
        assert!((gap - ds).abs() < 1e-3, "spacing {gap} vs arc {ds}");
    }
    // It leaves along the first leg and arrives along the last, at the end points.
    let (first, last) = (samples[0], *samples.last().expect("samples"));
    assert!(first.x_m.abs() < 1e-9 && first.heading_rad.abs() < 1e-9);
    let goal_heading = (12.0_f64 - 8.0).atan2(3.0 - 10.0);
    assert!((last.x_m - 3.0).abs() < 1e-3 && (last.y_m - 12.0).abs() < 1e-3);
    assert!(forkbench_core::units::wrap_angle(last.heading_rad - goal_heading).abs() < 1e-3);
}

#[test]
fn a_corner_without_room_for_its_clothoids_is_reported_where_it_is() {
    let e = smooth(
        &[[0.0, 0.0], [5.0, 0.0], [5.0, 0.5]],
        &Obstacles::new(),
        (&[], &[]),
        &params(),
    )
    .expect_err("too tight");
    match e {
        SmoothError::CornerTooTight {
            x, y, available_m, ..
        } => {
            assert_eq!((x, y), (5.0, 0.0));
            assert!((available_m - 0.5).abs() < 1e-9, "{available_m}");
        }
        other => panic!("{other:?}"),
    }
    assert!(
        e_text().contains("(5.00, 0.00) m turns 90°"),
        "{}",
        e_text()
    );
}

fn e_text() -> String {
    smooth(
        &[[0.0, 0.0], [5.0, 0.0], [5.0, 0.5]],
        &Obstacles::new(),
        (&[], &[]),
        &params(),
    )
    .expect_err("too tight")
    .to_string()
}

#[test]
fn the_swept_footprint_strike_is_found_and_located() {
    let truck = ForkliftSpec::default();
    let poly = [[0.0, 0.0], [10.0, 0.0], [10.0, 10.0]];
    // A post 0.4 m inside the point where the path passes closest to the corner: under
    // the truck's 1.2 m wide body.
    let free = smooth(&poly, &Obstacles::new(), (&[], &[]), &params()).expect("smooths");
    let near = free
        .path
        .samples
        .iter()
        .min_by(|a, b| {
            let d = |p: &&forkbench_core::PathSample| (p.x_m - 10.0).hypot(p.y_m);
            d(a).total_cmp(&d(b))
        })
        .expect("samples");
    let away = [near.x_m - 10.0, near.y_m];
    let n = away[0].hypot(away[1]);
    let post = [near.x_m + 0.4 * away[0] / n, near.y_m + 0.4 * away[1] / n];
    let mut obs = Obstacles::new();
    obs.add_rect(&Pose2::new(post[0], post[1], 0.0), 0.1, 0.1);
    let s = smooth(
        &poly,
        &obs,
        (&truck_parts(&truck, 0.0), &truck_parts(&truck, 0.0)),
        &params(),
    )
    .expect("smooths");
    let hit = s.hit.expect("the chassis swings over the post");
    assert_eq!(hit.obstacle, 0);
    assert!(hit.s_m > 5.0 && hit.s_m < near.s_m + 1.0, "{hit:?}");
    assert_eq!(s.min_clearance_m, 0.0);
}

#[test]
fn a_footprint_edge_is_free_exactly_when_the_swept_body_is() {
    let truck = ForkliftSpec::default();
    let map = room();
    let space = FootprintSpace::new(&map.grid, &map.obstacles, &truck, 0.0);
    // Along the wall at y = 1.0: the chassis (1.2 m wide) clears the wall by 0.4 m.
    assert!(space.segment_free([3.0, 1.0], [10.0, 1.0]));
    // At y = 0.5 the half width reaches the wall.
    assert!(!space.segment_free([3.0, 0.5], [10.0, 0.5]));
    // Driving east toward the block: the forks, 1.6 m ahead of the root, reach it first.
    assert!(space.segment_free([3.0, 10.0], [10.3, 10.0]));
    assert!(!space.segment_free([3.0, 10.0], [10.5, 10.0]));
    // Driving west away from it, the chassis behind the root hits it.
    assert!(!space.segment_free([13.0, 10.0], [5.0, 10.0]));
    // A point model sees no difference between the two directions.
    let grid: &OccupancyGrid = &map.grid.inflated(0.8);
    assert_eq!(
        grid.segment_free([3.0, 10.0], [10.5, 10.0]),
        FreeSpace::segment_free(grid, [10.5, 10.0], [3.0, 10.0])
    );
}

#[test]
fn shortcuts_keep_the_anchors_and_cut_the_rest() {
    let map = room();
    let grid = map.grid.inflated(0.8);
    let pts = [[2.0, 2.0], [4.0, 2.0], [6.0, 2.0], [8.0, 3.0], [10.0, 2.0]];
    assert_eq!(shortcut(&grid, &pts, &[]), vec![[2.0, 2.0], [10.0, 2.0]]);
    assert_eq!(
        shortcut(&grid, &pts, &[2]),
        vec![[2.0, 2.0], [6.0, 2.0], [10.0, 2.0]]
    );
}

#[test]
fn blocked_rectangles_cover_exactly_the_blocked_cells() {
    let map = room();
    let g = &map.grid;
    let rects = blocked_rects(g);
    let (free, occupied, unknown) = g.counts();
    let area: f64 = rects
        .iter()
        .map(|[lo, hi]| (hi[0] - lo[0]) * (hi[1] - lo[1]))
        .sum();
    let cell = g.resolution_m * g.resolution_m;
    assert!(((area / cell) - (occupied + unknown) as f64).abs() < 1e-6);
    assert!(free > 0 && rects.len() < 50, "{} rectangles", rects.len());
}

#[test]
fn a_footprint_plan_is_drivable_and_clears_the_truck_by_its_margin() {
    let map = room();
    let truck = ForkliftSpec::default();
    let q = GlobalQuery {
        start: Pose2::new(3.0, 3.0, 0.0),
        goal: Pose2::new(26.0, 16.0, std::f64::consts::FRAC_PI_2),
        algorithm: Algorithm::Prm(PrmParams {
            nodes: 300,
            connect_m: Some(10.0),
            seed: 3,
        }),
        collision: CollisionModel::Footprint,
        inflate_m: 0.8,
        smooth: true,
        lead_m: [2.5, 2.5],
        approach: Vec::new(),
        margin_m: 0.2,
        truck: truck.clone(),
        manoeuvre_fallback: None,
    };
    let plan = plan_global(&map, &q).expect("plans");
    let s = plan.drivable().expect("a drivable path");
    assert!(s.min_clearance_m >= 0.2 - 1e-6, "{}", s.min_clearance_m);
    assert!(s.max_curvature_per_m <= truck.max_curvature_per_m() + 1e-9);
    let end = s.path.samples.last().expect("samples");
    assert!((end.x_m - 26.0).abs() < 1e-3 && (end.y_m - 16.0).abs() < 1e-3);
    assert!(plan.smoothing_s > 0.0 && plan.route.timing.total_s() > 0.0);
    // The same query gives the same path.
    let again = plan_global(&map, &q).expect("plans");
    assert_eq!(again.drivable().expect("drivable").path, s.path);
}

#[test]
fn roadmaps_that_would_not_finish_are_refused() {
    let map = room();
    let grid = map.grid.inflated(0.8);
    for (nodes, connect_m) in [(100_001, Some(10.0)), (5_001, None)] {
        let p = PrmParams {
            nodes,
            connect_m,
            seed: 0,
        };
        let e = forkbench_nav::plan_prm(&grid, [3.0, 3.0], [26.0, 16.0], &p).expect_err("refused");
        assert!(e.to_string().contains("at most"), "{e}");
    }
}
