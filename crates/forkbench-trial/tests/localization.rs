//! Localisation on reflectors in missions and picks: the warehouse mission fixes throughout on the full layout and measurably degrades when the west end's reflectors go; bad localiser settings name the file, line and field.

use std::path::{Path, PathBuf};

use forkbench_trial::{Scenario, TrialOptions, TrialOutcome, run_trial};

fn data(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}

fn run(scn: &Scenario, seed: u64) -> TrialOutcome {
    let opts = TrialOptions {
        seed: Some(seed),
        ..TrialOptions::default()
    };
    run_trial(scn, &scn.cases[0], &opts)
}

/// The reflectors that cover the west end, where the stations and the shelf are: the
/// west wall's, the first bays' ends, and the rack faces nearest it.
const WEST: [&str; 15] = [
    "west-3",
    "west-13",
    "west-17.25",
    "west-23",
    "shelf-frame0-end",
    "south-2",
    "north-2",
    "south-10",
    "north-10",
    "row1-north-12",
    "row2-north-12",
    "row1-south-15.5",
    "row2-south-15.5",
    "row3-south-15.5",
    "row3-north-15.5",
];

#[test]
fn the_mission_degrades_measurably_when_the_west_reflectors_go() {
    let full = Scenario::load(&data("data/scenarios/warehouse-mission.toml")).expect("loads");
    assert_eq!(full.localizer.kind, "nav350");
    let missing: Vec<String> = WEST.iter().map(|s| (*s).to_owned()).collect();
    let dark = full
        .clone()
        .with_missing_reflectors(&missing)
        .expect("names exist");
    for seed in [1, 2] {
        let (a, b) = (run(&full, seed), run(&dark, seed));
        assert!(a.success, "full layout, seed {seed}: {}", a.verdict_line());
        assert_eq!(a.fixes_missed, 0, "full layout, seed {seed}");
        assert!(a.largest_fix_gap_s < 0.2, "{}", a.largest_fix_gap_s);
        assert!(a.fixes > 500, "{}", a.fixes);
        assert!(
            b.fixes_missed >= 20,
            "dark, seed {seed}: {}",
            b.fixes_missed
        );
        assert!(b.largest_fix_gap_s > 1.0, "{}", b.largest_fix_gap_s);
        assert!(
            b.localization_error_max_m > 3.0 * a.localization_error_max_m,
            "seed {seed}: {} m against {} m",
            b.localization_error_max_m,
            a.localization_error_max_m
        );
        assert!(
            b.legs
                .iter()
                .all(|l| l.fixes_missed > 0 && l.largest_fix_gap_s > 1.0),
            "{:?}",
            b.legs
        );
        assert!((b.time_without_fix_s - f64::from(b.fixes_missed) / 8.0).abs() < 1e-9);
    }
}

#[test]
fn the_gaussian_localizer_never_misses_a_fix() {
    let scn = Scenario::load(&data("data/scenarios/warehouse-mission.toml"))
        .expect("loads")
        .with_localizer("gaussian")
        .expect("kind");
    let o = run(&scn, 1);
    assert_eq!(o.fixes_missed, 0);
    assert!(o.largest_fix_gap_s < 0.2);
    assert!(o.localization_error_mean_m > 0.0 && o.localization_error_mean_m < 0.01);
    let e = scn
        .with_missing_reflectors(&["west-3".to_owned()])
        .expect_err("the Gaussian model has no reflectors")
        .to_string();
    assert!(e.contains("sensors.localizer.missing_reflectors"), "{e}");
}

#[test]
fn bad_localizer_settings_name_the_file_line_and_field() {
    let text = std::fs::read_to_string(data("data/scenarios/rack-pick.toml")).expect("reads");
    let world = |p: &Path| forkbench_trial::World::load(&data("data/scenarios").join(p));
    assert!(text.contains("kind = \"nav350\"\n"));
    let line = text
        .lines()
        .position(|l| l == "kind = \"nav350\"")
        .expect("line")
        + 1;
    let cases = [
        (
            "kind = \"gps\"",
            "sensors.localizer.kind",
            "unknown localizer \"gps\"",
        ),
        (
            "kind = \"nav350\"\nmount = { x_m = 0.5, y_m = 0.0, heading_rad = 0.0 }",
            "sensors.localizer.mount",
            "outside the truck",
        ),
        (
            "kind = \"nav350\"\nmissing_reflectors = [\"nope\"]",
            "sensors.localizer.missing_reflectors",
            "\"nope\" is not a reflector",
        ),
        (
            "kind = \"nav350\"\nmeasurement = { range_sigma_m = -1.0 }",
            "sensors.localizer.measurement.range_sigma_m",
            "must lie within",
        ),
        (
            "kind = \"nav350\"\nmeasurement = { range_sigma_m = 1e-100 }",
            "sensors.localizer.measurement.range_sigma_m",
            "1e-6",
        ),
        (
            "kind = \"nav350\"\nmeasurement = { bearing_sigma_rad = 100.0 }",
            "sensors.localizer.measurement.bearing_sigma_rad",
            "must lie within",
        ),
        (
            "kind = \"nav350\"\nmount = { x_m = nan, y_m = 0.0, heading_rad = 0.0 }",
            "sensors.localizer.mount",
            "finite",
        ),
    ];
    for (to, field, reason) in cases {
        let bad = text.replacen("kind = \"nav350\"", to, 1);
        let e = Scenario::parse(&bad, "r.toml", world)
            .expect_err(to)
            .to_string();
        assert!(
            e.contains("r.toml:") && e.contains(field) && e.contains(reason),
            "{e}"
        );
        assert!(
            (line..line + 2).any(|l| e.contains(&format!("r.toml:{l}"))),
            "{e} (the table is at line {line})"
        );
    }
}

/// Reflector lists that would make every NAV350 fix slow are refused at load, with the
/// work they ask for; 80,000 uniquely named reflectors on an open floor load quickly
/// (the duplicate-name check is linear); a name with a comma, which the command line
/// could not name, is refused.
#[test]
fn reflector_work_is_bounded_and_names_are_checked_in_linear_time() {
    let dir = std::env::temp_dir().join(format!("forkbench-refl-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let world = |name: &str, racks: usize, reflectors: usize, bad: &str| {
        let mut t = String::from("name = \"w\"\n");
        for i in 0..racks {
            t += &format!(
                "[[rack]]\nname = \"r{i}\"\nx_m = {}\ny_m = 50.0\nlength_m = 0.5\nwidth_m = 0.5\n",
                i as f64
            );
        }
        for i in 0..reflectors {
            t += &format!(
                "[[reflector]]\nname=\"f{i}{bad}\"\nx_m={}\ny_m=0\n",
                i as f64 * 0.01
            );
        }
        let p = dir.join(name);
        std::fs::write(&p, t).expect("write");
        p
    };
    let t0 = std::time::Instant::now();
    let err = forkbench_trial::World::load(&world("heavy.toml", 100, 30_000, ""))
        .expect_err("too much work per fix")
        .to_string();
    assert!(
        err.contains("heavy.toml") && err.contains("3000000"),
        "{err}"
    );
    assert!(t0.elapsed().as_secs_f64() < 5.0);
    let t0 = std::time::Instant::now();
    forkbench_trial::World::load(&world("many.toml", 0, 80_000, "")).expect("loads");
    assert!(t0.elapsed().as_secs_f64() < 5.0, "{:?}", t0.elapsed());
    let err = forkbench_trial::World::load(&world("comma.toml", 0, 2, ",x"))
        .expect_err("comma")
        .to_string();
    assert!(
        err.contains("reflector[0].name") && err.contains("comma"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The NAV350 on a world without enough reflectors for one fix is refused, naming why,
/// instead of running every trial on dead reckoning with zero fixes.
#[test]
fn nav350_without_reflectors_is_refused() {
    let scn = Scenario::load(&data("../../scenarios/field-test.toml")).expect("loads");
    let err = scn
        .with_localizer("nav350")
        .expect_err("no reflectors")
        .to_string();
    assert!(
        err.contains("sensors.localizer") && err.contains("at least 3 reflectors"),
        "{err}"
    );
    // The warehouse mission's world has them.
    let mission = Scenario::load(&data("../../scenarios/warehouse-mission.toml")).expect("loads");
    assert!(mission.with_localizer("nav350").is_ok());
}
