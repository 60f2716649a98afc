//! `forkbench estimate` and `forkbench falsify` end to end: results and every trial written, the found failure recorded and replayable, bad input refused with the reason and nothing of others overwritten.

use crate::common::{forkbench, repo_root, s, text, tmp_in};

fn tails() -> String {
    repo_root()
        .join("examples/rare/field-test-tails.toml")
        .display()
        .to_string()
}

#[test]
fn falsify_records_the_failure_it_found_and_its_line_replays() {
    let out = tmp_in("forkbench-rare", "falsify");
    // An .rrd where rerun is built in (`--features rerun`), else the MCAP.
    let (flag, rrd) = match cfg!(feature = "rerun") {
        true => ("--rrd", tmp_in("forkbench-rare", "found.rrd")),
        false => ("--mcap", tmp_in("forkbench-rare", "found.mcap")),
    };
    let _ = std::fs::remove_dir_all(&out);
    let _ = std::fs::remove_file(&rrd);
    if !cfg!(feature = "rerun") {
        // Asked for an .rrd it cannot write, the campaign is refused before any trial.
        let o = forkbench(&["falsify", &tails(), "--out", s(&out), "--rrd", "x.rrd"]);
        assert_eq!(o.status.code(), Some(1), "{}", text(&o));
        assert!(text(&o).contains("--rrd needs rerun"), "{}", text(&o));
        assert!(!out.join("trials.jsonl").exists(), "no trial ran");
    }
    let o = forkbench(&[
        "falsify",
        &tails(),
        "--budget",
        "200",
        "--seed",
        "1",
        "--out",
        s(&out),
        flag,
        s(&rrd),
    ]);
    let t = text(&o);
    assert_eq!(o.status.code(), Some(3), "{t}");
    assert!(
        t.contains("most likely failure found") && t.contains("steering_time_constant_s"),
        "{t}"
    );
    assert!(rrd.exists(), "{t}");
    let found: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("falsify.json")).expect("json"))
            .expect("json");
    assert!(
        found["most_likely"]["outcome"]["event"]
            .as_bool()
            .expect("event")
    );
    let lines = std::fs::read_to_string(out.join("trials.jsonl")).expect("trials");
    assert_eq!(lines.lines().count(), 200);
    // The printed replay command's line repeats the failure exactly.
    let line = t
        .split("--line ")
        .nth(1)
        .and_then(|r| r.split_whitespace().next())
        .expect("a replay line");
    let r = forkbench(&[
        "replay",
        s(&out.join("trials.jsonl")),
        "--line",
        line,
        "--scenario",
        &tails(),
    ]);
    assert!(
        text(&r).contains("identical to the recorded outcome"),
        "{}",
        text(&r)
    );
}

#[test]
fn an_estimate_writes_its_result_and_refuses_what_it_cannot_weigh() {
    let out = tmp_in("forkbench-rare", "estimate");
    let _ = std::fs::remove_dir_all(&out);
    let o = forkbench(&[
        "estimate",
        &tails(),
        "--method",
        "mc",
        "--budget",
        "100",
        "--out",
        s(&out),
        "--json",
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let e: serde_json::Value = serde_json::from_slice(&o.stdout).expect("json");
    assert_eq!(e["trials"], 100);
    assert!(out.join("estimate.json").exists());
    // A directory holding someone else's file is refused, and the file kept.
    let theirs = tmp_in("forkbench-rare", "theirs");
    std::fs::create_dir_all(&theirs).expect("dir");
    std::fs::write(theirs.join("notes.txt"), "mine").expect("write");
    let o = forkbench(&["estimate", &tails(), "--budget", "100", "--out", s(&theirs)]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(text(&o).contains("notes.txt"), "{}", text(&o));
    assert_eq!(
        std::fs::read_to_string(theirs.join("notes.txt")).expect("kept"),
        "mine"
    );
    let field = repo_root().join("scenarios/field-test.toml");
    for (args, why) in [
        (
            vec!["estimate", s(&field), "--budget", "100"],
            "no [[uncertain]]",
        ),
        (
            vec!["estimate", &tails(), "--event", "wobble", "--budget", "100"],
            "wobble",
        ),
        (vec!["falsify", &tails(), "--budget", "10"], "budget"),
    ] {
        let mut a = args.clone();
        let dir = tmp_in("forkbench-rare", "refused");
        a.extend(["--out", s(&dir)]);
        let o = forkbench(&a);
        // 1 from forkbench, 2 from the argument parser (the budget's range).
        assert!(
            matches!(o.status.code(), Some(1 | 2)),
            "{args:?}: {}",
            text(&o)
        );
        assert!(text(&o).contains(why), "{args:?}: {}", text(&o));
    }
}

/// Subset simulation runs on the physics through the CLI: its levels are in the text and
/// the JSON, within the budget.
#[test]
fn subset_simulation_reports_its_levels() {
    let out = tmp_in("forkbench-rare", "subset");
    let _ = std::fs::remove_dir_all(&out);
    let args = [
        "estimate",
        &tails(),
        "--method",
        "subset",
        "--budget",
        "120",
    ];
    let o = forkbench(&[&args[..], &["--out", s(&out)]].concat());
    assert!(o.status.success(), "{}", text(&o));
    let said = String::from_utf8_lossy(&o.stdout);
    assert!(said.contains("method subset simulation: "), "{said}");
    assert!(said.contains(" levels (shares 0."), "{said}");
    let e: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("estimate.json")).expect("read"))
            .expect("json");
    assert_eq!(e["method"], "subset");
    assert!(e["trials"].as_u64().expect("trials") <= 120, "{e}");
    assert_eq!(e["levels"][0]["points"], 30, "{e}");
    // Its settings act: 40 trials a level, and the run's settings name them.
    let out = tmp_in("forkbench-rare", "subset-set");
    let _ = std::fs::remove_dir_all(&out);
    let set = ["--per-level", "40", "--level-fraction", "0.2", "--json"];
    let o = forkbench(&[&args[..], &set, &["--out", s(&out)]].concat());
    assert!(o.status.success(), "{}", text(&o));
    let e: serde_json::Value = serde_json::from_slice(&o.stdout).expect("json");
    assert_eq!(e["levels"][0]["points"], 40, "{e}");
    let run = std::fs::read_to_string(out.join("rare.json")).expect("rare.json");
    assert!(
        run.contains(r#""subset":{"level_fraction":0.2,"per_level":40}"#),
        "{run}"
    );
    // Refused for another method, and out of range, naming the setting.
    for (extra, why) in [
        (
            vec!["--method", "ce", "--per-level", "40"],
            "--method subset",
        ),
        (
            vec!["--method", "subset", "--level-fraction", "0.9"],
            "subset.level_fraction",
        ),
        (
            vec!["--method", "subset", "--per-level", "500"],
            "subset.per_level",
        ),
    ] {
        let dir = tmp_in("forkbench-rare", "subset-refused");
        let _ = std::fs::remove_dir_all(&dir);
        let a = ["estimate", &tails(), "--budget", "120"];
        let o = forkbench(&[&a[..], &extra, &["--out", s(&dir)]].concat());
        assert_eq!(o.status.code(), Some(1), "{extra:?}: {}", text(&o));
        assert!(text(&o).contains(why), "{extra:?}: {}", text(&o));
    }
}

/// A run stopped part-way resumes: the trials already in OUT are not run again (a line
/// torn by the kill is dropped), and the result is the one an unbroken run gives; a run
/// with other settings is refused, naming them, until --force-new.
#[test]
fn a_stopped_run_resumes_and_another_run_is_refused() {
    let out = tmp_in("forkbench-rare", "resume");
    let _ = std::fs::remove_dir_all(&out);
    let t = tails();
    let run = |seed: &str, extra: &[&str]| {
        let mut a = vec![
            "falsify",
            &t,
            "--budget",
            "100",
            "--seed",
            seed,
            "--out",
            s(&out),
        ];
        a.extend(extra);
        forkbench(&a)
    };
    let o = run("1", &[]);
    assert_eq!(o.status.code(), Some(3), "{}", text(&o));
    let whole = std::fs::read(out.join("falsify.json")).expect("result");
    let trials = std::fs::read_to_string(out.join("trials.jsonl")).expect("trials");
    assert_eq!(trials.lines().count(), 100);
    // As a kill leaves it: 40 trials, a torn 41st, no result.
    let kept: Vec<&str> = trials.lines().collect();
    let torn = format!("{}\n{}", kept[..40].join("\n"), &kept[40][..80]);
    std::fs::write(out.join("trials.jsonl"), torn).expect("write");
    std::fs::remove_file(out.join("falsify.json")).expect("remove");
    let o = run("1", &[]);
    assert_eq!(o.status.code(), Some(3), "{}", text(&o));
    assert!(text(&o).contains("resuming: 40 trials"), "{}", text(&o));
    assert_eq!(
        std::fs::read(out.join("falsify.json")).expect("result"),
        whole
    );
    let again = std::fs::read_to_string(out.join("trials.jsonl")).expect("trials");
    assert_eq!(again.lines().count(), 100);
    // Another seed: refused, nothing changed; then started over.
    let o = run("2", &[]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(text(&o).contains("seed: 1 → 2"), "{}", text(&o));
    assert_eq!(
        std::fs::read(out.join("falsify.json")).expect("kept"),
        whole
    );
    let o = run("2", &["--force-new"]);
    assert!(matches!(o.status.code(), Some(0 | 3)), "{}", text(&o));
    assert!(!text(&o).contains("resuming"), "{}", text(&o));
}
