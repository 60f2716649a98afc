//! Rust time of one control tick of a stepped session (a Gymnasium step: sensing, physics, judging), under the scenario's tracker and under a caller's command.

use std::path::Path;
use std::sync::Arc;

use criterion::{BatchSize, Criterion, criterion_group, criterion_main};
use forkbench_trial::trial::{Control, Session};
use forkbench_trial::{Scenario, TrialOptions};

/// Ticks stepped per measured batch: the first 5 s of the field test's approach.
const TICKS: u32 = 500;

fn bench(c: &mut Criterion) {
    let file = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenarios/field-test.toml"
    ));
    let scn = Arc::new(Scenario::load(file).expect("field test loads"));
    let opts = TrialOptions {
        seed: Some(7),
        ..TrialOptions::default()
    };
    let start = || Session::start(scn.clone(), "default", &opts).expect("starts");
    let mut g = c.benchmark_group("session");
    g.throughput(criterion::Throughput::Elements(u64::from(TICKS)));
    let controls = [
        ("tracker", Control::Tracker),
        (
            "command",
            Control::Command {
                speed_mps: 0.5,
                steer_rad: 0.05,
            },
        ),
    ];
    for (label, control) in controls {
        g.bench_function(format!("{TICKS}_ticks/{label}"), |b| {
            b.iter_batched(
                start,
                |mut s| {
                    for _ in 0..TICKS {
                        s.step(control);
                    }
                    s
                },
                BatchSize::SmallInput,
            )
        });
    }
    g.throughput(criterion::Throughput::Elements(1));
    g.bench_function("start", |b| b.iter(start));
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
