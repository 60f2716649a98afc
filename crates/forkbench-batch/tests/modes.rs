//! Replanning against planning once, where people look: the summary's paired broke/fixed
//! counts per row equal a count made by hand from the records, and `compare` pairs the
//! two modes as it pairs planners.

use forkbench_batch::{self as batch, BatchSpec, CompareOptions};
use forkbench_trial::defaults;

/// A batch of `trials` per case of `scenario`, both modes when `both`.
fn spec(scenario: &str, trials: u64, both: bool, force_new: bool) -> BatchSpec {
    BatchSpec {
        scenarios: vec![defaults::embedded_scenario(scenario).expect("embedded")],
        planners: vec![],
        trackers: vec![],
        trials,
        seed: 1,
        shard: (0, 1),
        overrides: Default::default(),
        replan: None,
        compare_replanning: both,
        force_new,
        success_run: Default::default(),
        profile: false,
    }
}

#[test]
fn the_summary_and_compare_pair_the_two_modes() {
    let dir = std::env::temp_dir().join(format!("forkbench-modes-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let spec = spec("bspline-table2", 3, true, true);
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

/// `force_new` never deletes what forkbench did not write: a directory without a
/// manifest is refused untouched (and a new batch does not write into it either), and in a batch's own directory a user's file under
/// `recordings/` survives while the batch's recordings go.
#[test]
fn force_new_deletes_only_what_a_batch_wrote() {
    let dir = std::env::temp_dir().join(format!("forkbench-force-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let mine = dir.join("recordings/mine");
    std::fs::create_dir_all(&mine).expect("mkdir");
    std::fs::write(mine.join("thesis.txt"), "x").expect("write");
    let spec = spec("field-test", 1, false, true);
    let e = batch::run_batch(&spec, &dir, 1, &|_| {}).expect_err("refused");
    assert!(e.to_string().contains("no manifest.json"), "{e}");
    // The error says what failed by its type: the directory, not a setting.
    assert!(matches!(e, batch::BatchError::Directory(_)), "{e:?}");
    assert!(
        mine.join("thesis.txt").is_file(),
        "the user's file was deleted"
    );
    // Nor does a new batch write into it (`out="/"` would have written into `/`).
    let spec = BatchSpec {
        force_new: false,
        success_run: Default::default(),
        ..spec
    };
    let e = batch::run_batch(&spec, &dir, 1, &|_| {}).expect_err("refused");
    assert!(e.to_string().contains("is not empty (recordings)"), "{e}");
    assert!(matches!(e, batch::BatchError::Directory(_)), "{e:?}");
    let zero = BatchSpec {
        trials: 0,
        ..spec.clone()
    };
    let e = batch::run_batch(&zero, &dir, 1, &|_| {}).expect_err("refused");
    assert!(matches!(e, batch::BatchError::Setting(_)), "{e:?}");
    assert!(!dir.join("manifest.json").exists() && !dir.join("trials.jsonl").exists());
    // A batch's own directory: its recording goes, the user's file stays.
    let ours = dir.join("batch");
    batch::run_batch(&spec, &ours, 1, &|_| {}).expect("batch");
    std::fs::create_dir_all(ours.join("recordings")).expect("mkdir");
    let first = &batch::read_records(&ours.join("trials.jsonl")).expect("records")[0];
    let recording = format!("recordings/{}.mcap", first.outcome.recording_stem(false));
    std::fs::write(ours.join(&recording), "m").expect("write");
    std::fs::write(ours.join("recordings/t.mcap"), "yours").expect("write");
    std::fs::write(ours.join("recordings/notes.txt"), "n").expect("write");
    let spec = BatchSpec {
        force_new: true,
        success_run: Default::default(),
        ..spec
    };
    batch::run_batch(&spec, &ours, 1, &|_| {}).expect("starts over");
    assert!(!ours.join(&recording).exists());
    assert!(
        ours.join("recordings/t.mcap").is_file(),
        "a recording not named for a trial"
    );
    assert!(ours.join("recordings/notes.txt").is_file());
    let _ = std::fs::remove_dir_all(dir);
}

/// Records are read whole, so their file's size is capped: a `trials.jsonl` past
/// `MAX_RECORDS_BYTES` (here a sparse file) is refused at once, naming it and the cap.
#[test]
fn a_records_file_past_the_byte_cap_is_refused_before_reading() {
    let dir = std::env::temp_dir().join(format!("forkbench-cap-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let spec = spec("field-test", 1, false, false);
    batch::run_batch(&spec, &dir, 1, &|_| {}).expect("batch");
    let f = std::fs::OpenOptions::new()
        .write(true)
        .open(dir.join("trials.jsonl"))
        .expect("open");
    f.set_len(batch::MAX_RECORDS_BYTES + 1).expect("sparse");
    let t0 = std::time::Instant::now();
    let e = batch::load_results(&dir).expect_err("refused");
    assert!(matches!(e, batch::BatchError::Content(_)), "{e:?}");
    let e = e.to_string();
    assert!(
        e.contains("trials.jsonl") && e.contains("read at once"),
        "{e}"
    );
    assert!(t0.elapsed().as_secs() < 5);
    let _ = std::fs::remove_dir_all(dir);
}

/// The gate never pairs silently around trials whose seed differs from the baseline's at
/// the same key: it says so and compares unpaired.
#[test]
fn swapped_seeds_make_the_gate_unpaired_with_the_reason_named() {
    let dir = std::env::temp_dir().join(format!("forkbench-seeds-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let spec = spec("field-test", 4, false, false);
    let summary = batch::run_batch(&spec, &dir, 1, &|_| {}).expect("batch");
    let mut records = batch::read_records(&dir.join("trials.jsonl")).expect("records");
    let manifest = batch::Manifest::read(&dir)
        .expect("read")
        .expect("manifest");
    let summary = batch::Summary {
        provenance: summary.provenance.clone(),
        ..batch::summarize(&records)
    };
    let base = batch::Baseline::from_results(&summary, &records, "t".into());
    let o = batch::GateOptions::default();
    let paired = batch::regress(&base, &summary, &records, Some(&manifest), &o);
    assert!(
        matches!(paired.pairing, batch::Pairing::Paired { pairs: 4 }),
        "{:?}",
        paired.pairing
    );
    let (a, b) = (records[0].outcome.seed, records[1].outcome.seed);
    records[0].outcome.seed = b;
    records[1].outcome.seed = a;
    let report = batch::regress(&base, &summary, &records, Some(&manifest), &o);
    match &report.pairing {
        batch::Pairing::Unpaired { reason } => {
            assert!(
                reason.contains("2 trials share a key with the baseline but not its seed"),
                "{reason}"
            )
        }
        p => panic!("paired despite swapped seeds: {p:?}"),
    }
    let _ = std::fs::remove_dir_all(dir);
}
