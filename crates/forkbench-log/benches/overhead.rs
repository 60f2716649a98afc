//! Recording overhead as a ratio: off, MCAP, .rrd and both, interleaved trial by trial so
//! that drift in the machine's speed (large on shared VMs) hits every mode alike.

mod common;

use std::collections::BTreeMap;
use std::time::Instant;

use forkbench_log::{McapRecorder, RerunRecorder, RerunTarget};
use forkbench_trial::{NoRecorder, Recorder, Tee, run_trial_recorded};

const MODES: [&str; 4] = ["off", "mcap", "rrd", "rrd+mcap"];
const ROUNDS: usize = 60;

/// `OVERHEAD_MODES=mcap OVERHEAD_ROUNDS=3` runs only the named modes, a few rounds: for
/// counting instructions under `valgrind --tool=callgrind`, which, unlike wall or CPU
/// time, does not drift with the machine's load.
fn selected(mode: &str) -> bool {
    std::env::var("OVERHEAD_MODES").map_or(true, |m| m.split(',').any(|x| x == mode))
}

fn main() {
    let (scn, opts) = common::field_test();
    let case = &scn.cases[0];
    let dir = common::scratch_dir("overhead");
    let mut times_ms: [Vec<f64>; 4] = Default::default();
    let mut cpu_ms: [Vec<f64>; 4] = Default::default();
    let rounds = std::env::var("OVERHEAD_ROUNDS")
        .ok()
        .and_then(|r| r.parse().ok())
        .unwrap_or(ROUNDS);
    for round in 0..rounds {
        for ((mode, times), cpu) in MODES.iter().zip(times_ms.iter_mut()).zip(cpu_ms.iter_mut()) {
            if !selected(mode) {
                continue;
            }
            let (mcap, rrd) = (dir.join("t.mcap"), dir.join("t.rrd"));
            // Fresh files, as a real run writes them (no truncation cost in the timing).
            let _ = std::fs::remove_file(&mcap);
            let _ = std::fs::remove_file(&rrd);
            let (t0, c0) = (Instant::now(), process_cpu_ms());
            let mut m = mode
                .contains("mcap")
                .then(|| McapRecorder::create(&mcap, BTreeMap::new()).expect("opens"));
            let mut r = mode
                .contains("rrd")
                .then(|| RerunRecorder::new(&RerunTarget::File(rrd.clone())).expect("opens"));
            let mut sinks: Vec<&mut dyn Recorder> = Vec::new();
            if let Some(m) = m.as_mut() {
                sinks.push(m);
            }
            if let Some(r) = r.as_mut() {
                sinks.push(r);
            }
            let out = if sinks.is_empty() {
                run_trial_recorded(&scn, case, &opts, &mut NoRecorder)
            } else {
                run_trial_recorded(&scn, case, &opts, &mut Tee(sinks))
            };
            let t_run = t0.elapsed().as_secs_f64() * 1e3;
            if let Some(mut m) = m {
                m.finish().expect("finishes");
            }
            if let Some(mut r) = r {
                r.finish().expect("flushes");
            }
            // Dropping the sinks above joins their writer threads: part of the cost.
            times.push(t0.elapsed().as_secs_f64() * 1e3);
            cpu.push(process_cpu_ms() - c0);
            if std::env::var("OVERHEAD_SPLIT").is_ok() {
                eprintln!(
                    "{mode} run {t_run:.2} total {:.2}",
                    times.last().unwrap_or(&0.0)
                );
            }
            std::hint::black_box(out);
        }
        if round == 0 {
            // The first round warms caches and builds the blueprint once.
            times_ms.iter_mut().for_each(Vec::clear);
            cpu_ms.iter_mut().for_each(Vec::clear);
        }
    }
    let median = |v: &[f64]| {
        let mut v = v.to_vec();
        v.sort_by(f64::total_cmp);
        v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
    };
    let base = median(&times_ms[0]);
    println!(
        "recording overhead, field-test trial, {} interleaved rounds:",
        rounds - 1
    );
    let cpu_base = median(&cpu_ms[0]);
    for ((mode, times), cpu) in MODES.iter().zip(&times_ms).zip(&cpu_ms) {
        let (m, c) = (median(times), median(cpu));
        // Each round's time over the same round's plain trial: the machine's speed drifts
        // between rounds far more than within one, so this ratio is the steadier figure.
        let ratios: Vec<f64> = times.iter().zip(&times_ms[0]).map(|(t, b)| t / b).collect();
        println!(
            "  {mode:9} median {m:6.2} ms  {:.2}x the plain trial (per round: {:.2}x)   CPU (all threads) {c:6.2} ms  {:.2}x",
            m / base,
            median(&ratios),
            c / cpu_base
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// CPU time of the whole process, all threads (the writer threads' included, also after
/// they exit): the cost that does not depend on how busy the machine's other cores are.
fn process_cpu_ms() -> f64 {
    cpu_time::ProcessTime::now().as_duration().as_secs_f64() * 1e3
}
