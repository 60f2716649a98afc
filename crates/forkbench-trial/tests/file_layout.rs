//! The layout of a scenario file never changes an outcome: tables written in another
//! order, scanners listed the other way round, and each scanner's defaults spelt out give
//! the same records, because every random stream is keyed by what it is for.

use forkbench_trial::scenario::World;
use forkbench_trial::{Scenario, TrialOptions, run_trial};

const FIELD_TEST: &str = include_str!("../data/scenarios/field-test.toml");

fn parse(text: &str) -> Scenario {
    Scenario::parse(text, "field-test.toml", |_| Ok(World::default())).expect("parses")
}

/// The outcomes of 30 seeds, wall times removed.
fn outcomes(scn: &Scenario) -> Vec<serde_json::Value> {
    (1..=30)
        .map(|seed| {
            let opts = TrialOptions {
                seed: Some(seed),
                ..Default::default()
            };
            serde_json::to_value(run_trial(scn, &scn.cases[0], &opts).without_wall_times())
                .expect("json")
        })
        .collect()
}

/// The file's tables re-serialised in toml's key order (another order than the file's).
fn permuted(text: &str) -> String {
    let v: toml::Table = toml::from_str(text).expect("toml");
    toml::to_string(&v).expect("serialises")
}

#[test]
fn a_scenario_whose_tables_are_permuted_gives_identical_records() {
    let original = parse(FIELD_TEST);
    let want = outcomes(&original);
    assert!(
        want.iter().any(|o| o["success"] == true) && want.iter().any(|o| o["success"] == false),
        "the seeds should cover both outcomes"
    );
    let reordered = permuted(FIELD_TEST);
    assert_ne!(reordered, FIELD_TEST);
    assert_eq!(
        outcomes(&parse(&reordered)),
        want,
        "tables in another order"
    );
    // The scanners named the other way round, each with a table of its own defaults,
    // in both orders.
    let swapped = FIELD_TEST.replace("kind = \"tim561+kinect2\"", "kind = \"kinect2+tim561\"");
    assert_ne!(swapped, FIELD_TEST);
    let tim = "[sensors.pallet.scanners.tim561]\nrange_max_m = 10.0\n";
    let kinect = "[sensors.pallet.scanners.kinect2]\nrange_max_m = 4.5\n";
    for text in [
        swapped.clone(),
        format!("{swapped}\n{tim}\n{kinect}"),
        format!("{FIELD_TEST}\n{kinect}\n{tim}"),
        permuted(&format!("{FIELD_TEST}\n{tim}\n{kinect}")),
    ] {
        assert_eq!(outcomes(&parse(&text)), want, "{text}");
    }
}

#[test]
fn a_partial_scanner_table_lays_its_keys_over_that_models_defaults() {
    let text = format!("{FIELD_TEST}\n[sensors.pallet.scanners.kinect2]\nrate_hz = 30.0\n");
    let scn = parse(&text);
    let kinect = scn.pallet_sensing.scanner("kinect2").expect("kinect2");
    assert_eq!(
        *kinect,
        forkbench_sensors::scan::ScannerConfig::kinect2(),
        "not the TiM561's defaults"
    );
}

#[test]
fn a_huge_back_out_is_refused_at_load_naming_its_field() {
    let text = include_str!("../data/scenarios/warehouse-cycle.toml")
        .replace("backout_m = 3.0", "backout_m = 1e9");
    let e = Scenario::parse(&text, "cycle.toml", |p| {
        let name = p.file_name().and_then(|n| n.to_str()).unwrap_or_default();
        forkbench_trial::defaults::embedded_world(name)
    })
    .expect_err("refused")
    .to_string();
    assert!(
        e.contains("mission.backout_m") && e.contains("(0, 50]"),
        "{e}"
    );
}

#[test]
fn pocket_detector_settings_are_range_checked_at_load() {
    for (key, value) in [
        ("roi_m", "nan"),
        ("min_coverage", "1.5"),
        ("roi_rad", "-1.0"),
    ] {
        let text = format!("{FIELD_TEST}\n[sensors.pallet.detector]\n{key} = {value}\n");
        let e = Scenario::parse(&text, "d.toml", |_| Ok(World::default()))
            .expect_err(key)
            .to_string();
        assert!(e.contains(&format!("sensors.pallet.detector.{key}")), "{e}");
    }
}
