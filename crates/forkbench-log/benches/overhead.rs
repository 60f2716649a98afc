//! Recording overhead as a ratio: off, MCAP, .rrd and both, interleaved trial by trial so
//! that drift in the machine's speed (large on shared VMs) hits every mode alike.

mod common;

use std::collections::BTreeMap;
use std::time::Instant;

use forkbench_log::{McapRecorder, RerunRecorder, RerunTarget};
use forkbench_trial::{NoRecorder, Recorder, Tee, run_trial_recorded};

const MODES: [&str; 4] = ["off", "mcap", "rrd", "rrd+mcap"];
const ROUNDS: usize = 60;

fn main() {
    let (scn, opts) = common::field_test();
    let case = &scn.cases[0];
    let dir = common::scratch_dir("overhead");
    let mut times_ms: [Vec<f64>; 4] = Default::default();
    for round in 0..ROUNDS {
        for (mode, times) in MODES.iter().zip(times_ms.iter_mut()) {
            let (mcap, rrd) = (dir.join("t.mcap"), dir.join("t.rrd"));
            // Fresh files, as a real run writes them (no truncation cost in the timing).
            let _ = std::fs::remove_file(&mcap);
            let _ = std::fs::remove_file(&rrd);
            let t0 = Instant::now();
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
            if let Some(mut m) = m {
                m.finish().expect("finishes");
            }
            if let Some(mut r) = r {
                r.finish().expect("flushes");
            }
            // Dropping the sinks above joins their writer threads: part of the cost.
            times.push(t0.elapsed().as_secs_f64() * 1e3);
            std::hint::black_box(out);
        }
        if round == 0 {
            // The first round warms caches and builds the blueprint once.
            times_ms.iter_mut().for_each(Vec::clear);
        }
    }
    let median = |v: &[f64]| {
        let mut v = v.to_vec();
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let base = median(&times_ms[0]);
    println!(
        "recording overhead, field-test trial, {} interleaved rounds:",
        ROUNDS - 1
    );
    for (mode, times) in MODES.iter().zip(&times_ms) {
        let m = median(times);
        println!(
            "  {mode:9} median {m:6.2} ms  {:.2}x the plain trial",
            m / base
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
