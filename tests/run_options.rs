//! A run's options are defined once (`Overrides`): every field reaches each trial-running command's flags, a batch's manifest and CSV, and Python's keywords (the stub's `RunOptions`; `python/tests/test_options.py` checks the module itself).

use forkbench_trial::trial::Overrides;

use crate::common::{forkbench, repo_root, s, text, tmp_in};

/// The flag of an option: its name with dashes; the truck's preset and settings are both
/// `--truck` (a preset's name, or a truck file giving a preset and settings).
fn flag(name: &str) -> String {
    if name.starts_with("truck") {
        "--truck".to_owned()
    } else {
        format!("--{}", name.replace('_', "-"))
    }
}

#[test]
fn every_run_option_reaches_the_flags_the_manifest_the_csv_and_python() {
    let names = Overrides::field_names();
    assert!(names.len() >= 8, "{names:?}");
    for cmd in ["trial", "mission", "batch", "estimate", "falsify"] {
        let help = text(&forkbench(&[cmd, "--help"]));
        for n in names {
            assert!(help.contains(&flag(n)), "{cmd} --help lacks {}", flag(n));
        }
    }
    // A batch with every option set records each in its manifest and its CSV.
    let truck = tmp_in("forkbench-run-options", "truck.toml");
    std::fs::write(
        &truck,
        "preset = \"realistic\"\n[steering]\ndead_time_s = 0.05\n",
    )
    .expect("writes");
    let out = tmp_in("forkbench-run-options", "batch");
    let _ = std::fs::remove_dir_all(&out);
    let scenario = repo_root().join("scenarios/rack-pick.toml");
    let run = forkbench(&[
        "batch",
        s(&scenario),
        "--trials",
        "1",
        "--pallet-noise-scale",
        "0.5",
        "--localization-noise-scale",
        "0.5",
        "--odometry-noise-scale",
        "0.5",
        "--pallet-sensing",
        "gaussian",
        "--localizer",
        "nav350",
        "--missing-reflectors",
        "back-wall-left",
        "--truck",
        s(&truck),
        "--csv",
        "--out",
        s(&out),
    ]);
    assert!(matches!(run.status.code(), Some(0 | 3)), "{}", text(&run));
    let manifest: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(out.join("manifest.json")).expect("manifest"),
    )
    .expect("JSON");
    let csv = std::fs::read_to_string(out.join("trials.csv")).expect("CSV");
    let (header, row) = csv.split_once('\n').expect("a header and a row");
    let columns: Vec<&str> = header.split(',').collect();
    let cells: Vec<&str> = row.lines().next().expect("a row").split(',').collect();
    for n in names {
        assert!(!manifest[n].is_null(), "the manifest lacks {n}: {manifest}");
        let i = columns.iter().position(|c| c == n);
        let i = i.unwrap_or_else(|| panic!("the CSV lacks a {n} column: {header}"));
        assert!(!cells[i].is_empty(), "{n} is empty in the CSV row");
    }
    let at = |n: &str| cells[columns.iter().position(|c| *c == n).expect("column")];
    assert_eq!(at("truck_preset"), "realistic");
    assert_eq!(at("truck"), "steering.dead_time_s=0.05");
    assert_eq!(at("missing_reflectors"), "back-wall-left");
    // Python's stub declares each as a keyword of every function that runs trials.
    let stub =
        std::fs::read_to_string(repo_root().join("python/forkbench/_forkbench.pyi")).expect("stub");
    let (_, options) = stub
        .split_once("class RunOptions(TypedDict, total=False):")
        .expect("the stub's RunOptions");
    let options = options.split("\nOutcome").next().unwrap_or_default();
    for n in names {
        assert!(
            options.contains(&format!("\n    {n}: ")),
            "RunOptions lacks {n}"
        );
    }
    let _ = std::fs::remove_dir_all(out);
}
