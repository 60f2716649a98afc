//! What the actuator and timing models cost a trial: the same trials with the `ideal` truck and the `realistic` one, interleaved trial by trial (alternating which goes first), medians of each and of their per-round ratio.

use forkbench_trial::trial::Overrides;
use forkbench_trial::{TrialOptions, run_trial};

fn options(seed: u64, ideal: bool) -> TrialOptions {
    let preset = if ideal { "ideal" } else { "realistic" };
    TrialOptions {
        seed: Some(seed),
        replan: Some(false),
        overrides: Overrides {
            truck_preset: Some(preset.to_owned()),
            ..Overrides::default()
        },
        ..TrialOptions::default()
    }
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    // `cargo bench` passes `--bench`; `cargo test --benches` runs it once, quickly.
    let rounds: usize = if std::env::args().any(|a| a == "--bench") {
        std::env::var("ACTUATOR_ROUNDS")
            .ok()
            .and_then(|r| r.parse().ok())
            .unwrap_or(30)
    } else {
        1
    };
    let scenarios = forkbench_trial::defaults::default_scenarios().expect("embedded scenarios");
    for (name, case) in [
        ("field-test", ""),
        ("bspline-table2", "1"),
        ("rack-pick", ""),
    ] {
        let scn = scenarios.iter().find(|s| s.name == name).expect("embedded");
        let case = scn.case(case).unwrap_or(&scn.cases[0]);
        let (mut ideal, mut real, mut ratio) = (Vec::new(), Vec::new(), Vec::new());
        for r in 0..rounds {
            let seed = 7 + r as u64 % 5;
            let time = |is_ideal: bool| {
                let t0 = std::time::Instant::now();
                std::hint::black_box(run_trial(scn, case, &options(seed, is_ideal)));
                t0.elapsed().as_secs_f64() * 1e3
            };
            let (a, b) = if r % 2 == 0 {
                let a = time(true);
                (a, time(false))
            } else {
                let b = time(false);
                (time(true), b)
            };
            ideal.push(a);
            real.push(b);
            ratio.push(b / a);
        }
        println!(
            "{name}: ideal {:.2} ms, realistic {:.2} ms, realistic / ideal {:.3} (medians of {rounds} interleaved rounds)",
            median(&mut ideal),
            median(&mut real),
            median(&mut ratio)
        );
    }
}
