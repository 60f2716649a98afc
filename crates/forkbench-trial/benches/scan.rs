//! One TiM561 scan (819 beams, spot and noise modelled, and ideal rays) in the warehouse world, the truck at a rack-aisle pick (issue target: ≤ 150 µs); one NAV350 sweep there as the localiser runs it (visibility, each reflector measured from where the rotating beam passed it and carried to the sweep's end by the speed input, association, least squares; target ≤ 50 µs).

use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};
use forkbench_core::Pose2;
use forkbench_sensors::scan::{Errors, ScannerConfig, scan};
use forkbench_sensors::{Localizer, LocalizerInput, ReflectorNav, ReflectorNavSettings};
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
    // A NAV350 sweep from the same spot, the truck creeping along the aisle: which of the
    // 36 reflectors are in sight past the racks and walls, each measured from the trail,
    // carried by the speed input, associated from a pose 5 cm off, and the solve.
    let fixed = world.fixed_surfaces();
    let settings = ReflectorNavSettings::default();
    let mut nav = ReflectorNav::new(settings, &world.reflector, &fixed, (8.0, 0.0), 1.0);
    let mut k = 0u64;
    g.bench_function("nav350_fix/warehouse", |b| {
        b.iter(|| {
            // One call per period: every call sweeps.
            k += 1;
            let t_s = k as f64 * 0.125;
            let truth = Pose2::new(root.x_m + 1e-6 * t_s, root.y_m, 0.0);
            let input = LocalizerInput {
                t_s,
                truth,
                predicted: Some(Pose2::new(truth.x_m + 0.05, truth.y_m - 0.03, 0.01)),
                odometry: Some(truth),
                occluders: Vec::new(),
            };
            let r = nav.update(&input, &mut rng).expect("a sweep each call");
            r.pose.expect("a fix in the aisle")
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
