//! Outputs that never destroy: an output naming one of the command's inputs, a symbolic link, a FIFO or a device is refused and left as it was; `-` prints.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use crate::common::{forkbench, s};

fn tmp(name: &str) -> PathBuf {
    crate::common::tmp_in("forkbench-outputs", name)
}

fn err(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).to_string()
}

#[test]
fn outputs_refuse_inputs_links_and_fifos_and_dash_prints() {
    let dir = tmp("batch");
    let scn = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/field-test.toml");
    let run = forkbench(&[
        "batch",
        s(&scn),
        "--trials",
        "2",
        "--record",
        "none",
        "--force-new",
        "--out",
        s(&dir),
    ]);
    assert!(matches!(run.status.code(), Some(0 | 3)), "{}", err(&run));
    let trials = dir.join("trials.jsonl");
    let before = std::fs::read(&trials).expect("trials");
    // The output is one of the inputs: refused, the input intact.
    let out = forkbench(&["baseline", s(&dir), "--out", s(&trials)]);
    assert_eq!(out.status.code(), Some(1), "{}", err(&out));
    assert!(
        err(&out).contains("which this command reads"),
        "{}",
        err(&out)
    );
    assert_eq!(std::fs::read(&trials).expect("trials"), before);
    // `-` prints the baseline; the note goes to standard error.
    let out = forkbench(&["baseline", s(&dir), "--out", "-"]);
    assert!(out.status.success(), "{}", err(&out));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("the baseline as JSON");
    assert_eq!(v["rows"][0]["trials"], 2, "{v}");
    // A symbolic link and a FIFO are refused and left standing.
    let target = tmp("target.json");
    std::fs::write(&target, "keep").expect("target");
    let link = tmp("link.json");
    let _ = std::fs::remove_file(&link);
    std::os::unix::fs::symlink(&target, &link).expect("symlink");
    let fifo = tmp("fifo");
    let _ = std::fs::remove_file(&fifo);
    assert!(
        Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .is_ok_and(|s| s.success())
    );
    for (path, kind) in [(&link, "a symbolic link"), (&fifo, "a FIFO")] {
        let out = forkbench(&["baseline", s(&dir), "--out", s(path)]);
        assert_eq!(out.status.code(), Some(1), "{}", err(&out));
        assert!(err(&out).contains(kind), "{}", err(&out));
        let kept = std::fs::symlink_metadata(path)
            .expect("still there")
            .file_type();
        assert!(!kept.is_file(), "{} replaced by a file", path.display());
    }
    assert_eq!(std::fs::read_to_string(&target).expect("target"), "keep");
    // The gate's JUnit file may not be its baseline.
    let base = tmp("base.json");
    assert!(
        forkbench(&["baseline", s(&dir), "--out", s(&base)])
            .status
            .success()
    );
    let kept = std::fs::read(&base).expect("baseline");
    let out = forkbench(&[
        "regress",
        "--baseline",
        s(&base),
        s(&dir),
        "--junit",
        s(&base),
    ]);
    assert_eq!(out.status.code(), Some(1), "{}", err(&out));
    assert_eq!(std::fs::read(&base).expect("baseline"), kept);
    let _ = std::fs::remove_dir_all(tmp(""));
}
