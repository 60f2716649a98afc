//! Wall time of one trial: a 6.5 m pick with each planner and sensing, and one trial of each kind the main job runs.

use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};
use forkbench_trial::{Scenario, TrialOptions, run_trial};

fn bench(c: &mut Criterion) {
    let file = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenarios/field-test.toml"
    ));
    let scn = Scenario::load(file).expect("field test loads");
    let case = &scn.cases[0];
    let mut g = c.benchmark_group("trial");
    for planner in ["bspline", "spiral"] {
        for (label, no_noise) in [("no_noise", true), ("noise", false)] {
            let opts = TrialOptions {
                no_noise,
                planner: Some(planner.to_owned()),
                seed: Some(7),
                ..TrialOptions::default()
            };
            g.bench_function(format!("field_test/{planner}/{label}"), |b| {
                b.iter(|| run_trial(&scn, case, &opts))
            });
        }
    }
    // The same pick with the pallet estimated from a TiM561 scan (and with the Kinect v2
    // row fused) and the pocket detector (first estimate and two re-estimates), and with
    // the Gaussian model.
    for (label, sensing) in [
        ("gaussian", ""),
        ("tim561", "[sensors.pallet]\nkind = \"tim561\"\n"),
        (
            "tim561_kinect2",
            "[sensors.pallet]\nkind = \"tim561+kinect2\"\n",
        ),
    ] {
        let text = format!(
            "name = \"near\"\nplanner = \"bspline\"\npallet_kind = \"field-1200\"\n\
             start = {{ x_m = 0.0, y_m = 0.0, heading_deg = 0.0 }}\n\
             pallet = {{ x_m = 5.0, y_m = 0.4, heading_deg = 5.0 }}\n[replan]\nenabled = true\n{sensing}"
        );
        let scn = Scenario::parse(&text, "near.toml", |_: &Path| {
            Ok(forkbench_trial::World::default())
        })
        .expect("parses");
        let opts = TrialOptions {
            seed: Some(7),
            ..TrialOptions::default()
        };
        g.bench_function(format!("near_5m/replan/{label}"), |b| {
            b.iter(|| run_trial(&scn, &scn.cases[0], &opts))
        });
    }
    g.finish();
}

/// One trial of each kind the main job runs, at the embedded scenarios' own settings
/// (TiM561 scans, NAV350 reflector fixes, odometry errors), plan once, fixed seed.
fn kinds(c: &mut Criterion) {
    let scenarios = forkbench_trial::defaults::default_scenarios().expect("embedded scenarios");
    let mut g = c.benchmark_group("kind");
    for (name, case) in [
        ("bspline-table2", "1"),
        ("spiral-table2", "1"),
        ("rack-pick", ""),
        ("field-test", ""),
        ("warehouse-mission", ""),
    ] {
        let scn = scenarios
            .iter()
            .find(|s| s.name == name)
            .expect("embedded scenario");
        let case = scn.case(case).unwrap_or(&scn.cases[0]);
        let opts = TrialOptions {
            seed: Some(7),
            replan: Some(false),
            ..TrialOptions::default()
        };
        g.bench_function(name, |b| b.iter(|| run_trial(scn, case, &opts)));
    }
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).measurement_time(std::time::Duration::from_secs(2));
    targets = bench, kinds
}
criterion_main!(benches);
