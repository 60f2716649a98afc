//! Pallet sensing that looks at the world: a TiM561 scan and the pocket detector drive the pick; a pallet out of its sight is never found; bad sensor settings are refused at load.

use std::path::Path;

use forkbench_trial::{Failure, Scenario, TrialOptions, World, run_trial};

fn scenario(extra: &str, pallet: &str) -> Result<Scenario, forkbench_trial::ScenarioError> {
    let text = format!(
        "name = \"s\"\nplanner = \"bspline\"\npallet_kind = \"field-1200\"\n\
         start = {{ x_m = 0.0, y_m = 0.0, heading_deg = 0.0 }}\npallet = {pallet}\n{extra}"
    );
    Scenario::parse(&text, "s.toml", |_: &Path| Ok(World::default()))
}

const NEAR: &str = "{ x_m = 5.0, y_m = 0.4, heading_deg = 5.0 }";

#[test]
fn a_tim561_scan_guides_the_pick() {
    let scn = scenario("[sensors.pallet]\nkind = \"tim561\"\n", NEAR).expect("loads");
    for (no_noise, seed) in [(true, 1), (false, 1), (false, 2)] {
        let opts = TrialOptions {
            no_noise,
            seed: Some(seed),
            ..TrialOptions::default()
        };
        let out = run_trial(&scn, &scn.cases[0], &opts);
        assert!(
            out.success,
            "{no_noise} {seed}: {:?} {:?}",
            out.failure, out.failure_detail
        );
        assert!(out.estimates >= 1 && out.estimates_missed == 0, "{out:?}");
        let lateral = out.estimate_lateral_error_m.expect("an estimate");
        // Ideal rays: within half a beam step at 5 m; with the sensor's errors, centimetres.
        let tol = if no_noise { 0.015 } else { 0.06 };
        assert!(
            lateral.abs() < tol,
            "{no_noise} {seed}: estimate {lateral} m off"
        );
    }
}

#[test]
fn a_pallet_beyond_the_scanners_range_is_never_found() {
    let far = "{ x_m = 14.0, y_m = 0.0, heading_deg = 0.0 }";
    let once = "[pick]\nwhen_not_seen = \"fail\"\n[sensors.pallet]\nkind = \"tim561\"\n";
    let scn = scenario(once, far).expect("loads");
    let out = run_trial(&scn, &scn.cases[0], &TrialOptions::default());
    assert_eq!(out.failure, Some(Failure::PalletNotFound), "{out:?}");
    assert_eq!((out.estimates, out.estimates_missed), (1, 1));
    // Staged (the default), the truck drives to 3 m before where the pallet should stand
    // and finds it there.
    let scn = scenario("[sensors.pallet]\nkind = \"tim561\"\n", far).expect("loads");
    let out = run_trial(&scn, &scn.cases[0], &TrialOptions::default());
    assert_ne!(out.failure, Some(Failure::PalletNotFound), "{out:?}");
    assert_eq!((out.estimates_missed, out.legs.len()), (1, 1), "{out:?}");
    // The Gaussian model, by construction, always "sees" it.
    let gaussian = scenario("", far).expect("loads");
    let out = run_trial(&gaussian, &gaussian.cases[0], &TrialOptions::default());
    assert_ne!(out.failure, Some(Failure::PalletNotFound));
    assert_eq!(out.estimates_missed, 0);
}

#[test]
fn bad_sensor_settings_are_refused_naming_the_field() {
    let cases = [
        (
            "[sensors.pallet]\nkind = \"lidar\"\n",
            "sensors.pallet.kind",
        ),
        (
            "[sensors.pallet]\nkind = \"tim561\"\n[sensors.pallet.scanner]\nrange_sigma_m = -0.02\n",
            "sensors.pallet.scanner.range_sigma_m",
        ),
        (
            "[sensors.pallet]\nkind = \"tim561\"\n[sensors.pallet.scanner]\nfov_rad = 7.0\n",
            "sensors.pallet.scanner.fov_rad",
        ),
        (
            "[sensors.pallet]\nkind = \"tim561\"\n[sensors.pallet.scanner]\nmount = { x_m = -1.0, y_m = 0.0, heading_rad = 0.0 }\n",
            "inside the truck's body",
        ),
        (
            "[sensors.pallet]\nkind = \"tim561\"\nrange = 3\n",
            "unknown field",
        ),
    ];
    for (extra, want) in cases {
        let e = scenario(extra, NEAR).expect_err(extra).to_string();
        assert!(e.contains(want), "{extra}: {e}");
    }
}

#[test]
fn a_failed_trial_names_every_broken_criterion_and_the_likely_cause() {
    // The estimate 0.3 m to the side of the pallet: the truck aims beside the pockets.
    let scn = scenario(
        "estimate_bias = { x_m = 0.0, y_m = 0.3, heading_deg = 0.0 }\n",
        "{ x_m = 5.0, y_m = 0.0, heading_deg = 0.0 }",
    )
    .expect("loads");
    let opts = TrialOptions {
        no_noise: true,
        ..TrialOptions::default()
    };
    let out = run_trial(&scn, &scn.cases[0], &opts);
    assert!(!out.success, "{out:?}");
    let first = out.failure.as_ref().expect("a failure").name();
    assert!(!out.also_failed.is_empty(), "{out:?}");
    assert!(
        out.also_failed
            .iter()
            .all(|a| !a.starts_with(&format!("{first}:"))),
        "{:?}",
        out.also_failed
    );
    let cause = out.likely_cause.clone().expect("a likely cause");
    assert!(
        cause.contains("-0.300 m") || cause.contains("0.300 m"),
        "{cause}"
    );
    let line = out.verdict_line();
    assert!(
        line.contains("likely cause") && line.contains("; also "),
        "{line}"
    );
}

/// A scanner's `rate_hz` sets how often a look gets a new frame from it: at one frame in
/// 100 s, the re-estimates during the approach get nothing new (missed, the first estimate
/// kept); at its datasheet's 15 Hz every look gets one.
#[test]
fn a_scanners_frame_rate_bounds_its_looks() {
    let far = "{ x_m = 8.0, y_m = 0.3, heading_deg = 2.0 }";
    let run = |rate: &str| {
        let extra = format!(
            "[replan]\nenabled = true\n[sensors.pallet]\nkind = \"tim561\"\n\
             [sensors.pallet.scanner]\n{rate}"
        );
        let scn = scenario(&extra, far).expect("loads");
        run_trial(&scn, &scn.cases[0], &TrialOptions::default())
    };
    let fast = run("");
    assert!(fast.estimates >= 3, "{fast:?}");
    assert_eq!(fast.estimates_missed, 0);
    let slow = run("rate_hz = 0.01\n");
    assert_eq!(
        slow.estimates, fast.estimates,
        "the same looks are asked for"
    );
    assert_eq!(slow.estimates_missed, slow.estimates - 1, "{slow:?}");
}

/// What a trial's plans and replans were: (time, replan number) of each plan, and the
/// range of each "replan at R m" event.
#[derive(Default)]
struct Plans {
    at: Vec<(f64, u32)>,
    replan_ranges_m: Vec<f64>,
}

impl forkbench_trial::Recorder for Plans {
    fn plan(&mut self, t: f64, i: u32, _: &forkbench_core::Path, _: Option<&[[f64; 2]]>) {
        self.at.push((t, i));
    }
    fn event(&mut self, _: f64, _: forkbench_trial::Level, text: &str) {
        if let Some(r) = text
            .strip_prefix("replan at ")
            .and_then(|r| r.split(' ').next())
        {
            self.replan_ranges_m.push(r.parse().expect("a range"));
        }
    }
}

fn plans(scn: &Scenario, seed: u64) -> Plans {
    let mut rec = Plans::default();
    let opts = TrialOptions {
        seed: Some(seed),
        ..TrialOptions::default()
    };
    forkbench_trial::run_trial_recorded(scn, &scn.cases[0], &opts, &mut rec);
    rec
}

/// A detector's estimate reaches the controller its latency after the scan: the first
/// plan waits for it, and a re-estimate's replan comes that much later, nearer the pallet.
#[test]
fn a_detectors_latency_delays_its_estimates() {
    let with = |latency_s: f64| {
        let extra = format!(
            "[replan]\nenabled = true\nreestimate_at_m = [3.5]\n\
             [sensors.pallet]\nkind = \"tim561\"\nlatency_s = {latency_s}\n"
        );
        scenario(&extra, NEAR).expect("loads")
    };
    let (prompt, late) = (plans(&with(0.0), 3), plans(&with(0.6), 3));
    let first = |p: &Plans| p.at.first().expect("a first plan").0;
    assert!(
        first(&late) - first(&prompt) > 0.6 - 0.011,
        "{:?} vs {:?}",
        late.at,
        prompt.at
    );
    // The re-estimate at 3.5 m replans once its estimate arrives: 0.6 s of driving later.
    let (a, b) = (&prompt.replan_ranges_m, &late.replan_ranges_m);
    assert!(!a.is_empty() && !b.is_empty(), "{a:?} {b:?}");
    assert!(
        b[0] < a[0] - 0.3,
        "replanned at {} m, without latency {} m",
        b[0],
        a[0]
    );
    // Refused where it cannot act, or out of range, naming the field.
    let e = scenario(
        "[sensors.pallet]\nkind = \"gaussian\"\nlatency_s = 0.1\n",
        NEAR,
    )
    .expect_err("gaussian")
    .to_string();
    assert!(e.contains("sensors.pallet.latency_s"), "{e}");
    let e = scenario(
        "[sensors.pallet]\nkind = \"tim561\"\nlatency_s = -1.0\n",
        NEAR,
    )
    .expect_err("negative")
    .to_string();
    assert!(e.contains("sensors.pallet.latency_s"), "{e}");
}
