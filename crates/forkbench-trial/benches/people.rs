//! CPU of the warehouse cycle with people crossing against the same cycle without them (the safety fields kept), and against the cycle with neither: four seeds per iteration.

use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};
use forkbench_trial::{Scenario, TrialOptions, World, run_trial};

fn scenario(file: &str, movers: bool) -> Scenario {
    let path = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenarios")).join(file);
    let mut text = std::fs::read_to_string(&path).expect("the scenario");
    if !movers && let Some(at) = text.find("[[mover]]") {
        text.truncate(at);
    }
    let dir = path.parent().expect("a folder").to_owned();
    Scenario::parse(&text, file, |w| World::load(&dir.join(w))).expect("loads")
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("people");
    g.sample_size(10);
    for (label, scn) in [
        ("with_people", scenario("warehouse-people.toml", true)),
        ("without_people", scenario("warehouse-people.toml", false)),
        (
            "no_safety_no_people",
            scenario("warehouse-cycle.toml", true),
        ),
    ] {
        g.bench_function(format!("warehouse_cycle/{label}"), |b| {
            b.iter(|| {
                (1..=4u64)
                    .map(|seed| {
                        let opts = TrialOptions {
                            seed: Some(seed),
                            ..TrialOptions::default()
                        };
                        run_trial(&scn, &scn.cases[0], &opts).sim_time_s
                    })
                    .sum::<f64>()
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
