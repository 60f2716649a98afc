//! Plan time of both planners over the papers' Table 2 scenarios (issue target: median ≤ 200 µs).

use criterion::{Criterion, criterion_group, criterion_main};
use forkbench_core::ForkliftSpec;
use forkbench_plan::reproduce::{BsplineTable, SpiralTable};
use forkbench_plan::{BsplineConfig, PlanRequest, SpiralConfig, bspline, spiral};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let truck = ForkliftSpec::default();
    let bt = BsplineTable::embedded();
    let mut g = c.benchmark_group("bspline");
    for case in &bt.case {
        let req = PlanRequest::new(bt.start(), bt.goal(case));
        g.bench_function(format!("table2/{:0>2}", case.name), |b| {
            b.iter(|| bspline::plan(black_box(&req), &BsplineConfig::default()))
        });
    }
    g.finish();
    let st = SpiralTable::embedded();
    let mut g = c.benchmark_group("spiral");
    for case in &st.case {
        let req = st.request(case, &truck);
        g.bench_function(format!("table2/{:0>2}", case.name), |b| {
            b.iter(|| spiral::plan(black_box(&req), &SpiralConfig::default()))
        });
    }
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(30).measurement_time(std::time::Duration::from_millis(600)).warm_up_time(std::time::Duration::from_millis(200));
    targets = bench
}
criterion_main!(benches);
