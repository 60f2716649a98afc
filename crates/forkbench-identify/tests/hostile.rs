//! Logs that carry no information, or too much: values beyond any truck are refused naming the cell, a response that never moves is refused, runs too short are left out, a fast log is thinned and a long one bounded, each said in a note.

use forkbench_core::ForkliftSpec;
use forkbench_core::actuators::SteeringActuator;
use forkbench_identify::excite::{StepTest, step_test};
use forkbench_identify::{IdentifyError, LogError, identify, parse_csv, to_csv};
use forkbench_sim::SimConfig;

/// A CSV log of one steering run: `f(k)` gives the command and the measured angle.
fn steering_csv(n: usize, dt: f64, f: impl Fn(usize) -> (f64, f64)) -> String {
    let mut s = String::from("t_s,steer_cmd_rad,steer_rad\n");
    for k in 0..n {
        let (c, m) = f(k);
        s.push_str(&format!("{},{c},{m}\n", k as f64 * dt));
    }
    s
}

#[test]
fn values_beyond_any_truck_are_refused_naming_the_cell() {
    // Alternating ±1e308 (once a panic in the fit), and one 1e300 spike in a sane log.
    let huge = steering_csv(500, 0.01, |k| {
        let v = if k % 2 == 0 { 1e308 } else { -1e308 };
        (v, v)
    });
    let spike = steering_csv(500, 0.01, |k| (0.2, if k == 250 { 1e300 } else { 0.1 }));
    for (text, line, column) in [(huge, 2, "steer_cmd_rad"), (spike, 252, "steer_rad")] {
        match parse_csv(&text, "log.csv") {
            Err(LogError::Cell {
                line: l,
                column: c,
                reason,
                ..
            }) => {
                assert_eq!((l, c.as_str()), (line, column), "{reason}");
                assert!(reason.contains("beyond"), "{reason}");
            }
            other => panic!("not refused: {other:?}"),
        }
    }
}

#[test]
fn a_response_that_never_moves_is_refused() {
    // The wheel held at its stop while the command swings: any dynamics fit it.
    let text = steering_csv(800, 0.01, |k| {
        (if (k / 100) % 2 == 0 { 0.3 } else { -0.3 }, 0.6)
    });
    let log = parse_csv(&text, "log.csv").expect("reads");
    let e = identify(&log).expect_err("refused");
    assert!(matches!(e, IdentifyError::NoResponse { .. }), "{e}");
    assert!(e.to_string().contains("no response"), "{e}");
}

#[test]
fn runs_too_short_to_fit_are_left_out_and_none_left_is_refused() {
    // 400 runs of 3 samples.
    let mut s = String::from("run,t_s,steer_cmd_rad,steer_rad\n");
    for r in 0..400 {
        for k in 0..3 {
            s.push_str(&format!(
                "{r},{},{},{}\n",
                k as f64 * 0.01,
                0.1 * k as f64,
                0.05 * k as f64
            ));
        }
    }
    let log = parse_csv(&s, "log.csv").expect("reads");
    let e = identify(&log).expect_err("refused");
    assert!(
        matches!(e, IdentifyError::TooShort { samples: 0, .. }),
        "{e}"
    );
}

/// A truck whose steering is known, logged by a step test at `rate_hz`.
fn logged_at(rate_hz: f64, runs: usize, run_s: f64) -> forkbench_identify::ActuatorLog {
    let truck = ForkliftSpec {
        max_steer_rate_radps: 0.8,
        steering: SteeringActuator {
            dead_time_s: 0.1,
            time_constant_s: 0.15,
            ..SteeringActuator::IDEAL
        },
        ..ForkliftSpec::default().with_actuators(forkbench_core::actuators::Actuators::IDEAL)
    };
    let sim = SimConfig {
        dt_s: 1.0 / rate_hz,
        ..SimConfig::default()
    };
    let test = StepTest {
        runs,
        run_s,
        seed: 9,
        steering: true,
    };
    let log = step_test(&truck, &sim, &test).expect("valid truck");
    parse_csv(&to_csv(&log), "log.csv").expect("reads back")
}

#[test]
fn a_fast_log_is_thinned_to_the_fit_rate_and_still_identified() {
    let log = logged_at(1000.0, 4, 10.0);
    let got = identify(&log).expect("identified");
    let steer = &got.channels[0];
    assert!(
        steer
            .notes
            .iter()
            .any(|n| n.contains("thinned to about 100 Hz")),
        "{:?}",
        steer.notes
    );
    assert!((steer.dead_time_step_s - 0.01).abs() < 1e-9);
    let d = steer.settings["steering.dead_time_s"];
    assert!((d - 0.1).abs() <= 0.03, "dead time {d}");
    assert!(got.text().contains("0.010 s grid"), "{}", got.text());
}
