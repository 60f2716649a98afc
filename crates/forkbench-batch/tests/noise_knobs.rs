//! Every noise knob acts on the sensing in use: paired sweeps (same trial seeds) move the
//! error they scale and never leave success unchanged at every scale; knobs that cannot
//! act are refused; a record's overrides replay it; a file's layout changes no outcome.

use std::path::Path;

use forkbench_batch::{self as batch, BatchSpec, Summary, Sweep};
use forkbench_trial::trial::Overrides;
use forkbench_trial::{Scenario, TrialOptions, defaults, run_trial};

fn field_test() -> Scenario {
    defaults::embedded_scenario("field-test").expect("embedded")
}

fn spec(scenarios: Vec<Scenario>, trials: u64, overrides: Overrides) -> BatchSpec {
    BatchSpec {
        scenarios,
        planners: vec![],
        trackers: vec![],
        trials,
        seed: 1,
        shard: (0, 1),
        overrides,
        replan: None,
        compare_replanning: false,
        force_new: true,
        success_run: Default::default(),
        profile: false,
    }
}

/// The sweep's points on the field test: (scale, its one row's summary).
fn sweep(knob: &str, dir: &Path) -> Vec<(f64, forkbench_batch::SummaryRow)> {
    let sweep = Sweep::parse(&format!("{knob}=0,1,3")).expect("sweep");
    batch::sweep_points(
        &spec(vec![field_test()], 40, Overrides::default()),
        dir,
        &sweep,
    )
    .into_iter()
    .map(|p| {
        let s: Summary = batch::run_batch(&p.spec, &p.dir, 2, &|_| {}).expect("batch");
        assert_eq!(s.rows.len(), 1);
        (p.value, s.rows[0].clone())
    })
    .collect()
}

fn tmp(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("forkbench-noise-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("tmp dir");
    d
}

/// Success at each scale is at most the previous one's, and not all equal; `error` rises.
fn assert_degrades(
    points: &[(f64, forkbench_batch::SummaryRow)],
    error: impl Fn(&forkbench_batch::SummaryRow) -> f64,
) {
    let rates: Vec<f64> = points.iter().map(|p| p.1.success_rate).collect();
    let errors: Vec<f64> = points.iter().map(|p| error(&p.1)).collect();
    assert!(
        errors.windows(2).all(|w| w[1] > w[0]),
        "the scaled error does not rise: {errors:?}"
    );
    assert!(
        rates.windows(2).all(|w| w[1] <= w[0]) && rates[0] > rates[2],
        "success does not fall with the scale: {rates:?}"
    );
}

#[test]
fn the_pallet_noise_sweep_moves_the_estimate_error_and_the_success_rate() {
    let dir = tmp("pallet");
    let points = sweep("pallet_noise", &dir);
    assert_degrades(&points, |r| r.estimate_error_median_m.expect("estimates"));
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn the_localization_noise_sweep_moves_the_localization_error_and_the_success_rate() {
    let dir = tmp("loc");
    let points = sweep("localization_noise", &dir);
    assert_degrades(&points, |r| r.localization_error_median_m.expect("fixes"));
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn the_odometry_noise_knob_reaches_the_odometry() {
    let scn = field_test();
    let case = &scn.cases[0];
    let run = |s: f64| {
        let opts = TrialOptions {
            seed: Some(3),
            overrides: Overrides {
                odometry_noise_scale: Some(s),
                ..Default::default()
            },
            ..Default::default()
        };
        run_trial(&scn, case, &opts).localization_error_mean_m
    };
    let (zero, one, ten) = (run(0.0), run(1.0), run(10.0));
    assert!(zero < one && one < ten, "{zero} {one} {ten}");
}

#[test]
fn knobs_that_cannot_act_are_refused_naming_the_component_and_the_knob() {
    let scn = field_test();
    let refuse = |o: Overrides, no_noise: bool| {
        let opts = TrialOptions {
            no_noise,
            overrides: o,
            ..Default::default()
        };
        opts.check_against(&scn).expect_err("refused").to_string()
    };
    let e = refuse(
        Overrides {
            pallet_noise_scale: Some(1.0),
            ..Default::default()
        },
        true,
    );
    assert!(
        e.contains("pallet_noise_scale") && e.contains("no-noise"),
        "{e}"
    );
    let e = refuse(
        Overrides {
            localization_noise_scale: Some(-1.0),
            ..Default::default()
        },
        false,
    );
    assert!(
        e.contains("localization_noise_scale") && e.contains("from 0 to"),
        "{e}"
    );
    // A localiser registered without a noise scale cannot be scaled.
    let registry = forkbench_trial::Registry::builtin().with_localizer("mine", |_, _| {
        Ok(Box::new(forkbench_sensors::Nav350::new(
            forkbench_sensors::Nav350Config::default(),
            true,
        )))
    });
    let text = "name = \"own\"\nplanner = \"bspline\"\nstart = { x_m = 0, y_m = 0, heading_deg = 0 }\n\
                pallet = { x_m = 8, y_m = 1, heading_deg = 0 }\n[sensors.localizer]\nkind = \"mine\"\n";
    let dir = tmp("own");
    let file = dir.join("own.toml");
    std::fs::write(&file, text).expect("write");
    let own = Scenario::load_with(&file, std::sync::Arc::new(registry)).expect("loads");
    let _ = std::fs::remove_dir_all(dir);
    let opts = TrialOptions {
        overrides: Overrides {
            localization_noise_scale: Some(2.0),
            ..Default::default()
        },
        ..Default::default()
    };
    let e = opts.check_against(&own).expect_err("refused").to_string();
    assert!(
        e.contains("\"mine\"") && e.contains("localization_noise_scale"),
        "{e}"
    );
}

/// Records of a batch run with every kind of override reproduce through their own
/// options (what `replay` does).
#[test]
fn records_of_an_overridden_batch_replay_identically() {
    let dir = tmp("replay");
    let scenarios = vec![
        field_test(),
        defaults::embedded_scenario("rack-pick").expect("embedded"),
    ];
    let overrides = Overrides {
        pallet_noise_scale: Some(2.0),
        localization_noise_scale: Some(0.5),
        odometry_noise_scale: Some(2.0),
        localizer: Some("gaussian".into()),
        pallet_sensing: Some("tim561".into()),
        missing_reflectors: None,
        // A run's truck too: a preset and a setting over it.
        truck_preset: Some("ideal".into()),
        truck: [("steering.dead_time_s".to_owned(), 0.1)]
            .into_iter()
            .collect(),
    };
    batch::run_batch(
        &spec(scenarios.clone(), 2, overrides.clone()),
        &dir,
        2,
        &|_| {},
    )
    .expect("batch");
    let records = batch::read_records(&dir.join("trials.jsonl")).expect("records");
    assert_eq!(records.len(), 4);
    for r in &records {
        assert_eq!(r.overrides, overrides, "the record carries its overrides");
        let scn = scenarios
            .iter()
            .find(|s| s.name == r.outcome.scenario)
            .expect("scn");
        let again = run_trial(scn, scn.case(&r.outcome.case).expect("case"), &r.options());
        assert_eq!(
            serde_json::to_value(again.without_wall_times()).expect("json"),
            serde_json::to_value(r.outcome.without_wall_times()).expect("json"),
        );
    }
    let _ = std::fs::remove_dir_all(dir);
}
