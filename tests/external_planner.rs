//! The Python planner of examples/planners/ runs in `trial` and `batch`, is recorded like
//! the built-in planners, and sits beside them in summaries, baselines and `regress`.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn forkbench(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_forkbench"))
        .args(args)
        .current_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join("../.."))
        .output()
        .expect("binary runs")
}

fn ok(out: &Output) -> String {
    assert!(
        out.status.success(),
        "status {:?}\nstdout: {}\nstderr: {}",
        out.status,
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("forkbench-ext-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir.join(name)
}

const SCENARIO: &str = "examples/planners/quintic-field-test.toml";

#[test]
fn the_python_planner_runs_in_a_trial_and_is_recorded() {
    let (rrd, mcap) = (tmp("quintic.rrd"), tmp("quintic.mcap"));
    let mut args = vec![
        "trial",
        SCENARIO,
        "--no-noise",
        "--json",
        "--mcap",
        mcap.to_str().expect("utf-8"),
        "--force",
    ];
    // The .rrd too where rerun is built in (`--features rerun`).
    let mut files = vec![&mcap];
    if cfg!(feature = "rerun") {
        args.extend(["--rrd", rrd.to_str().expect("utf-8")]);
        files.push(&rrd);
    }
    let out = forkbench(&args);
    let v: serde_json::Value = serde_json::from_str(&ok(&out)).expect("json");
    assert_eq!(v["planner"], "quintic");
    assert_eq!(v["success"], true, "{v}");
    for f in files {
        let len = std::fs::metadata(f).expect("written").len();
        assert!(len > 10_000, "{} is {len} bytes", f.display());
    }
    // The MCAP's metadata names the external planner.
    let bytes = std::fs::read(&mcap).expect("read");
    assert!(bytes.windows(7).any(|w| w == b"quintic"));
}

#[test]
fn the_python_planner_sits_beside_the_built_in_ones_in_batch_and_regress() {
    let dir = tmp("batch");
    let d = dir.to_str().expect("utf-8");
    ok(&forkbench(&[
        "batch",
        SCENARIO,
        "--planner",
        "quintic",
        "bspline",
        "spiral",
        "--tracker",
        "pure_pursuit",
        "regulated_pure_pursuit",
        "--trials",
        "6",
        "--record",
        "none",
        "--out",
        d,
        "--force-new",
    ]));
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("summary.json")).expect("summary"))
            .expect("json");
    let planners: Vec<&str> = summary["rows"]
        .as_array()
        .expect("rows")
        .iter()
        .map(|r| r["planner"].as_str().expect("planner"))
        .collect();
    // Rows are scenario × planner × tracker.
    assert_eq!(
        planners,
        [
            "bspline", "bspline", "quintic", "quintic", "spiral", "spiral"
        ]
    );
    let base = tmp("baseline.json");
    let b = base.to_str().expect("utf-8");
    ok(&forkbench(&["baseline", d, "--out", b]));
    let text = ok(&forkbench(&["regress", "--baseline", b, d]));
    for tracker in ["pure_pursuit", "regulated_pure_pursuit"] {
        let row = format!("| quintic | {tracker} |");
        assert!(
            text.lines()
                .any(|l| l.contains(&row) && l.contains("| ok |")),
            "{text}"
        );
    }
}
