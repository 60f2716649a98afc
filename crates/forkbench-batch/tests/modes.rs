//! Replanning against planning once, where people look: the summary's paired broke/fixed
//! counts per row equal a count made by hand from the records, and `compare` pairs the
//! two modes as it pairs planners.

use forkbench_batch::{self as batch, BatchSpec, CompareOptions};
use forkbench_trial::defaults;

#[test]
fn the_summary_and_compare_pair_the_two_modes() {
    let dir = std::env::temp_dir().join(format!("forkbench-modes-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let spec = BatchSpec {
        scenarios: vec![defaults::embedded_scenario("bspline-table2").expect("embedded")],
        planners: vec![],
        trackers: vec![],
        trials: 3,
        seed: 1,
        shard: (0, 1),
        overrides: Default::default(),
        replan: None,
        compare_replanning: true,
        force_new: true,
    };
    let summary = batch::run_batch(&spec, &dir, 2, &|_| {}).expect("batch");
    let records = batch::read_records(&dir.join("trials.jsonl")).expect("records");
    let (mut broke, mut fixed) = (0, 0);
    for once in records.iter().filter(|r| r.replan == Some(false)) {
        let again = records
            .iter()
            .find(|r| {
                r.replan == Some(true)
                    && r.trial == once.trial
                    && r.outcome.case == once.outcome.case
            })
            .expect("partner");
        broke += u64::from(once.outcome.success && !again.outcome.success);
        fixed += u64::from(again.outcome.success && !once.outcome.success);
    }
    assert!(broke + fixed > 0, "the modes should differ somewhere");
    assert_eq!(summary.replanning.len(), 1);
    let row = &summary.replanning[0];
    assert_eq!((row.pairs, row.broke, row.fixed), (54, broke, fixed));
    assert!(summary.markdown().contains("replanning broke"));
    let numbered: Vec<_> = records
        .into_iter()
        .enumerate()
        .map(|(i, r)| (i + 1, r))
        .collect();
    let o = CompareOptions {
        alpha: 0.05,
        correction: batch::stats::Correction::Holm,
    };
    let c = batch::compare(&numbered, "plan_once", "replan", &o).expect("compares modes");
    assert_eq!(c.kind, "mode");
    assert_eq!((c.rows[0].a_only, c.rows[0].b_only), (broke, fixed));
    assert_eq!(c.discordant.len() as u64, broke + fixed);
    let _ = std::fs::remove_dir_all(dir);
}
