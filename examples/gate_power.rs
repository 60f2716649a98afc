//! How many trials the regression gate needs to see a real degradation, paired on common
//! random numbers against unpaired: a steering actuator 16× too slow (field test) and a
//! tracker that believes the truck 2 cm to the left of where it is (rack pick).
//!
//! `cargo run --release -p forkbench-batch --example gate_power` prints, for doubling
//! trial counts, the paired p (McNemar, same batch seed before and after) and the unpaired
//! p (two-proportion z-test, baseline run with another batch seed, as a gate without
//! per-trial results compares).

use std::path::{Path, PathBuf};
use std::sync::Arc;

use forkbench_batch::stats::{
    drop_p_value, mcnemar_drop_p, paired_power, trials_needed, unpaired_power,
};
use forkbench_batch::{self as batch, BatchSpec, Summary, TrialRecord};
use forkbench_core::{ForkliftSpec, Path as TrackPath};
use forkbench_track::{Command, PurePursuit, Tracker, TrackerInput};
use forkbench_trial::{Registry, Scenario};

/// Pure pursuit fed a pose `.1` metres left of the measured one.
struct Offset(PurePursuit, f64);

impl Tracker for Offset {
    fn name(&self) -> &str {
        Tracker::name(&self.0)
    }
    fn reset(&mut self, path: &TrackPath, truck: &ForkliftSpec) {
        Tracker::reset(&mut self.0, path, truck);
    }
    fn command(&mut self, input: &TrackerInput) -> Command {
        let mut i = *input;
        let h = i.pose.heading_rad;
        i.pose.x_m -= self.1 * h.sin();
        i.pose.y_m += self.1 * h.cos();
        Tracker::command(&mut self.0, &i)
    }
}

fn file(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenarios")
        .join(name)
}

fn run(s: Scenario, trials: u64, seed: u64) -> (Summary, Vec<TrialRecord>) {
    let dir = std::env::temp_dir().join(format!("forkbench-gate-power-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let spec = BatchSpec {
        scenarios: vec![s],
        planners: vec![],
        trackers: vec![],
        trials,
        seed,
        shard: (0, 1),
        overrides: Default::default(),
        replan: None,
        compare_replanning: false,
        force_new: false,
        success_run: Default::default(),
        profile: false,
    };
    let summary = batch::run_batch(&spec, &dir, 2, &|_| {}).expect("batch runs");
    let mut records = batch::read_records(&dir.join("trials.jsonl")).expect("records");
    records.sort_by_key(TrialRecord::key);
    let _ = std::fs::remove_dir_all(&dir);
    (summary, records)
}

fn study(title: &str, good: &Scenario, bad: &Scenario, counts: &[u64]) {
    println!(
        "\n{title}\n\n| trials | before | after | broke / fixed | p paired | p unpaired |\n|---|---|---|---|---|---|"
    );
    let cases = good.cases.len() as u64;
    let mut last = (0, 0.0, 0.0, 0.0);
    for &per_case in counts {
        let n = per_case * cases;
        let (s0, r0) = run(good.clone(), per_case, 1);
        let (s1, r1) = run(bad.clone(), per_case, 1);
        let (u0, _) = run(good.clone(), per_case, 2);
        let broke = r0
            .iter()
            .zip(&r1)
            .filter(|(a, b)| a.outcome.success && !b.outcome.success)
            .count() as u64;
        let fixed = r0
            .iter()
            .zip(&r1)
            .filter(|(a, b)| !a.outcome.success && b.outcome.success)
            .count() as u64;
        let (k0, k1, ku) = (s0.successes, s1.successes, u0.successes);
        println!(
            "| {n} | {:.1} % | {:.1} % | {broke} / {fixed} | {:.2e} | {:.2e} |",
            100.0 * k0 as f64 / n as f64,
            100.0 * k1 as f64 / n as f64,
            mcnemar_drop_p(broke, fixed),
            drop_p_value(ku, n, k1, n)
        );
        last = (
            n,
            k0 as f64 / n as f64,
            k1 as f64 / n as f64,
            (broke + fixed) as f64 / n as f64,
        );
    }
    let (n, p0, p1, psi) = last;
    let d = p0 - p1;
    if d > 0.0 {
        let paired = trials_needed(10_000_000, |m| paired_power(m, d, psi, 0.05));
        let unpaired = trials_needed(10_000_000, |m| unpaired_power(p0, m, m, d, 0.05));
        println!(
            "\nFrom the {n}-trial run (drop {:.1} pp, discordance {:.1} %): trials for 80 % power \
             at one-sided α 0.05, paired {paired:?}, unpaired {unpaired:?} per side.",
            100.0 * d,
            100.0 * psi
        );
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let field = Scenario::load(&file("field-test.toml")).expect("loads");
    if args.is_empty() {
        let mut slow = field.clone();
        slow.truck.max_steer_rate_radps /= 16.0;
        study(
            "Steering actuator 16× too slow (field test)",
            &field,
            &slow,
            &[10, 20, 40, 80, 160, 320],
        );
    }
    let name = args.first().map_or("bspline-table2.toml", String::as_str);
    let offset_m: f64 = args
        .get(1)
        .map_or(0.02, |a| a.parse().expect("offset in metres"));
    let good = Scenario::load(&file(name)).expect("loads");
    let registry = Registry::builtin().with_tracker("pure_pursuit", move |s, _| {
        Ok(Box::new(Offset(PurePursuit::from_settings(s)?, offset_m)))
    });
    let bad = Scenario::load_with(&file(name), Arc::new(registry)).expect("loads");
    let counts: Vec<u64> = if good.cases.len() > 1 {
        vec![1, 2, 4, 8, 16, 32]
    } else {
        vec![10, 20, 40, 80, 160, 320]
    };
    study(
        &format!("Tracker {:.0} cm off ({name})", offset_m * 100.0),
        &good,
        &bad,
        &counts,
    );
}
