//! `--shard auto` under a Kubernetes Indexed Job (JOB_COMPLETION_INDEX set by the test):
//! shards write OUT/shard-I-of-N/, `merge OUT` equals one unsharded run, and missing or
//! contradictory scheduler variables are clear errors.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const SCHEDULER_VARS: [&str; 7] = [
    "SLURM_ARRAY_TASK_ID",
    "SLURM_ARRAY_TASK_MIN",
    "SLURM_ARRAY_TASK_MAX",
    "SLURM_ARRAY_TASK_STEP",
    "SLURM_ARRAY_TASK_COUNT",
    "JOB_COMPLETION_INDEX",
    "FORKBENCH_SHARDS",
];

fn forkbench(args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_forkbench"));
    for v in SCHEDULER_VARS {
        c.env_remove(v);
    }
    c.args(args)
        .envs(env.iter().copied())
        .output()
        .expect("binary runs")
}

fn ok(out: &Output) {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("forkbench-shards-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// Trial records without wall times, sorted.
fn records(dir: &Path) -> Vec<serde_json::Value> {
    let text = std::fs::read_to_string(dir.join("trials.jsonl")).expect("trials");
    let mut v: Vec<serde_json::Value> = text
        .lines()
        .map(|l| {
            let mut r: serde_json::Value = serde_json::from_str(l).expect("json");
            r.as_object_mut().expect("object").remove("wall_time_ms");
            // A mission's legs carry their planning wall time.
            for leg in r["legs"].as_array_mut().into_iter().flatten() {
                leg.as_object_mut().expect("leg").remove("planning_time_s");
            }
            r
        })
        .collect();
    v.sort_by_key(|r| r.to_string());
    v
}

const ARGS: [&str; 6] = ["--trials", "3", "--seed", "9", "--record", "none"];

#[test]
fn kubernetes_indexed_job_shards_merge_into_the_unsharded_run() {
    let (single, out) = (tmp("single"), tmp("k8s"));
    let s = single.to_str().expect("utf-8");
    let o = out.to_str().expect("utf-8");
    ok(&forkbench(
        &[&["batch", "--out", s][..], &ARGS].concat(),
        &[],
    ));
    for i in ["0", "1", "2"] {
        let args = [
            &["batch", "--shard", "auto", "--shard-count", "3", "--out", o][..],
            &ARGS,
        ]
        .concat();
        ok(&forkbench(&args, &[("JOB_COMPLETION_INDEX", i)]));
        assert!(out.join(format!("shard-{i}-of-3/trials.jsonl")).is_file());
    }
    let merged = out.join("merged");
    ok(&forkbench(
        &["merge", o, "--out", merged.to_str().expect("utf-8")],
        &[],
    ));
    assert_eq!(records(&merged), records(&single));
    // Merging again (with merged/ now inside OUT) still reads only the shards.
    ok(&forkbench(
        &[
            "merge",
            o,
            "--out",
            out.join("again").to_str().expect("utf-8"),
        ],
        &[],
    ));
    // A missing shard is named.
    std::fs::remove_dir_all(out.join("shard-1-of-3")).expect("rm");
    let e = forkbench(
        &["merge", o, "--out", out.join("m2").to_str().expect("utf-8")],
        &[],
    );
    assert_eq!(e.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&e.stderr).contains("shards 1 of 3 are missing"));
}

#[test]
fn scheduler_variables_that_are_missing_or_disagree_are_errors() {
    let o = tmp("errors");
    let o = o.to_str().expect("utf-8");
    let run = |extra: &[&str], env: &[(&str, &str)]| {
        let out = forkbench(&[&["batch", "--out", o][..], &ARGS, extra].concat(), env);
        assert_eq!(out.status.code(), Some(1), "{extra:?} {env:?}");
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    assert!(run(&["--shard", "auto"], &[]).contains("no scheduler shard in the environment"));
    assert!(run(&["--shard", "auto"], &[("JOB_COMPLETION_INDEX", "1")]).contains("shard_count"));
    let both = [
        ("JOB_COMPLETION_INDEX", "1"),
        ("SLURM_ARRAY_TASK_ID", "2"),
        ("SLURM_ARRAY_TASK_COUNT", "4"),
    ];
    assert!(
        run(&["--shard", "auto", "--shard-count", "4"], &both).contains("Slurm says shard 2/4")
    );
    assert!(run(&["--shard-count", "4"], &[]).contains("--shard-count goes with --shard auto"));
    // Slurm without a count: SLURM_ARRAY_TASK_COUNT, arrays not starting at 0.
    let slurm = [
        ("SLURM_ARRAY_TASK_ID", "5"),
        ("SLURM_ARRAY_TASK_MIN", "4"),
        ("SLURM_ARRAY_TASK_MAX", "5"),
        ("SLURM_ARRAY_TASK_COUNT", "2"),
    ];
    let out = forkbench(
        &[&["batch", "--out", o, "--shard", "auto"][..], &ARGS].concat(),
        &slurm,
    );
    ok(&out);
    assert!(Path::new(o).join("shard-1-of-2/manifest.json").is_file());
}

#[test]
fn shards_stating_success_runs_differently_are_not_merged_under_one() {
    let out = tmp("confidence");
    let field = crate::common::repo_root().join("scenarios/field-test.toml");
    let shard = |i: &str, confidence: &str| {
        let o = forkbench(
            &[
                "batch",
                crate::common::s(&field),
                "--out",
                out.to_str().expect("utf-8"),
                "--shard",
                i,
                "--success-confidence",
                confidence,
            ]
            .iter()
            .chain(&ARGS)
            .copied()
            .collect::<Vec<_>>(),
            &[],
        );
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    };
    shard("0/2", "0.95");
    shard("1/2", "0.9");
    let merged = out.join("merged");
    let o = forkbench(
        &[
            "merge",
            out.to_str().expect("utf-8"),
            "--out",
            merged.to_str().expect("utf-8"),
        ],
        &[],
    );
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(
        e.contains("confidence 0.95")
            && e.contains("confidence 0.9 ")
            && e.contains("--success-confidence"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&out);
}
