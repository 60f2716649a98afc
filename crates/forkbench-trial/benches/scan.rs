//! One TiM561 scan (819 beams, spot and noise modelled, and ideal rays) in the warehouse world, the truck at a rack-aisle pick (issue target: ≤ 150 µs); one NAV350 reflector fix there (visibility, association, least squares; target ≤ 50 µs).

use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};
use forkbench_core::Pose2;
use forkbench_sensors::reflectors::{ReflectorNavConfig, associate, measure, solve, visible};
use forkbench_sensors::scan::{Errors, ScannerConfig, scan};
use forkbench_sim::{PalletSpec, Sim, SimConfig};
use forkbench_trial::World;
use rand::SeedableRng;

fn bench(c: &mut Criterion) {
    let file = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../worlds/warehouse.toml"
    ));
    let world = World::load(file).expect("warehouse loads");
    let obstacles = world.obstacles();
    // In an aisle facing a pallet 6.5 m ahead: racks on both sides, walls beyond.
    let root = Pose2::new(6.0, 6.5, 0.0);
    let sim = Sim::new(
        &forkbench_core::ForkliftSpec::default(),
        &root,
        &PalletSpec::field_1200(),
        &Pose2::new(12.5, 6.5, 0.0),
        &obstacles,
        &SimConfig::default(),
    )
    .expect("world builds");
    let cfg = ScannerConfig::tim561();
    let sensor = cfg.sensor_pose(&root);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
    let bias = cfg.draw_bias(&mut rng);
    let mut g = c.benchmark_group("scan");
    g.bench_function("tim561/warehouse/modelled", |b| {
        b.iter(|| {
            let e = Errors::Modelled {
                bias_m: bias,
                rng: &mut rng,
            };
            scan(&cfg, &sim, sensor, e)
        })
    });
    g.bench_function("tim561/warehouse/ideal", |b| {
        b.iter(|| scan::<rand_chacha::ChaCha8Rng>(&cfg, &sim, sensor, Errors::Ideal))
    });
    // A NAV350 fix from the same spot: which of the 36 reflectors are in sight past the
    // racks and walls, their measurement, association from a pose 5 cm off, the solve.
    let fixed = world.fixed_surfaces();
    let ncfg = ReflectorNavConfig::default();
    let predicted = Pose2::new(root.x_m + 0.05, root.y_m - 0.03, 0.01);
    g.bench_function("nav350_fix/warehouse", |b| {
        b.iter(|| {
            let at = [root.x_m, root.y_m];
            let seen = visible(at, &world.reflector, &fixed, &ncfg);
            let obs = measure(&root, &world.reflector, &seen, &ncfg, &mut rng);
            let pairs = associate(&obs, &predicted, &world.reflector, &ncfg);
            solve(&obs, &pairs, &world.reflector, &predicted, &ncfg).expect("a fix in the aisle")
        })
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(30).measurement_time(std::time::Duration::from_secs(3));
    targets = bench
}
criterion_main!(benches);
