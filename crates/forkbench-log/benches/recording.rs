//! Cost of recording one field-test trial to .rrd and .mcap against the plain trial (target ≤ 3× with both).

mod common;

use std::collections::BTreeMap;

use criterion::{BatchSize, Criterion, criterion_group, criterion_main};
use forkbench_log::{McapRecorder, RerunRecorder, RerunTarget};
use forkbench_trial::{Tee, run_trial, run_trial_recorded};

fn bench(c: &mut Criterion) {
    let (scn, opts) = common::field_test();
    let case = &scn.cases[0];
    let dir = common::scratch_dir("bench");
    let mut g = c.benchmark_group("recording");
    g.bench_function("off", |b| b.iter(|| run_trial(&scn, case, &opts)));
    // Each iteration writes fresh files, as a batch does (truncating last iteration's
    // files would add the file system's cost of freeing them to the timing).
    let fresh = |names: &'static [&'static str]| {
        let dir = dir.clone();
        move || {
            for n in names {
                let _ = std::fs::remove_file(dir.join(n));
            }
        }
    };
    g.bench_function("mcap", |b| {
        b.iter_batched(
            fresh(&["b.mcap"]),
            |()| {
                let mut m =
                    McapRecorder::create(&dir.join("b.mcap"), BTreeMap::new()).expect("opens");
                let out = run_trial_recorded(&scn, case, &opts, &mut m);
                m.finish().expect("finishes");
                out
            },
            BatchSize::PerIteration,
        )
    });
    g.bench_function("rrd", |b| {
        b.iter_batched(
            fresh(&["b.rrd"]),
            |()| {
                let mut r =
                    RerunRecorder::new(&RerunTarget::File(dir.join("b.rrd"))).expect("opens");
                let out = run_trial_recorded(&scn, case, &opts, &mut r);
                r.finish().expect("flushes");
                out
            },
            BatchSize::PerIteration,
        )
    });
    g.bench_function("rrd-setup", |b| {
        b.iter(|| {
            let mut r = RerunRecorder::new(&RerunTarget::File(dir.join("e.rrd"))).expect("opens");
            r.finish().expect("flushes");
        })
    });
    g.bench_function("rrd+mcap", |b| {
        b.iter_batched(
            fresh(&["c.mcap", "c.rrd"]),
            |()| {
                let mut m =
                    McapRecorder::create(&dir.join("c.mcap"), BTreeMap::new()).expect("opens");
                let mut r =
                    RerunRecorder::new(&RerunTarget::File(dir.join("c.rrd"))).expect("opens");
                let out = run_trial_recorded(&scn, case, &opts, &mut Tee(vec![&mut m, &mut r]));
                m.finish().expect("finishes");
                r.finish().expect("flushes");
                out
            },
            BatchSize::PerIteration,
        )
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).measurement_time(std::time::Duration::from_secs(3));
    targets = bench
}
criterion_main!(benches);
