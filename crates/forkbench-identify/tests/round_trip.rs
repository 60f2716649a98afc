//! Round trip: step-test logs of trucks with known actuators, simulated in the physics, are identified within 20 ms, 20 % and 20 %, with a held-out fit of at least 90 %.

use forkbench_core::ForkliftSpec;
use forkbench_core::actuators::SteeringActuator;
use forkbench_identify::excite::{StepTest, step_test};
use forkbench_identify::{identify, parse_csv, to_csv};
use forkbench_sim::SimConfig;

/// The A30 with the first truck's actuators: what a test sets is all there is.
fn ideal() -> ForkliftSpec {
    ForkliftSpec::default().with_actuators(forkbench_core::actuators::Actuators::IDEAL)
}

fn truck(dead_s: f64, tau_s: f64, rate: f64) -> ForkliftSpec {
    ForkliftSpec {
        max_steer_rate_radps: rate,
        steering: SteeringActuator {
            dead_time_s: dead_s,
            time_constant_s: tau_s,
            ..SteeringActuator::IDEAL
        },
        ..ideal()
    }
}

#[test]
fn hidden_steering_actuators_are_recovered_from_their_logs() {
    // Corners and the middle of the ranges: 0.05–0.4 s, 0.05–0.5 s, 0.3–2 rad/s.
    let cases = [
        (0.05, 0.05, 0.3),
        (0.4, 0.5, 2.0),
        (0.2, 0.2, 1.0),
        (0.05, 0.5, 0.3),
        (0.4, 0.05, 2.0),
        (0.13, 0.31, 0.7),
    ];
    for (k, &(d, tau, rate)) in cases.iter().enumerate() {
        let test = StepTest {
            runs: 8,
            run_s: 20.0,
            seed: 100 + k as u64,
            steering: true,
        };
        let log =
            step_test(&truck(d, tau, rate), &SimConfig::default(), &test).expect("valid truck");
        // Through the CSV, as a user's log arrives.
        let log = parse_csv(&to_csv(&log), "log.csv").expect("reads back");
        let got = identify(&log).expect("identified");
        let steer = got
            .channels
            .iter()
            .find(|c| c.channel == "steering")
            .expect("steering");
        let s = &steer.settings;
        let fd = s["steering.dead_time_s"];
        let ft = s["steering.time_constant_s"];
        let fr = s
            .get("max_steer_rate_radps")
            .copied()
            .unwrap_or(f64::INFINITY);
        let case = format!(
            "d {d}, τ {tau}, r {rate}: fitted d {fd:.3}, τ {ft:.3}, r {fr:.3}, fit {:.1} %",
            steer.fit_percent
        );
        assert!((fd - d).abs() <= 0.02, "{case}");
        assert!((ft - tau).abs() <= 0.2 * tau, "{case}");
        assert!((fr - rate).abs() <= 0.2 * rate, "{case}");
        assert!(
            steer.fit_percent >= 90.0 && steer.held_out_runs >= 2,
            "{case}"
        );
    }
}

#[test]
fn the_ideal_drive_fits_its_speed_loop() {
    // Driving straight: a steered rear tyre drags the truck, which no speed model holds.
    let test = StepTest {
        steering: false,
        ..StepTest::default()
    };
    let log = step_test(&ideal(), &SimConfig::default(), &test).expect("valid");
    let log = parse_csv(&to_csv(&log), "log.csv").expect("reads back");
    let got = identify(&log).expect("identified");
    assert_eq!(got.channels.len(), 1, "no steering channel");
    let drive = &got.channels[0];
    // The [sim] speed loop: gain 4/s (τ 0.25 s), no dead time, 1 m/s² both ways.
    let s = &drive.settings;
    assert!(s["drive.dead_time_s"] <= 0.01, "{s:?}");
    assert!((s["drive.time_constant_s"] - 0.25).abs() < 0.025, "{s:?}");
    for limit in ["drive.accel_limit_mps2", "drive.brake_limit_mps2"] {
        if let Some(v) = s.get(limit) {
            assert!((v - 1.0).abs() < 0.1, "{limit}: {s:?}");
        }
    }
    assert!(drive.fit_percent >= 90.0, "{}", drive.fit_percent);
}

#[test]
fn logs_that_cannot_be_fitted_are_refused_with_the_reason() {
    let still = "t_s,steer_cmd_rad,steer_rad\n".to_owned()
        + &(0..500)
            .map(|k| format!("{},0.1,0.1\n", k as f64 * 0.01))
            .collect::<String>();
    let e = identify(&parse_csv(&still, "l.csv").expect("valid")).expect_err("no excitation");
    assert!(e.to_string().contains("no excitation"), "{e}");
    let short = "t_s,steer_cmd_rad,steer_rad\n0,0,0\n0.01,0.2,0\n";
    let e = identify(&parse_csv(short, "l.csv").expect("valid")).expect_err("short");
    assert!(e.to_string().contains("too short"), "{e}");
}
