//! Minimum corridor width per mode at one angle, 1 cm / 1° (target ≤ 1 s each).

use criterion::{Criterion, criterion_group, criterion_main};
use forkbench_corridor::{Mode, Resolution, Vehicle, min_width_m};

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
            b.iter(|| min_width_m(&amv, mode, 90f64.to_radians(), res, 5.0))
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
