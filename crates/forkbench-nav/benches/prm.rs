//! PRM on the warehouse map: roadmap build and A* query, 500 nodes at 10 m (target: median ≤ 5 ms), RRT-Connect beside it.

use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};
use forkbench_nav::{OccupancyGrid, PrmParams, RrtParams, plan_prm, plan_rrt_connect};

fn warehouse() -> OccupancyGrid {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../worlds/warehouse.toml");
    let world = forkbench_trial::World::load(&file).expect("warehouse world");
    let truck = forkbench_core::ForkliftSpec::default();
    OccupancyGrid::from_obstacles(&world.obstacles(), &[], 0.05, 0.0)
        .expect("grid")
        .inflated(forkbench_nav::luo_inflation_m(&truck))
}

fn bench(c: &mut Criterion) {
    let grid = warehouse();
    let (start, goal) = ([3.0, 3.0], [30.75, 9.75]);
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
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
