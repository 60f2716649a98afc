//! PRM on the warehouse map: roadmap build and A* query, 500 nodes at 10 m (target: median ≤ 5 ms), PRM to the first solution, RRT-Connect (and a simplified RRT-Connect route) beside it, a footprint-checked, smoothed plan, and Hybrid-A* out of a station.

use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};
use forkbench_core::Pose2;
use forkbench_nav::{
    Algorithm, CollisionModel, GlobalQuery, NavMap, OccupancyGrid, PrmParams, RrtParams,
    plan_global, plan_prm, plan_rrt_connect,
};

fn warehouse() -> NavMap {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../worlds/warehouse.toml");
    let world = forkbench_trial::World::load(&file).expect("warehouse world");
    NavMap::from_world(&world.obstacles(), 0.05).expect("map")
}

fn inflated(map: &NavMap) -> OccupancyGrid {
    let truck = forkbench_core::ForkliftSpec::default();
    map.grid.inflated(forkbench_nav::luo_inflation_m(&truck))
}

fn bench(c: &mut Criterion) {
    let map = warehouse();
    let grid = inflated(&map);
    let (start, goal) = ([3.0, 3.0], [30.75, 10.25]);
    let mut g = c.benchmark_group("warehouse");
    // A new seed per iteration: the cost of a typical roadmap, not of one lucky sample.
    let mut seed = 0;
    g.bench_function("prm-500-10m", |b| {
        b.iter(|| {
            seed += 1;
            let p = PrmParams {
                nodes: 500,
                connect_m: Some(10.0),
                seed,
            };
            plan_prm(&grid, start, goal, &p).expect("plans").0
        })
    });
    g.bench_function("prm-first-solution-10m", |b| {
        b.iter(|| {
            seed += 1;
            let p = PrmParams {
                nodes: 5000,
                connect_m: Some(10.0),
                seed,
            };
            forkbench_nav::plan_prm_first(&grid, start, goal, &p)
                .expect("plans")
                .0
        })
    });
    g.bench_function("simplify-rrt-connect-route", |b| {
        b.iter(|| {
            seed += 1;
            let p = RrtParams {
                seed,
                ..RrtParams::default()
            };
            let route = plan_rrt_connect(&grid, start, goal, &p).expect("plans");
            let points = route.points.expect("a route");
            forkbench_nav::simplify::simplify(&grid, &points, seed)
        })
    });
    g.bench_function("rrt-connect", |b| {
        b.iter(|| {
            seed += 1;
            let p = RrtParams {
                seed,
                ..RrtParams::default()
            };
            plan_rrt_connect(&grid, start, goal, &p).expect("plans")
        })
    });
    g.bench_function("prm-500-10m-footprint-smoothed", |b| {
        b.iter(|| {
            seed += 1;
            let q = GlobalQuery {
                start: Pose2::new(3.0, 3.0, std::f64::consts::FRAC_PI_2),
                goal: Pose2::new(30.75, 10.25, 0.0),
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
                truck: forkbench_core::ForkliftSpec::default(),
                manoeuvre_fallback: None,
            };
            plan_global(&map, &q).expect("plans")
        })
    });
    // Hybrid-A* on the mission's second leg: out of the sorting station (a K-turn) to the
    // staging pose before the shelf, ending in the 1.8 m approach; deterministic.
    g.bench_function("hybrid-astar-sorting-to-staging", |b| {
        let q = forkbench_nav::hybrid::HybridQuery {
            start: Pose2::new(6.5, 21.5, std::f64::consts::FRAC_PI_2),
            goal: Pose2::new(6.0, 9.05, std::f64::consts::PI),
            truck: forkbench_core::ForkliftSpec::default(),
            margin_m: 0.15,
            load: None,
            params: forkbench_nav::hybrid::HybridParams::default(),
            approach_m: 1.8,
        };
        b.iter(|| forkbench_nav::hybrid::plan_hybrid(&map, &q).expect("plans"))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
