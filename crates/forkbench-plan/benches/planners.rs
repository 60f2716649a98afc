//! Plan time of both planners over the papers' Table 2 scenarios, and of the spiral over the random goals of its optimality test (issue targets: spiral median ≤ 150 µs, max ≤ 1 ms).

#[path = "../tests/common/reference.rs"]
#[allow(dead_code)]
mod reference;

use criterion::{Criterion, criterion_group, criterion_main};
use forkbench_core::ForkliftSpec;
use forkbench_plan::reproduce::{BsplineTable, SpiralTable};
use forkbench_plan::{BsplineConfig, PlanRequest, SpiralConfig, bspline, spiral};
use std::hint::black_box;

/// The random and holdout goals of `tests/spiral_optimal.rs` that have a feasible spiral
/// in the paper's window (the planner's default).
fn random_goals() -> Vec<(String, PlanRequest)> {
    reference::reference()
        .goals
        .into_iter()
        .filter(|g| g.length_window && g.cost.is_some() && !g.name.starts_with("row"))
        .map(|g| (g.name.replace(' ', "/"), g.request()))
        .collect()
}

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
    let mut g = c.benchmark_group("spiral-random");
    g.sample_size(10)
        .measurement_time(std::time::Duration::from_millis(150))
        .warm_up_time(std::time::Duration::from_millis(50));
    for (name, req) in random_goals() {
        g.bench_function(name, |b| {
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
