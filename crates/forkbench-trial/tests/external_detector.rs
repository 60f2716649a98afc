//! A detector in another language: the Python RANSAC example guides picks; a detector that hangs, crashes, answers garbage or an impossible pose fails only its trial, with the reason; one that finds nothing is `pallet_not_found`.

use std::path::{Path, PathBuf};

use forkbench_trial::{Failure, Scenario, TrialOptions, run_trial};

const PICK: &str = "name = \"s\"\nplanner = \"bspline\"\npallet_kind = \"field-1200\"\n\
    start = { x_m = 0.0, y_m = 0.0, heading_deg = 0.0 }\n\
    pallet = { x_m = 5.0, y_m = 0.4, heading_deg = 5.0 }\n\
    [sensors.pallet]\nkind = \"tim561\"\n";

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("forkbench-det-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

/// A scenario in its own directory whose detector is `script` (Python), run there.
fn with_detector(name: &str, script: &str, timeout_s: f64) -> Scenario {
    let d = dir(name);
    std::fs::write(d.join("det.py"), script).expect("script");
    let text = format!(
        "{PICK}[sensors.pallet.detector]\nkind = \"external\"\nname = \"{name}\"\n\
         command = [\"python3\", \"det.py\"]\ntimeout_s = {timeout_s}\n"
    );
    let path = d.join("s.toml");
    std::fs::write(&path, text).expect("scenario");
    Scenario::load(&path).expect("loads")
}

/// Answers the hello, then runs `body` (Python, with `req` the parsed request) per line.
fn script(body: &str) -> String {
    format!(
        "import json, sys, time\n\
         for line in sys.stdin:\n    req = json.loads(line)\n    if req['type'] == 'hello':\n        \
         print(json.dumps({{'type': 'hello', 'protocol': 'forkbench-detector', 'version': 1}}), flush=True)\n        \
         continue\n{body}"
    )
}

fn seeded(seed: u64) -> TrialOptions {
    TrialOptions {
        seed: Some(seed),
        ..TrialOptions::default()
    }
}

#[test]
fn the_python_ransac_detector_guides_picks() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/detectors/ransac-near-pick.toml");
    let scn = Scenario::load(&path).expect("loads");
    for seed in 1..=5 {
        let out = run_trial(&scn, &scn.cases[0], &seeded(seed));
        assert!(
            out.success,
            "seed {seed}: {:?} {:?}",
            out.failure, out.failure_detail
        );
        assert_eq!(out.estimates_missed, 0, "{out:?}");
        let lateral = out.estimate_lateral_error_m.expect("estimate");
        assert!(lateral.abs() < 0.05, "seed {seed}: {lateral} m");
    }
}

#[test]
fn a_misbehaving_detector_fails_only_its_trial_with_the_reason() {
    let cases = [
        ("hang", script("    time.sleep(30)\n"), "no answer within"),
        ("crash", script("    sys.exit(3)\n"), "exited"),
        (
            "garbage",
            script("    print('{not json', flush=True)\n"),
            "invalid answer",
        ),
        (
            "far",
            script(
                "    print(json.dumps({'type': 'pallet', 'id': req['id'], 'face': \
                 {'x_m': 900.0, 'y_m': 0.0, 'heading_rad': 0.0}}), flush=True)\n",
            ),
            "beyond the sensor's reach",
        ),
        (
            "spin",
            script(
                "    print(json.dumps({'type': 'pallet', 'id': req['id'], 'face': \
                 {'x_m': 3.0, 'y_m': 0.0, 'heading_rad': 1e300}}), flush=True)\n",
            ),
            "not an angle",
        ),
        (
            "residual",
            script(
                "    print(json.dumps({'type': 'pallet', 'id': req['id'], 'face': \
                 {'x_m': 3.0, 'y_m': 0.0, 'heading_rad': 0.0}, 'rms_m': -1e308}), flush=True)\n",
            ),
            "rms_m",
        ),
        (
            "reported",
            script(
                "    print(json.dumps({'type': 'error', 'id': req['id'], 'message': 'no model'}), \
                 flush=True)\n",
            ),
            "no model",
        ),
    ];
    for (name, body, why) in cases {
        let scn = with_detector(name, &body, 1.0);
        let out = run_trial(&scn, &scn.cases[0], &seeded(1));
        assert_eq!(out.failure, Some(Failure::Error), "{name}: {out:?}");
        let detail = out.failure_detail.unwrap_or_default();
        assert!(
            detail.contains(why) && detail.contains(name),
            "{name}: {detail}"
        );
    }
}

#[test]
fn a_detector_that_finds_nothing_is_pallet_not_found() {
    let body = "    print(json.dumps({'type': 'none', 'id': req['id']}), flush=True)\n";
    let scn = with_detector("blind", &script(body), 5.0);
    let out = run_trial(&scn, &scn.cases[0], &seeded(1));
    assert_eq!(out.failure, Some(Failure::PalletNotFound), "{out:?}");
    // One look from the start, then the staging pose's three.
    assert_eq!((out.estimates, out.estimates_missed), (4, 4));
    let detail = out.failure_detail.unwrap_or_default();
    assert!(detail.contains("3 looks from the staging pose"), "{detail}");
}

#[test]
fn detector_settings_are_checked_at_load() {
    let d = dir("bad");
    let path = d.join("s.toml");
    for (table, field) in [
        ("kind = \"external\"\ncommand = []\n", "command"),
        (
            "kind = \"external\"\ncommand = [\"x\"]\ntimeout_s = -1.0\n",
            "timeout_s",
        ),
        ("kind = \"magic\"\n", "kind"),
        ("break_m = 0.1\nbreak_mm = 3.0\n", "break_mm"),
    ] {
        std::fs::write(&path, format!("{PICK}[sensors.pallet.detector]\n{table}")).expect("w");
        let e = Scenario::load(&path).expect_err(table).to_string();
        assert!(
            e.contains(&format!("sensors.pallet.detector.{field}")),
            "{table}: {e}"
        );
    }
}
