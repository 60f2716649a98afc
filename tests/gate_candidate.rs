//! Gating your own component against what you ship: a candidate tracker's results mapped onto the built-in's baseline (`regress --as`) pair trial by trial, pass when equal and fail when worse; a changed setting keeps the pairing and is listed.

use std::path::{Path, PathBuf};

use crate::common::{forkbench, s};

fn tmp(name: &str) -> PathBuf {
    crate::common::tmp_in("forkbench-candidate", name)
}

fn field_test() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/field-test.toml")
}

/// A 12-trial field-test batch with `tracker` (and `extra` flags) into `name`.
fn batch(name: &str, tracker: &str, extra: &[&str]) -> PathBuf {
    let out = tmp(name);
    let scn = field_test();
    let mut args = vec![
        "batch",
        s(&scn),
        "--trials",
        "12",
        "--tracker",
        tracker,
        "--record",
        "none",
        "--force-new",
        "--out",
        s(&out),
    ];
    args.extend_from_slice(extra);
    let run = forkbench(&args);
    assert!(
        matches!(run.status.code(), Some(0 | 3)),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    out
}

fn baseline(dir: &Path, name: &str) -> PathBuf {
    let file = tmp(name);
    let out = forkbench(&["baseline", s(dir), "--out", s(&file)]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    file
}

fn regress(base: &Path, dir: &Path, extra: &[&str]) -> (Option<i32>, serde_json::Value, String) {
    let mut args = vec!["regress", "--baseline", s(base), s(dir), "--json"];
    args.extend_from_slice(extra);
    let out = forkbench(&args);
    let v = serde_json::from_slice(&out.stdout).unwrap_or(serde_json::Value::Null);
    (
        out.status.code(),
        v,
        String::from_utf8_lossy(&out.stderr).to_string(),
    )
}

#[test]
fn a_candidate_mapped_onto_the_shipped_tracker_is_gated_pair_by_pair() {
    // A truck whose 0.2 s steering dead time and 0.27 s lag (Autoware's sample vehicle)
    // break plain pure pursuit: the compensated tracker is what ships here.
    let truck = tmp("slow.toml");
    std::fs::write(
        &truck,
        "preset = \"realistic\"\n[steering]\ndead_time_s = 0.2\ntime_constant_s = 0.27\n",
    )
    .expect("truck file");
    let t = ["--truck", s(&truck)];
    let shipped = batch("shipped", "pure_pursuit_compensated", &t);
    let base = baseline(&shipped, "base.json");
    // Unmapped, nothing is compared: the shipped row is missing, the candidate's new.
    let worse = batch("worse", "pure_pursuit", &t);
    let (code, v, _) = regress(&base, &worse, &[]);
    assert_eq!(code, Some(3), "{v}");
    let verdicts: Vec<&str> = v["rows"]
        .as_array()
        .expect("rows")
        .iter()
        .filter_map(|r| r["verdict"].as_str())
        .collect();
    assert_eq!(verdicts, ["missing", "new"], "{v}");
    // Mapped, it pairs with the shipped tracker's trials and fails on the drop.
    let (code, v, err) = regress(
        &base,
        &worse,
        &["--as", "pure_pursuit=pure_pursuit_compensated"],
    );
    assert_eq!(code, Some(3), "{v} {err}");
    assert_eq!(v["pairing"]["pairs"], 12, "{v}");
    let row = &v["rows"][0];
    assert!(
        row["paired"]["broke"].as_u64().expect("broke") >= 6,
        "{row}"
    );
    // An equal candidate passes: on the default truck the compensated tracker ends every
    // field-test trial as pure pursuit does.
    let same_base = baseline(&batch("pp", "pure_pursuit", &[]), "pp.json");
    let equal = batch("ppc", "pure_pursuit_compensated", &[]);
    let (code, v, err) = regress(
        &same_base,
        &equal,
        &["--as", "pure_pursuit_compensated=pure_pursuit"],
    );
    assert_eq!(code, Some(0), "{v} {err}");
    assert_eq!(v["pairing"]["pairs"], 12, "{v}");
    // Its JUnit cases are named after the candidate, and the passing one carries its
    // numbers.
    let junit = tmp("ppc.xml");
    let (code, _, err) = regress(
        &same_base,
        &equal,
        &[
            "--as",
            "pure_pursuit_compensated=pure_pursuit",
            "--junit",
            s(&junit),
        ],
    );
    assert_eq!(code, Some(0), "{err}");
    let xml = std::fs::read_to_string(&junit).expect("junit");
    assert!(
        xml.contains("bspline / pure_pursuit_compensated (as pure_pursuit) /"),
        "{xml}"
    );
    assert!(
        xml.contains("<system-out>baseline ")
            && xml.contains("detectable drop")
            && !xml.contains("<failure"),
        "{xml}"
    );
    // Results that run both would merge two components' trials into one row: refused.
    let both = batch(
        "both",
        "pure_pursuit",
        &["--tracker", "pure_pursuit_compensated"],
    );
    let (code, _, err) = regress(
        &same_base,
        &both,
        &["--as", "pure_pursuit_compensated=pure_pursuit"],
    );
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("merge"), "{err}");
    // A mapping of a name the results do not have is refused, naming it.
    let (code, _, err) = regress(&same_base, &equal, &["--as", "mypp=pure_pursuit"]);
    assert_eq!(code, Some(1));
    assert!(
        err.contains("no planner or tracker named \"mypp\""),
        "{err}"
    );
    // Issue 78: a target the baseline does not have (a typo) is refused naming it, not
    // read as every row missing (exit 3).
    let (code, _, err) = regress(
        &same_base,
        &equal,
        &["--as", "pure_pursuit_compensated=pure_pursit"],
    );
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("no planner or tracker named \"pure_pursit\" in the baseline"),
        "{err}"
    );
    // Issue 78: two candidates mapped onto one shipped name would merge into one row.
    let two = batch(
        "two",
        "pure_pursuit_compensated",
        &["--tracker", "regulated_pure_pursuit"],
    );
    let (code, _, err) = regress(
        &same_base,
        &two,
        &[
            "--as",
            "pure_pursuit_compensated=pure_pursuit",
            "--as",
            "regulated_pure_pursuit=pure_pursuit",
        ],
    );
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("mapped onto \"pure_pursuit\" too"), "{err}");
}

/// A tracker setting changed in the scenario runs the same trials: still paired, and the
/// change listed.
#[test]
fn a_changed_setting_keeps_the_gate_paired() {
    let base = baseline(&batch("set-base", "pure_pursuit", &[]), "set-base.json");
    let text = std::fs::read_to_string(field_test()).expect("scenario");
    let changed = tmp("changed.toml");
    std::fs::write(&changed, text + "\n[tolerances]\nlateral_m = 0.05\n").expect("write");
    let out = tmp("set-changed");
    let run = forkbench(&[
        "batch",
        s(&changed),
        "--trials",
        "12",
        "--record",
        "none",
        "--force-new",
        "--out",
        s(&out),
    ]);
    assert!(matches!(run.status.code(), Some(0 | 3)));
    let (_, v, err) = regress(&base, &out, &[]);
    assert_eq!(v["pairing"]["pairs"], 12, "{v} {err}");
    assert!(
        err.contains("still paired by seed): field-test: tolerances.lateral_m"),
        "{err}"
    );
}

/// `compare --b-from`: a candidate run in its own batch compared with the shipped
/// tracker's batch, pair by pair on the shared seeds; batches of another seed are refused.
#[test]
fn compare_pairs_a_candidate_run_apart_with_what_you_ship() {
    let shipped = batch("cmp-shipped", "pure_pursuit", &[]);
    let cand = batch("cmp-cand", "pure_pursuit_compensated", &[]);
    let compare = |shipped: &Path, extra: &[&str]| {
        let mut args = vec![
            "compare",
            s(&cand),
            "--a",
            "pure_pursuit_compensated",
            "--b",
            "pure_pursuit",
            "--b-from",
            s(shipped),
        ];
        args.extend_from_slice(extra);
        forkbench(&args)
    };
    let o = compare(&shipped, &["--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("json");
    let pairs: u64 = v["rows"]
        .as_array()
        .expect("rows")
        .iter()
        .map(|r| r["pairs"].as_u64().expect("pairs"))
        .sum();
    assert_eq!(pairs, 12, "{v}");
    let other = batch("cmp-seed", "pure_pursuit", &["--seed", "9"]);
    let o = compare(&other, &[]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("cannot be paired"),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
}
