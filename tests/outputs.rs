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

/// A trial's recordings (`--rrd`, `--mcap`, `--ros2`, `--actuator-log`): a run refused for
/// any of them touches none, `--force` or not; no recording replaces an input of the run
/// (scenario, truck file, components) or writes through a link; `-` is refused (it would
/// mix a recording into the report); a recording appears at its path whole, with no
/// temporary file left beside it.
#[test]
fn recordings_are_checked_before_anything_is_touched() {
    let dir = crate::common::tmp_in("forkbench-recordings", "run");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("dir");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let scn = dir.join("s.toml");
    std::fs::copy(root.join("scenarios/field-test.toml"), &scn).expect("scenario");
    let truck = dir.join("t.toml");
    std::fs::copy(root.join("trucks/hangcha-a30.toml"), &truck).expect("truck");
    let trial = |extra: &[&str]| {
        let mut args = vec!["trial", s(&scn), "--no-noise", "--force"];
        args.extend_from_slice(extra);
        Command::new(env!("CARGO_BIN_EXE_forkbench"))
            .args(&args)
            .current_dir(&dir)
            .output()
            .expect("runs")
    };
    let old = dir.join("old.mcap");
    std::fs::write(&old, "keep").expect("old");
    let kept = |p: &Path, what: &[u8]| {
        assert_eq!(
            std::fs::read(p).expect("still there"),
            what,
            "{}",
            p.display()
        )
    };
    // One bad target refuses the run before any other is opened.
    let scenario_text = std::fs::read(&scn).expect("scenario");
    let truck_text = std::fs::read(&truck).expect("truck");
    for (flags, says) in [
        (
            vec!["--mcap", s(&old), "--actuator-log", "nodir/x.csv"],
            "does not exist",
        ),
        (
            vec!["--mcap", s(&old), "--ros2", s(&scn)],
            "which this run reads",
        ),
        (
            vec!["--rrd", s(&scn)],
            crate::common::rrd_says("which this run reads"),
        ),
        (vec!["--actuator-log", s(&scn)], "which this run reads"),
        (
            vec!["--truck", s(&truck), "--mcap", s(&truck)],
            "which this run reads",
        ),
        (
            vec!["--mcap", s(&old), "--actuator-log", "-"],
            "standard output",
        ),
    ] {
        let out = trial(&flags);
        assert_eq!(out.status.code(), Some(1), "{flags:?}: {}", err(&out));
        assert!(err(&out).contains(says), "{flags:?}: {}", err(&out));
        kept(&old, b"keep");
        kept(&scn, &scenario_text);
        kept(&truck, &truck_text);
    }
    assert!(!dir.join("-").exists(), "`-` made a file");
    // A link is refused, forced or not, and neither it nor its target changes.
    let link = dir.join("link.mcap");
    std::os::unix::fs::symlink(&old, &link).expect("symlink");
    for flag in ["--mcap", "--ros2", "--rrd", "--actuator-log"] {
        let out = trial(&[flag, s(&link)]);
        let says = match flag {
            "--rrd" => crate::common::rrd_says("symbolic link"),
            _ => "symbolic link",
        };
        assert_eq!(out.status.code(), Some(1), "{flag}: {}", err(&out));
        assert!(err(&out).contains(says), "{flag}: {}", err(&out));
        assert!(
            std::fs::symlink_metadata(&link)
                .expect("link")
                .file_type()
                .is_symlink()
        );
        kept(&old, b"keep");
    }
    // Forced, a good run replaces the file whole and leaves nothing else behind.
    let out = trial(&["--mcap", s(&old), "--actuator-log", "a.csv"]);
    assert!(matches!(out.status.code(), Some(0 | 3)), "{}", err(&out));
    assert!(
        std::fs::read(&old)
            .expect("mcap")
            .starts_with(b"\x89MCAP0\r\n")
    );
    assert_eq!(
        crate::common::names_in(&dir),
        ["a.csv", "link.mcap", "old.mcap", "s.toml", "t.toml"]
    );
    let _ = std::fs::remove_dir_all(&dir);
}
