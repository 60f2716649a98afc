//! The stages a trial's profile names, each alone (`--profile` times them inside a trial): one physics step of the field test's world, one pure-pursuit command on a B-spline pick path, one evidence check of a face against a TiM561 scan. Scans, NAV350 sweeps, planners, people and recording have their own benches.

use criterion::{Criterion, criterion_group, criterion_main};
use forkbench_core::{ForkliftSpec, Pose2};
use forkbench_plan::PlanRequest;
use forkbench_sensors::evidence::face_evidence;
use forkbench_sensors::scan::{Errors, ScannerConfig, scan};
use forkbench_sim::{PalletSpec, Sim, SimConfig};
use forkbench_track::{PurePursuit, Tracker, TrackerConfig, TrackerInput};

fn bench(c: &mut Criterion) {
    let truck = ForkliftSpec::default();
    let pallet = PalletSpec::field_1200();
    let face = Pose2::new(6.5, 0.3, 0.05);
    let start = Pose2::new(0.0, 0.0, 0.0);
    let mut g = c.benchmark_group("stage");
    // Physics: the truck creeping towards the pallet in an open world, the pallet asleep;
    // a fresh world every thousand steps (built outside the clock) keeps it short of the
    // pallet, as most of a pick's steps are.
    let fresh = || {
        Sim::new(&truck, &start, &pallet, &face, &[], &SimConfig::default()).expect("world builds")
    };
    g.bench_function("physics_step/field_test", |b| {
        b.iter_custom(|iters| {
            let mut spent = std::time::Duration::ZERO;
            let mut left = iters;
            while left > 0 {
                let mut sim = fresh();
                let n = left.min(1000);
                let t = std::time::Instant::now();
                for _ in 0..n {
                    sim.step(0.3, 0.02);
                }
                spent += t.elapsed();
                left -= n;
            }
            spent
        })
    });
    // Tracking: pure pursuit on the pick's B-spline path, from a pose near its start.
    let req = PlanRequest::new(
        start,
        face.to_world(&Pose2::new(-truck.fork_length_m - 0.3, 0.0, 0.0)),
    );
    let plan = forkbench_plan::bspline::plan(&req, &Default::default()).expect("plans");
    let mut pp = PurePursuit::new(plan.path, TrackerConfig::default(), 0.0);
    let input = TrackerInput {
        t_s: 1.0,
        pose: Pose2::new(1.0, 0.02, 0.01),
        speed_mps: 0.4,
        steer_rad: 0.01,
        fix_measured_s: Some(0.95),
        truck: &truck,
    };
    g.bench_function("tracking/pure_pursuit", |b| {
        b.iter(|| Tracker::command(&mut pp, &input))
    });
    // The evidence check: one candidate face scored against a scan of the pallet.
    let cfg = ScannerConfig::tim561();
    let sensor = cfg.sensor_pose(&Pose2::new(3.0, 0.0, 0.0));
    let sim = Sim::new(
        &truck,
        &Pose2::new(3.0, 0.0, 0.0),
        &pallet,
        &face,
        &[],
        &SimConfig::default(),
    )
    .expect("world builds");
    let shot = scan::<rand_chacha::ChaCha8Rng>(&cfg, &sim, sensor, Errors::Ideal);
    let local = shot.sensor.to_local(&face);
    g.bench_function("evidence_check/field_1200", |b| {
        b.iter(|| face_evidence(&shot, &pallet, &local).score)
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(30).measurement_time(std::time::Duration::from_secs(3));
    targets = bench
}
criterion_main!(benches);
