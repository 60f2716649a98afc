//! Minimum corridor width per mode at one angle: the AMV at 1 cm / 1° (target ≤ 1 s each), the forklift at 3 cm.

use criterion::{Criterion, criterion_group, criterion_main};
use forkbench_corridor::{Junction, Mode, Resolution, Vehicle, min_width_m};

fn bench(c: &mut Criterion) {
    let amv = Vehicle {
        length_m: 0.56,
        width_m: 0.40,
        kinematic_ahead_m: 0.0,
        min_radius_m: 0.0,
    };
    let res = Resolution {
        cell_m: 0.01,
        heading_rad: 1f64.to_radians(),
    };
    let mut g = c.benchmark_group("min_width_amv_90deg");
    for mode in [
        Mode::Oblique,
        Mode::Spin,
        Mode::Curve,
        Mode::CurveFixedRadius,
    ] {
        g.bench_function(mode.name(), |b| {
            b.iter(|| min_width_m(&amv, mode, Junction::L, 90f64.to_radians(), res, 5.0))
        });
    }
    g.finish();
    // The forklift at the same relative resolution (Wc/40 = 3 cm), two shifted grids.
    let truck = Vehicle::forklift(&forkbench_core::ForkliftSpec::default());
    let res3 = Resolution {
        cell_m: truck.width_m / 40.0,
        ..res
    };
    let mut g = c.benchmark_group("min_width_a30_3cm");
    for deg in [60.0f64, 90.0] {
        g.bench_function(format!("truck_{deg}deg"), |b| {
            b.iter(|| {
                min_width_m(
                    &truck,
                    Mode::Truck,
                    Junction::L,
                    deg.to_radians(),
                    res3,
                    20.0,
                )
            })
        });
    }
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = bench
}
criterion_main!(benches);
