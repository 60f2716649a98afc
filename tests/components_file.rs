//! External components defined once: a components file names a tracker usable with `--tracker` on any scenario (and one beside a scenario comes with it), and a batch's manifest fingerprints its script, so a resume after an edit is refused, naming the file.

use std::path::{Path, PathBuf};

use crate::common::{forkbench, repo_root, s, text, tmp_in};

fn tmp(name: &str) -> PathBuf {
    tmp_in("forkbench-components", name)
}

/// A folder holding stanley.py and a components file defining it as `stan`.
fn components(folder: &str) -> (PathBuf, PathBuf) {
    let dir = tmp(folder);
    std::fs::create_dir_all(&dir).expect("dir");
    let script = dir.join("stanley.py");
    std::fs::copy(repo_root().join("examples/trackers/stanley.py"), &script).expect("copy");
    let file = dir.join("components.toml");
    std::fs::write(
        &file,
        "[[tracker]]\nname = \"stan\"\nkind = \"external\"\ncommand = [\"python3\", \"stanley.py\"]\ntimeout_s = 5.0\n",
    )
    .expect("components");
    (file, script)
}

/// The field test batched with `stan` from the components `file` into `out`.
fn stan_batch(file: &Path, out: &Path, trials: &str, extra: &[&str]) -> std::process::Output {
    let field = repo_root().join("scenarios/field-test.toml");
    let mut args = vec![
        "batch",
        s(&field),
        "--components",
        s(file),
        "--tracker",
        "stan",
        "--trials",
        trials,
        "--record",
        "none",
        "--out",
        s(out),
    ];
    args.extend_from_slice(extra);
    forkbench(&args)
}

#[test]
fn a_tracker_defined_once_runs_on_any_scenario_and_an_edited_script_refuses_a_resume() {
    let (file, script) = components("resume");
    let field = repo_root().join("scenarios/field-test.toml");
    let out = tmp("resume-out");
    let batch = |extra: &[&str]| stan_batch(&file, &out, "2", extra);
    let first = batch(&["--force-new"]);
    assert!(
        matches!(first.status.code(), Some(0 | 3)),
        "{}",
        text(&first)
    );
    assert!(text(&first).contains("stan"), "{}", text(&first));
    let again = batch(&[]);
    assert!(
        matches!(again.status.code(), Some(0 | 3)),
        "{}",
        text(&again)
    );
    let mut edited = std::fs::read_to_string(&script).expect("script");
    edited.push_str("\n# tuned\n");
    std::fs::write(&script, edited).expect("edit");
    let stale = batch(&[]);
    assert_eq!(stale.status.code(), Some(1), "{}", text(&stale));
    assert!(
        text(&stale).contains("stanley.py") && text(&stale).contains("different batch"),
        "{}",
        text(&stale)
    );
    // Without the file, the name is unknown, and the message says where names come from.
    let o = forkbench(&["trial", s(&field), "--tracker", "stan"]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(text(&o).contains("components file"), "{}", text(&o));
}

#[test]
fn a_components_file_beside_a_scenario_comes_with_it() {
    let (_, _) = components("beside");
    let dir = tmp("beside");
    let scn = dir.join("field.toml");
    let original =
        std::fs::read_to_string(repo_root().join("scenarios/field-test.toml")).expect("field test");
    std::fs::write(&scn, original).expect("scenario");
    let o = forkbench(&["trial", s(&scn), "--tracker", "stan", "--json"]);
    assert!(matches!(o.status.code(), Some(0 | 3)), "{}", text(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("json");
    assert_eq!(v["tracker"], "stan", "{v}");
    // A malformed file is refused naming its line and field.
    std::fs::write(
        dir.join("components.toml"),
        "[[tracker]]\nkind = \"external\"\n",
    )
    .expect("write");
    let o = forkbench(&["trial", s(&scn), "--tracker", "stan"]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(
        text(&o).contains("components.toml:1") && text(&o).contains("tracker[0].name"),
        "{}",
        text(&o)
    );
}

/// A detector defined by name in a components file is what `detect --detector NAME`
/// runs; an unknown name is refused, naming where names come from.
#[test]
fn detect_runs_a_detector_defined_by_name() {
    let dir = tmp("detector");
    std::fs::create_dir_all(&dir).expect("dir");
    let file = dir.join("components.toml");
    std::fs::write(&file, "[[detector]]\nname = \"fit\"\nkind = \"face_fit\"\n").expect("write");
    let mcap = dir.join("field.mcap");
    crate::common::record_field_mcap(&mcap);
    let field = repo_root().join("scenarios/field-test.toml");
    let o = forkbench(&[
        "detect",
        s(&mcap),
        "--scenario",
        s(&field),
        "--components",
        s(&file),
        "--detector",
        "fit",
    ]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("detector fit on"), "{}", text(&o));
    let o = forkbench(&[
        "detect",
        s(&mcap),
        "--scenario",
        s(&field),
        "--detector",
        "nope",
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
}

/// A batch run with `--components` replays with the same file.
#[test]
fn a_trial_of_a_defined_tracker_replays_with_its_components_file() {
    let (file, _) = components("replay");
    let out = tmp("replay-out");
    let o = stan_batch(&file, &out, "1", &["--force-new"]);
    assert!(matches!(o.status.code(), Some(0 | 3)), "{}", text(&o));
    let records = out.join("trials.jsonl");
    let o = forkbench(&["replay", s(&records), "--components", s(&file)]);
    assert!(
        text(&o).contains("identical to the recorded outcome"),
        "{}",
        text(&o)
    );
}

/// A built-in kind defined by name with settings of its own is fingerprinted by them: a
/// resume after its settings were edited is refused, naming the setting (once only
/// external commands were, and every stale trial was reused).
#[test]
fn an_edited_setting_of_a_named_component_refuses_a_resume() {
    let dir = tmp("settings");
    std::fs::create_dir_all(&dir).expect("dir");
    let file = dir.join("components.toml");
    let define = |lookahead: f64| {
        std::fs::write(
            &file,
            format!(
                "[[tracker]]\nname = \"pp\"\nkind = \"pure_pursuit\"\nlookahead_m = {lookahead}\n"
            ),
        )
        .expect("components");
    };
    define(1.0);
    let out = tmp("settings-out");
    let field = repo_root().join("scenarios/field-test.toml");
    let batch = |extra: &[&str]| {
        let mut args = vec![
            "batch",
            s(&field),
            "--components",
            s(&file),
            "--tracker",
            "pp",
            "--trials",
            "2",
            "--record",
            "none",
            "--out",
            s(&out),
        ];
        args.extend_from_slice(extra);
        forkbench(&args)
    };
    let first = batch(&["--force-new"]);
    assert!(
        matches!(first.status.code(), Some(0 | 3)),
        "{}",
        text(&first)
    );
    let again = batch(&[]);
    assert!(
        matches!(again.status.code(), Some(0 | 3)),
        "{}",
        text(&again)
    );
    define(1.6);
    let stale = batch(&[]);
    assert_eq!(stale.status.code(), Some(1), "{}", text(&stale));
    assert!(
        text(&stale).contains("components[0].settings.lookahead_m: 1 → 1.6")
            && text(&stale).contains("different batch"),
        "{}",
        text(&stale)
    );
}
